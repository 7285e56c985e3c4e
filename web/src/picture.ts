// Pictures that travel by what changed (docs/api.md "Pictures"): the ray image is fetched whole once per
// document and channel, then after each edit only the box of pixels that changed (GET image.png?since=V, with
// X-Lidarshop-Box), which is patched into the picture held; overlays come cropped to the box of their drawn
// cells (crop=1). A large scan's edit then moves a few kilobytes of picture, not megabytes.

// A box of cells: column, row, width, height (empty when width or height is 0).
export interface Box {
  col: number;
  row: number;
  width: number;
  height: number;
}

// Parses "col,row,width,height" (X-Lidarshop-Box); null when absent or malformed.
export function parseBox(header: string | null): Box | null {
  if (header === null) return null;
  const parts = header.split(',').map((part) => Number(part.trim()));
  if (parts.length !== 4 || parts.some((value) => !Number.isInteger(value) || value < 0)) return null;
  const [col, row, width, height] = parts;
  return { col, row, width, height };
}

// Copies the RGBA pixels of `patch` (box.width x box.height) into `target` (RGBA, width x height) at the box.
// Throws when the box does not lie inside the target or the patch has the wrong size: a patch for another
// picture must not be drawn.
export function patchPixels(
  target: Uint8ClampedArray,
  width: number,
  height: number,
  patch: Uint8ClampedArray,
  box: Box,
): void {
  if (box.col + box.width > width || box.row + box.height > height) {
    throw new Error(
      `picture patch ${box.width} x ${box.height} at (${box.col}, ${box.row}) lies outside the ${width} x ${height} picture`,
    );
  }
  if (target.length !== 4 * width * height || patch.length !== 4 * box.width * box.height) {
    throw new Error(`picture patch: ${patch.length} bytes for a ${box.width} x ${box.height} box`);
  }
  for (let r = 0; r < box.height; ++r) {
    const from = 4 * r * box.width;
    target.set(patch.subarray(from, from + 4 * box.width), 4 * ((box.row + r) * width + box.col));
  }
}

// An overlay drawn over the ray image: its picture and the box of cells it covers.
export interface Overlay {
  image: CanvasImageSource;
  box: Box;
}

// RGBA pixels of an encoded image (PNG).
async function decode(blob: Blob): Promise<ImageData> {
  const bitmap = await createImageBitmap(blob);
  const canvas = document.createElement('canvas');
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  const context = canvas.getContext('2d', { willReadFrequently: true })!;
  context.drawImage(bitmap, 0, 0);
  bitmap.close();
  return context.getImageData(0, 0, canvas.width, canvas.height);
}

// Loads an overlay asked with crop=1 (the whole picture when the server sent no box); null when it draws nothing.
export async function loadOverlay(
  url: string,
  rows: number,
  cols: number,
  count: (bytes: number) => void,
): Promise<Overlay | null> {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`could not load ${url.split('?')[0]}: ${response.status}`);
  const blob = await response.blob();
  count(blob.size);
  const box = parseBox(response.headers.get('X-Lidarshop-Box')) ?? {
    col: 0,
    row: 0,
    width: cols,
    height: rows,
  };
  if (box.width === 0 || box.height === 0) return null;
  return { image: await createImageBitmap(blob), box };
}

// The ray images held, per document and channel, each with the version it shows; answers are applied one at a
// time (a patch is the change from the version held, so two must not overlap).
export class PictureStore {
  bytes = 0; // bytes of pictures received, for tests
  private held = new Map<string, { version: number; canvas: HTMLCanvasElement; pixels: ImageData }>();
  private chain: Promise<unknown> = Promise.resolve();

  // The ray image of `channel` of document `id` at the server's current version (at least `version`).
  picture(
    url: (params: Record<string, string | number>) => string,
    id: number,
    channel: string,
    version: number,
  ): Promise<HTMLCanvasElement> {
    const next = this.chain.then(() => this.fetchPicture(url, id, channel, version));
    this.chain = next.catch(() => {});
    return next;
  }

  // The picture held for a document and channel, and its version (tests).
  heldPicture(id: number, channel: string) {
    const held = this.held.get(`${id}:${channel}`);
    return held ? { version: held.version, canvas: held.canvas } : null;
  }

  // Forgets a document's pictures (closed).
  forget(id: number) {
    for (const key of [...this.held.keys()]) if (key.startsWith(`${id}:`)) this.held.delete(key);
  }

  private async fetchPicture(
    url: (params: Record<string, string | number>) => string,
    id: number,
    channel: string,
    version: number,
  ) {
    const key = `${id}:${channel}`;
    const held = this.held.get(key);
    if (held && held.version >= version) return held.canvas;
    const response = await fetch(
      url(held ? { channel, v: version, since: held.version } : { channel, v: version }),
    );
    if (!response.ok)
      throw new Error(`ray image: ${response.status} ${(await response.text()).slice(0, 200)}`);
    const blob = await response.blob();
    this.bytes += blob.size;
    const shows = Number(response.headers.get('X-Lidarshop-Version') ?? version);
    const box = parseBox(response.headers.get('X-Lidarshop-Box'));
    if (held && box) {
      if (box.width > 0 && box.height > 0) {
        const patch = await decode(blob);
        patchPixels(held.pixels.data, held.pixels.width, held.pixels.height, patch.data, box);
        held.canvas
          .getContext('2d')!
          .putImageData(held.pixels, 0, 0, box.col, box.row, box.width, box.height);
      }
      held.version = shows;
      return held.canvas;
    }
    const pixels = await decode(blob);
    const canvas = document.createElement('canvas');
    canvas.width = pixels.width;
    canvas.height = pixels.height;
    canvas.getContext('2d')!.putImageData(pixels, 0, 0);
    this.held.set(key, { version: shows, canvas, pixels });
    return canvas;
  }
}

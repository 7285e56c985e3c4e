// The ray image of a large scan as a tile pyramid (docs/api.md "Tiles"): GET tiles.json describes the levels
// (0 = one pixel per ray, each level halving), GET tiles/LEVEL/TX/TY.png one 256-pixel tile. The view fetches
// only the tiles it shows, at the level its zoom needs; the coarsest level (one tile for the whole picture)
// comes first, so a station of millions of rays shows its first picture at once and is refined where the user
// looks. After an edit, tiles.json?since=V names the box of pixels that changed since the version held: only
// held tiles meeting it are dropped and fetched again. The browser never holds the full-resolution picture.
import type { TileLevelEntry, TilesReply } from './api_types.generated';
import type { Narrowed } from './api';
import type { ImageView } from './strokes';

// One level of the pyramid (tiles.json "levels"), as the server describes it.
export type TileLevel = TileLevelEntry;

// GET /api/docs/ID/tiles.json[?channel=C&since=V]: `changed` is col, row, width, height of level-0 pixels
// (0 0 0 0: none).
export type TilesInfo = Narrowed<TilesReply, { changed: [number, number, number, number] }>;

// A box of level-0 cells.
export interface CellBox {
  col: number;
  row: number;
  width: number;
  height: number;
}

export function boxesMeet(a: CellBox, b: CellBox): boolean {
  return (
    a.width > 0 &&
    a.height > 0 &&
    b.width > 0 &&
    b.height > 0 &&
    a.col < b.col + b.width &&
    b.col < a.col + a.width &&
    a.row < b.row + b.height &&
    b.row < a.row + a.height
  );
}

// The level that shows about one tile pixel per screen pixel: a cell drawn `scale` screen pixels wide (and
// `scale * aspect` high) needs level floor(log2(1 / the larger)), between 0 and the coarsest.
export function levelFor(view: Pick<ImageView, 'scale' | 'aspect'>, coarsest: number): number {
  const pixels = view.scale * Math.max(1, view.aspect);
  if (!(pixels > 0)) return coarsest;
  return Math.min(coarsest, Math.max(0, Math.floor(Math.log2(1 / pixels) + 1e-9)));
}

// The level-0 cells tile (tx, ty) of `level` covers (clipped to the picture).
export function tileFootprint(
  info: Pick<TilesInfo, 'rows' | 'cols' | 'tile_px'>,
  level: number,
  tx: number,
  ty: number,
): CellBox {
  const span = info.tile_px * 2 ** level;
  const col = tx * span,
    row = ty * span;
  return {
    col,
    row,
    width: Math.max(0, Math.min(span, info.cols - col)),
    height: Math.max(0, Math.min(span, info.rows - row)),
  };
}

// The cells of the picture a canvas of width x height screen pixels shows through `view`.
export function visibleCells(
  view: ImageView,
  width: number,
  height: number,
  rows: number,
  cols: number,
): CellBox {
  const col0 = Math.max(0, Math.floor(-view.offsetX / view.scale));
  const col1 = Math.min(cols, Math.ceil((width - view.offsetX) / view.scale));
  const rowScale = view.scale * view.aspect;
  const row0 = Math.max(0, Math.floor(-view.offsetY / rowScale));
  const row1 = Math.min(rows, Math.ceil((height - view.offsetY) / rowScale));
  return { col: col0, row: row0, width: Math.max(0, col1 - col0), height: Math.max(0, row1 - row0) };
}

// The tiles of `level` that meet `cells`, nearest the centre first.
export function tilesMeeting(info: TilesInfo, level: number, cells: CellBox): { tx: number; ty: number }[] {
  const span = info.tile_px * 2 ** level;
  const { tiles_x, tiles_y } = info.levels[level];
  if (cells.width <= 0 || cells.height <= 0) return [];
  const tx0 = Math.max(0, Math.floor(cells.col / span)),
    tx1 = Math.min(tiles_x - 1, Math.floor((cells.col + cells.width - 1) / span));
  const ty0 = Math.max(0, Math.floor(cells.row / span)),
    ty1 = Math.min(tiles_y - 1, Math.floor((cells.row + cells.height - 1) / span));
  const tiles: { tx: number; ty: number }[] = [];
  for (let ty = ty0; ty <= ty1; ++ty) for (let tx = tx0; tx <= tx1; ++tx) tiles.push({ tx, ty });
  const cx = (tx0 + tx1) / 2,
    cy = (ty0 + ty1) / 2;
  return tiles.sort((a, b) => Math.hypot(a.tx - cx, a.ty - cy) - Math.hypot(b.tx - cx, b.ty - cy));
}

interface HeldTile {
  image: CanvasImageSource & { width: number; height: number };
  level: number;
  tx: number;
  ty: number;
  version: number; // the document version of the answer
  used: number;
}

const MOST_TILES = 600; // held at once (256 x 256 RGBA each: about 160 MB at most); the least used go first
const AT_ONCE = 6; // requests in flight (a browser's connections per host)

type Url = (path: string, params: Record<string, string | number>) => string;

// The tiles of one document and channel held by the browser, at the version `version` of the document.
export class TiledPicture {
  bytes = 0; // bytes of tiles and tile descriptions received, for tests
  onTile: () => void = () => {};
  private held = new Map<string, HeldTile>();
  private wanted: { level: number; tx: number; ty: number }[] = [];
  private inFlight = new Set<string>();
  private uses = 0;
  private idle: (() => void)[] = [];

  private constructor(
    private url: Url,
    readonly id: number,
    readonly channel: string,
    public info: TilesInfo,
  ) {}

  // The pyramid of document `id` in `channel`, with its coarsest level loaded (the first picture).
  static async open(url: Url, id: number, channel: string): Promise<TiledPicture> {
    const response = await fetch(url(`/api/docs/${id}/tiles.json`, { channel }));
    if (!response.ok) throw new Error(`tiles: ${response.status} ${(await response.text()).slice(0, 200)}`);
    const text = await response.text();
    const picture = new TiledPicture(url, id, channel, JSON.parse(text) as TilesInfo);
    picture.bytes += text.length;
    await picture.loadCoarsest();
    return picture;
  }

  get version() {
    return this.info.version;
  }
  get rows() {
    return this.info.rows;
  }
  get cols() {
    return this.info.cols;
  }
  get coarsest() {
    return this.info.levels.length - 1;
  }

  // Brings the picture to the server's current version (at least `version`): only held tiles that meet the box
  // of pixels changed since the version held are dropped; the coarsest level is loaded again when it was.
  async update(version: number): Promise<void> {
    if (version <= this.info.version) return;
    const response = await fetch(
      this.url(`/api/docs/${this.id}/tiles.json`, {
        channel: this.channel,
        since: this.info.version,
        v: version,
      }),
    );
    if (!response.ok) throw new Error(`tiles: ${response.status} ${(await response.text()).slice(0, 200)}`);
    const text = await response.text();
    this.bytes += text.length;
    const next = JSON.parse(text) as TilesInfo;
    const [col, row, width, height] = next.changed;
    const changed = { col, row, width, height };
    const sameGrid = next.rows === this.info.rows && next.cols === this.info.cols;
    for (const [key, tile] of this.held) {
      const keep =
        sameGrid &&
        (tile.version === next.version ||
          (tile.version === this.info.version &&
            !boxesMeet(changed, tileFootprint(next, tile.level, tile.tx, tile.ty))));
      if (keep) tile.version = next.version;
      else this.held.delete(key);
    }
    this.info = next;
    this.wanted = [];
    await this.loadCoarsest();
  }

  // Draws the held tiles that `view` shows (coarse ones under finer ones) and asks for the missing ones of
  // the level the view needs.
  draw(context: CanvasRenderingContext2D, view: ImageView, width: number, height: number) {
    const { rows, cols } = this.info;
    const cells = visibleCells(view, width, height, rows, cols);
    const level = levelFor(view, this.coarsest);
    context.save();
    context.beginPath();
    context.rect(view.offsetX, view.offsetY, cols * view.scale, rows * view.scale * view.aspect);
    context.clip();
    const tiles = [...this.held.values()]
      .filter((t) => t.level >= level && boxesMeet(cells, tileFootprint(this.info, t.level, t.tx, t.ty)))
      .sort((a, b) => b.level - a.level);
    for (const tile of tiles) {
      const span = this.info.tile_px * 2 ** tile.level;
      const factor = 2 ** tile.level;
      context.drawImage(
        tile.image,
        view.offsetX + tile.tx * span * view.scale,
        view.offsetY + tile.ty * span * view.scale * view.aspect,
        tile.image.width * factor * view.scale,
        tile.image.height * factor * view.scale * view.aspect,
      );
      tile.used = ++this.uses;
    }
    context.restore();
    this.wanted = tilesMeeting(this.info, level, cells)
      .map(({ tx, ty }) => ({ level, tx, ty }))
      .filter((t) => !this.held.has(key(t.level, t.tx, t.ty)));
    this.pump();
  }

  // Resolves when every tile the last drawn view needs is held.
  settled(): Promise<void> {
    if (this.wanted.length === 0 && this.inFlight.size === 0) return Promise.resolve();
    return new Promise((resolve) => this.idle.push(resolve));
  }

  // Tiles held and asked (tests).
  counts() {
    const levels: Record<number, number> = {};
    for (const tile of this.held.values()) levels[tile.level] = (levels[tile.level] ?? 0) + 1;
    return { held: this.held.size, wanted: this.wanted.length, inFlight: this.inFlight.size, levels };
  }

  // Compares every held tile of the current version with the server's (fetched anew): '' when all agree, else
  // what differs (tests: the tiles kept across an edit must be the server's).
  async mismatch(): Promise<string> {
    const problems: string[] = [];
    for (const tile of [...this.held.values()]) {
      if (tile.version !== this.info.version) continue;
      const fresh = await createImageBitmap(
        await (
          await fetch(
            this.url(`/api/docs/${this.id}/tiles/${tile.level}/${tile.tx}/${tile.ty}.png`, {
              channel: this.channel,
              v: this.info.version,
              fresh: Date.now(),
            }),
          )
        ).blob(),
      );
      const a = pixelsOf(fresh),
        b = pixelsOf(tile.image);
      if (a.length !== b.length) problems.push(`tile ${tile.level}/${tile.tx}/${tile.ty}: sizes differ`);
      else if (a.some((value, i) => value !== b[i]))
        problems.push(`tile ${tile.level}/${tile.tx}/${tile.ty}: pixels differ`);
    }
    return problems.join('; ');
  }

  private async loadCoarsest() {
    const level = this.coarsest;
    const { tiles_x, tiles_y } = this.info.levels[level];
    const loads: Promise<void>[] = [];
    for (let ty = 0; ty < tiles_y; ++ty)
      for (let tx = 0; tx < tiles_x; ++tx)
        if (!this.held.has(key(level, tx, ty))) loads.push(this.load(level, tx, ty));
    await Promise.all(loads);
  }

  private pump() {
    while (this.inFlight.size < AT_ONCE && this.wanted.length > 0) {
      const next = this.wanted.shift()!;
      const k = key(next.level, next.tx, next.ty);
      if (this.held.has(k) || this.inFlight.has(k)) continue;
      void this.load(next.level, next.tx, next.ty)
        .then(() => this.onTile())
        .catch(() => {});
    }
    if (this.wanted.length === 0 && this.inFlight.size === 0) {
      for (const resolve of this.idle.splice(0)) resolve();
    }
  }

  private async load(level: number, tx: number, ty: number) {
    const k = key(level, tx, ty);
    this.inFlight.add(k);
    try {
      const version = this.info.version;
      const response = await fetch(
        this.url(`/api/docs/${this.id}/tiles/${level}/${tx}/${ty}.png`, {
          channel: this.channel,
          v: version,
        }),
      );
      if (!response.ok) throw new Error(`tile ${level}/${tx}/${ty}: ${response.status}`);
      const blob = await response.blob();
      this.bytes += blob.size;
      const shows = Number(response.headers.get('X-Lidarshop-Version') ?? version);
      // An answer about a version older than the one held now (an edit came in between) is not kept.
      if (shows < this.info.version) return;
      const image = await createImageBitmap(blob);
      this.held.set(k, { image, level, tx, ty, version: shows, used: ++this.uses });
      this.trim();
    } finally {
      this.inFlight.delete(k);
      this.pump();
    }
  }

  private trim() {
    if (this.held.size <= MOST_TILES) return;
    const coarsest = this.coarsest;
    const order = [...this.held.entries()]
      .filter(([, tile]) => tile.level !== coarsest)
      .sort((a, b) => a[1].used - b[1].used);
    for (const [k, tile] of order.slice(0, this.held.size - MOST_TILES)) {
      if ('close' in tile.image) (tile.image as ImageBitmap).close();
      this.held.delete(k);
    }
  }
}

function key(level: number, tx: number, ty: number) {
  return `${level}/${tx}/${ty}`;
}

function pixelsOf(image: CanvasImageSource & { width: number; height: number }): Uint8ClampedArray {
  const canvas = document.createElement('canvas');
  canvas.width = image.width;
  canvas.height = image.height;
  const context = canvas.getContext('2d', { willReadFrequently: true })!;
  context.drawImage(image, 0, 0);
  return context.getImageData(0, 0, canvas.width, canvas.height).data;
}

// The pyramids held, per document and channel; their updates are applied one at a time.
export class TileStore {
  private forgottenBytes = 0;
  private held = new Map<string, TiledPicture>();
  private chain: Promise<unknown> = Promise.resolve();

  constructor(private url: Url) {}

  // The picture of `channel` of document `id` at the server's current version (at least `version`; -1: as held).
  picture(id: number, channel: string, version: number): Promise<TiledPicture> {
    const next = this.chain.then(async () => {
      const k = `${id}:${channel}`;
      let picture = this.held.get(k);
      if (!picture) {
        picture = await TiledPicture.open(this.url, id, channel);
        this.held.set(k, picture);
      } else if (version >= 0) {
        await picture.update(version);
      }
      return picture;
    });
    this.chain = next.catch(() => {});
    return next;
  }

  // The bytes received by every pyramid (tiles arriving after `picture` resolved included).
  totalBytes() {
    let total = this.forgottenBytes;
    for (const picture of this.held.values()) total += picture.bytes;
    return total;
  }

  heldPicture(id: number, channel: string) {
    return this.held.get(`${id}:${channel}`) ?? null;
  }

  forget(id: number) {
    for (const [k, picture] of [...this.held.entries()]) {
      if (!k.startsWith(`${id}:`)) continue;
      this.forgottenBytes += picture.bytes;
      this.held.delete(k);
    }
  }
}

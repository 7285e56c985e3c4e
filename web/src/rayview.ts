// The scan's ray image on a canvas: any channel, zoom (wheel) and pan (drag with the pick tool or the middle
// button), strokes painted with the brushes, the segmented object tinted, the picked cell marked. The strokes
// drawn are the server's (its overlay image of the document's state): an undone stroke disappears, and a
// stroke keeps the radius it was painted with. A stroke is drawn locally only until the server's state
// that holds it is shown.
import { Overlay } from './picture';
import { TiledPicture } from './tiles';
import { Cell, ImageView, cellsAlong, cellToScreen, fitView, screenToCell, zoomAt } from './strokes';

export type Brush = 'object' | 'background' | 'erase' | 'hole' | 'lasso' | 'none';

export class RayView {
  brush: Brush = 'object';
  radius = 2;
  onStroke: (brush: Brush, cells: Cell[]) => void = () => {};
  onPick: (cell: Cell) => void = () => {};

  private image: CanvasImageSource | TiledPicture | null = null; // a large scan's picture: tiles (tiles.ts)
  private mask: Overlay | null = null;
  private holeMask: Overlay | null = null;
  private strokeImage: Overlay | null = null;
  // The document and version of the pictures shown, and when the frame showing them was drawn (performance.now;
  // -1 until then): what a stroke's round trip is timed to.
  private shown = { id: -1, version: -1, drawnAt: -1 };
  private view: ImageView = { scale: 1, aspect: 1, offsetX: 0, offsetY: 0 };
  private rows = 0;
  private cols = 0;
  private pending: { brush: Brush; cells: Cell[]; radius: number } | null = null;
  // Strokes sent to the server and not yet in a state shown (each with the radius it was painted with).
  private sent: { brush: Brush; cells: Cell[]; radius: number }[] = [];
  private picked: Cell | null = null;
  private panFrom: { x: number; y: number } | null = null;

  constructor(private canvas: HTMLCanvasElement) {
    canvas.addEventListener(
      'wheel',
      (event) => {
        event.preventDefault();
        this.view = zoomAt(this.view, event.deltaY < 0 ? 1.25 : 0.8, event.offsetX, event.offsetY);
        this.draw();
      },
      { passive: false },
    );
    canvas.addEventListener('pointerdown', (event) => this.down(event));
    canvas.addEventListener('pointermove', (event) => this.move(event));
    canvas.addEventListener('pointerup', () => this.up());
    canvas.addEventListener('pointerleave', () => this.up());
    new ResizeObserver(() => this.fit()).observe(canvas);
  }

  // Shows the pictures of version `version` of document `id`; an answer older than the one shown (an
  // overlapping refresh that finished late) is dropped. False when dropped.
  // The picture and overlays are URLs of whole images or what was loaded already (picture.ts: patched ray
  // images, cropped overlays).
  async show(
    id: number,
    version: number,
    imageSource: string | CanvasImageSource | Promise<CanvasImageSource | TiledPicture>,
    maskSource: OverlaySource,
    holeSource: OverlaySource,
    strokesSource: OverlaySource,
    rows: number,
    cols: number,
    aspect: number,
    keepView: boolean,
  ): Promise<boolean> {
    const whole = (image: CanvasImageSource): Overlay => ({
      image,
      box: { col: 0, row: 0, width: cols, height: rows },
    });
    const optional = async (source: OverlaySource): Promise<Overlay | null> =>
      typeof source === 'string' ? whole(await loadImage(source)) : source;
    const [image, mask, hole, strokes] = await Promise.all([
      typeof imageSource === 'string' ? loadImage(imageSource) : imageSource,
      optional(maskSource),
      optional(holeSource),
      optional(strokesSource),
    ]);
    if (id === this.shown.id && version < this.shown.version) return false;
    const shown = { id, version, drawnAt: -1 };
    this.shown = shown;
    this.holeMask = hole;
    this.strokeImage = strokes;
    this.sent = [];
    const sizeChanged = rows !== this.rows || cols !== this.cols;
    this.image = image;
    if (image instanceof TiledPicture) image.onTile = () => this.draw();
    this.mask = mask;
    this.rows = rows;
    this.cols = cols;
    this.view.aspect = aspect;
    if (!keepView || sizeChanged) this.fit();
    this.draw();
    requestAnimationFrame(() => (shown.drawnAt = performance.now()));
    return true;
  }

  // The document and version shown (tests).
  shownState() {
    return { ...this.shown, sent: this.sent.length };
  }

  // Drops strokes drawn locally but not sent (e.g. when another document is shown).
  clearStrokes() {
    this.sent = [];
    this.pending = null;
    this.draw();
  }

  // Fits the image into the canvas (F).
  fitToView() {
    this.fit();
  }

  pick(cell: Cell | null) {
    this.picked = cell;
    this.draw();
  }

  // Screen position of a cell's centre in the canvas, for tests and tools.
  screenOf(cell: Cell) {
    return cellToScreen(this.view, cell);
  }

  private fit() {
    const rect = this.canvas.getBoundingClientRect();
    this.canvas.width = Math.max(1, Math.round(rect.width));
    this.canvas.height = Math.max(1, Math.round(rect.height));
    if (this.rows > 0)
      this.view = fitView(this.rows, this.cols, this.view.aspect, this.canvas.width, this.canvas.height);
    this.draw();
  }

  private down(event: PointerEvent) {
    this.canvas.setPointerCapture(event.pointerId);
    if (this.brush === 'none' || event.button === 1) {
      this.panFrom = { x: event.offsetX, y: event.offsetY };
      const cell = screenToCell(this.view, event.offsetX, event.offsetY, this.rows, this.cols);
      if (cell && this.brush === 'none') this.onPick(cell);
      return;
    }
    const cell = screenToCell(this.view, event.offsetX, event.offsetY, this.rows, this.cols);
    if (cell) this.pending = { brush: this.brush, cells: [cell], radius: this.radius };
  }

  private move(event: PointerEvent) {
    if (this.panFrom) {
      this.view = {
        ...this.view,
        offsetX: this.view.offsetX + event.offsetX - this.panFrom.x,
        offsetY: this.view.offsetY + event.offsetY - this.panFrom.y,
      };
      this.panFrom = { x: event.offsetX, y: event.offsetY };
      this.draw();
      return;
    }
    if (!this.pending) return;
    const cell = screenToCell(this.view, event.offsetX, event.offsetY, this.rows, this.cols);
    if (!cell) return;
    const last = this.pending.cells[this.pending.cells.length - 1];
    this.pending.cells.push(...cellsAlong(last, cell).slice(1));
    this.draw();
  }

  private up() {
    this.panFrom = null;
    if (!this.pending) return;
    const stroke = this.pending;
    this.pending = null;
    this.sent.push(stroke);
    this.onStroke(stroke.brush, stroke.cells);
    this.draw();
  }

  private draw() {
    const context = this.canvas.getContext('2d');
    if (!context) return;
    context.fillStyle = '#111';
    context.fillRect(0, 0, this.canvas.width, this.canvas.height);
    if (!this.image) return;
    const { scale, aspect, offsetX, offsetY } = this.view;
    context.imageSmoothingEnabled = false;
    if (this.image instanceof TiledPicture) {
      this.image.draw(context, this.view, this.canvas.width, this.canvas.height);
    } else {
      context.drawImage(
        this.image,
        0,
        0,
        this.cols,
        this.rows,
        offsetX,
        offsetY,
        this.cols * scale,
        this.rows * scale * aspect,
      );
    }
    for (const overlay of [this.holeMask, this.mask, this.strokeImage]) {
      if (!overlay) continue;
      const { col, row, width, height } = overlay.box;
      context.drawImage(
        overlay.image,
        0,
        0,
        width,
        height,
        offsetX + col * scale,
        offsetY + row * scale * aspect,
        width * scale,
        height * scale * aspect,
      );
    }
    for (const stroke of [...this.sent, ...(this.pending ? [this.pending] : [])]) {
      context.fillStyle =
        stroke.brush === 'object'
          ? 'rgba(60, 220, 60, 0.8)'
          : stroke.brush === 'background'
            ? 'rgba(230, 60, 60, 0.8)'
            : stroke.brush === 'erase'
              ? 'rgba(20, 20, 20, 0.7)'
              : 'rgba(60, 120, 255, 0.8)';
      const r = stroke.brush === 'lasso' ? 0.5 : Math.max(stroke.radius, 0.5);
      for (const cell of stroke.cells) {
        context.fillRect(
          offsetX + (cell.col - r + 0.5) * scale,
          offsetY + (cell.row - r + 0.5) * scale * aspect,
          2 * r * scale,
          2 * r * scale * aspect,
        );
      }
    }
    if (this.picked) {
      const { x, y } = cellToScreen(this.view, this.picked);
      context.strokeStyle = '#ff0';
      context.lineWidth = 2;
      context.strokeRect(x - 6, y - 6, 12, 12);
    }
  }
}

// An overlay: the URL of a whole overlay image, one loaded already (cropped), or none.
export type OverlaySource = string | Overlay | null | Promise<Overlay | null>;

export function loadImage(url: string): Promise<HTMLImageElement> {
  return new Promise((resolve, reject) => {
    const image = new Image();
    image.onload = () => resolve(image);
    image.onerror = () => reject(new Error(`could not load ${url.split('?')[0]}`));
    image.src = url;
  });
}

// The scan's ray image on a canvas: any channel, zoom (wheel) and pan (drag with the pick tool or the middle
// button), strokes painted with the brushes, the segmented object tinted, the picked cell marked.
import { Cell, ImageView, cellsAlong, cellToScreen, fitView, screenToCell, zoomAt } from './strokes';

export type Brush = 'object' | 'background' | 'hole' | 'lasso' | 'none';

export class RayView {
  brush: Brush = 'object';
  radius = 2;
  onStroke: (brush: Brush, cells: Cell[]) => void = () => {};
  onPick: (cell: Cell) => void = () => {};

  private image: HTMLImageElement | null = null;
  private mask: HTMLImageElement | null = null;
  private holeMask: HTMLImageElement | null = null;
  private view: ImageView = { scale: 1, aspect: 1, offsetX: 0, offsetY: 0 };
  private rows = 0;
  private cols = 0;
  private pending: { brush: Brush; cells: Cell[] } | null = null;
  private strokes: { brush: Brush; cells: Cell[] }[] = [];
  private picked: Cell | null = null;
  private panFrom: { x: number; y: number } | null = null;

  constructor(private canvas: HTMLCanvasElement) {
    canvas.addEventListener('wheel', (event) => {
      event.preventDefault();
      this.view = zoomAt(this.view, event.deltaY < 0 ? 1.25 : 0.8, event.offsetX, event.offsetY);
      this.draw();
    }, { passive: false });
    canvas.addEventListener('pointerdown', (event) => this.down(event));
    canvas.addEventListener('pointermove', (event) => this.move(event));
    canvas.addEventListener('pointerup', () => this.up());
    canvas.addEventListener('pointerleave', () => this.up());
    new ResizeObserver(() => this.fit()).observe(canvas);
  }

  async show(imageUrl: string, maskUrl: string | null, holeUrl: string | null, rows: number, cols: number, aspect: number,
             keepView: boolean) {
    const [image, mask, hole] = await Promise.all([loadImage(imageUrl), maskUrl ? loadImage(maskUrl) : Promise.resolve(null),
                                                   holeUrl ? loadImage(holeUrl) : Promise.resolve(null)]);
    this.holeMask = hole;
    const sizeChanged = rows !== this.rows || cols !== this.cols;
    this.image = image;
    this.mask = mask;
    this.rows = rows;
    this.cols = cols;
    this.view.aspect = aspect;
    if (!keepView || sizeChanged) this.fit();
    this.draw();
  }

  clearStrokes(brushes: Brush[] = ['object', 'background', 'hole', 'lasso']) {
    this.strokes = this.strokes.filter((stroke) => !brushes.includes(stroke.brush));
    this.draw();
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
    if (this.rows > 0) this.view = fitView(this.rows, this.cols, this.view.aspect, this.canvas.width, this.canvas.height);
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
    if (cell) this.pending = { brush: this.brush, cells: [cell] };
  }

  private move(event: PointerEvent) {
    if (this.panFrom) {
      this.view = { ...this.view, offsetX: this.view.offsetX + event.offsetX - this.panFrom.x, offsetY: this.view.offsetY + event.offsetY - this.panFrom.y };
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
    this.strokes.push(stroke);
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
    context.drawImage(this.image, 0, 0, this.cols, this.rows, offsetX, offsetY, this.cols * scale, this.rows * scale * aspect);
    if (this.holeMask) {
      context.drawImage(this.holeMask, 0, 0, this.cols, this.rows, offsetX, offsetY, this.cols * scale, this.rows * scale * aspect);
    }
    if (this.mask) {
      context.drawImage(this.mask, 0, 0, this.cols, this.rows, offsetX, offsetY, this.cols * scale, this.rows * scale * aspect);
    }
    for (const stroke of [...this.strokes, ...(this.pending ? [this.pending] : [])]) {
      context.fillStyle = stroke.brush === 'object' ? 'rgba(60, 220, 60, 0.8)'
        : stroke.brush === 'background' ? 'rgba(230, 60, 60, 0.8)' : 'rgba(60, 120, 255, 0.8)';
      const r = stroke.brush === 'lasso' ? 0.5 : Math.max(this.radius, 0.5);
      for (const cell of stroke.cells) {
        context.fillRect(offsetX + (cell.col - r + 0.5) * scale, offsetY + (cell.row - r + 0.5) * scale * aspect, 2 * r * scale, 2 * r * scale * aspect);
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

export function loadImage(url: string): Promise<HTMLImageElement> {
  return new Promise((resolve, reject) => {
    const image = new Image();
    image.onload = () => resolve(image);
    image.onerror = () => reject(new Error(`could not load ${url.split('?')[0]}`));
    image.src = url;
  });
}

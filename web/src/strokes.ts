// Strokes on the ray image: a drag becomes the cells along it (Bresenham), in image orientation.

export interface Cell {
  row: number;
  col: number;
}

// The cells on the segment from `a` to `b`, both ends included, each once.
export function cellsAlong(a: Cell, b: Cell): Cell[] {
  const cells: Cell[] = [];
  let { row, col } = a;
  const dRow = Math.abs(b.row - a.row),
    dCol = Math.abs(b.col - a.col);
  const sRow = a.row < b.row ? 1 : -1,
    sCol = a.col < b.col ? 1 : -1;
  let error = dCol - dRow;
  for (;;) {
    cells.push({ row, col });
    if (row === b.row && col === b.col) break;
    const twice = 2 * error;
    if (twice > -dRow) {
      error -= dRow;
      col += sCol;
    }
    if (twice < dCol) {
      error += dCol;
      row += sRow;
    }
  }
  return cells;
}

// The view of the ray image: `scale` screen pixels per cell horizontally, `aspect` = cell height / width on
// screen (square angular pixels: elevation step / azimuth step), `offsetX/Y` the screen position of cell (0, 0).
export interface ImageView {
  scale: number;
  aspect: number;
  offsetX: number;
  offsetY: number;
}

export function screenToCell(view: ImageView, x: number, y: number, rows: number, cols: number): Cell | null {
  const col = Math.floor((x - view.offsetX) / view.scale);
  const row = Math.floor((y - view.offsetY) / (view.scale * view.aspect));
  if (row < 0 || col < 0 || row >= rows || col >= cols) return null;
  return { row, col };
}

export function cellToScreen(view: ImageView, cell: Cell): { x: number; y: number } {
  return {
    x: view.offsetX + (cell.col + 0.5) * view.scale,
    y: view.offsetY + (cell.row + 0.5) * view.scale * view.aspect,
  };
}

// Zooms by `factor` keeping the screen point (x, y) over the same cell.
export function zoomAt(view: ImageView, factor: number, x: number, y: number): ImageView {
  const scale = Math.min(64, Math.max(0.05, view.scale * factor));
  const applied = scale / view.scale;
  return {
    ...view,
    scale,
    offsetX: x - (x - view.offsetX) * applied,
    offsetY: y - (y - view.offsetY) * applied,
  };
}

// The view that fits a rows x cols image into a width x height canvas, centred.
export function fitView(
  rows: number,
  cols: number,
  aspect: number,
  width: number,
  height: number,
): ImageView {
  const scale = Math.min(width / cols, height / (rows * aspect));
  return {
    scale,
    aspect,
    offsetX: (width - cols * scale) / 2,
    offsetY: (height - rows * aspect * scale) / 2,
  };
}

// Stroke cells as the API's [[row, col], ...] lists, without repeats.
export function toCellList(cells: Cell[]): number[][] {
  const seen = new Set<number>();
  const list: number[][] = [];
  for (const { row, col } of cells) {
    const key = row * 1_000_003 + col;
    if (seen.has(key)) continue;
    seen.add(key);
    list.push([row, col]);
  }
  return list;
}

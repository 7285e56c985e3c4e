import { describe, expect, it } from 'vitest';
import { cellsAlong, cellToScreen, fitView, screenToCell, toCellList, zoomAt } from '../src/strokes';

describe('cellsAlong', () => {
  it('includes both ends and steps one cell at a time', () => {
    const cells = cellsAlong({ row: 2, col: 1 }, { row: 5, col: 9 });
    expect(cells[0]).toEqual({ row: 2, col: 1 });
    expect(cells[cells.length - 1]).toEqual({ row: 5, col: 9 });
    expect(cells.length).toBe(9); // the longer axis: 8 steps + 1
    for (let i = 1; i < cells.length; ++i) {
      expect(Math.abs(cells[i].row - cells[i - 1].row)).toBeLessThanOrEqual(1);
      expect(Math.abs(cells[i].col - cells[i - 1].col)).toBe(1);
    }
  });
  it('handles a single cell and reversed directions', () => {
    expect(cellsAlong({ row: 3, col: 3 }, { row: 3, col: 3 })).toEqual([{ row: 3, col: 3 }]);
    expect(cellsAlong({ row: 5, col: 5 }, { row: 1, col: 5 }).map((c) => c.row)).toEqual([5, 4, 3, 2, 1]);
  });
});

describe('views', () => {
  it('maps cells to the screen and back, with square angular pixels', () => {
    const view = fitView(100, 400, 0.5, 800, 600);
    expect(view.scale).toBe(2);
    for (const cell of [
      { row: 0, col: 0 },
      { row: 57, col: 311 },
      { row: 99, col: 399 },
    ]) {
      const { x, y } = cellToScreen(view, cell);
      expect(screenToCell(view, x, y, 100, 400)).toEqual(cell);
    }
    expect(screenToCell(view, -5, 300, 100, 400)).toBeNull();
  });
  it('zooms about the pointer', () => {
    const view = fitView(100, 100, 1, 500, 500);
    const cell = screenToCell(view, 123, 321, 100, 100);
    const zoomed = zoomAt(view, 2, 123, 321);
    expect(zoomed.scale).toBe(view.scale * 2);
    expect(screenToCell(zoomed, 123, 321, 100, 100)).toEqual(cell);
  });
});

describe('toCellList', () => {
  it('drops repeats', () => {
    expect(
      toCellList([
        { row: 1, col: 2 },
        { row: 1, col: 2 },
        { row: 2, col: 1 },
      ]),
    ).toEqual([
      [1, 2],
      [2, 1],
    ]);
  });
});

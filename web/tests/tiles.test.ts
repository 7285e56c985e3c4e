import { afterEach, describe, expect, it, vi } from 'vitest';
import {
  TiledPicture,
  TilesInfo,
  boxesMeet,
  levelFor,
  tileFootprint,
  tilesMeeting,
  visibleCells,
} from '../src/tiles';

// A 600 x 900 picture in 256-pixel tiles: levels 0 (4 x 3 tiles), 1 (2 x 2), 2 (1).
function info(version: number, changed: [number, number, number, number] = [0, 0, 900, 600]): TilesInfo {
  return {
    version,
    rows: 600,
    cols: 900,
    tile_px: 256,
    levels: [
      { level: 0, rows: 600, cols: 900, tiles_x: 4, tiles_y: 3 },
      { level: 1, rows: 300, cols: 450, tiles_x: 2, tiles_y: 2 },
      { level: 2, rows: 150, cols: 225, tiles_x: 1, tiles_y: 1 },
    ],
    changed,
  };
}

describe('levelFor', () => {
  it('picks the level with about one tile pixel per screen pixel', () => {
    expect(levelFor({ scale: 1, aspect: 1 }, 5)).toBe(0);
    expect(levelFor({ scale: 3, aspect: 1 }, 5)).toBe(0);
    expect(levelFor({ scale: 0.5, aspect: 1 }, 5)).toBe(1);
    expect(levelFor({ scale: 0.3, aspect: 1 }, 5)).toBe(1);
    expect(levelFor({ scale: 0.25, aspect: 1 }, 5)).toBe(2);
    expect(levelFor({ scale: 0.25, aspect: 2 }, 5)).toBe(1); // cells drawn twice as high
    expect(levelFor({ scale: 0.001, aspect: 1 }, 5)).toBe(5); // never past the coarsest
  });
});

describe('tiles and footprints', () => {
  it('clips the footprint of the last tiles to the picture', () => {
    expect(tileFootprint(info(1), 0, 3, 2)).toEqual({ col: 768, row: 512, width: 132, height: 88 });
    expect(tileFootprint(info(1), 1, 1, 1)).toEqual({ col: 512, row: 512, width: 388, height: 88 });
    expect(tileFootprint(info(1), 2, 0, 0)).toEqual({ col: 0, row: 0, width: 900, height: 600 });
  });
  it('sees the cells of the canvas and the tiles meeting them', () => {
    const cells = visibleCells({ scale: 2, aspect: 1, offsetX: -600, offsetY: -400 }, 400, 300, 600, 900);
    expect(cells).toEqual({ col: 300, row: 200, width: 200, height: 150 });
    const tiles = tilesMeeting(info(1), 0, cells);
    expect(tiles.map((t) => `${t.tx},${t.ty}`).sort()).toEqual(['1,0', '1,1']);
    expect(tilesMeeting(info(1), 0, { col: 0, row: 0, width: 0, height: 10 })).toEqual([]);
  });
  it('meets only boxes that share a cell', () => {
    const a = { col: 0, row: 0, width: 10, height: 10 };
    expect(boxesMeet(a, { col: 9, row: 9, width: 1, height: 1 })).toBe(true);
    expect(boxesMeet(a, { col: 10, row: 0, width: 5, height: 5 })).toBe(false);
    expect(boxesMeet(a, { col: 5, row: 5, width: 0, height: 0 })).toBe(false);
  });
});

describe('TiledPicture', () => {
  afterEach(() => vi.unstubAllGlobals());

  // A server whose tiles.json answers `infos` in turn and whose tiles are counted by path.
  function serve(infos: TilesInfo[]) {
    const asked: string[] = [];
    let current = infos[0];
    vi.stubGlobal('fetch', async (url: string) => {
      const path = url.split('?')[0];
      if (path.endsWith('tiles.json')) {
        current = infos.shift()!;
        return new Response(JSON.stringify(current));
      }
      asked.push(path.replace('/api/docs/1/tiles/', ''));
      return new Response('png', { headers: { 'X-Lidarshop-Version': String(current.version) } });
    });
    vi.stubGlobal('createImageBitmap', async () => ({ width: 256, height: 256, close() {} }));
    return asked;
  }
  const context = {
    save() {},
    restore() {},
    beginPath() {},
    rect() {},
    clip() {},
    drawImage() {},
  } as unknown as CanvasRenderingContext2D;
  const url = (path: string) => path;

  it('loads the coarsest level first, then the visible tiles of the view level', async () => {
    const asked = serve([info(1)]);
    const picture = await TiledPicture.open(url, 1, 'range');
    expect(asked).toEqual(['2/0/0.png']);
    // One cell per screen pixel, the top left 500 x 300 cells: level 0, tiles (0..1, 0..1).
    picture.draw(context, { scale: 1, aspect: 1, offsetX: 0, offsetY: 0 }, 500, 300);
    await picture.settled();
    expect(asked.slice(1).sort()).toEqual(['0/0/0.png', '0/0/1.png', '0/1/0.png', '0/1/1.png']);
    expect(picture.counts().levels).toEqual({ 0: 4, 2: 1 });
  });

  it('after an edit drops only the tiles meeting the changed box', async () => {
    const asked = serve([info(1), info(2, [300, 10, 20, 20])]);
    const picture = await TiledPicture.open(url, 1, 'range');
    picture.draw(context, { scale: 1, aspect: 1, offsetX: 0, offsetY: 0 }, 500, 300);
    await picture.settled();
    asked.length = 0;
    await picture.update(2);
    expect(picture.version).toBe(2);
    // The box (300..319, 10..29) lies in level-0 tile (1, 0) and in the coarsest tile: both fetched again.
    expect(asked).toEqual(['2/0/0.png']);
    expect(picture.counts().levels).toEqual({ 0: 3, 2: 1 });
    picture.draw(context, { scale: 1, aspect: 1, offsetX: 0, offsetY: 0 }, 500, 300);
    await picture.settled();
    expect(asked).toEqual(['2/0/0.png', '0/1/0.png']);
  });

  it('keeps every tile after an edit that changed no pixel, and none when the grid changed', async () => {
    const grown = { ...info(3), rows: 700 };
    const asked = serve([info(1), info(2, [0, 0, 0, 0]), grown]);
    const picture = await TiledPicture.open(url, 1, 'range');
    picture.draw(context, { scale: 1, aspect: 1, offsetX: 0, offsetY: 0 }, 500, 300);
    await picture.settled();
    asked.length = 0;
    await picture.update(2);
    expect(asked).toEqual([]);
    expect(picture.counts().held).toBe(5);
    await picture.update(3);
    expect(asked).toEqual(['2/0/0.png']);
    expect(picture.counts().held).toBe(1);
  });
});

import { describe, expect, it } from 'vitest';
import { FLAG_FROM_STATION, FLAG_OBJECT, FLAG_SYNTHESIZED, poseMatrix, PointSet } from '../src/api';
import { layerOf, pointColours, visiblePoints } from '../src/pointview';
import {
  SiteInfo,
  StationInfo,
  centroid,
  cleanSummary,
  fillHoleKind,
  fillSummary,
  pointsOfCells,
  stationLabel,
  stationPositionsInView,
  viewFromStation,
} from '../src/stations';

function station(
  index: number,
  x: number,
  y: number,
  yawDeg: number,
  extra: Partial<StationInfo> = {},
): StationInfo {
  return {
    index,
    name: `station${index}`,
    position_m: [x, y, 1.6],
    heading_deg: yawDeg,
    world_from_scanner_column_major: (() => {
      const m = poseMatrix(x, y, 1.6, yawDeg);
      return m;
    })(),
    rows: 10,
    cols: 20,
    returns: 150,
    organized: true,
    document: 10 + index,
    open: true,
    current: index === 0,
    ...extra,
  };
}

describe('stationLabel', () => {
  it('gives index, name, position and heading', () => {
    expect(stationLabel(station(2, 8, 2, 30))).toBe('2 · station2 · (8.0, 2.0, 1.6) m · 30°');
  });
  it('names a station without a name by its scan, and says when it is closed', () => {
    expect(stationLabel(station(1, -8, 2, -30, { name: '', open: false }))).toBe(
      '1 · scan #11 · (-8.0, 2.0, 1.6) m · -30° (closed)',
    );
  });
});

describe("stations in the shown scan's frame", () => {
  const site: SiteInfo = {
    site: 1,
    name: 's',
    station: 1,
    stations: [station(0, 0, 0, 0), station(1, -8, 2, -30), station(2, 8, 2, 30)],
  };
  it('puts the shown station at the origin and the others where they stand from it', () => {
    const positions = stationPositionsInView(site, site.stations[1].world_from_scanner_column_major);
    expect(positions[1].map((v) => Math.abs(v) < 1e-9)).toEqual([true, true, true]);
    // Station 0 seen from station 1: 8 m along world +x and 2 m back, in a frame turned by -30 degrees.
    const d = Math.hypot(positions[0][0], positions[0][1]);
    expect(d).toBeCloseTo(Math.hypot(8, 2), 9);
    expect(positions[0][2]).toBeCloseTo(0, 9);
    const c = Math.cos((-30 * Math.PI) / 180),
      s = Math.sin((-30 * Math.PI) / 180);
    // current_from_world rotation is R^T: x' = c*dx + s*dy, y' = -s*dx + c*dy.
    expect(positions[0][0]).toBeCloseTo(c * 8 + s * -2, 9);
    expect(positions[0][1]).toBeCloseTo(-s * 8 + c * -2, 9);
  });
  it('maps a point of another station into the shown frame as the poses say', () => {
    const m = viewFromStation(
      site.stations[1].world_from_scanner_column_major,
      site.stations[2].world_from_scanner_column_major,
    );
    // The origin of station 2 lands where stationPositionsInView puts it.
    const positions = stationPositionsInView(site, site.stations[1].world_from_scanner_column_major);
    expect(m[12]).toBeCloseTo(positions[2][0], 9);
    expect(m[13]).toBeCloseTo(positions[2][1], 9);
    expect(m[14]).toBeCloseTo(positions[2][2], 9);
    // Identity for the station itself.
    const self = viewFromStation(
      site.stations[2].world_from_scanner_column_major,
      site.stations[2].world_from_scanner_column_major,
    );
    self.forEach((v, i) => expect(v).toBeCloseTo([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1][i], 9));
  });
});

describe('pointsOfCells', () => {
  const points: PointSet = {
    count: 4,
    rows: 2,
    cols: 3,
    xyz: new Float32Array([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]),
    cells: new Uint32Array([0, 2, 4, 4]),
    rgb: new Uint8Array(12),
    flags: new Uint8Array([0, 1, 0, 4]), // the last is the layer behind a kept object: not the scan's cell
  };
  it('keeps the points of the wanted cells, in order, not the layer behind', () => {
    expect(Array.from(pointsOfCells(points, [4, 2]))).toEqual([3, 4, 5, 6, 7, 8]);
    expect(pointsOfCells(points, []).length).toBe(0);
    expect(pointsOfCells(points, [5]).length).toBe(0);
  });
});

describe('centroid', () => {
  it('is the mean point, null for none', () => {
    expect(centroid(new Float32Array([0, 0, 0, 2, 4, -6]))).toEqual([1, 2, -3]);
    expect(centroid(new Float32Array([]))).toBeNull();
  });
});

describe('cleanSummary', () => {
  it('says how many went here, per station, and which other scans changed', () => {
    const text = cleanSummary({
      station: 2,
      removed_cells: 1234,
      version: 3,
      stations: [
        { station: 0, document: 4, removed: 0, filled: 0, changed: false, why: 'nothing moved here' },
        { station: 1, document: 5, removed: 12, filled: 12, changed: true },
        { station: 2, document: 6, removed: 1234, filled: 1300, changed: true },
      ],
    });
    expect(text).toContain('1234 points removed here (station 2)');
    expect(text).toContain('station 0: 0 (nothing moved here)');
    expect(text).toContain('station 1: 12');
    expect(text).toContain('Scans #5 were cleaned too');
    expect(text).not.toContain('#6');
  });
  it('copes with no result', () => {
    expect(cleanSummary(undefined)).toBe('clean: no result');
  });
});

describe('the layer of points filled from other stations', () => {
  const points: PointSet = {
    count: 4,
    rows: 1,
    cols: 4,
    xyz: new Float32Array(12),
    cells: new Uint32Array([0, 1, 2, 3]),
    rgb: new Uint8Array(12),
    flags: new Uint8Array([0, FLAG_SYNTHESIZED, FLAG_FROM_STATION, FLAG_FROM_STATION | FLAG_OBJECT]),
  };
  it('is its own layer, distinct from synthesized, the object first', () => {
    expect(Array.from(points.flags, layerOf)).toEqual(['original', 'synthesized', 'from-stations', 'object']);
  });
  it('can be hidden alone', () => {
    const shown = visiblePoints(points, new Set(['from-stations']));
    expect(Array.from(shown.cells)).toEqual([0, 1, 3]);
  });
  it('has its own colour', () => {
    const colours = pointColours(points, 'layers');
    const rgb = (i: number) => Array.from(colours.slice(3 * i, 3 * i + 3));
    expect(rgb(2)).not.toEqual(rgb(1));
    expect(rgb(2)).not.toEqual(rgb(0));
  });
});

describe('fill from stations', () => {
  it('fills the painted hole first, then the object of the strokes, then the last cut', () => {
    expect(fillHoleKind({ hole_cells: 5, object_stroke_cells: 3, object_cells: 2 })).toBe('painted');
    expect(fillHoleKind({ hole_cells: 0, object_stroke_cells: 3, object_cells: 2 })).toBe('strokes');
    expect(fillHoleKind({ hole_cells: 0, object_stroke_cells: 0, object_cells: 2 })).toBe('object');
  });
  it('says what each station gave and what was synthesized', () => {
    const text = fillSummary({
      hole_cells: 100,
      from_station_cells: 70,
      synthesized_cells: 30,
      stations: [
        { station: 0, cells: 50 },
        { station: 1, cells: 20 },
      ],
    });
    expect(text).toBe(
      'fill from stations: 70 of 100 cells from other stations (station 0: 50, station 1: 20), 30 synthesized',
    );
  });
});

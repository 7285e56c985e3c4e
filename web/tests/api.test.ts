import { describe, expect, it } from 'vitest';
import {
  Api,
  FLAG_OBJECT,
  FLAG_SYNTHESIZED,
  JobInfo,
  Narrowed,
  ScanFileEntry,
  fileLabel,
  firstReadableFile,
  parsePoints,
  resultWarnings,
} from '../src/api';
import type { TilesReply } from '../src/api_types.generated';
import { pointColours } from '../src/pointview';

function encode(points: { xyz: number[]; cell: number; rgb: number[]; flag: number }[], rows = 4, cols = 5) {
  const n = points.length;
  const buffer = new ArrayBuffer(16 + n * 20);
  const header = new DataView(buffer);
  header.setUint32(0, 0x3150534c, true);
  header.setUint32(4, n, true);
  header.setUint32(8, rows, true);
  header.setUint32(12, cols, true);
  new Float32Array(buffer, 16, 3 * n).set(points.flatMap((p) => p.xyz));
  new Uint32Array(buffer, 16 + 12 * n, n).set(points.map((p) => p.cell));
  new Uint8Array(buffer, 16 + 16 * n, 3 * n).set(points.flatMap((p) => p.rgb));
  new Uint8Array(buffer, 16 + 19 * n, n).set(points.map((p) => p.flag));
  return buffer;
}

describe('parsePoints', () => {
  const sample = [
    { xyz: [1, 2, 3], cell: 7, rgb: [10, 20, 30], flag: 0 },
    { xyz: [-1.5, 0.25, 9], cell: 19, rgb: [255, 0, 128], flag: FLAG_SYNTHESIZED | FLAG_OBJECT },
  ];
  it('reads every array', () => {
    const points = parsePoints(encode(sample));
    expect(points.count).toBe(2);
    expect(points.rows).toBe(4);
    expect(points.cols).toBe(5);
    expect(Array.from(points.xyz)).toEqual([1, 2, 3, -1.5, 0.25, 9]);
    expect(Array.from(points.cells)).toEqual([7, 19]);
    expect(Array.from(points.rgb)).toEqual([10, 20, 30, 255, 0, 128]);
    expect(Array.from(points.flags)).toEqual([0, 3]);
  });
  it('refuses short or foreign data', () => {
    expect(() => parsePoints(new ArrayBuffer(8))).toThrow(/shorter than the header/);
    expect(() => parsePoints(encode(sample).slice(0, 40))).toThrow(/expected/);
    const foreign = encode(sample);
    new DataView(foreign).setUint32(0, 0, true);
    expect(() => parsePoints(foreign)).toThrow(/not LSP1/);
  });
  it('colours by layer', () => {
    const colours = pointColours(parsePoints(encode(sample)), 'layers');
    expect(Array.from(colours.slice(0, 3)).map((v) => v.toFixed(2))).toEqual(['0.60', '0.60', '0.60']);
    expect(colours[3]).toBe(1); // object orange wins over synthesized
  });
});

describe('Api', () => {
  it('puts the token on every URL', () => {
    const api = Api.fromLocation({ search: '?token=abc123', origin: 'http://127.0.0.1:9' });
    expect(api.url('/api/docs/3/image.png', { channel: 'range' })).toBe(
      'http://127.0.0.1:9/api/docs/3/image.png?channel=range&token=abc123',
    );
  });
  it('leaves the token out when the page has none (its cookie carries it)', () => {
    const api = Api.fromLocation({ search: '', origin: 'http://127.0.0.1:9' });
    expect(api.url('/api/docs/3/image.png', { channel: 'range' })).toBe(
      'http://127.0.0.1:9/api/docs/3/image.png?channel=range',
    );
    expect(api.url('/api/health')).toBe('http://127.0.0.1:9/api/health');
  });
});

import { inverseRigid, multiply, parseMesh, poseMatrix } from '../src/api';

describe('poses', () => {
  it('yaw turns x towards y, and the inverse undoes the pose', () => {
    const pose = poseMatrix(1, 2, 3, 90);
    const x = multiply(pose, [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
    expect(x[0]).toBeCloseTo(0);
    expect(x[1]).toBeCloseTo(1); // the model's x axis points along world y
    const identity = multiply(inverseRigid(pose), pose);
    identity.forEach((value, i) =>
      expect(value).toBeCloseTo([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1][i]),
    );
  });
  it('reads a mesh and refuses a wrong size', () => {
    const buffer = new ArrayBuffer(16 + 3 * 12 + 12);
    const header = new DataView(buffer);
    header.setUint32(0, 0x314d534c, true);
    header.setUint32(4, 3, true);
    header.setUint32(8, 1, true);
    new Float32Array(buffer, 16, 9).set([0, 0, 0, 1, 0, 0, 0, 1, 0]);
    new Uint32Array(buffer, 52, 3).set([0, 1, 2]);
    expect(Array.from(parseMesh(buffer).indices)).toEqual([0, 1, 2]);
    expect(() => parseMesh(buffer.slice(0, 60))).toThrow(/size/);
  });
});

describe('resultWarnings', () => {
  const job = (result?: Record<string, unknown>): JobInfo => ({
    id: 1,
    kind: 'fill',
    document: 1,
    state: 'done',
    label: '',
    done: 1,
    total: 1,
    result,
  });
  it('reads the result warnings, once each', () => {
    expect(resultWarnings(job({ warnings: ['the hole mask is empty', 'the hole mask is empty'] }))).toEqual([
      'the hole mask is empty',
    ]);
  });
  it('gives none for a result without warnings, an empty list or no result', () => {
    expect(resultWarnings(job({ object_cells: 3 }))).toEqual([]);
    expect(resultWarnings(job({ warnings: [] }))).toEqual([]);
    expect(resultWarnings(job())).toEqual([]);
    expect(resultWarnings(job({ warnings: 'not a list' }))).toEqual([]);
  });
});

describe('the file dialog', () => {
  const files: ScanFileEntry[] = [
    { path: '/data/a_broken.e57', bytes: 4, readable: false, error: 'a_broken.e57: not an E57 file' },
    { path: '/data/b_scan.ptx', bytes: 900, readable: true },
    { path: '/data/c_scan.ply', bytes: 700, readable: true },
  ];
  it('starts on the first file that opens, not on a broken one', () => {
    expect(firstReadableFile(files)?.path).toBe('/data/b_scan.ptx');
    expect(firstReadableFile([files[0]])).toBeUndefined();
  });
  it('labels a broken file', () => {
    expect(fileLabel(files[0])).toBe('a_broken.e57 (does not open)');
    expect(fileLabel(files[1])).toBe('b_scan.ptx');
  });
});

// The editor's reply types narrow the generated ones; a narrowing the server's reply does not admit must not
// compile (tsc over tests/ in scripts/web.sh fails on an unused @ts-expect-error).
describe('Narrowed', () => {
  it('refuses a field the reply lacks and a type its field does not admit', () => {
    // @ts-expect-error: TilesReply has no such field
    const lacking: Narrowed<TilesReply, { no_such_field: number }> | null = null;
    // @ts-expect-error: its tile size is a number
    const retyped: Narrowed<TilesReply, { tile_px: string }> | null = null;
    const narrowed: Narrowed<TilesReply, { changed: [number, number, number, number] }> = {
      version: 1,
      rows: 2,
      cols: 3,
      tile_px: 256,
      levels: [],
      changed: [0, 0, 3, 2],
    };
    expect([lacking, retyped, narrowed.changed.length]).toEqual([null, null, 4]);
  });
});

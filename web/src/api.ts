// The editor's calls to `lidarshop serve` (docs/api.md). The server moves the token of the URL it printed into an
// HttpOnly cookie on the first page load and reloads the page without it, so the calls normally carry only the
// cookie; a page opened with ?token= still puts it on every URL (the server accepts either).

import type { DocumentReply, FileEntry, JobReply } from './api_types.generated';

// The replies' types are generated from the server's descriptions (api_types.generated.ts, `lidarshop schema
// --typescript`); the editor narrows only what the description cannot say: a pair as a tuple, a fixed string as a
// union, a number that is never null. A result's number is `number | null` there (the server writes a NaN as
// null); a document's pose and grid steps are finite (the readers refuse a pose that is not).
// Narrowed<T, U>: T with U's fields in place of its own. A key T lacks, or a type T's field does not admit, fails
// to compile, so a field renamed or retyped on the server fails the editor's build (tsc in scripts/web.sh).
export type Narrowed<T, U extends { [K in keyof U]: K extends keyof T ? T[K] : never }> = Omit<T, keyof U> &
  U;

export type DocumentInfo = Narrowed<
  DocumentReply,
  { world_from_scanner_column_major: number[]; azimuth_step_deg: number; elevation_step_deg: number }
>;

// A job's `result` is the operation's own reply, an object whose type follows the kind.
export type JobInfo = Narrowed<JobReply, { result?: Record<string, unknown> }>;

// A number of a reply to `digits` significant digits; "none" for null (a NaN on the server).
export function precision(value: number | null, digits: number): string {
  return value === null ? 'none' : value.toPrecision(digits);
}

// One entry of GET /api/files: a scan file under the served folders; `readable` false (with `error`) when its
// header does not read.
export type ScanFileEntry = FileEntry;

// The file the dialog starts on: the first that reads.
export function firstReadableFile(files: ScanFileEntry[]): ScanFileEntry | undefined {
  return files.find((file) => file.readable !== false);
}

// The dialog's label of a file: its name, and "(does not open)" for a broken one.
export function fileLabel(file: ScanFileEntry): string {
  const name = file.path.split('/').pop()!;
  return file.readable === false ? `${name} (does not open)` : name;
}

// The warnings of a finished job's result (`warnings`: what looks wrong with a cut, a fill or a recolouring,
// one sentence each; docs/api.md), with a removal's cut and fill warnings once each. Empty when none.
export function resultWarnings(job: JobInfo): string[] {
  const list = job.result?.warnings;
  if (!Array.isArray(list)) return [];
  return [...new Set(list.filter((item): item is string => typeof item === 'string'))];
}

// The points of a scan as typed arrays: positions in the scanner frame (metres), the cell of each point
// (row * cols + col), RGB and flags (1 = synthesized, 2 = object).
export interface PointSet {
  count: number;
  rows: number;
  cols: number;
  xyz: Float32Array;
  cells: Uint32Array;
  rgb: Uint8Array;
  flags: Uint8Array;
}

// The points at indices `keep` of `points`, in that order.
export function selectPoints(points: PointSet, keep: number[]): PointSet {
  const n = keep.length;
  const out: PointSet = {
    count: n,
    rows: points.rows,
    cols: points.cols,
    xyz: new Float32Array(3 * n),
    cells: new Uint32Array(n),
    rgb: new Uint8Array(3 * n),
    flags: new Uint8Array(n),
  };
  keep.forEach((i, k) => {
    out.xyz.set(points.xyz.subarray(3 * i, 3 * i + 3), 3 * k);
    out.rgb.set(points.rgb.subarray(3 * i, 3 * i + 3), 3 * k);
    out.cells[k] = points.cells[i];
    out.flags[k] = points.flags[i];
  });
  return out;
}

export const FLAG_SYNTHESIZED = 1;
export const FLAG_OBJECT = 2;
// The point was filled from what another station of the site measured (real, not synthesized; issue 31 part 3).
export const FLAG_FROM_STATION = 8;

const MAGIC = 0x3150534c; // "LSP1"

// Decodes GET /api/docs/ID/points: 16-byte header (magic, count, rows, cols; uint32 little-endian), then
// xyz float32[3n], cells uint32[n], rgb uint8[3n], flags uint8[n].
export function parsePoints(buffer: ArrayBuffer): PointSet {
  if (buffer.byteLength < 16)
    throw new Error(`points: ${buffer.byteLength} bytes is shorter than the header`);
  const header = new DataView(buffer, 0, 16);
  if (header.getUint32(0, true) !== MAGIC) throw new Error('points: not LSP1 data');
  const count = header.getUint32(4, true);
  const rows = header.getUint32(8, true);
  const cols = header.getUint32(12, true);
  const expected = 16 + count * (12 + 4 + 3 + 1);
  if (buffer.byteLength !== expected) {
    throw new Error(`points: ${buffer.byteLength} bytes, expected ${expected} for ${count} points`);
  }
  let offset = 16;
  const xyz = new Float32Array(buffer, offset, count * 3);
  offset += count * 12;
  const cells = new Uint32Array(buffer, offset, count);
  offset += count * 4;
  const rgb = new Uint8Array(buffer, offset, count * 3);
  offset += count * 3;
  const flags = new Uint8Array(buffer, offset, count);
  return { count, rows, cols, xyz, cells, rgb, flags };
}

// A model mesh from GET /api/models/ID/mesh: header (magic "LSM1", vertices, triangles, 0; uint32
// little-endian), float32 xyz per vertex (model frame), uint32 corner indices per triangle.
export interface MeshData {
  vertices: number;
  triangles: number;
  xyz: Float32Array;
  indices: Uint32Array;
}

export function parseMesh(buffer: ArrayBuffer): MeshData {
  if (buffer.byteLength < 16) throw new Error('mesh: shorter than the header');
  const header = new DataView(buffer, 0, 16);
  if (header.getUint32(0, true) !== 0x314d534c) throw new Error('mesh: not LSM1 data');
  const vertices = header.getUint32(4, true),
    triangles = header.getUint32(8, true);
  if (buffer.byteLength !== 16 + vertices * 12 + triangles * 12)
    throw new Error('mesh: size does not match its header');
  return {
    vertices,
    triangles,
    xyz: new Float32Array(buffer, 16, vertices * 3),
    indices: new Uint32Array(buffer, 16 + vertices * 12, triangles * 3),
  };
}

// world_from_model of a pose on the ground (verify/PoseFromXyzYaw with no pitch or roll): translate, then yaw
// about +z, x towards y. Column-major 4x4.
export function poseMatrix(x: number, y: number, z: number, yawDeg: number): number[] {
  const c = Math.cos((yawDeg * Math.PI) / 180),
    s = Math.sin((yawDeg * Math.PI) / 180);
  return [c, s, 0, 0, -s, c, 0, 0, 0, 0, 1, 0, x, y, z, 1];
}

// a * b for column-major 4x4 matrices.
export function multiply(a: number[], b: number[]): number[] {
  const out = new Array(16).fill(0);
  for (let col = 0; col < 4; ++col)
    for (let row = 0; row < 4; ++row)
      for (let k = 0; k < 4; ++k) out[col * 4 + row] += a[k * 4 + row] * b[col * 4 + k];
  return out;
}

// The inverse of a rigid transform (rotation + translation), column-major.
export function inverseRigid(m: number[]): number[] {
  const out = [m[0], m[4], m[8], 0, m[1], m[5], m[9], 0, m[2], m[6], m[10], 0, 0, 0, 0, 1];
  for (let row = 0; row < 3; ++row)
    out[12 + row] = -(out[row] * m[12] + out[4 + row] * m[13] + out[8 + row] * m[14]);
  return out;
}

export class ApiError extends Error {
  constructor(
    public status: number,
    message: string,
  ) {
    super(message);
  }
}

export class Api {
  constructor(
    private token: string,
    private base = '',
  ) {}

  static fromLocation(location: { search: string; origin: string }): Api {
    const token = new URLSearchParams(location.search).get('token') ?? '';
    return new Api(token, location.origin);
  }

  url(path: string, params: Record<string, string | number> = {}): string {
    const query = new URLSearchParams(
      Object.fromEntries(Object.entries(params).map(([k, v]) => [k, String(v)])),
    );
    if (this.token) query.set('token', this.token);
    const text = query.toString();
    return text ? `${this.base}${path}?${text}` : `${this.base}${path}`;
  }

  async json<T>(path: string, params: Record<string, string | number> = {}, body?: unknown): Promise<T> {
    const response = await fetch(
      this.url(path, params),
      body === undefined
        ? {}
        : {
            method: 'POST',
            headers: { 'Content-Type': 'application/json' },
            body: JSON.stringify(body),
          },
    );
    const text = await response.text();
    const json = text ? JSON.parse(text) : {};
    if (!response.ok)
      throw new ApiError(response.status, json.error ?? `${response.status} ${response.statusText}`);
    return json as T;
  }

  async delete(path: string): Promise<void> {
    const response = await fetch(this.url(path), { method: 'DELETE' });
    if (!response.ok)
      throw new ApiError(
        response.status,
        (await response.json().catch(() => ({}))).error ?? `${response.status}`,
      );
  }

  async mesh(id: number): Promise<MeshData> {
    const response = await fetch(this.url(`/api/models/${id}/mesh`));
    if (!response.ok) throw new ApiError(response.status, `mesh: ${response.status}`);
    return parseMesh(await response.arrayBuffer());
  }

  // The points of document `id` as an answer to show: the cells changed since `since` (LSD1) when the server
  // still holds that version, else the whole points (LSP1); `version` is the version they show
  // (X-Lidarshop-Version), `bytes` what travelled.
  // `step` > 1: the level of detail holding every step-th row and column (a large scan's 3-D view).
  // `box` (COL,ROW,WIDTH,HEIGHT, detail.ts): only the cells inside that box of the grid.
  async pointsSince(
    id: number,
    since: number | null,
    step = 1,
    box?: string,
  ): Promise<{ buffer: ArrayBuffer; version: number; bytes: number }> {
    const params: Record<string, number | string> = since === null ? {} : { since };
    if (step > 1) params.step = step;
    if (box) params.box = box;
    const response = await fetch(this.url(`/api/docs/${id}/points`, params));
    if (!response.ok) throw new ApiError(response.status, `points: ${response.status}`);
    const buffer = await response.arrayBuffer();
    return {
      buffer,
      version: Number(response.headers.get('X-Lidarshop-Version') ?? -1),
      bytes: buffer.byteLength,
    };
  }

  async points(id: number): Promise<PointSet> {
    const response = await fetch(this.url(`/api/docs/${id}/points`));
    if (!response.ok) throw new ApiError(response.status, `points: ${response.status}`);
    return parsePoints(await response.arrayBuffer());
  }

  // Asks for a job's state until it ends, reporting progress; resolves with its last state. Each request
  // waits on the server up to `wait_ms` for the end (a long poll): the end is seen when it comes, progress at
  // least every `wait_ms`.
  async waitForJob(job: JobInfo, onProgress: (job: JobInfo) => void, wait_ms = 250): Promise<JobInfo> {
    let current = job;
    while (current.state === 'queued' || current.state === 'running') {
      onProgress(current);
      current = await this.json<JobInfo>(`/api/jobs/${current.id}`, { wait_ms });
    }
    onProgress(current);
    return current;
  }
}

// The editor's calls to `lidarshop serve` (docs/api.md). Every /api/ call carries the token from the page URL.

export interface DocumentInfo {
  id: number;
  name: string;
  rows: number;
  cols: number;
  channels: string[];
  valid_cells: number;
  synthesized_cells: number;
  object_cells: number;
  hole_cells: number;
  behind_cells: number;
  azimuth_step_deg: number;
  elevation_step_deg: number;
  version: number;
  can_undo: boolean;
  can_redo: boolean;
}

export interface JobInfo {
  id: number;
  kind: string;
  state: 'queued' | 'running' | 'done' | 'failed' | 'cancelled';
  label: string;
  done: number;
  total: number;
  error?: string;
  result?: Record<string, unknown>;
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

export const FLAG_SYNTHESIZED = 1;
export const FLAG_OBJECT = 2;

const MAGIC = 0x3150534c; // "LSP1"

// Decodes GET /api/docs/ID/points: 16-byte header (magic, count, rows, cols; uint32 little-endian), then
// xyz float32[3n], cells uint32[n], rgb uint8[3n], flags uint8[n].
export function parsePoints(buffer: ArrayBuffer): PointSet {
  if (buffer.byteLength < 16) throw new Error(`points: ${buffer.byteLength} bytes is shorter than the header`);
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

export class ApiError extends Error {
  constructor(public status: number, message: string) {
    super(message);
  }
}

export class Api {
  constructor(private token: string, private base = '') {}

  static fromLocation(location: { search: string; origin: string }): Api {
    const token = new URLSearchParams(location.search).get('token') ?? '';
    return new Api(token, location.origin);
  }

  url(path: string, params: Record<string, string | number> = {}): string {
    const query = new URLSearchParams({ ...Object.fromEntries(Object.entries(params).map(([k, v]) => [k, String(v)])), token: this.token });
    return `${this.base}${path}?${query.toString()}`;
  }

  async json<T>(path: string, params: Record<string, string | number> = {}, body?: unknown): Promise<T> {
    const response = await fetch(this.url(path, params), body === undefined ? {} : {
      method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify(body),
    });
    const text = await response.text();
    const json = text ? JSON.parse(text) : {};
    if (!response.ok) throw new ApiError(response.status, json.error ?? `${response.status} ${response.statusText}`);
    return json as T;
  }

  async points(id: number): Promise<PointSet> {
    const response = await fetch(this.url(`/api/docs/${id}/points`));
    if (!response.ok) throw new ApiError(response.status, `points: ${response.status}`);
    return parsePoints(await response.arrayBuffer());
  }

  // Polls a job every `interval_ms` until it ends, reporting progress; resolves with its last state.
  async waitForJob(job: JobInfo, onProgress: (job: JobInfo) => void, interval_ms = 150): Promise<JobInfo> {
    let current = job;
    while (current.state === 'queued' || current.state === 'running') {
      onProgress(current);
      await new Promise((resolve) => setTimeout(resolve, interval_ms));
      current = await this.json<JobInfo>(`/api/jobs/${current.id}`);
    }
    onProgress(current);
    return current;
  }
}

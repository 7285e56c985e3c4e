// The editor: wires the toolbar, the ray image and the 3-D view to the server (docs/api.md).
import { Api, ApiError, DocumentInfo, JobInfo, MeshData, inverseRigid, multiply, poseMatrix } from './api';
import { PointColouring, PointView } from './pointview';
import { Brush, RayView } from './rayview';
import { Cell, toCellList } from './strokes';

const api = Api.fromLocation(window.location);
const element = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const status = (text: string) => (element('status').textContent = text);

const rayView = new RayView(element<HTMLCanvasElement>('ray'));
const pointView = new PointView(element('points'));
let doc: DocumentInfo | null = null;
let runningJob: JobInfo | null = null;
let placed: { id: number; mesh: MeshData } | null = null;
let picked: { row: number; col: number } | null = null;
const strokeKinds = new Set<Brush>();  // brushes used on the open scan since its last cut was reset

// For end-to-end tests: where a cell is on screen, and what is open.
(window as unknown as Record<string, unknown>).lidarshop = { rayView, pointView, current: () => doc, verify: () => verify() };

async function refresh(keepView: boolean) {
  if (!doc) return;
  doc = await api.json<DocumentInfo>(`/api/docs/${doc.id}`);
  const channel = element<HTMLSelectElement>('channel').value;
  const usable = channel === 'rgb' && !doc.channels.includes('color') ? 'intensity' : channel;
  const aspect = doc.azimuth_step_deg > 0 ? doc.elevation_step_deg / doc.azimuth_step_deg : 1;
  const mask = doc.object_cells > 0 ? api.url(`/api/docs/${doc.id}/mask.png`, { style: 'overlay', v: doc.version }) : null;
  const hole = doc.hole_cells > 0 ? api.url(`/api/docs/${doc.id}/mask.png`, { style: 'overlay', layer: 'hole', v: doc.version }) : null;
  await rayView.show(api.url(`/api/docs/${doc.id}/image.png`, { channel: usable, v: doc.version }), mask, hole, doc.rows, doc.cols, aspect, keepView);
  pointView.show(await api.points(doc.id), keepView);
  element<HTMLButtonElement>('undo').disabled = !doc.can_undo;
  element<HTMLButtonElement>('redo').disabled = !doc.can_redo;
  const behind = doc.behind_cells > 0 ? `, ${doc.behind_cells} behind the object` : '';
  status(`${doc.name}: ${doc.rows} x ${doc.cols} cells, ${doc.valid_cells} returns, ${doc.synthesized_cells} synthesized, ${doc.object_cells} in the object, ${doc.hole_cells} in the hole${behind} (version ${doc.version})`);
}

async function open(params: Record<string, string>) {
  try {
    status('opening…');
    doc = await api.json<DocumentInfo>('/api/open', params);
    rayView.clearStrokes();
    strokeKinds.clear();
    await refresh(false);
  } catch (error) {
    status(`open failed: ${(error as Error).message}`);
  }
}

// Runs an operation as a job; shows the progress bar once it has taken half a second, with cancel.
async function runJob(path: string, body: unknown, what: string) {
  if (!doc) return status('open a scan first');
  const started = Date.now();
  try {
    runningJob = await api.json<JobInfo>(path, {}, body);
    const finished = await api.waitForJob(runningJob, (job) => {
      const show = Date.now() - started > 500 && (job.state === 'queued' || job.state === 'running');
      element('progress').hidden = !show;
      element('progress-label').textContent = `${what}: ${job.label}`;
      const bar = element<HTMLProgressElement>('progress-bar');
      bar.max = Math.max(1, job.total);
      bar.value = job.done;
    });
    element('progress').hidden = true;
    runningJob = null;
    if (finished.state === 'done') {
      await refresh(true);
      status(`${what} done. ${element('status').textContent}`);
    } else {
      status(`${what} ${finished.state}${finished.error ? `: ${finished.error}` : ''}`);
    }
  } catch (error) {
    element('progress').hidden = true;
    status(`${what} failed: ${error instanceof ApiError ? error.message : String(error)}`);
  }
}

rayView.onStroke = async (brush: Brush, cells: Cell[]) => {
  if (!doc || brush === 'none') return;
  try {
    const key = brush === 'lasso' ? 'hole_polygon' : brush;
    await api.json(`/api/docs/${doc.id}/strokes`, {}, { [key]: toCellList(cells), radius: rayView.radius });
    status(`${cells.length} ${brush} stroke cells painted`);
    if (brush === 'hole' || brush === 'lasso') {
      rayView.clearStrokes(['hole', 'lasso']);
      await refresh(true);
    } else if (element<HTMLInputElement>('live').checked && (strokeKinds.add(brush), strokeKinds.size === 2)) {
      // Live: once both kinds of strokes exist, every stroke re-cuts (incrementally after the first cut).
      await runJob(`/api/docs/${doc.id}/segment`, { refine: doc.object_cells > 0 }, 'segment');
    }
  } catch (error) {
    status(`stroke failed: ${(error as Error).message}`);
  }
};
rayView.onPick = (cell) => {
  if (!doc) return;
  picked = cell;
  addPairForCell(cell);
  rayView.pick(cell);
  pointView.highlight(cell.row * doc.cols + cell.col);
  status(`cell row ${cell.row}, column ${cell.col}`);
};
pointView.onPick = (index) => {
  if (!doc) return;
  picked = { row: Math.floor(index / doc.cols), col: index % doc.cols };
  rayView.pick({ row: Math.floor(index / doc.cols), col: index % doc.cols });
};

for (const button of document.querySelectorAll<HTMLButtonElement>('button.brush')) {
  button.addEventListener('click', () => {
    rayView.brush = button.dataset.brush as Brush;
    document.querySelectorAll('button.brush').forEach((b) => b.classList.toggle('active', b === button));
  });
}
element('brush-object').classList.add('active');
element<HTMLInputElement>('radius').addEventListener('change', (event) => {
  rayView.radius = Number((event.target as HTMLInputElement).value);
});
element('channel').addEventListener('change', () => refresh(true));
element<HTMLInputElement>('point-size').addEventListener('input', (event) => pointView.setPointSize(Number((event.target as HTMLInputElement).value)));
element<HTMLSelectElement>('point-colour').addEventListener('change', (event) => pointView.setColouring((event.target as HTMLSelectElement).value as PointColouring));
element('open-scene').addEventListener('click', () => open({ scene: element<HTMLSelectElement>('scene').value }));
element('open-file').addEventListener('click', () => open({ path: element<HTMLSelectElement>('file').value }));
element('segment').addEventListener('click', () => runJob(`/api/docs/${doc?.id}/segment`, {}, 'segment'));
element('remove').addEventListener('click', async () => {
  await runJob(`/api/docs/${doc?.id}/remove`, {}, 'remove');
  rayView.clearStrokes();
  strokeKinds.clear();
});
element('fill').addEventListener('click', () => runJob(`/api/docs/${doc?.id}/fill`, {}, 'fill'));
element('fill-hole').addEventListener('click', () => runJob(`/api/docs/${doc?.id}/fill`, { hole: 'painted' }, 'fill hole'));
element('fill-shadow').addEventListener('click', async () => {
  await runJob(`/api/docs/${doc?.id}/remove`, { options: { keep_object: true } }, 'fill shadow');
  rayView.clearStrokes(['object', 'background']);
});
for (const action of ['undo', 'redo']) {
  element(action).addEventListener('click', async () => {
    if (!doc) return;
    try {
      await api.json(`/api/docs/${doc.id}/${action}`, {}, {});
      await refresh(true);
    } catch (error) {
      status(`${action}: ${(error as Error).message}`);
    }
  });
}
element('cancel').addEventListener('click', () => {
  if (runningJob) api.json(`/api/jobs/${runningJob.id}/cancel`, {}, {}).catch(() => {});
});
element('save').addEventListener('click', () => {
  if (!doc) return;
  const link = document.createElement('a');
  link.href = api.url(`/api/docs/${doc.id}/save`, { format: element<HTMLSelectElement>('format').value });
  link.download = '';
  link.click();
});

// Verification: place a model, then every change of the pose re-verifies it (thesis ch. 4).
const poseInputs = ['pose-x', 'pose-y', 'pose-z', 'pose-yaw'].map((id) => element<HTMLInputElement>(id));
let verifyTimer: ReturnType<typeof setTimeout> | undefined;
async function verify() {
  if (!doc || !placed) return;
  const [x, y, z, yaw] = poseInputs.map((input) => Number(input.value));
  try {
    const result = await api.json<{ consistency: number | null; confidence: number; summary: string }>(
      `/api/docs/${doc.id}/verify`, {}, { model: placed.id, pose: { x_m: x, y_m: y, z_m: z, yaw_deg: yaw } });
    element('verify-result').textContent = result.summary;
    const scannerFromWorld = inverseRigid(doc.world_from_scanner_column_major);
    pointView.showModel(placed.mesh, multiply(scannerFromWorld, poseMatrix(x, y, z, yaw)), result.consistency);
  } catch (error) {
    element('verify-result').textContent = `verify: ${(error as Error).message}`;
  }
}
for (const input of poseInputs) {
  input.addEventListener('input', () => {
    clearTimeout(verifyTimer);
    verifyTimer = setTimeout(verify, 120);
  });
}
element('place').addEventListener('click', async () => {
  if (!doc) return status('open a scan first');
  try {
    const model = await api.json<{ id: number }>('/api/models', {}, { model: element<HTMLSelectElement>('model').value });
    placed = { id: model.id, mesh: await api.mesh(model.id) };
    if (picked) {
      // The picked cell's point in the world frame (the scan's pose): the model stands there.
      const points = await api.points(doc.id);
      const index = points.cells.indexOf(picked.row * doc.cols + picked.col);
      if (index >= 0) {
        const w = doc.world_from_scanner_column_major;
        const [px, py, pz] = [points.xyz[3 * index], points.xyz[3 * index + 1], points.xyz[3 * index + 2]];
        poseInputs[0].value = (w[0] * px + w[4] * py + w[8] * pz + w[12]).toFixed(2);
        poseInputs[1].value = (w[1] * px + w[5] * py + w[9] * pz + w[13]).toFixed(2);
        poseInputs[2].value = (w[2] * px + w[6] * py + w[10] * pz + w[14]).toFixed(2);
      }
    }
    await verify();
  } catch (error) {
    status(`place: ${(error as Error).message}`);
  }
});

// Recolouring (thesis 3.2): click a pixel in the photo, then the same spot in the ray image (Pick tool); six or
// more pairs give the camera; the photo's colours then go to the points it sees.
const photoCanvas = element<HTMLCanvasElement>('photo');
let photo: HTMLImageElement | null = null;
let pendingPixel: [number, number] | null = null;
const pairs: { pixel: [number, number]; cell: [number, number] }[] = [];
function drawPhoto() {
  const context = photoCanvas.getContext('2d');
  if (!context || !photo) return;
  photoCanvas.width = photoCanvas.clientWidth;
  photoCanvas.height = photoCanvas.clientHeight;
  const scale = Math.min(photoCanvas.width / photo.width, photoCanvas.height / photo.height);
  context.drawImage(photo, 0, 0, photo.width * scale, photo.height * scale);
  context.fillStyle = '#ff0';
  for (const pair of pairs) context.fillRect(pair.pixel[0] * scale - 3, pair.pixel[1] * scale - 3, 6, 6);
  if (pendingPixel) {
    context.strokeStyle = '#0ff';
    context.strokeRect(pendingPixel[0] * scale - 5, pendingPixel[1] * scale - 5, 10, 10);
  }
  photoCanvas.dataset.scale = String(scale);
}
photoCanvas.addEventListener('click', (event) => {
  if (!photo) return;
  const scale = Number(photoCanvas.dataset.scale);
  const pixel: [number, number] = [event.offsetX / scale, event.offsetY / scale];
  if (pixel[0] >= photo.width || pixel[1] >= photo.height) return;
  pendingPixel = pixel;
  drawPhoto();
  status(`photo pixel (${pixel[0].toFixed(1)}, ${pixel[1].toFixed(1)}): now pick the same spot in the ray image`);
});
function addPairForCell(cell: { row: number; col: number }) {
  if (!pendingPixel) return;
  pairs.push({ pixel: pendingPixel, cell: [cell.row, cell.col] });
  pendingPixel = null;
  element('pairs').textContent = `${pairs.length} pairs`;
  drawPhoto();
}
element<HTMLInputElement>('photo-file').addEventListener('change', async (event) => {
  const file = (event.target as HTMLInputElement).files?.[0];
  if (!file || !doc) return;
  try {
    await fetch(api.url(`/api/docs/${doc.id}/photo`), { method: 'POST', body: file, headers: { 'Content-Type': file.type } })
      .then(async (response) => { if (!response.ok) throw new Error((await response.json()).error); });
    photo = new Image();
    photo.onload = drawPhoto;
    photo.src = api.url(`/api/docs/${doc.id}/photo.png`, { v: Date.now() });
    element('photo-panel').hidden = false;
    pairs.length = 0;
    element('pairs').textContent = '0 pairs';
    status('photo loaded: click a pixel in it, then the same spot in the ray image (Pick tool)');
  } catch (error) {
    status(`photo: ${(error as Error).message}`);
  }
});
element('recolor').addEventListener('click', () => runJob(`/api/docs/${doc?.id}/recolor`, { pairs }, 'recolour'));

async function start() {
  try {
    const { scenes } = await api.json<{ scenes: string[] }>('/api/scenes');
    element('scene').replaceChildren(...scenes.map((name) => new Option(name, name)));
    const { files } = await api.json<{ files: { path: string }[] }>('/api/files');
    element('file').replaceChildren(...files.map((file) => new Option(file.path.split('/').pop()!, file.path)));
    const models = await api.json<{ builtin: string[]; files: string[] }>('/api/models');
    element('model').replaceChildren(...models.builtin.map((name) => new Option(name, name)),
      ...models.files.map((path) => new Option(path.split('/').pop()!, path)));
    const { documents } = await api.json<{ documents: DocumentInfo[] }>('/api/docs');
    if (documents.length > 0) {
      doc = documents[0];
      await refresh(false);
    }
  } catch (error) {
    status(error instanceof ApiError && error.status === 401 ? 'open the URL `lidarshop serve` printed (it holds the token)' : String(error));
  }
}
start();

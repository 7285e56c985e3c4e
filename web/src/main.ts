// The editor: wires the toolbar, the ray image and the 3-D view to the server (docs/api.md).
import {
  Api,
  ApiError,
  DocumentInfo,
  JobInfo,
  MeshData,
  Narrowed,
  PointSet,
  fileLabel,
  firstReadableFile,
  inverseRigid,
  multiply,
  poseMatrix,
  resultWarnings,
} from './api';
import { PointColouring, PointView } from './pointview';
import { PairsPanel } from './pairsui';
import { Brush, RayView, loadImage } from './rayview';
import { PendingReview, ReviewChoice, decisionBody } from './review';
import { ReviewPanel } from './reviewpanel';
import { Cell, toCellList } from './strokes';
import { VersionGate, applyDelta, parsePointsAnswer } from './delta';
import { StationsPanel } from './stations';
import { PictureStore, loadOverlay } from './picture';
import type {
  DocumentsReply,
  FilesReply,
  FormatsReply,
  ModelReply,
  ModelsReply,
  SavePlanReply,
  ScenesReply,
  VerifyReply,
  VerifyResult,
} from './api_types.generated';
import { TileStore } from './tiles';
import { CellBox, boxParam, detailBox, lookedAtPoint, mergeDetail, nearBoxCentre } from './detail';

const api = Api.fromLocation(window.location);
const element = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const status = (text: string) => (element('status').textContent = text);

const rayView = new RayView(element<HTMLCanvasElement>('ray'));
const pointView = new PointView(element('points'));
let doc: DocumentInfo | null = null;
let runningJob: JobInfo | null = null;
let jobsFinished = 0; // jobs that ended (done, failed or cancelled): for end-to-end tests
let placed: { id: number; mesh: MeshData } | null = null;
let picked: { row: number; col: number } | null = null;
let openDocuments: DocumentInfo[] = []; // the server's open documents, for the list
const gate = new VersionGate(); // answers are shown in version order
// Per document: the points held, their version and level of detail (every step-th row and column).
// A large scan also holds a box of cells at full resolution where the camera looks (detail.ts); `shown` is
// what the view draws (the coarse points outside the box and the detail).
interface Detail {
  box: CellBox;
  version: number;
  points: PointSet;
}
interface HeldPoints {
  version: number;
  step: number;
  points: PointSet;
  detail?: Detail;
  shown?: PointSet;
}
const heldPoints = new Map<number, HeldPoints>();
// Levels of detail of the 3-D view: the first download holds at most about FIRST_POINTS points, then it is
// refined to at most about MOST_POINTS (the browser's budget, issue 34: 1-2 M points; a 1400-pixel-wide view
// shows no more; deltas then name only those cells).
// A scan over the budget keeps DETAIL_POINTS of it for the box at full resolution where the camera looks.
const FIRST_POINTS = 1_000_000,
  MOST_POINTS = 2_000_000,
  DETAIL_POINTS = 500_000;
const pointsHeld = () =>
  [...heldPoints.values()].reduce(
    (sum, held) => sum + held.points.count + (held.detail?.points.count ?? 0),
    0,
  );
const stepFor = (returns: number, most: number) => Math.max(1, Math.ceil(Math.sqrt(returns / most)));
// The level a scan's 3-D view is refined to: whole when it fits the budget, else coarse enough to leave room for
// the detail.
const refinedStep = (returns: number) =>
  returns <= MOST_POINTS ? 1 : stepFor(returns, MOST_POINTS - DETAIL_POINTS);
let pointsShown: { id: number; version: number; points: PointSet | null } = {
  id: -1,
  version: -1,
  points: null,
};
let pointsChain: Promise<void> = Promise.resolve(); // point updates one at a time, in order
let pointBytes = 0; // bytes of points received (whole or deltas), for tests
const pictures = new PictureStore(); // ray images held per document and channel, patched by what changed
// A large scan's ray image comes as tiles of the level the zoom needs (tiles.ts), never whole.
const tiles = new TileStore((path, params) => api.url(path, params));
const TILED_CELLS = 4_000_000;
let overlayBytes = 0; // bytes of overlays received, for tests
const firstPictures = new Map<number, number>(); // when a large scan's first picture was shown (tests)
const strokeKinds = new Set<Brush>(); // brushes used on the open scan since its last cut was reset

let pending: PendingReview | null = null; // the patch review shown (null = none)
let placingByHand = false; // the next pick in the ray image is a review's source patch

// The stations of the shown scan's site (stations.ts): the list, their markers in 3-D, Clean.
async function showById(id: number) {
  await listDocuments();
  const next = openDocuments.find((d) => d.id === id);
  if (next) await showDocument(next);
}
const stationsPanel = new StationsPanel(
  { api, doc: () => doc, show: showById, status, runJob, ...pointView.overlay() },
  element('stations-list'),
  element<HTMLButtonElement>('clean'),
  element('clean-result'),
  element<HTMLButtonElement>('fill-stations'),
);

// For end-to-end tests: where a cell is on screen, and what is open.
(window as unknown as Record<string, unknown>).lidarshop = {
  rayView,
  pointView,
  current: () => doc,
  verify: () => verify(),
  review: () => pending,
  pairs: () => pairsPanel,
  pointLevel: () => (doc ? (heldPoints.get(doc.id)?.step ?? 0) : 0),
  refinedLevel: (returns: number) => refinedStep(returns),
  // The box held at full resolution where the camera looks, and its points (null without one).
  detail: () => {
    const detail = doc ? heldPoints.get(doc.id)?.detail : undefined;
    return detail ? { box: detail.box, version: detail.version, count: detail.points.count } : null;
  },
  detailPoints: () => (doc ? (heldPoints.get(doc.id)?.detail?.points ?? null) : null),
  // Points the browser holds over every open scan (the budget is MOST_POINTS per scan shown).
  pointsHeld: () => pointsHeld(),
  pointBudget: MOST_POINTS,
  firstPictures: () => Object.fromEntries(firstPictures),
  pictures,
  pointBytes: () => pointBytes,
  pictureBytes: () => pictures.bytes + tiles.totalBytes() + overlayBytes,
  tiles,
  tiled: (id: number) => tiles.heldPicture(id, element<HTMLSelectElement>('channel').value),
  pointsShown: () => pointsShown,
  documents: () => openDocuments,
  settled: () => pointsChain.then(() => true),
  stations: () => stationsPanel,
  jobsFinished: () => jobsFinished,
};

// The points of level `step` (only those inside `box` when given) at the server's current version: a delta from
// `held` when the server still keeps its version, else the whole points.
async function pointsUpToDate(
  id: number,
  held: { version: number; points: PointSet } | undefined,
  step: number,
  box?: CellBox,
): Promise<{ version: number; points: PointSet }> {
  const param = box ? boxParam(box) : undefined;
  const answer = await api.pointsSince(id, held ? held.version : null, step, param);
  pointBytes += answer.bytes;
  const parsed = parsePointsAnswer(answer.buffer);
  if ('whole' in parsed) return { version: answer.version, points: parsed.whole };
  if (held && parsed.delta.from === held.version) {
    const points = parsed.delta.count > 0 ? applyDelta(held.points, parsed.delta) : held.points;
    return { version: parsed.delta.to, points };
  }
  const whole = await api.pointsSince(id, null, step, param);
  pointBytes += whole.bytes;
  return { version: whole.version, points: (parsePointsAnswer(whole.buffer) as { whole: PointSet }).whole };
}

// What the view draws of `next`: its coarse points, merged with its detail (the merge of `before` again when
// neither moved).
function shownPoints(next: HeldPoints, before: HeldPoints | undefined): PointSet {
  if (!next.detail) return next.points;
  if (before?.shown && before.points === next.points && before.detail?.points === next.detail.points)
    return before.shown;
  return mergeDetail(next.points, next.detail.points, next.detail.box);
}

// Shows the held points of `id` if it is the document shown; an edit that moved no point (a stroke, a cut that
// changed no cell held) keeps the points shown: building the view's buffers again costs seconds at a million
// points.
function showHeld(id: number, held: HeldPoints, keepView: boolean) {
  if (doc?.id !== id) return;
  const points = held.shown ?? held.points;
  if (pointsShown.id !== id || pointsShown.points !== points || !keepView) {
    pointView.show(points, keepView && pointsShown.id === id);
  }
  pointsShown = { id, version: held.version, points };
}

// Brings the held points of document `id` to the server's current version: the cells changed since the held
// version (a delta), or the whole points the first time, and the same for the detail box; then shows them if
// the document is still shown. `step`: a level of detail to download whole instead (a refinement); by default
// the one held, or for the first download the coarsest that holds about FIRST_POINTS.
function updatePoints(id: number, keepView: boolean, step?: number): Promise<void> {
  pointsChain = pointsChain.then(async () => {
    try {
      const before = heldPoints.get(id);
      const kept = before && (step === undefined || step === before.step) ? before : undefined;
      const level = kept?.step ?? step ?? stepFor(doc?.id === id ? doc.valid_cells : 0, FIRST_POINTS);
      const coarse = await pointsUpToDate(id, kept, level);
      const next: HeldPoints = { ...coarse, step: level, detail: before?.detail };
      if (next.detail && next.detail.version !== coarse.version) {
        const box = next.detail.box;
        next.detail = { box, ...(await pointsUpToDate(id, next.detail, 1, box)) };
      }
      next.shown = shownPoints(next, before);
      heldPoints.set(id, next);
      // The browser's point budget holds over every open scan: other scans' points go first (fetched again
      // when shown again).
      for (const other of [...heldPoints.keys()]) {
        if (pointsHeld() <= MOST_POINTS) break;
        if (other !== id) heldPoints.delete(other);
      }
      showHeld(id, next, keepView);
    } catch (error) {
      status(`points: ${(error as Error).message}`);
    }
  });
  return pointsChain;
}

// Holds the box of cells around (row, col) at full resolution beside the coarse level (a scan refined to a
// coarser level only), unless (row, col) is near the middle of the box held already.
function refineAt(id: number, row: number, col: number): Promise<void> {
  pointsChain = pointsChain.then(async () => {
    try {
      const held = heldPoints.get(id);
      if (!held || held.step <= 1 || (held.detail && nearBoxCentre(held.detail.box, row, col))) return;
      const box = detailBox(held.points.rows, held.points.cols, row, col, DETAIL_POINTS);
      const next: HeldPoints = { ...held, detail: { box, ...(await pointsUpToDate(id, undefined, 1, box)) } };
      next.shown = shownPoints(next, held);
      heldPoints.set(id, next);
      showHeld(id, next, true);
      if (next.detail!.version !== held.version) void updatePoints(id, true); // an edit came in between
    } catch (error) {
      status(`points: ${(error as Error).message}`);
    }
  });
  return pointsChain;
}

// When the camera stops moving: the detail where it now looks (the point nearest its view axis).
pointView.onSettled = () => {
  const held = doc ? heldPoints.get(doc.id) : undefined;
  if (!doc || !held || held.step <= 1) return;
  const shown = held.shown ?? held.points;
  const { eye, direction } = pointView.view();
  const index = lookedAtPoint(shown, eye, direction);
  if (index < 0) return;
  const cell = shown.cells[index];
  void refineAt(doc.id, Math.floor(cell / shown.cols), cell % shown.cols);
};

// The list of open documents (the server's), the shown one selected.
async function listDocuments() {
  const { documents } = await api.json<Narrowed<DocumentsReply, { documents: DocumentInfo[] }>>('/api/docs');
  openDocuments = documents;
  const select = element<HTMLSelectElement>('documents');
  select.replaceChildren(
    ...documents.map((d) => {
      const option = new Option(`#${d.id} ${d.name}${d.can_undo ? ' (edited)' : ''}`, String(d.id));
      option.title = `${d.rows} x ${d.cols} cells, version ${d.version}`;
      return option;
    }),
  );
  if (doc) select.value = String(doc.id);
  element<HTMLButtonElement>('close-doc').disabled = documents.length === 0;
}

// Shows another open document (its history, points and view are the server's; nothing is lost switching).
async function showDocument(next: DocumentInfo | null) {
  doc = next;
  rayView.clearStrokes();
  strokeKinds.clear();
  pending = null;
  reviewPanel.hide();
  if (doc) {
    await refresh(false);
  } else {
    status('No scan open: open a built-in scene or a file.');
  }
  await listDocuments();
}

// Shows the server's state of the document: its pictures (ray image, object, hole and strokes overlays) and
// points. `strokesOnly`: an edit of the strokes or the hole, which changes no point or ray image, so only the
// overlays are fetched. An answer about an older version than the one shown is dropped (VersionGate).
async function refresh(keepView: boolean, strokesOnly = false) {
  if (!doc) return;
  const id = doc.id;
  const info = await api.json<DocumentInfo>(`/api/docs/${id}`);
  if (doc?.id !== id || !gate.accept(id, info.version)) return; // switched away, or overtaken by a newer answer
  doc = info;
  const channel = element<HTMLSelectElement>('channel').value;
  // A channel the scan does not hold falls back to intensity, then range (a file may hold neither colour nor
  // intensity); labels and classes to range.
  const has = (name: string) => info.channels.includes(name);
  let usable = channel;
  if (usable === 'rgb' && !has('color')) usable = 'intensity';
  if (usable === 'intensity' && !has('intensity')) usable = 'range';
  if ((usable === 'labels' || usable === 'classification') && !has('label')) usable = 'range';
  const aspect = info.azimuth_step_deg > 0 ? info.elevation_step_deg / info.azimuth_step_deg : 1;
  const v = info.version;
  // Overlays cropped to their drawn cells, the ray image patched by the pixels that changed (picture.ts).
  const overlay = (params: Record<string, string | number>) =>
    loadOverlay(
      api.url(`/api/docs/${id}/mask.png`, { style: 'overlay', crop: 1, v, ...params }),
      info.rows,
      info.cols,
      (bytes) => (overlayBytes += bytes),
    );
  const mask = info.object_cells > 0 ? overlay({}) : null;
  const hole = info.hole_cells > 0 ? overlay({ layer: 'hole' }) : null;
  const strokes = overlay({ layer: 'strokes' });
  const image =
    info.rows * info.cols > TILED_CELLS
      ? tiles.picture(id, usable, strokesOnly ? -1 : v)
      : pictures.picture(
          (params) => api.url(`/api/docs/${id}/image.png`, params),
          id,
          usable,
          strokesOnly ? -1 : v,
        );
  const shown = await rayView.show(id, v, image, mask, hole, strokes, info.rows, info.cols, aspect, keepView);
  if (!strokesOnly) {
    // The 3-D view follows the ray image and does not hold it up: a large scan's coarse level first, refined
    // after the first picture (its deltas then name the refined level's cells).
    const first = !heldPoints.has(id);
    const points = updatePoints(id, keepView);
    const finer = refinedStep(info.valid_cells);
    if (first && finer < stepFor(info.valid_cells, FIRST_POINTS)) {
      firstPictures.set(id, performance.now());
      void points.then(() => updatePoints(id, true, finer));
    } else {
      await points;
    }
  }
  if (!strokesOnly && doc?.id === id) {
    await stationsPanel
      .refresh(info, heldPoints.get(id)?.points)
      .catch((error) => status(`stations: ${(error as Error).message}`));
  }
  if (!shown || doc?.id !== id || gate.version(id) !== v) return;
  const photos = info.e57_images ?? [];
  const photoSelect = element<HTMLSelectElement>('e57-photo');
  if (photoSelect.dataset.doc !== String(id)) {
    photoSelect.dataset.doc = String(id);
    photoSelect.replaceChildren(
      new Option(`E57 photos (${photos.length})`, ''),
      ...photos.map((p) => {
        const option = new Option(`${p.name} (${p.width_px} x ${p.height_px})`, String(p.index));
        option.disabled = !p.usable;
        return option;
      }),
    );
    photoSelect.hidden = photos.length === 0;
    element('recolor-station').hidden = photos.length === 0;
  }
  element<HTMLButtonElement>('undo').disabled = !info.can_undo;
  element<HTMLButtonElement>('redo').disabled = !info.can_redo;
  const behind = info.behind_cells > 0 ? `, ${info.behind_cells} behind the object` : '';
  status(
    `${info.name}: ${info.rows} x ${info.cols} cells, ${info.valid_cells} returns, ${info.synthesized_cells} synthesized, ${info.object_cells} in the object, ${info.hole_cells} in the hole${behind} (version ${v})`,
  );
}

async function open(params: Record<string, string>) {
  try {
    status('opening…');
    const opened = await api.json<DocumentInfo>('/api/open', params);
    await showDocument(opened);
    if (pairsPanel.pairs.mode === 'scan-scan') await pairsPanel.listTargets();
  } catch (error) {
    // 409 (16 open) or 507 (no memory left): the server refuses rather than closing one; the message says so.
    status(`open failed: ${(error as Error).message}`);
    await listDocuments().catch(() => {});
  }
}

// Runs an operation as a job; shows the progress bar once it has taken half a second, with cancel. Resolves
// with the job's last state (null when it could not start); `refreshAfter` reloads the scan when it is done.
async function runJob(
  path: string,
  body: unknown,
  what: string,
  refreshAfter = true,
): Promise<JobInfo | null> {
  if (!doc) {
    status('open a scan first');
    return null;
  }
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
      if (refreshAfter) await refresh(true);
      // A result that looks wrong says so first (a cut that leaked, an empty hole, a camera that disagrees).
      const warnings = resultWarnings(finished)
        .map((warning) => `warning: ${warning}. `)
        .join('');
      status(`${what} done. ${warnings}${element('status').textContent}`);
    } else {
      status(`${what} ${finished.state}${finished.error ? `: ${finished.error}` : ''}`);
    }
    ++jobsFinished; // after the refresh: the document shown is the job's result
    return finished;
  } catch (error) {
    element('progress').hidden = true;
    ++jobsFinished;
    status(`${what} failed: ${error instanceof ApiError ? error.message : String(error)}`);
    return null;
  }
}

rayView.onStroke = async (brush: Brush, cells: Cell[]) => {
  if (!doc || brush === 'none') return;
  try {
    const key = brush === 'lasso' ? 'hole_polygon' : brush;
    await api.json(`/api/docs/${doc.id}/strokes`, {}, { [key]: toCellList(cells), radius: rayView.radius });
    const hadCut = doc.object_cells > 0;
    const strokesShown = refresh(true, true); // the strokes as the server holds them
    if (
      (brush === 'object' || brush === 'background') &&
      element<HTMLInputElement>('live').checked &&
      (strokeKinds.add(brush), strokeKinds.size === 2)
    ) {
      // Live: once both kinds of strokes exist, every stroke re-cuts (incrementally after the first cut). The
      // cut starts without waiting for the strokes' picture: answers are shown in version order (VersionGate),
      // so the strokes' picture is dropped if the cut's comes first.
      status(`${cells.length} ${brush} stroke cells painted`);
      await Promise.all([strokesShown, runJob(`/api/docs/${doc.id}/segment`, { refine: hadCut }, 'segment')]);
    } else {
      await strokesShown;
      status(`${cells.length} ${brush} stroke cells painted`);
    }
  } catch (error) {
    status(`stroke failed: ${(error as Error).message}`);
    await refresh(true, true).catch(() => {});
  }
};
rayView.onPick = (cell) => {
  if (!doc) return;
  if (placingByHand) {
    setPlacing(false);
    reviewStep(`/api/docs/${doc.id}/inpaint/review/decide`, { source: [cell.row, cell.col] }, 'place patch');
    return;
  }
  picked = cell;
  pairsPanel.pickCell(cell);
  rayView.pick(cell);
  pointView.highlight(cell.row * doc.cols + cell.col);
  status(`cell row ${cell.row}, column ${cell.col}`);
};
pointView.onPick = (index) => {
  if (!doc) return;
  picked = { row: Math.floor(index / doc.cols), col: index % doc.cols };
  pairsPanel.pickCell(picked);
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
for (const layer of ['original', 'synthesized', 'object', 'from-stations'] as const) {
  element<HTMLInputElement>(`layer-${layer}`).addEventListener('change', (event) =>
    pointView.setLayerVisible(layer, (event.target as HTMLInputElement).checked),
  );
}
element<HTMLInputElement>('layer-stations').addEventListener('change', (event) =>
  stationsPanel.setOthersVisible((event.target as HTMLInputElement).checked),
);
const openSite = (body: { scene?: string; path?: string; documents?: number[] }) =>
  stationsPanel.open(body).catch(async (error) => {
    status(`open site failed: ${(error as Error).message}`);
    await listDocuments().catch(() => {});
  });
element('open-site-scene').addEventListener('click', () =>
  openSite({ scene: element<HTMLSelectElement>('scene').value }),
);
element('open-site-file').addEventListener('click', () =>
  openSite({ path: element<HTMLSelectElement>('file').value }),
);
element('group-docs').addEventListener('click', () =>
  openSite({ documents: openDocuments.map((d) => d.id) }),
);
element<HTMLInputElement>('point-size').addEventListener('input', (event) =>
  pointView.setPointSize(Number((event.target as HTMLInputElement).value)),
);
element<HTMLSelectElement>('point-colour').addEventListener('change', (event) =>
  pointView.setColouring((event.target as HTMLSelectElement).value as PointColouring),
);
element('open-scene').addEventListener('click', () =>
  open({ scene: element<HTMLSelectElement>('scene').value }),
);
element('open-file').addEventListener('click', () =>
  open({ path: element<HTMLSelectElement>('file').value }),
);
element('segment').addEventListener('click', () => runJob(`/api/docs/${doc?.id}/segment`, {}, 'segment'));
element('remove').addEventListener('click', async () => {
  await runJob(`/api/docs/${doc?.id}/remove`, {}, 'remove');
  strokeKinds.clear(); // the removal cleared the server's strokes
});
element('fill').addEventListener('click', () => runJob(`/api/docs/${doc?.id}/fill`, {}, 'fill'));
element('fill-hole').addEventListener('click', () =>
  runJob(`/api/docs/${doc?.id}/fill`, { hole: 'painted' }, 'fill hole'),
);
element('fill-shadow').addEventListener('click', async () => {
  await runJob(`/api/docs/${doc?.id}/remove`, { options: { keep_object: true } }, 'fill shadow');
  strokeKinds.clear();
});
// Undo / redo ask the server (which answers 409 when there is nothing to undo or redo): the keys do not wait
// for the buttons' state, which follows the last refresh.
async function undoRedo(action: 'undo' | 'redo') {
  if (!doc) return;
  try {
    await api.json(`/api/docs/${doc.id}/${action}`, {}, {});
    await refresh(true);
  } catch (error) {
    status(`${action}: ${(error as Error).message}`);
  }
}
for (const action of ['undo', 'redo'] as const)
  element(action).addEventListener('click', () => undoRedo(action));
element('recolor-station').addEventListener('click', () =>
  runJob(`/api/docs/${doc?.id}/recolor-station`, {}, "colour from the station's photos"),
);
element('e57-photo').addEventListener('change', () => {
  const value = element<HTMLSelectElement>('e57-photo').value;
  if (value !== '') pairsPanel.useE57Photo(Number(value));
});
element('documents').addEventListener('change', () => {
  const id = Number(element<HTMLSelectElement>('documents').value);
  const next = openDocuments.find((d) => d.id === id);
  if (next && next.id !== doc?.id) showDocument(next);
});
element('close-doc').addEventListener('click', async () => {
  if (!doc) return;
  const closing = doc;
  // Closing is the user's alone (the server never closes one); edits not saved are lost, so it asks.
  if (closing.can_undo && !window.confirm(`Close ${closing.name}? Its edits are lost unless saved.`)) return;
  try {
    await api.delete(`/api/docs/${closing.id}`);
  } catch (error) {
    status(`close: ${(error as Error).message}`);
    return;
  }
  heldPoints.delete(closing.id);
  pictures.forget(closing.id);
  tiles.forget(closing.id);
  gate.forget(closing.id);
  await listDocuments();
  await showDocument(openDocuments[0] ?? null);
  status(`closed ${closing.name}. ${element('status').textContent}`);
});

// Keyboard: B / E brush / eraser, [ ] radius, Ctrl+Z / Ctrl+Y (or Ctrl+Shift+Z) undo / redo, F fit view.
document.addEventListener('keydown', (event) => {
  const target = event.target as HTMLElement;
  if (target.closest('input, select, textarea')) return;
  const radius = element<HTMLInputElement>('radius');
  const setRadius = (value: number) => {
    radius.value = String(Math.max(0, Math.min(20, value)));
    rayView.radius = Number(radius.value);
  };
  const key = event.key.toLowerCase();
  if ((event.ctrlKey || event.metaKey) && (key === 'y' || (key === 'z' && event.shiftKey))) undoRedo('redo');
  else if ((event.ctrlKey || event.metaKey) && key === 'z') undoRedo('undo');
  else if (event.ctrlKey || event.metaKey || event.altKey) return;
  else if (key === 'b') element('brush-object').click();
  else if (key === 'e') element('brush-erase').click();
  else if (key === '[') setRadius(Number(radius.value) - 1);
  else if (key === ']') setRadius(Number(radius.value) + 1);
  else if (key === 'f') rayView.fitToView();
  else return;
  event.preventDefault();
});

element('cancel').addEventListener('click', () => {
  if (runningJob) api.json(`/api/jobs/${runningJob.id}/cancel`, {}, {}).catch(() => {});
});
element('save').addEventListener('click', async () => {
  if (!doc) return;
  const format = element<HTMLSelectElement>('format').value;
  // Ask first what the format would drop: nothing is lost without a word.
  try {
    const plan = await api.json<SavePlanReply>(`/api/docs/${doc.id}/save-plan`, {
      format,
    });
    if (plan.refused) {
      status(`save: ${plan.refused}`);
      return;
    }
    if (plan.dropped.length > 0) {
      const lost = plan.dropped.map((line) => `• ${line.replace(/^[^:]*: /, '')}`).join('\n');
      if (
        !window.confirm(
          `Saving as ${format.toUpperCase()} loses:\n${lost}\n\nSave anyway? (E57 keeps everything.)`,
        )
      ) {
        status(`save: not saved as ${format}`);
        return;
      }
    }
  } catch (error) {
    status(`save: ${(error as Error).message}`);
    return;
  }
  const link = document.createElement('a');
  link.href = api.url(`/api/docs/${doc.id}/save`, { format });
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
    const result = await api.json<VerifyResult & VerifyReply>(
      `/api/docs/${doc.id}/verify`,
      {},
      { model: placed.id, pose: { x_m: x, y_m: y, z_m: z, yaw_deg: yaw } },
    );
    element('verify-result').textContent = result.summary;
    const scannerFromWorld = inverseRigid(doc.world_from_scanner_column_major);
    pointView.showModel(
      placed.mesh,
      multiply(scannerFromWorld, poseMatrix(x, y, z, yaw)),
      result.consistency,
    );
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
    const model = await api.json<ModelReply>(
      '/api/models',
      {},
      { model: element<HTMLSelectElement>('model').value },
    );
    placed = { id: model.id, mesh: await api.mesh(model.id) };
    if (picked) {
      // The picked cell's point in the world frame (the scan's pose): the model stands there.
      await pointsChain;
      const held = heldPoints.get(doc.id);
      const points = held?.shown ?? held?.points;
      const index = !points ? -1 : points.cells.indexOf(picked.row * doc.cols + picked.col);
      if (points && index >= 0) {
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

// Correspondences of the three kinds (pairsui.ts).
const pairsPanel = new PairsPanel({ api, doc: () => doc, status, runJob, refresh: () => refresh(true) });

// The patch review of the inpainting (thesis 7.1 "User action"): the fill stops where no patch passes the
// acceptance tests; the panel shows the candidates grouped, a click accepts one, or a pick places one by hand.
const reviewPanel = new ReviewPanel(
  element('review-panel'),
  element<HTMLCanvasElement>('review-target'),
  element('review-tiles'),
  element('review-caption'),
);
let reviewImages = 0; // a counter in the image URLs: each stop's pictures are new
function setPlacing(on: boolean) {
  placingByHand = on;
  document.body.classList.toggle('placing', on);
  element('review-place').classList.toggle('active', on);
  if (on) element('brush-none').click();
}
async function reviewStep(path: string, body: unknown, what: string) {
  const finished = await runJob(path, body, what, false);
  const result = finished?.result as { state?: string } | undefined;
  if (finished?.state === 'done' && result?.state === 'review') return showReview();
  pending = null;
  reviewPanel.hide();
  setPlacing(false);
  if (finished?.state === 'done') {
    await refresh(true);
    status(`review done: the fill is one edit (undo takes it back). ${element('status').textContent}`);
  }
}
async function showReview() {
  if (!doc) return;
  try {
    pending = await api.json<PendingReview>(`/api/docs/${doc.id}/inpaint/review`);
    const v = ++reviewImages;
    const [canvas, tentative] = await Promise.all(
      ['canvas', 'tentative'].map((layer) =>
        loadImage(api.url(`/api/docs/${doc!.id}/inpaint/review/image.png`, { layer, v })),
      ),
    );
    reviewPanel.show(pending, canvas, tentative);
    const [row, col] = pending.review.target;
    rayView.pick({ row, col });
    status(
      `review: no patch passes at row ${row}, column ${col}; accept a group's patch or place one by hand`,
    );
  } catch (error) {
    status(`review: ${(error as Error).message}`);
  }
}
reviewPanel.onAccept = (candidate) => {
  if (!doc) return;
  const choice: ReviewChoice = { candidate };
  reviewStep(
    `/api/docs/${doc.id}/inpaint/review/decide`,
    decisionBody(choice),
    `accept candidate ${candidate}`,
  );
};
element('review-fill').addEventListener('click', () => {
  if (!doc) return status('open a scan first');
  let options: unknown = undefined;
  const text = element<HTMLInputElement>('review-options').value.trim();
  try {
    if (text) options = JSON.parse(text);
  } catch {
    return status('review options: not JSON');
  }
  reviewStep(
    `/api/docs/${doc.id}/inpaint/review`,
    options === undefined ? { hole: 'painted' } : { hole: 'painted', options },
    'review fill',
  );
});
element('review-place').addEventListener('click', () => {
  setPlacing(!placingByHand);
  if (placingByHand) status('click the centre of the source patch in the ray image');
});
element('review-stop').addEventListener('click', async () => {
  if (!doc) return;
  try {
    await api.delete(`/api/docs/${doc.id}/inpaint/review`);
  } catch (error) {
    status(`stop review: ${(error as Error).message}`);
  }
  pending = null;
  reviewPanel.hide();
  setPlacing(false);
  status('review stopped; the scan is as it was');
});

async function start() {
  try {
    const { scenes } = await api.json<ScenesReply>('/api/scenes');
    const formats = await api.json<FormatsReply>('/api/formats');
    // E57 first: the format that holds everything the editor makes (synthesized flags, photos, two layers).
    const writable = [...formats.write].sort((a, b) => Number(b === 'e57') - Number(a === 'e57'));
    element('format').replaceChildren(...writable.map((name) => new Option(name, name)));
    element('scene').replaceChildren(...scenes.map((name) => new Option(name, name)));
    const { files } = await api.json<FilesReply>('/api/files');
    const fileSelect = element<HTMLSelectElement>('file');
    fileSelect.replaceChildren(
      ...files.map((file) => {
        const option = new Option(fileLabel(file), file.path);
        option.disabled = file.readable === false; // broken files are listed (with why) but not chosen
        if (file.error) option.title = file.error;
        return option;
      }),
    );
    // The dialog starts on the first file that opens (the server lists them in name order, broken ones too).
    const first = firstReadableFile(files);
    if (first) fileSelect.value = first.path;
    const models = await api.json<ModelsReply>('/api/models');
    element('model').replaceChildren(
      ...models.builtin.map((name) => new Option(name, name)),
      ...models.files.map((path) => new Option(path.split('/').pop()!, path)),
    );
    await listDocuments();
    if (openDocuments.length > 0) await showDocument(openDocuments[0]);
  } catch (error) {
    status(
      error instanceof ApiError && error.status === 401
        ? 'open the URL `lidarshop serve` printed (it holds the token)'
        : String(error),
    );
  }
}
start();

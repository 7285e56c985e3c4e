// End to end on a large station (issues 34 and 36): the built-in parking lot scanned on a fine grid (by default
// 2250 x 3600 rays, 5.4 M returns; made here, never committed), served, opened in Debian's chromium. Measures
// how long `serve` reads it, the time from page open to the first ray picture (the coarsest tile, tiles.ts) and
// to the tiles of the view's level, the bytes until then, and the first (coarse) and refined 3-D points, which
// must stay within the browser's point budget (1-2 M points); then counts the bytes of each edit — a stroke,
// its undo and redo, a painted hole filled (points move), its undo — and checks every tile the browser holds
// against the server's after the fill and after its undo. Then the live cut on the parking lot's hatchback: an
// object stroke, a background stroke that runs the first cut, and two strokes that refine it (one inside, one
// taking the car's end away), each timed to the frame that shows its picture. Last, the station is opened again in the running
// server (the file dialog): the time to read it and from then to its first picture. Prints one JSON line with
// the numbers (bench/results/editor.md). --budget S fails the run when the first picture after page open takes
// longer than S seconds.
//
//   node e2e/station.mjs LIDARSHOP_BINARY [ARTEFACTS_DIR] [--rows R --columns C | --station FILE.e57] [--budget S]
//   (a 4000 x 4000 grid: the 16 M-ray station of issue 34)
import { spawn, execFileSync } from 'node:child_process';
import { linkSync, mkdirSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { join, dirname, resolve } from 'node:path';
import { tmpdir } from 'node:os';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : fallback;
};
const [binary, artefacts = join(tmpdir(), 'lidarshop-e2e-station')] = args.filter(
  (a, i) => !a.startsWith('--') && !args[i - 1]?.startsWith('--'),
);
if (!binary)
  throw new Error('usage: node e2e/station.mjs LIDARSHOP_BINARY [ARTEFACTS_DIR] [--rows R --columns C]');
const rows = Number(option('--rows', 2250)),
  columns = Number(option('--columns', 3600));
mkdirSync(artefacts, { recursive: true });
const root = mkdtempSync(join(tmpdir(), 'lidarshop-e2e-station-'));

function fail(message) {
  console.error(`e2e station: FAILED: ${message}`);
  process.exitCode = 1;
  throw new Error(message);
}

// As editor.mjs: polls page.evaluate (Playwright's waitForFunction uses eval, which the CSP forbids).
async function waitForFunction(page, fn, arg, { timeout = 60000 } = {}) {
  const deadline = Date.now() + timeout;
  for (;;) {
    if (await page.evaluate(fn, arg)) return;
    if (Date.now() > deadline) throw new Error(`timed out after ${timeout} ms waiting for ${fn}`);
    await new Promise((resolve) => setTimeout(resolve, 25));
  }
}

const started = Date.now();
// --station FILE: an E57 station made before (e.g. by a previous run's scan), linked into the served folder.
const given = option('--station', '');
const station = join(root, 'station.e57');
if (given) {
  linkSync(resolve(given), station); // a hard link: a symlink out of the served folder is refused
} else {
  execFileSync(binary, [
    'scan',
    'parking_lot',
    '--rows',
    String(rows),
    '--columns',
    String(columns),
    '-o',
    station,
    '--quiet',
  ]);
}
const scanSeconds = (Date.now() - started) / 1000;

// The server opens the station at start (`serve FILE`), as a user opening a scan given on the command line.
const server = spawn(
  binary,
  ['serve', station, '--port', '0', '--web', join(here, '../dist'), '--root', root],
  {
    stdio: ['ignore', 'pipe', 'inherit'],
  },
);
const serveStarted = Date.now();
const url = await new Promise((resolve, reject) => {
  let output = '';
  server.stdout.on('data', (chunk) => {
    output += chunk;
    const match = output.match(/http:\/\/\S+/);
    if (match) resolve(match[0]);
  });
  server.on('exit', (code) => reject(new Error(`lidarshop serve exited with ${code}`)));
  setTimeout(() => reject(new Error('lidarshop serve printed no URL in 120 s')), 120000);
});
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: [
    '--no-sandbox',
    '--disable-gpu',
    '--disable-quic',
    '--no-first-run',
    '--disable-background-networking',
    '--disable-component-update',
    '--disable-sync',
    '--use-gl=swiftshader',
    '--enable-unsafe-swiftshader',
  ],
});
// The server's peak resident memory so far (Linux: VmHWM of /proc/PID/status), KiB; null elsewhere.
const serverPeakKib = () => {
  try {
    return Number(readFileSync(`/proc/${server.pid}/status`, 'utf8').match(/VmHWM:\s+(\d+) kB/)[1]);
  } catch {
    return null;
  }
};
const result = { rows, columns, scan_seconds: scanSeconds, serve_read_s: (Date.now() - serveStarted) / 1000 };
const budget = Number(option('--budget', 5));
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 800 } });
  page.on('pageerror', (error) => console.error(`page error: ${error.message}`));
  // Where the time went: the page's API requests since `since` (start-end, ms after page open). The browser
  // keeps 250 resource timings by default: the buffer is cleared before each measured part.
  const requestsSince = (since) =>
    page.evaluate(
      (t) =>
        performance
          .getEntriesByType('resource')
          .filter((e) => e.name.includes('/api/') && e.startTime >= t)
          .map(
            (e) =>
              `${e.name.split('?')[0].replace(location.origin, '')} ${Math.round(e.startTime)}-${Math.round(e.responseEnd)}`,
          ),
      since,
    );
  const clearRequests = () =>
    page.evaluate(() => {
      performance.clearResourceTimings();
      return performance.now();
    });
  let apiBytes = 0;
  page.on('requestfinished', async (request) => {
    if (request.url().includes('/api/'))
      apiBytes += (await request.sizes().catch(() => ({ responseBodySize: 0 }))).responseBodySize;
  });
  const opened = Date.now();
  await page.goto(url);
  await waitForFunction(page, () => window.lidarshop?.rayView.shownState().id > 0, null, { timeout: 120000 });
  result.first_picture_s = (Date.now() - opened) / 1000;
  // Where the time went: the page's requests until the first picture (start and end, ms after page open).
  result.first_picture_requests = (await requestsSince(0)).slice(0, 12);
  result.page_loaded_ms = await page.evaluate(() =>
    Math.round(performance.getEntriesByType('navigation')[0]?.domContentLoadedEventEnd ?? -1),
  );
  // The first picture's bytes: what the ray image's requests brought (tiles or the whole picture).
  result.first_picture_bytes = await page.evaluate(() => window.lidarshop.pictureBytes());
  result.first_picture_serve_peak_kib = serverPeakKib();
  result.tiled = await page.evaluate(() => window.lidarshop.tiled(window.lidarshop.current().id) !== null);
  if (result.tiled) {
    // The tiles of the level the view needs, all of them held.
    await waitForFunction(
      page,
      () => {
        const counts = window.lidarshop.tiled(window.lidarshop.current().id).counts();
        return counts.wanted === 0 && counts.inFlight === 0;
      },
      null,
      { timeout: 120000 },
    );
    result.view_tiles_s = (Date.now() - opened) / 1000;
    result.view_tiles = await page.evaluate(() =>
      window.lidarshop.tiled(window.lidarshop.current().id).counts(),
    );
    result.view_tiles_bytes = await page.evaluate(() => window.lidarshop.pictureBytes());
  }
  if (result.first_picture_s > budget)
    console.error(`e2e station: the first picture took ${result.first_picture_s} s (budget ${budget} s)`);
  await waitForFunction(page, () => window.lidarshop.pointsShown().id > 0, null, { timeout: 120000 });
  result.first_points_s = (Date.now() - opened) / 1000;
  result.first_level = await page.evaluate(() => window.lidarshop.pointLevel());
  const doc = await page.evaluate(() => window.lidarshop.current());
  result.returns = doc.valid_cells;
  [result.rows, result.columns] = [doc.rows, doc.cols]; // a --station file's own grid
  await page.screenshot({ path: join(artefacts, 'station_opened.png') });
  // The refinement to the finer level (the 3-D view's; it does not hold up the ray image).
  await waitForFunction(
    page,
    () =>
      window.lidarshop.pointLevel() === window.lidarshop.refinedLevel(window.lidarshop.current().valid_cells),
    null,
    { timeout: 240000 },
  );
  await page.evaluate(() => window.lidarshop.settled());
  result.refined_points_s = (Date.now() - opened) / 1000;
  result.refined_level = await page.evaluate(() => window.lidarshop.pointLevel());
  result.open_bytes = apiBytes;
  result.points_held = await page.evaluate(() => window.lidarshop.pointsHeld());
  result.point_budget = await page.evaluate(() => window.lidarshop.pointBudget);
  if (result.points_held > result.point_budget)
    fail(`the browser holds ${result.points_held} points (budget ${result.point_budget})`);
  // The 3-D view refined where the camera looks: a zoom with the wheel over the view, and when it ends the box
  // of cells around the point on the view's axis comes at full resolution beside the coarse level.
  if (result.refined_level > 1) {
    const view3d = await page.locator('#points canvas').boundingBox();
    const zoomed = Date.now();
    await page.mouse.move(view3d.x + view3d.width / 2, view3d.y + view3d.height / 2);
    await page.mouse.wheel(0, -600);
    await waitForFunction(page, () => window.lidarshop.detail() !== null, null, { timeout: 120000 });
    await page.evaluate(() => window.lidarshop.settled());
    result.detail_s = (Date.now() - zoomed) / 1000;
    result.detail = await page.evaluate(() => window.lidarshop.detail());
    result.points_held_with_detail = await page.evaluate(() => window.lidarshop.pointsHeld());
    if (result.points_held_with_detail > result.point_budget)
      fail(`with the detail the browser holds ${result.points_held_with_detail} points`);
    // Full resolution in the box: cells off the coarse level's rows, and no cell outside the box.
    const check = await page.evaluate((level) => {
      const points = window.lidarshop.detailPoints();
      const { box } = window.lidarshop.detail();
      let offLevel = 0,
        outside = 0;
      for (let i = 0; i < points.count; ++i) {
        const r = Math.floor(points.cells[i] / points.cols),
          c = points.cells[i] % points.cols;
        if (r % level !== 0 || c % level !== 0) ++offLevel;
        if (r < box.row || r >= box.row + box.height || c < box.col || c >= box.col + box.width) ++outside;
      }
      return { offLevel, outside };
    }, result.refined_level);
    if (check.outside > 0 || check.offLevel < result.detail.count / 2)
      fail(`the detail's points: ${JSON.stringify(check)} of ${result.detail.count}`);
    await page.screenshot({ path: join(artefacts, 'station_detail.png') });
  }
  console.log(`e2e station: opened: ${JSON.stringify(result)}`);
  // A station over the point budget comes coarse first (a smaller one, e.g. bench/scale.py's 1 M row, may not).
  if (result.first_level < 2 && doc.valid_cells > result.point_budget)
    fail(`a ${doc.valid_cells}-return station was first downloaded at level ${result.first_level}`);

  const canvas = await page.locator('#ray').boundingBox();
  const screen = (row, col) =>
    page.evaluate(([r, c]) => window.lidarshop.rayView.screenOf({ row: r, col: c }), [row, col]);
  const drag = async (cells) => {
    const first = await screen(...cells[0]);
    await page.mouse.move(canvas.x + first.x, canvas.y + first.y);
    await page.mouse.down();
    for (const cell of cells.slice(1)) {
      const point = await screen(...cell);
      await page.mouse.move(canvas.x + point.x, canvas.y + point.y, { steps: 4 });
    }
    await page.mouse.up();
  };
  const counters = () =>
    page.evaluate(() => ({
      points: window.lidarshop.pointBytes(),
      pictures: window.lidarshop.pictureBytes(),
    }));
  const shownCurrent = () => {
    const d = window.lidarshop.current();
    return window.lidarshop.rayView.shownState().version === d.version; // points: awaited with settled() below
  };
  const edits = [];
  const edit = async (what, action, done) => {
    await page.evaluate(() => window.lidarshop.settled());
    await new Promise((resolve) => setTimeout(resolve, 200));
    const before = await counters();
    const allBefore = apiBytes;
    const version = (await page.evaluate(() => window.lidarshop.current())).version;
    const pageT0 = await page.evaluate(() => Math.round(performance.now()));
    const t0 = Date.now();
    await action();
    await done(version);
    await waitForFunction(page, shownCurrent, null, { timeout: 120000 });
    const seconds = (Date.now() - t0) / 1000;
    const pageT1 = await page.evaluate(() => Math.round(performance.now()));
    // The frame that showed the edit's picture (the page may be busy after it, e.g. with the 3-D view).
    const drawnAt = await page.evaluate(() => window.lidarshop.rayView.shownState().drawnAt);
    await page.evaluate(() => window.lidarshop.settled());
    await new Promise((resolve) => setTimeout(resolve, 300)); // the last answers' sizes
    const after = await counters();
    edits.push({
      what,
      seconds,
      page_ms: [pageT0, pageT1], // start and end in the page's clock (performance.now)
      picture_s: drawnAt >= pageT0 ? Math.round(drawnAt - pageT0) / 1000 : null, // start -> picture drawn
      points: after.points - before.points,
      pictures: after.pictures - before.pictures,
      all: apiBytes - allBefore,
    });
  };
  const newerThan = (version) =>
    waitForFunction(page, (v) => window.lidarshop.current().version > v, version, { timeout: 120000 });
  const pictureMismatch = () =>
    page.evaluate(async () => {
      const d = window.lidarshop.current();
      const channel = document.getElementById('channel').value;
      // A tiled picture: every tile held of the version shown must be the server's (tiles.ts).
      const tiled = window.lidarshop.tiled(d.id);
      if (tiled)
        return tiled.version === d.version ? await tiled.mismatch() : `tiles of version ${tiled.version}`;
      const held = window.lidarshop.pictures.heldPicture(d.id, channel);
      if (!held) return 'no picture held';
      const bitmap = await createImageBitmap(
        await (await fetch(`/api/docs/${d.id}/image.png?channel=${channel}&v=${held.version}`)).blob(),
      );
      const canvas = document.createElement('canvas');
      [canvas.width, canvas.height] = [bitmap.width, bitmap.height];
      const context = canvas.getContext('2d');
      context.drawImage(bitmap, 0, 0);
      const whole = context.getImageData(0, 0, bitmap.width, bitmap.height).data;
      const patched = held.canvas
        .getContext('2d')
        .getImageData(0, 0, held.canvas.width, held.canvas.height).data;
      if (whole.length !== patched.length) return `sizes differ: ${whole.length} and ${patched.length}`;
      let differ = 0;
      for (let i = 0; i < whole.length; ++i) if (whole[i] !== patched[i]) ++differ;
      return differ === 0 ? '' : `${differ} of ${whole.length} bytes differ`;
    });

  // A stroke across the ground before the scanner (the lower rows), its undo and redo.
  const r = Math.round(doc.rows * 0.8),
    c0 = Math.round(doc.cols * 0.45),
    c1 = Math.round(doc.cols * 0.55);
  await page.click('#brush-object');
  await edit(
    'stroke',
    () =>
      drag([
        [r, c0],
        [r, c1],
      ]),
    newerThan,
  );
  await edit('undo stroke', () => page.keyboard.press('Control+z'), newerThan);
  await edit('redo stroke', () => page.keyboard.press('Control+y'), newerThan);
  // A painted hole on the ground, filled (the points there move), then undone.
  const h = Math.round(doc.rows * 0.03),
    w = Math.round(doc.cols * 0.02);
  await page.click('#brush-lasso');
  await edit(
    'lasso',
    () =>
      drag([
        [r - h, c0],
        [r - h, c0 + w],
        [r + h, c0 + w],
        [r + h, c0],
        [r - h, c0],
      ]),
    newerThan,
  );
  const fillStart = (await page.evaluate(() => window.lidarshop.current())).version;
  await edit(
    'fill hole',
    () => page.click('#fill-hole'),
    () =>
      waitForFunction(
        page,
        (v) => {
          const d = window.lidarshop.current();
          return d.version > v && d.synthesized_cells > 0;
        },
        fillStart,
        { timeout: 300000 },
      ),
  );
  const filled = await page.evaluate(() => window.lidarshop.current());
  if (filled.synthesized_cells === 0) fail('the fill synthesized nothing');
  const afterFill = await pictureMismatch();
  if (afterFill) fail(`the patched ray image after the fill is not the server's: ${afterFill}`);
  await edit('undo fill', () => page.click('#undo'), newerThan);
  const afterUndo = await pictureMismatch();
  if (afterUndo) fail(`the patched ray image after undoing the fill is not the server's: ${afterUndo}`);
  await page.screenshot({ path: join(artefacts, 'station_edited.png') });

  // The live cut (issue 36's stroke -> cut -> picture): the lasso and the ground stroke undone, an object stroke
  // across the hatchback (the parking lot's car left of the scanner's view centre; its place as a fraction of the
  // grid, so any grid size of that scene), then a background stroke under it: with Live on, that stroke runs the
  // first cut; later strokes refine it incrementally. Each is timed from the stroke's start to the frame that
  // shows the job's result (picture_s) and to the page settled (seconds).
  for (let i = 0; i < 2; ++i) {
    const v = (await page.evaluate(() => window.lidarshop.current())).version;
    await page.keyboard.press('Control+z');
    await newerThan(v);
  }
  // The segment jobs' own timings (SegmentResult's, seconds), from their answers.
  const segmentTimings = [];
  page.on('response', async (response) => {
    if (!/\/api\/jobs\/\d+(\?|$)/.test(response.url())) return;
    const job = await response.json().catch(() => null);
    if (job?.kind === 'segment' && job.state === 'done')
      segmentTimings.push({ refined: job.result.refined, ...job.result.timings });
  });
  const at = (fr, fc) => [Math.round(doc.rows * fr), Math.round(doc.cols * fc)];
  const jobsFinished = () => page.evaluate(() => window.lidarshop.jobsFinished());
  const afterJob = (before) => () =>
    waitForFunction(page, (n) => window.lidarshop.jobsFinished() > n, before, { timeout: 300000 });
  await page.click('#brush-object');
  await edit('object stroke', () => drag([at(0.583, 0.452), at(0.583, 0.546)]), newerThan);
  // A stroke with the brush `brush` from grid fraction `from` to `to` that runs a cut (Live): timed to its end.
  const cutStroke = async (what, brush, from, to) => {
    await page.click(`#brush-${brush}`);
    await edit(what, () => drag([at(...from), at(...to)]), afterJob(await jobsFinished()));
  };
  const cutStart = await clearRequests();
  await cutStroke('background stroke -> first cut', 'background', [0.647, 0.402], [0.647, 0.592]);
  result.first_cut_requests = await requestsSince(cutStart);
  const cut = await page.evaluate(() => window.lidarshop.current());
  if (!(cut.object_cells > 0)) fail('the live cut took no cell');
  if (result.detail) {
    // The detail box follows the edits (its deltas, points?box=...&since=V).
    await page.evaluate(() => window.lidarshop.settled());
    const detail = await page.evaluate(() => window.lidarshop.detail());
    if (detail.version !== cut.version)
      fail(`the detail shows version ${detail.version}, the scan is at ${cut.version}`);
  }
  const refineStart = await clearRequests();
  // Two refinements: an object stroke inside the cut (nothing changes), a background stroke across the car's
  // left end (the cut gives those cells up).
  await cutStroke('object stroke -> refined cut', 'object', [0.6, 0.47], [0.6, 0.53]);
  await cutStroke('background stroke -> refined cut', 'background', [0.6, 0.404], [0.6, 0.42]);
  const refined = await page.evaluate(() => window.lidarshop.current());
  result.cut_cells = [cut.object_cells, refined.object_cells];
  if (!(refined.object_cells < cut.object_cells && refined.object_cells > cut.object_cells / 2))
    fail(`the background stroke took the cut from ${cut.object_cells} to ${refined.object_cells} cells`);
  result.cut_timings = segmentTimings;
  result.refine_requests = await requestsSince(refineStart);
  await page.screenshot({ path: join(artefacts, 'station_cut.png') });

  // The station opened again in the running server: the time its read takes, then to its first picture.
  const points = await page.evaluate(() => window.lidarshop.pointsHeld());
  if (points > result.point_budget) fail(`the browser holds ${points} points after the edits`);
  const options = await page.locator('#file option').evaluateAll((all) => all.map((o) => o.value));
  const file = options.find((value) => value.endsWith('station.e57'));
  if (!file) fail(`the file dialog does not list station.e57: ${options.join(', ')}`);
  await page.selectOption('#file', file);
  const firstId = doc.id;
  const reopen = Date.now();
  const answer = page.waitForResponse((response) => response.url().includes('/api/open'), {
    timeout: 300000,
  });
  await page.click('#open-file');
  await answer;
  result.reopen_read_s = (Date.now() - reopen) / 1000;
  const read = Date.now();
  await waitForFunction(page, (id) => window.lidarshop.rayView.shownState().id > id, firstId, {
    timeout: 120000,
  });
  result.reopen_first_picture_s = (Date.now() - read) / 1000;
  await page.evaluate(() => window.lidarshop.settled());
  result.points_held_two_open = await page.evaluate(() => window.lidarshop.pointsHeld());
  if (result.points_held_two_open > result.point_budget)
    fail(`with the station open twice the browser holds ${result.points_held_two_open} points`);

  const wholePoints = 16 + 20 * doc.valid_cells;
  result.edits = edits;
  // The server's peak over the whole run (the station open twice at the end).
  result.serve_peak_kib = serverPeakKib();
  result.whole_points_bytes = wholePoints;
  for (const e of edits) {
    if (e.points >= wholePoints / 10)
      fail(`${e.what} moved ${e.points} B of points (the whole points are ${wholePoints} B)`);
    if (e.pictures >= 1_000_000) fail(`${e.what} moved ${e.pictures} B of pictures`);
  }
  console.log(`e2e station: ${JSON.stringify(result)}`);
  console.log(
    `e2e station: passed (${doc.valid_cells} returns; first picture ${result.first_picture_s} s; stroke -> cut -> picture ${edits
      .filter((e) => e.what.includes('cut'))
      .map((e) => `${e.what.split(' ->')[0]} ${e.picture_s} s`)
      .join(', ')}; bytes per edit ${edits.map((e) => `${e.what} ${e.all}`).join(', ')})`,
  );
} finally {
  await browser.close();
  server.kill('SIGTERM');
  rmSync(root, { recursive: true, force: true });
}

// End to end in a real browser (Debian's chromium, playwright-core) against `lidarshop serve`: the stations of a
// site (docs/stations.md "In the editor"). Opens the built-in site parking_lot_stations as a site, sees its 3
// stations listed with station 0 shown, shows station 2 (where the late sedan parked), shows the other stations'
// points, runs Clean, sees the count and the removed points highlighted, and undoes it. Screenshots of each
// step go to ARTEFACTS (and to docs/results/editor/ with --docs).
//
//   node e2e/stations.mjs LIDARSHOP_BINARY ARTEFACTS_DIR [--docs]
import { spawn } from 'node:child_process';
import { mkdirSync, copyFileSync, mkdtempSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { tmpdir } from 'node:os';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const [binary, artefacts = join(tmpdir(), 'lidarshop-e2e-stations')] = process.argv.slice(2);
const toDocs = process.argv.includes('--docs');
if (!binary) throw new Error('usage: node e2e/stations.mjs LIDARSHOP_BINARY [ARTEFACTS_DIR] [--docs]');
mkdirSync(artefacts, { recursive: true });
const root = mkdtempSync(join(tmpdir(), 'lidarshop-e2e-stations-root-'));

function fail(message) {
  console.error(`e2e stations: FAILED: ${message}`);
  process.exitCode = 1;
  throw new Error(message);
}

// page.waitForFunction without eval (the server's Content-Security-Policy forbids it): polls page.evaluate.
async function waitForFunction(page, fn, arg, { timeout = 30000 } = {}) {
  const deadline = Date.now() + timeout;
  for (;;) {
    if (await page.evaluate(fn, arg)) return;
    if (Date.now() > deadline) throw new Error(`timed out after ${timeout} ms waiting for ${fn}`);
    await new Promise((resolve) => setTimeout(resolve, 100));
  }
}

function startServer() {
  const server = spawn(binary, ['serve', '--port', '0', '--web', join(here, '../dist'), '--root', root], {
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  return new Promise((resolve, reject) => {
    let output = '';
    server.stdout.on('data', (chunk) => {
      output += chunk;
      const match = output.match(/http:\/\/\S+/);
      if (match) resolve({ server, url: match[0] });
    });
    server.on('exit', (code) => reject(new Error(`lidarshop serve exited with ${code}`)));
    setTimeout(() => reject(new Error('lidarshop serve printed no URL in 20 s')), 20000);
  });
}

const { server, url } = await startServer();
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
let step = 0;
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 800 } });
  page.on('pageerror', (error) => console.error(`page error: ${error.message}`));
  const blocked = [];
  page.on('console', (message) => {
    if (/Content Security Policy/i.test(message.text())) blocked.push(message.text());
  });
  const shot = async (name) => {
    const file = join(artefacts, `${String(++step).padStart(2, '0')}_stations_${name}.png`);
    await page.screenshot({ path: file });
    if (toDocs) {
      mkdirSync(join(here, '../../docs/results/editor'), { recursive: true });
      copyFileSync(
        file,
        join(here, '../../docs/results/editor', `stations_${String(step).padStart(2, '0')}_${name}.png`),
      );
    }
    console.log(`e2e stations: ${name} -> ${file}`);
  };
  const statusText = () => page.locator('#status').textContent();
  const current = () => page.evaluate(() => window.lidarshop.current());
  const listed = () =>
    page.evaluate(() =>
      Array.from(document.querySelectorAll('#stations-list li.station')).map((li) => ({
        index: Number(li.dataset.index),
        current: li.classList.contains('current'),
        text: li.textContent,
      })),
    );

  await page.goto(url);
  await page.selectOption('#scene', 'parking_lot_stations');
  await page.click('#open-site-scene');
  try {
    await waitForFunction(
      page,
      () => document.querySelectorAll('#stations-list li.station').length === 3,
      null,
      { timeout: 180000 },
    );
  } catch {
    fail(`the site's stations were never listed: '${await statusText()}'`);
  }
  let stations = await listed();
  if (!stations[0].current || stations[1].current || stations[2].current)
    fail(`station 0 is not the one shown: ${JSON.stringify(stations)}`);
  if (!/^2 · station2 · \(8\.0, 2\.0, 1\.6\) m · 30°/.test(stations[2].text))
    fail(`station 2 listed as '${stations[2].text}'`);
  if ((await current()).name !== 'parking_lot_stations#0') fail(`shown: ${(await current()).name}`);
  // Three documents, one per station.
  const documents = await page.evaluate(() => window.lidarshop.documents().map((d) => d.name));
  for (let i = 0; i < 3; ++i)
    if (!documents.includes(`parking_lot_stations#${i}`)) fail(`no scan for station ${i}: ${documents}`);
  await shot('listed');

  // Station 2 (the late sedan parked there after stations 0 and 1 looked): a click shows it.
  await page.click('#stations-list li.station[data-index="2"]');
  await waitForFunction(
    page,
    () =>
      window.lidarshop.current()?.name === 'parking_lot_stations#2' &&
      document.querySelector('#stations-list li.station.current')?.dataset.index === '2',
    null,
    { timeout: 60000 },
  );
  await page.check('#layer-stations');
  await page.evaluate(() => window.lidarshop.settled());
  await new Promise((resolve) => setTimeout(resolve, 1500));
  await shot('station2_with_others');
  await page.uncheck('#layer-stations');

  // Clean: the count in the panel and the status, the removed points highlighted, then undo.
  const before = await current();
  await page.click('#clean');
  try {
    await waitForFunction(
      page,
      () =>
        /^clean: \d+ points removed here \(station 2\)/.test(
          document.getElementById('clean-result').textContent,
        ),
      null,
      { timeout: 300000 },
    );
  } catch {
    fail(`clean: no count shown: '${await statusText()}'`);
  }
  const summary = await page.locator('#clean-result').textContent();
  const removed = Number(summary.match(/^clean: (\d+)/)[1]);
  if (removed < 100) fail(`clean removed only ${removed} points of station 2: ${summary}`);
  await waitForFunction(page, () => window.lidarshop.stations().removedShown > 0, null, { timeout: 60000 });
  const highlighted = await page.evaluate(() => window.lidarshop.stations().removedShown);
  const cleaned = await current();
  if (!cleaned.can_undo || cleaned.synthesized_cells === 0)
    fail(`clean left no undoable edit: ${JSON.stringify(cleaned)}`);
  stations = await listed();
  // The filled cells in cyan (layers), the removed ones highlighted in magenta.
  await page.selectOption('#point-colour', 'layers');
  await shot('cleaned');
  await page.selectOption('#point-colour', 'rgb');

  await page.click('#undo');
  await waitForFunction(
    page,
    () => {
      const d = window.lidarshop.current();
      return d && !d.can_undo && d.synthesized_cells === 0 && window.lidarshop.stations().removedShown === 0;
    },
    null,
    { timeout: 60000 },
  );
  const undone = await current();
  if (undone.valid_cells !== before.valid_cells)
    fail(`undo: ${undone.valid_cells} returns, ${before.valid_cells} before the clean`);
  await shot('undone');

  if (blocked.length > 0) fail(`the Content-Security-Policy blocked: ${blocked.join('; ')}`);
  console.log(
    `e2e stations: passed (3 stations listed; clean removed ${removed} points of station 2, ${highlighted} highlighted; undone)`,
  );
} finally {
  await browser.close();
  server.kill('SIGTERM');
}

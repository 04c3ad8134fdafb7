// Open a `voronoi-fit view` page in headless Debian chromium (playwright-core), wait for
// its first frame, take a screenshot and measure how much of the 3D canvas is drawn.
//
//   node tests/browser/check_page.mjs PAGE.html SCREENSHOT.png [TIMEOUT_MS]
//
// Prints one JSON object: { coverage, stats, console_errors, page_errors,
// network_requests, load_ms, frame_ms, toggled, ready }. Exits 0 whenever it could measure (the caller
// asserts), 3 when the browser cannot start or the page never becomes ready.
// Environment: VF_NODE_DIR (folder with node_modules/playwright-core, default
// target/node), VF_CHROMIUM (default /usr/bin/chromium).
import { createRequire } from 'node:module';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [page_path, shot_path, timeout_arg] = process.argv.slice(2);
if (!page_path || !shot_path) {
  console.error('usage: node check_page.mjs PAGE.html SCREENSHOT.png [TIMEOUT_MS]');
  process.exit(2);
}
const timeout = Number(timeout_arg || 60000);
const nodeDir = process.env.VF_NODE_DIR || path.resolve('target/node');
const require = createRequire(path.join(path.resolve(nodeDir), 'package.json'));
const { chromium } = require('playwright-core');

const executablePath = process.env.VF_CHROMIUM || '/usr/bin/chromium';
const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'vf-chromium-'));
const result = { console_errors: [], page_errors: [], network_requests: [], ready: null };
let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath,
    headless: true,
    viewport: { width: 1280, height: 900 },
    args: [
      '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync',
      // WebGL without a GPU: ANGLE on SwiftShader (software), which chromium only allows when asked.
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    ],
  });
} catch (e) {
  console.error(`cannot start ${executablePath}: ${e.message}`);
  process.exit(3);
}
try {
  const page = context.pages()[0] || (await context.newPage());
  page.on('console', (m) => { if (m.type() === 'error') result.console_errors.push(m.text()); });
  page.on('pageerror', (e) => result.page_errors.push(String(e)));
  // Offline: any request that is not file:, data: or blob: is recorded and refused.
  await context.route(/^(https?|wss?|ftp):/, (route) => { result.network_requests.push(route.request().url()); route.abort(); });
  const t0 = Date.now();
  await page.goto(pathToFileURL(path.resolve(page_path)).href, { waitUntil: 'load', timeout });
  await page.waitForFunction(() => document.body.dataset.vfReady, null, { timeout, polling: 100 });
  result.load_ms = Date.now() - t0;
  result.ready = await page.evaluate(() => document.body.dataset.vfReady);
  result.stats = await page.evaluate(() => window.vfStats || null);
  // Let the requested frame reach the screen, then measure the canvas: the WebGL canvas
  // is transparent where nothing is drawn (the page's gradient shows through).
  await page.waitForTimeout(200);
  result.coverage = await page.evaluate(() => {
    const c = document.getElementById('vf-canvas');
    const w = c.width, h = c.height;
    const t = document.createElement('canvas');
    t.width = w; t.height = h;
    const g = t.getContext('2d');
    g.drawImage(c, 0, 0);
    const d = g.getImageData(0, 0, w, h).data;
    let n = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n++;
    return n / (w * h);
  });
  // Interaction cost: the median of five synchronous frames, each after a 10° turn.
  result.frame_ms = await page.evaluate(() => {
    const t = [0, 1, 2, 3, 4].map(() => window.vfViewer.timedFrame(10));
    return t.sort((a, b) => a - b)[2];
  });
  await page.evaluate(() => window.vfViewer.timedFrame(-50));
  await page.locator('#vf-stage').screenshot({ path: shot_path });
  if (process.env.VF_SHOT_FULL) await page.screenshot({ path: process.env.VF_SHOT_FULL, fullPage: true });
  // Every control once on and off again (errors would land in console/page errors).
  result.toggled = [];
  for (const id of ['vf-wire', 'vf-side', 'vf-show-input', 'vf-show-crust', 'vf-show-inside', 'vf-show-outside', 'vf-show-wrong', 'vf-show-cells']) {
    const box = page.locator('#' + id);
    if (await box.isEnabled()) {
      await box.click();
      await page.evaluate(() => new Promise((ok) => requestAnimationFrame(() => requestAnimationFrame(ok))));
      await box.click();
      result.toggled.push(id);
    }
  }
  await page.locator('#vf-reset').click();
  await page.waitForTimeout(100);
  console.log(JSON.stringify(result));
  await context.close();
  fs.rmSync(userDataDir, { recursive: true, force: true });
  process.exit(0);
} catch (e) {
  result.error = String(e && e.message ? e.message : e);
  console.log(JSON.stringify(result));
  console.error(result.error);
  try { await context.close(); } catch (_) { /* already gone */ }
  fs.rmSync(userDataDir, { recursive: true, force: true });
  process.exit(3);
}

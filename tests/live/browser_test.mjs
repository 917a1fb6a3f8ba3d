// The gale live page in headless chromium (puppeteer-core): refused without the token; draws
// (the WebGL canvas's pixels vary); an edit of the .se on disk changes the slice's pixels; a
// dragged slider rewrites the literal in the file (comment kept); a syntax error shows
// file:line:col on the page. Saves a screenshot. Environment: CHROME, URL, SCENE_DIR, SHOT,
// NODE_PATH (the folder holding puppeteer-core).
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';

const require = createRequire(path.resolve(process.env.NODE_PATH, 'x.js'));
const puppeteer = require('puppeteer-core');
const { CHROME, URL: url, SCENE_DIR, SHOT } = process.env;
const se = path.join(SCENE_DIR, 'ice_wind.se');
const original = fs.readFileSync(se, 'utf8');
let failures = 0;
const started = Date.now();
const check = (ok, what) => {
  console.log((ok ? 'ok   ' : 'FAIL ') + what + `  [${((Date.now() - started) / 1000).toFixed(1)} s]`);
  if (!ok) failures++;
};
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function until(fn, ms, what) {
  const t0 = Date.now();
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() - t0 > ms) {
      check(false, what + ' (timed out after ' + ms + ' ms)');
      return null;
    }
    await sleep(50);
  }
}

const userDir = fs.mkdtempSync('/tmp/gale-chromium-');
const browser = await puppeteer.launch({
  executablePath: CHROME,
  headless: true,
  userDataDir: userDir,
  args: ['--headless', '--no-sandbox', '--enable-unsafe-swiftshader', '--disable-background-networking',
    '--disable-component-update', '--no-first-run', '--window-size=1280,800'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push('pageerror: ' + e.message));

  // Without the token: 403 and a JSON error naming it.
  const base = url.split('/?')[0];
  const refused = await page.goto(base + '/', { waitUntil: 'load' });
  check(refused.status() === 403, 'the page without the token is refused (403), got ' + refused.status());
  check((await refused.text()).includes('token'), 'the refusal names the token');

  await page.goto(url, { waitUntil: 'load' });
  await until(() => page.evaluate(() => window.galeLive && window.galeLive.ready && window.galeLive.fieldUpdates > 0), 20000,
    'the page loads its state and field');
  // The canvas's pixels, summarised in the page: distinct colours and a hash.
  const pixels = () => page.evaluate(() => {
    const v = document.getElementById('view');
    const c = document.createElement('canvas');
    c.width = v.width;
    c.height = v.height;
    const g = c.getContext('2d');
    g.drawImage(v, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const colours = new Set();
    let hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
      hash = (hash * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    return { colours: colours.size, hash, w: c.width, h: c.height };
  });
  console.log('     page timings (ms): ' + JSON.stringify(await page.evaluate(() => ({ modulesLoaded: window.galeLive.loadedAt, ...window.galeLive.lastFieldMs }))));
  const first = await pixels();
  await page.screenshot({ path: SHOT });
  check(first.colours > 200, `the canvas is drawn: ${first.colours} distinct colours over ${first.w}x${first.h}`);

  // An edit on disk: the wind gains a vertical wave; the page redraws a different slice.
  let n = await page.evaluate(() => window.galeLive.fieldUpdates);
  fs.writeFileSync(se, original.replace(/\+ eddies\s*$/, '+ eddies + [0, 6 * sin($P[0] * 4), 0]\n'));
  await until(() => page.evaluate((n0) => window.galeLive.fieldUpdates > n0, n), 15000, 'an edit of the .se reaches the page');
  // (Polled: a field requested before the edit may still be the one drawn.)
  const second = await until(async () => {
    const p = await pixels();
    return p.hash !== first.hash ? p : null;
  }, 15000, 'the slice\'s pixels change after the .se edit');
  if (second) check(true, `the slice's pixels change after the .se edit (${second.colours} colours)`);

  // A slider: $turbulenceScale (declared and set in the .se) dragged to the right end.
  n = await page.evaluate(() => window.galeLive.stateUpdates);
  const slider = await page.$('input[type=range][data-param="turbulenceScale"]');
  check(!!slider, 'a slider for $turbulenceScale');
  if (slider) {
    const b = await slider.boundingBox();
    await page.mouse.move(b.x + b.width * 0.1, b.y + b.height / 2);
    await page.mouse.down();
    for (let k = 1; k <= 8; ++k) await page.mouse.move(b.x + b.width * (0.1 + 0.1 * k), b.y + b.height / 2);
    await page.mouse.up();
    const text = await until(() => {
      const t = fs.readFileSync(se, 'utf8');
      const m = t.match(/^\$turbulenceScale = ([-0-9.e]+);( +)# 0\.1, 5  metres: size of the eddies$/m);
      return m && Number(m[1]) !== 0.5 ? t : null;
    }, 10000, 'dragging the slider rewrites $turbulenceScale in the file');
    if (text) {
      const v = Number(text.match(/^\$turbulenceScale = ([-0-9.e]+);/m)[1]);
      check(v > 3 && v <= 5, `the new literal ${v} is near the slider's right end (0.1 to 5)`);
      check(text.includes('$turbulence = 0.35;         # 0, 1  rms of each component'), 'the other lines are untouched');
    }
  }
  await until(() => page.evaluate((n0) => window.galeLive.stateUpdates > n0, n), 10000, 'the slider\'s edit comes back as state');

  // Simulate: a short run (frames 1-6) plays its frames in the page as they are written.
  const toml = path.join(SCENE_DIR, 'scene.toml');
  const scene = fs.readFileSync(toml, 'utf8');
  n = await page.evaluate(() => window.galeLive.stateUpdates);
  fs.writeFileSync(toml, scene.replace(/^frames = \[1, 72\]/m, 'frames = [1, 6]'));
  await until(() => page.evaluate((n0) => window.galeLive.stateUpdates > n0, n), 10000, 'the scene edit reaches the page');
  await page.click('#simulate');
  const shown = await until(() => page.evaluate(() => window.galeLive.simFrameShown), 30000, 'a simulated frame is drawn');
  check(shown >= 1 && shown <= 6, `simulated frame ${shown} is drawn in the page`);
  await until(() => page.evaluate(() => /done: 6 frames/.test(document.getElementById('simText').textContent)), 30000,
    'the simulation ends with 6 frames');
  fs.writeFileSync(toml, scene);

  // A syntax error: the page shows file:line:col and gale check's message.
  fs.writeFileSync(se, original.replace('dir = norm(getVar("windDir", [1, 0, 0]));', 'dir = norm(getVar("windDir", [1, 0, 0]);'));
  const banner = await until(() => page.evaluate(() => {
    const t = document.getElementById('diagBanner').textContent;
    return /ice_wind\.se:\d+:\d+: error: /.test(t) ? t : null;
  }), 15000, 'a syntax error appears in the page as file:line:col');
  if (banner) {
    console.log('     ' + banner.split('\n')[0]);
    const line = original.split('\n').findIndex((l) => l.startsWith('dir = norm(')) + 1;
    check(new RegExp(`ice_wind\\.se:${line}:\\d+: error: `).test(banner), `the error is on line ${line}, where the parenthesis is missing`);
    await until(() => page.evaluate((l) => [...document.querySelectorAll('#source .diag')].some((d) =>
      new RegExp(`ice_wind\\.se:${l}:\\d+: error: `).test(d.textContent) &&
      d.previousElementSibling && d.previousElementSibling.classList.contains('bad')), line), 5000,
    'the error is shown inline under its source line');
  }
  fs.writeFileSync(se, original);
  await until(() => page.evaluate(() => document.getElementById('diagBanner').classList.contains('hidden')), 15000,
    'fixing the file clears the error');
  if (failures) console.log(logs.join('\n'));
} finally {
  await browser.close();
  fs.rmSync(userDir, { recursive: true, force: true });
}
process.exit(failures ? 1 : 0);

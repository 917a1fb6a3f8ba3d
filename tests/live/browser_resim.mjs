// Trouble you can see and live re-simulation, in headless chromium, on tests/live/resim (a
// 24×24 flag whose wind speed is a slider, and a soft sheet pinned along its top that its own
// weight stretches): the sheet is drawn in strain colours where it is stretched (the top, about
// ρgL/k ≈ 49 %) and not at its free bottom edge; the timeline gets run.json's frames; a slider
// edit during the simulation restarts it, and the new run's frames are those of an independent
// `gale sim` of the edited scene. Environment: CHROME, URL, GALE, DIR (the scene's folder),
// SHOT, NODE_PATH.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { Checks, launch, canvasPixels, differing, sleep } from './page_helpers.mjs';

const { URL: url, DIR, GALE, SHOT } = process.env;
const c = new Checks();
const { browser, close } = await launch();
const frameOf = (page, n) => page.evaluate(async (n) => {
  const token = new URLSearchParams(location.search).get('token');
  const r = await fetch(`/api/frame?n=${n}&token=${token}`);
  return r.ok ? r.json() : null;
}, n);
// Counts the pixels whose colour is the stretched end of the strain map (orange to red: red
// well above green and blue, however the light shades it).
const hot = (px) => {
  let n = 0;
  for (let i = 0; i < px.length; i += 3) if (px[i] > 60 && px[i] > 1.6 * px[i + 1] && px[i] > 1.6 * px[i + 2]) n++;
  return n;
};
// Presses Simulate / Stop and waits (up to 10 s) for the server's reply to reach the page, so
// that what follows sees the state the press made (the page logs each press in galeLive.simLog).
const pressSimulate = async (page) => {
  const presses = () => page.evaluate(() => window.galeLive.simLog.filter((e) => e[0].startsWith('press')).length);
  const before = await presses();
  await page.click('#simulate');
  for (let t = 0; t < 200 && (await presses()) === before; t++) await sleep(50);
  if ((await presses()) === before) c.check(false, 'a press of Simulate reaches the server');
};
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push('pageerror: ' + e.message));
  page.on('response', (r) => { if (r.status() >= 400) logs.push(`${r.status()} ${r.request().method()} ${r.url()}`); });
  await page.goto(url, { waitUntil: 'load' });
  await c.until(() => page.evaluate(() => window.galeLive.ready && window.galeLive.fieldUpdates > 0), 20000, 'the page loads');
  for (const id of ['showSlice', 'showArrows', 'showLines', 'showRigs'])
    await page.evaluate((id) => { const e = document.getElementById(id); if (e.checked) e.click(); }, id);

  // ---- strain colours on a run's frame ----
  await pressSimulate(page);
  await c.until(() => page.evaluate(() => window.galeLive.simRun === 1 && window.galeLive.framesOfRun >= 12), 30000,
    'the first run reaches frame 12');
  await pressSimulate(page); // Stop: the frames stay, the page stops following new ones
  await c.until(() => page.evaluate(() => /stopped|done/.test(document.getElementById('simText').textContent)), 10000, 'the run stops');
  const f12 = await frameOf(page, 12);
  const sheet = f12 && f12.objects.find((o) => o.label === 'sheet');
  if (sheet) {
    // The server's strain: rows by rest height (y = 0.5 free edge .. 1.0 pinned edge).
    const ys = sheet.points.filter((_, i) => i % 3 === 1);
    const top = Math.max(...sheet.strain.filter((_, i) => ys[i] > Math.max(...ys) - 0.08));
    const bottom = Math.max(...sheet.strain.filter((_, i) => ys[i] < Math.min(...ys) + 0.05));
    c.check(top > 0.3 && top < 0.7, `the sheet's top is stretched: strain ${top.toFixed(3)} (ρgL/k ≈ 0.49)`);
    c.check(bottom < 0.12, `its free bottom edge is not: strain ${bottom.toFixed(3)}`);
  } else c.check(false, 'frame 12 has the sheet');
  await page.evaluate(() => window.galeLive.setTime(12 / 24));
  await c.until(() => page.evaluate(() => window.galeLive.simFrameShown === 12 && window.galeLive.strainShown), 10000,
    'frame 12 is shown in strain colours');
  await sleep(200);
  const box = await page.evaluate(() => window.galeLive.screenBox('sheet'));
  c.check(box && box[2] - box[0] > 10 && box[3] - box[1] > 10, 'the sheet is on the canvas: ' + JSON.stringify(box));
  if (box) {
    // The top and bottom quarters of its screen box: strain about 0.38-0.5 (red) and 0.05-0.16
    // (blue to yellow, not hot), from the linear profile of a hanging sheet.
    const q = Math.round((box[3] - box[1]) / 4);
    const halves = async () => [hot(await canvasPixels(page, [box[0], box[1], box[2], box[1] + q])), hot(await canvasPixels(page, [box[0], box[3] - q, box[2], box[3]]))];
    const on = await halves();
    await page.evaluate(() => document.getElementById('showStrain').click());
    await sleep(200);
    const off = await halves();
    // (The difference with strain off: whatever else is hot there, the axes, is not counted.)
    const upper = on[0] - off[0], lower = on[1] - off[1];
    c.check(upper > 50 && upper > 5 * Math.max(0, lower), `hot strain colours where the sheet is stretched: ${upper} more pixels in its top quarter, ${lower} in its bottom quarter`);
    await page.evaluate(() => document.getElementById('showStrain').click());
    await sleep(200);
    const legend = await page.evaluate(() => !document.getElementById('strainLegend').classList.contains('hidden'));
    c.check(legend, 'the strain legend is shown');
  }
  // (gale sim writes run.json after its first frame and then at most once a second.)
  const run = await c.until(() => page.evaluate(() => window.galeLive.run && window.galeLive.run.frames.length >= 1 && window.galeLive.run), 5000,
    'run.json\'s frames reach the timeline');
  if (run) c.check(run.frames.every((f) => Number.isFinite(f.maxStretch) && Array.isArray(f.events)), `${run.frames.length} frames of run.json on the timeline, status ${run.status}`);

  // ---- a slider edit during the simulation restarts it ----
  await pressSimulate(page); // Simulate again (run 2), and edit while it runs
  await c.until(() => page.evaluate(() => window.galeLive.simRun === 2 && window.galeLive.framesOfRun >= 3), 30000,
    'the second run reaches frame 3');
  const oldRun = await c.until(() => frameOf(page, 3), 5000, 'frame 3 of the run before the edit');
  const se = path.join(DIR, 'wind.se');
  const slider = await page.$('input[type=range][data-param="speed"]');
  c.check(!!slider, 'a slider for $speed');
  const running = await page.evaluate(() => document.getElementById('simulate').textContent === 'Stop');
  c.check(running, 'the run is still going when the slider moves');
  let edited = null;
  if (slider) {
    const b = await slider.boundingBox();
    await page.mouse.move(b.x + b.width * (4 / 12), b.y + b.height / 2);
    await page.mouse.down();
    for (let k = 1; k <= 6; ++k) await page.mouse.move(b.x + b.width * (4 / 12 + 0.07 * k), b.y + b.height / 2);
    await page.mouse.up();
    edited = await c.until(() => {
      const m = fs.readFileSync(se, 'utf8').match(/^\$speed = ([-0-9.e]+);/m);
      return m && Number(m[1]) !== 4 ? Number(m[1]) : null;
    }, 10000, 'the slider rewrites $speed');
  }
  const t0 = Date.now();
  // (The slider may send twice, during the drag and on release: each edit restarts the run.)
  const restarted = await c.until(() => page.evaluate(() => window.galeLive.simRun >= 3 && window.galeLive.simFrameShown !== null &&
    window.galeLive.simFrameRun === window.galeLive.simRun), 10000, 'the edit restarts the simulation and its first frame is drawn');
  if (restarted) console.log(`     edit on disk → first re-simulated frame drawn: ${Date.now() - t0} ms (polled every 20 ms)`);
  await sleep(500); // (a second send of the slider, if any, has restarted it again by now)
  const restarts = await page.evaluate(() => window.galeLive.restarts);
  c.check(restarts >= 1, `the edit restarted the run (${restarts} restart${restarts === 1 ? '' : 's'})`);
  edited = Number(fs.readFileSync(se, 'utf8').match(/^\$speed = ([-0-9.e]+);/m)[1]);
  const lastRun = await page.evaluate(() => window.galeLive.simRun);
  await c.until(() => page.evaluate((r) => window.galeLive.simRun === r && window.galeLive.framesOfRun >= 3, lastRun), 20000,
    'the new run writes frame 3');
  const newRun = await c.until(() => frameOf(page, 3), 5000, 'frame 3 of the new run');
  c.check(edited !== null && oldRun && newRun, `frame 3 of the run before the edit (${oldRun && oldRun.run}) and after (${newRun && newRun.run}), $speed = ${edited}`);
  if (edited !== null && oldRun && newRun) {
    const flag = (f) => f.objects.find((o) => o.label === 'flag').points;
    const a = flag(oldRun), b = flag(newRun);
    const moved = Math.max(...a.map((x, i) => Math.abs(x - b[i])));
    c.check(newRun.run === lastRun && moved > 1e-3, `frame 3 changed with $speed = ${edited} (largest move ${moved.toFixed(4)} m)`);
    // An independent run of the edited scene gives the same frame.
    const out = fs.mkdtempSync('/tmp/gale-resim-');
    const r = spawnSync(GALE, ['sim', path.join(DIR, 'scene.toml'), '-o', out, '--frames', '1:3', '--threads', '1'], { encoding: 'utf8' });
    c.check(r.status === 0, 'gale sim of the edited scene: ' + (r.stderr || '').trim().split('\n').pop());
    const ref = fs.readFileSync(path.join(out, 'flag.0003.obj'), 'utf8').split('\n').filter((l) => l.startsWith('v ')).flatMap((l) => l.split(/\s+/).slice(1, 4).map(Number));
    const diff = Math.max(...ref.map((x, i) => Math.abs(x - b[i])));
    c.check(ref.length === b.length && diff <= 1.01e-4, `the new run's frame 3 is gale sim's of the edited scene (within the page's 1e-4 rounding: ${diff.toExponential(2)})`);
    fs.rmSync(out, { recursive: true, force: true });
  }
  // ---- compare: the run the edit replaced, over the shown frame ----
  await pressSimulate(page); // Stop, so the shown frame stays put
  await c.until(() => page.evaluate(() => /stopped|done/.test(document.getElementById('simText').textContent)), 10000, 'the new run stops');
  // The kept run is the last one an edit replaced after it had stepped (run lastRun − 1, or an
  // earlier one when the slider's last send restarted a run that had not). On a slow machine it may
  // have been replaced after frame 2 and before frame 3: compare at the last of frames 3, 2 it has.
  const kept = await page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get('token');
    const run = window.galeLive.previousRun;
    for (const n of [3, 2]) {
      const r = await fetch(`/api/frame?n=${n}&run=${run}&token=${token}`);
      if (r.ok) return { run, frame: n };
    }
    return { run, frame: null };
  });
  c.check(kept.frame !== null, `the kept run ${kept.run} has frame ${kept.frame} (of 2, 3)`);
  const at = kept.frame || 3;
  await page.evaluate((n) => window.galeLive.setTime(n / 24), at);
  await c.until(() => page.evaluate((n) => window.galeLive.simFrameShown === n, at), 5000, `frame ${at} of the new run is shown`);
  await sleep(200);
  const flagBox = await page.evaluate(() => window.galeLive.screenBox('flag'));
  const before = flagBox ? await canvasPixels(page, flagBox) : null;
  await page.evaluate(() => document.getElementById('showCompare').click());
  const compared = await c.until(() => page.evaluate(() => window.galeLive.compareShown), 5000, 'the previous run is drawn over the frame');
  if (compared) {
    c.check(compared.run === kept.run && compared.run < lastRun && compared.run >= 2 && compared.frame === at,
      `compare shows frame ${compared.frame} of run ${compared.run} (the run the last stepped-in edit replaced; the new run is ${lastRun})`);
    await sleep(200);
    const after = await canvasPixels(page, flagBox);
    const changed = differing(before, after);
    c.check(changed > 0.01, `the previous run's flag shows inside the flag's box: ${(100 * changed).toFixed(1)} % of its pixels change`);
  }
  await page.screenshot({ path: SHOT });

  // ---- a run that ends by itself: Stop, then Simulate starts a new run ----
  // (On a fast machine the first run above can end before its Stop; the button must still
  // turn Stop into Simulate, and the next press start a run, not stop one that has ended.)
  const toml = path.join(DIR, 'scene.toml');
  fs.writeFileSync(toml, fs.readFileSync(toml, 'utf8').replace(/^frames = \[1, 240\]/m, 'frames = [1, 6]'));
  await c.until(() => page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get('token');
    const r = await fetch(`/api/state?token=${token}`);
    return r.ok && (await r.json()).frames[1] === 6;
  }), 10000, 'the page sees the scene\'s new frame range');
  const before6 = await page.evaluate(() => window.galeLive.simRun);
  await pressSimulate(page);
  await c.until(() => page.evaluate((r) => window.galeLive.simRun > r && /done/.test(document.getElementById('simText').textContent), before6), 20000, 'a 6-frame run ends by itself');
  await pressSimulate(page); // Stop (edits no longer re-simulate)
  await c.until(() => page.evaluate(() => document.getElementById('simulate').textContent === 'Simulate'), 5000, 'Stop after the run\'s end turns the button back to Simulate');
  const ended = await page.evaluate(() => window.galeLive.simRun);
  await pressSimulate(page);
  await c.until(() => page.evaluate((r) => window.galeLive.simRun === r + 1 && window.galeLive.framesOfRun >= 6, ended), 20000, 'Simulate then starts a new run, which writes its 6 frames');
  if (c.failures) {
    console.log(logs.join('\n'));
    // Each sim event and Simulate press: [kind, the page's run, the button's label, data].
    console.log((await page.evaluate(() => window.galeLive.simLog)).map((e) => JSON.stringify(e)).join('\n'));
  }
} finally {
  await close();
}
process.exit(c.failures ? 1 : 0);

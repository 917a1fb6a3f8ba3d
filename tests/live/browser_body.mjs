// The walking cape in headless chromium: a folder that appears after the server started is
// picked up (the diagnostic clears within 1 s of make_body.py's last file), and the moving
// body (a mesh-sequence collider) is drawn at the time shown, at rest and while a simulation
// plays. Environment: CHROME, URL, WALK (the scene's folder, without body/), SHOT, NODE_PATH.
import { spawnSync } from 'node:child_process';
import path from 'node:path';
import { Checks, launch, canvasPixels, differing, sleep } from './page_helpers.mjs';

const { URL: url, WALK, SHOT } = process.env;
const c = new Checks();
const { browser, close } = await launch();
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push('pageerror: ' + e.message));
  await page.goto(url, { waitUntil: 'load' });
  const banner = () => page.evaluate(() => {
    const b = document.getElementById('diagBanner');
    return b.classList.contains('hidden') ? '' : b.textContent;
  });

  // ---- the body folder does not exist yet ----
  const missing = await c.until(async () => /cannot list the folder of 'body\.#\.obj'/.test(await banner()), 15000,
    'the missing body folder is shown');
  if (missing) c.check(true, 'the page shows: ' + (await banner()).split('\n')[0].slice(0, 140));
  const made = spawnSync('python3', ['make_body.py', 'body'], { cwd: WALK, encoding: 'utf8' });
  const written = Date.now();
  const writtenInPage = await page.evaluate(() => performance.now());
  c.check(made.status === 0, 'make_body.py writes body/ (' + (made.stderr || '').trim() + ')');
  const cleared = await c.until(async () => (await banner()) === '' && (await page.evaluate(() => window.galeLive.ready)), 5000,
    'the diagnostic clears once body/ exists');
  const clearMs = Date.now() - written;
  console.log('     events in the page (ms after the last file): ' + JSON.stringify(await page.evaluate((w) => window.galeLive.events.map(([t, ms]) => [t, Math.round(ms - w)]), writtenInPage)));
  if (cleared) c.check(clearMs <= 1000, `the diagnostic clears ${clearMs} ms after the last file is written (at most 1000)`);

  // ---- the body at rest, at two times ----
  const fps = 24;
  const showAt = async (t) => {
    await page.evaluate((t) => window.galeLive.setTime(t), t);
    await c.until(() => page.evaluate((t) => window.galeLive.colliderTime === t && window.galeLive.fieldUpdates > 0, t), 10000,
      `the colliders are placed at t = ${t}`);
    await sleep(300); // (the field of that time may still arrive; it is drawn under the body)
    return page.evaluate(() => window.galeLive.screenBox('body'));
  };
  // Only the bodies, so that the difference is the body's own (the slice and arrows change with $t too).
  for (const id of ['showSlice', 'showArrows', 'showLines', 'showRigs'])
    await page.evaluate((id) => { const e = document.getElementById(id); if (e.checked) e.click(); }, id);
  const t0 = 1 / fps, t1 = 24 / fps;
  const box0 = await showAt(t0);
  const box1 = await showAt(t1);
  c.check(box0 && box1, `the body has a screen box at both times: ${JSON.stringify(box0)} ${JSON.stringify(box1)}`);
  if (box0 && box1) {
    const box = [Math.min(box0[0], box1[0]), Math.min(box0[1], box1[1]), Math.max(box0[2], box1[2]), Math.max(box0[3], box1[3])];
    c.check(box[2] - box[0] > 20 && box[3] - box[1] > 20, `the body's screen box is on the canvas: ${JSON.stringify(box)}`);
    const at1 = await canvasPixels(page, box);
    await showAt(t0);
    const at0 = await canvasPixels(page, box);
    const moved = differing(at0, at1);
    c.check(moved > 0.05, `pixels differ inside the body's box between frames 1 and 24: ${(100 * moved).toFixed(1)} %`);
    await page.evaluate(() => document.getElementById('showBodies').click());
    await sleep(100);
    const hidden = await canvasPixels(page, box);
    c.check(differing(at0, hidden) > 0.02, `hiding the bodies changes the box (${(100 * differing(at0, hidden)).toFixed(1)} %): the body was drawn`);
    await page.evaluate(() => document.getElementById('showBodies').click());
  }

  // ---- while a simulation plays: the body at each shown frame's time ----
  // The page logs every simulation frame it draws and every time it places the colliders at
  // (polling the shown frame from here would miss frames on a loaded machine).
  await page.click('#simulate');
  await c.until(async () => /done: 8 frames/.test(await page.evaluate(() => document.getElementById('simText').textContent)),
    60000, 'the simulation of 8 frames ends');
  await c.until(() => page.evaluate(() => window.galeLive.simFrameShown === 8 && window.galeLive.colliderTime === 8 / 24), 5000,
    'the last frame is shown with the body at its time');
  const last = await page.evaluate(() => [window.galeLive.simFrameShown, window.galeLive.colliderTime]);
  c.check(last[0] === 8 && Math.abs(last[1] - 8 / fps) < 1e-12, `frame ${last[0]} is shown with the body at t = ${last[1]} (8/24)`);
  const log = await page.evaluate(() => [window.galeLive.simFramesDrawn, window.galeLive.colliderTimes]);
  const drawn = [...new Set(log[0])];
  // (a frame superseded before its colliders arrived is skipped, as the newest wish wins)
  const followed = drawn.filter((n) => log[1].some((t) => Math.abs(t - n / fps) < 1e-12));
  c.check(drawn.length >= 2 && followed.length >= 2,
    `the body followed ${followed.length} of the ${drawn.length} frames drawn: ${JSON.stringify(followed)} of ${JSON.stringify(drawn)}`);
  await page.screenshot({ path: SHOT });
  if (c.failures) console.log(logs.join('\n'));
} finally {
  await close();
}
process.exit(c.failures ? 1 : 0);

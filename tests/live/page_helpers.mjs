// Shared by the gale live browser tests: headless chromium through puppeteer-core (the flags
// of ../shared/notes/anchors.md), a check that counts failures, polling, and the canvas's
// pixels read back in the page.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';

const require = createRequire(path.resolve(process.env.NODE_PATH, 'x.js'));
const puppeteer = require('puppeteer-core');

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

export class Checks {
  constructor() {
    this.failures = 0;
    this.started = Date.now();
  }
  check(ok, what) {
    console.log((ok ? 'ok   ' : 'FAIL ') + what + `  [${((Date.now() - this.started) / 1000).toFixed(1)} s]`);
    if (!ok) this.failures++;
    return ok;
  }
  // Polls fn every 20 ms until it gives a truthy value (returned) or `ms` pass (null, a failure).
  async until(fn, ms, what) {
    const t0 = Date.now();
    for (;;) {
      const v = await fn();
      if (v) return v;
      if (Date.now() - t0 > ms) {
        this.check(false, what + ' (timed out after ' + ms + ' ms)');
        return null;
      }
      await sleep(20);
    }
  }
}

export async function launch() {
  const userDir = fs.mkdtempSync('/tmp/gale-chromium-');
  const browser = await puppeteer.launch({
    executablePath: process.env.CHROME,
    headless: true,
    userDataDir: userDir,
    args: ['--headless', '--no-sandbox', '--enable-unsafe-swiftshader', '--disable-background-networking',
      '--disable-component-update', '--no-first-run', '--window-size=1280,800'],
  });
  return {
    browser,
    async close() {
      await browser.close();
      fs.rmSync(userDir, { recursive: true, force: true });
    },
  };
}

// The view canvas's RGB pixels inside `box` ([x0, y0, x1, y1], canvas pixels; all of it when
// null) as a plain array, read in the page.
export function canvasPixels(page, box = null) {
  return page.evaluate((box) => {
    const v = document.getElementById('view');
    const c = document.createElement('canvas');
    c.width = v.width;
    c.height = v.height;
    const g = c.getContext('2d');
    g.drawImage(v, 0, 0);
    const [x0, y0, x1, y1] = box || [0, 0, c.width, c.height];
    const d = g.getImageData(x0, y0, Math.max(1, x1 - x0), Math.max(1, y1 - y0)).data;
    const out = [];
    for (let i = 0; i < d.length; i += 4) out.push(d[i], d[i + 1], d[i + 2]);
    return out;
  }, box);
}

// The share of pixels (of two equal-sized RGB arrays) that differ by more than `tol` in a channel.
export function differing(a, b, tol = 8) {
  let n = 0;
  for (let i = 0; i < a.length; i += 3)
    if (Math.abs(a[i] - b[i]) > tol || Math.abs(a[i + 1] - b[i + 1]) > tol || Math.abs(a[i + 2] - b[i + 2]) > tol) n++;
  return n / Math.max(1, a.length / 3);
}

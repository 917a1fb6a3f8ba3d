// The side panels and bars of gale live: parameter sliders, ramp editors, the source with its
// diagnostics inline, the speed legend and the gust timeline. Each calls back into app.js; none
// talks to the server itself.
import { colourAt, strainColour, STRAIN_TOP, CLOTH_BASE } from 'gale/view.js';

const el = (tag, attrs = {}, ...kids) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const k of kids) e.append(k);
  return e;
};

export function shortPath(p) {
  return p.split('/').slice(-2).join('/');
}

export function fmt(v, digits = 3) {
  const s = Number(v).toFixed(digits).replace(/\.?0+$/, '');
  return s === '-0' ? '0' : s;
}

// One slider (or one per component) per parameter; `onSet(param, value)` once a drag pauses
// and on release, so the file is rewritten a few times per second at most.
export function renderParams(box, params, onSet) {
  box.replaceChildren();
  if (!params.length) box.append(el('p', { class: 'muted small' }, 'no `$name = value; # min, max` parameters'));
  for (const p of params) {
    const values = Array.isArray(p.value) ? [...p.value] : [p.value];
    values.forEach((v, k) => {
      let lo = p.min, hi = p.max;
      if (lo === null || hi === null) { lo = Math.min(0, 2 * v); hi = Math.max(1, 2 * v); }
      const step = p.integer ? 1 : (hi - lo) / 1000;
      const range = el('input', { type: 'range', min: lo, max: hi, step, value: v });
      const num = el('input', { type: 'number', step, value: fmt(v, 4) });
      range.disabled = num.disabled = !p.editable;
      range.dataset.param = p.name;
      let timer = null;
      const send = () => {
        timer = null;
        values[k] = Number(range.value);
        onSet(p, values.length === 1 ? values[0] : values);
      };
      range.addEventListener('input', () => {
        num.value = fmt(range.value, 4);
        if (!timer) timer = setTimeout(send, 120);
      });
      range.addEventListener('change', () => { clearTimeout(timer); send(); });
      num.addEventListener('change', () => {
        range.value = num.value;
        values[k] = Number(num.value);
        onSet(p, values.length === 1 ? values[0] : values);
      });
      const label = '$' + p.name + (values.length > 1 ? '[' + k + ']' : '');
      box.append(el('div', { class: 'param', title: p.doc || '' }, el('span', { class: 'name' }, label), range, num,
        el('span', { class: 'where muted small' }, shortPath(p.file) + ':' + p.line + (p.editable ? '' : ' (keyframed: edit the file)'))));
    });
  }
}

// Ramp editors: control points dragged in position (x) and, for curve(), value (y); the
// line between them is drawn piecewise linear (the shape, not the exact spline).
export function renderRamps(box, ramps, onSet) {
  box.replaceChildren();
  if (!ramps.length) box.append(el('p', { class: 'muted small' }, 'no literal curve() / ccurve() calls'));
  for (const r of ramps) {
    const canvas = el('canvas', { width: 340, height: 90 });
    const pts = r.points.map((p) => ({ ...p, value: Array.isArray(p.value) ? [...p.value] : p.value }));
    const colour = r.function === 'ccurve';
    const vals = colour ? [0, 1] : pts.map((p) => p.value);
    let vlo = Math.min(0, ...vals), vhi = Math.max(1, ...vals);
    const X = (x) => 6 + x * (canvas.width - 12), Y = (v) => canvas.height - 6 - (v - vlo) / (vhi - vlo) * (canvas.height - 12);
    const draw = () => {
      const g = canvas.getContext('2d');
      g.clearRect(0, 0, canvas.width, canvas.height);
      const order = [...pts].sort((a, b) => a.position - b.position);
      if (colour) {
        const grad = g.createLinearGradient(X(0), 0, X(1), 0);
        for (const p of order) grad.addColorStop(Math.min(1, Math.max(0, p.position)), `rgb(${p.value.map((c) => Math.round(255 * Math.min(1, Math.max(0, c)))).join(',')})`);
        g.fillStyle = grad;
        g.fillRect(X(0), 20, X(1) - X(0), canvas.height - 40);
      } else {
        g.strokeStyle = '#f0a040';
        g.lineWidth = 2;
        g.beginPath();
        order.forEach((p, i) => (i ? g.lineTo(X(p.position), Y(p.value)) : g.moveTo(X(p.position), Y(p.value))));
        g.stroke();
      }
      for (const p of pts) {
        g.fillStyle = '#fff';
        g.beginPath();
        g.arc(X(p.position), colour ? canvas.height / 2 : Y(p.value), 4, 0, 2 * Math.PI);
        g.fill();
      }
    };
    let drag = null;
    const at = (e) => {
      const b = canvas.getBoundingClientRect();
      return [(e.clientX - b.left) * canvas.width / b.width, (e.clientY - b.top) * canvas.height / b.height];
    };
    canvas.addEventListener('pointerdown', (e) => {
      const [x, y] = at(e);
      drag = pts.find((p) => Math.hypot(X(p.position) - x, (colour ? canvas.height / 2 : Y(p.value)) - y) < 8) || null;
      if (drag) canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const [x, y] = at(e);
      drag.position = Math.round(1000 * Math.min(1, Math.max(0, (x - 6) / (canvas.width - 12)))) / 1000;
      if (!colour) drag.value = Math.round(1000 * (vlo + (canvas.height - 6 - y) / (canvas.height - 12) * (vhi - vlo))) / 1000;
      draw();
    });
    canvas.addEventListener('pointerup', () => {
      if (!drag) return;
      drag = null;
      onSet(r, pts);
    });
    box.append(el('div', { class: 'ramp' }, el('div', { class: 'small muted' }, `${r.function}() at ${shortPath(r.file)}:${r.line}:${r.col}`), canvas));
    draw();
  }
}

// The source of one file, line-numbered, with each diagnostic (file:line:col: message, as
// gale check prints it) under its line.
export function renderSource(pre, path, text, diagnostics) {
  pre.replaceChildren();
  const mine = diagnostics.filter((d) => d.file === path || d.file.endsWith('/' + path.split('/').pop()) && path.endsWith(d.file.split('/').pop()));
  const lines = text.split('\n');
  lines.forEach((line, i) => {
    const here = mine.filter((d) => d.line === i + 1);
    pre.append(el('div', { class: 'line' + (here.length ? ' bad' : '') }, el('span', { class: 'ln' }, String(i + 1)), line));
    for (const d of here) pre.append(el('div', { class: 'diag' }, `${d.file}:${d.line}:${d.col}: ${d.severity}: ${d.message}`));
  });
  for (const d of mine.filter((d) => !(d.line >= 1 && d.line <= lines.length)))
    pre.append(el('div', { class: 'diag' }, `${d.file}: ${d.severity}: ${d.message}`));
  const first = pre.querySelector('.bad');
  if (first) first.scrollIntoView({ block: 'center' });
}

// The colour bar with round ticks from 0 to the scale's top.
export function renderLegend(bar, ticks, maxText, map, top, max) {
  const g = bar.getContext('2d');
  for (let y = 0; y < bar.height; ++y) {
    const c = colourAt(map, 1 - y / (bar.height - 1));
    g.fillStyle = `rgb(${c.map((x) => Math.round(255 * x)).join(',')})`;
    g.fillRect(0, y, bar.width, 1);
  }
  ticks.replaceChildren();
  const raw = top / 4, mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw) || raw;
  for (let v = 0; v <= top + 1e-9; v += step)
    ticks.append(el('span', { style: `top:${(1 - v / top) * 100}%` }, fmt(v, 2)));
  maxText.textContent = `max ${fmt(max, 2)} m/s` + (max > top ? ' (clipped)' : '');
}

// The strain legend: the map of viz/strain.h from −top (top of the bar: +top) with ticks.
export function renderStrainLegend(bar, ticks) {
  const g = bar.getContext('2d');
  for (let y = 0; y < bar.height; ++y) {
    const c = strainColour(STRAIN_TOP * (1 - 2 * y / (bar.height - 1)), CLOTH_BASE);
    g.fillStyle = `rgb(${c.map((x) => Math.round(255 * x)).join(',')})`;
    g.fillRect(0, y, bar.width, 1);
  }
  ticks.replaceChildren();
  for (const v of [STRAIN_TOP, STRAIN_TOP / 2, 0, -STRAIN_TOP / 2, -STRAIN_TOP])
    ticks.append(el('span', { style: `top:${(0.5 - v / (2 * STRAIN_TOP)) * 100}%` }, (v > 0 ? '+' : '') + fmt(100 * v, 1) + ' %'));
}

// The run's events (run.json), each at its frame; a click shows that frame.
export function renderRunEvents(box, run, onPick) {
  box.replaceChildren();
  const rows = [];
  for (const f of run.frames) {
    const marks = [];
    if (f.failed) marks.push('failed');
    if (f.overStretched) marks.push(`over-stretched (${fmt(f.maxStretch, 2)}× rest)`);
    if (f.halved) marks.push(`${f.halved} substep${f.halved === 1 ? '' : 's'} halved`);
    if (f.recovered) marks.push(`${f.recovered} recovered`);
    for (const e of f.events) marks.push(e);
    if (marks.length) rows.push([f.frame, marks]);
  }
  if (!rows.length) box.append(el('p', { class: 'muted small' }, run.frames.length ? `no events in ${run.frames.length} frames` : 'no simulation yet'));
  for (const [frame, marks] of rows)
    box.append(el('div', { class: 'event small', onclick: () => onPick(frame) }, el('span', { class: 'frame' }, 'frame ' + frame), ' ' + marks.join(' · ')));
}

// Makes a floating panel draggable.
export function draggable(node) {
  let start = null;
  node.addEventListener('pointerdown', (e) => {
    start = [e.clientX - node.offsetLeft, e.clientY - node.offsetTop];
    node.setPointerCapture(e.pointerId);
  });
  node.addEventListener('pointermove', (e) => {
    if (!start) return;
    node.style.left = Math.max(0, e.clientX - start[0]) + 'px';
    node.style.top = Math.max(0, e.clientY - start[1]) + 'px';
  });
  node.addEventListener('pointerup', () => { start = null; });
}

// The timeline: gust envelopes and the windicator speed over [t0, t1], the scene's frame range
// shaded, simulated frames ticked, and the playhead; click or drag to set $t.
export class Timeline {
  constructor(canvas, onScrub) {
    this.canvas = canvas;
    this.onScrub = onScrub;
    this.t = 0;
    this.range = [0, 2];
    this.data = null;
    this.simFrames = [];
    this.fps = 24;
    let down = false;
    const scrub = (e) => {
      const b = canvas.getBoundingClientRect();
      const s = Math.min(1, Math.max(0, (e.clientX - b.left) / b.width));
      this.onScrub(this.range[0] + s * (this.range[1] - this.range[0]));
    };
    canvas.addEventListener('pointerdown', (e) => { down = true; canvas.setPointerCapture(e.pointerId); scrub(e); });
    canvas.addEventListener('pointermove', (e) => { if (down) scrub(e); });
    canvas.addEventListener('pointerup', () => { down = false; });
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  set(timeline, fps, frames, timeZero = 0) {
    this.fps = fps;
    this.timeZero = timeZero;
    this.data = timeline;
    const end = frames ? (frames[1] - timeZero) / fps : 2;
    this.range = timeline && timeline.present ? [timeline.t0, timeline.t1] : [0, Math.max(end, 1)];
    this.draw();
  }

  draw() {
    const c = this.canvas, w = (c.width = c.clientWidth), h = (c.height = c.clientHeight);
    const g = c.getContext('2d');
    const [t0, t1] = this.range;
    const X = (t) => (t - t0) / (t1 - t0 || 1) * w;
    g.clearRect(0, 0, w, h);
    const tl = this.data;
    if (tl && tl.present) {
      g.fillStyle = '#1d2330';
      g.fillRect(X(tl.sceneStart), 0, X(tl.sceneEnd) - X(tl.sceneStart), h);
      let vmax = 1;
      for (const cv of tl.gusts) for (const p of cv.points) vmax = Math.max(vmax, p[1]);
      for (const p of tl.windicator || []) vmax = Math.max(vmax, p[1]);
      const Y = (v) => h - 4 - v / vmax * (h - 10);
      const curve = (pts, colour) => {
        g.strokeStyle = colour;
        g.beginPath();
        pts.forEach((p, i) => (i ? g.lineTo(X(p[0]), Y(p[1])) : g.moveTo(X(p[0]), Y(p[1]))));
        g.stroke();
      };
      if (tl.windicator && tl.windicator.length) curve(tl.windicator, '#6fa8ff');
      for (const cv of tl.gusts) curve(cv.points, '#ff8a3c');
    }
    const fw = Math.max(1, X(1 / this.fps) - X(0));
    g.fillStyle = '#6b7078'; // frames of a run an edit replaced, until the new run reaches them
    const T = (f) => (f - (this.timeZero || 0)) / this.fps; // frame f's time
    for (const f of this.staleFrames || []) if (!this.simFrames.includes(f)) g.fillRect(X(T(f)), h - 3, fw, 3);
    g.fillStyle = '#5fd38a';
    for (const f of this.simFrames) g.fillRect(X(T(f)), h - 3, fw, 3);
    // The run's trouble per frame (run.json): contacts grey, halved or recovered substeps orange,
    // over-stretched or failed red, and a white mark where an event was logged.
    for (const f of (this.run && this.run.frames) || []) {
      const x = X(T(f.frame));
      if (f.contacts) { g.fillStyle = '#9aa0a8'; g.fillRect(x, 2, fw, 3); }
      if (f.halved || f.recovered) { g.fillStyle = '#f0a040'; g.fillRect(x, 6, fw, 4); }
      if (f.overStretched || f.failed) { g.fillStyle = '#ff5050'; g.fillRect(x, 0, fw, h); }
      if (f.events.length) { g.fillStyle = '#fff'; g.fillRect(x, 11, fw, 3); }
    }
    g.strokeStyle = '#fff';
    g.beginPath();
    g.moveTo(X(this.t) + 0.5, 0);
    g.lineTo(X(this.t) + 0.5, h);
    g.stroke();
  }
}

// gale live's page: fetches the state and the field's marks from the server, listens to its
// Server-Sent Events (a file changed and recompiled, diagnostics, simulated frames) and wires
// the controls. Every request carries the session token from the page's URL.
import { View } from 'gale/view.js';
import { renderParams, renderRamps, renderSource, renderLegend, renderStrainLegend, renderRunEvents, draggable, Timeline, shortPath, fmt } from 'gale/panels.js';

const token = new URLSearchParams(location.search).get('token') || '';
const $ = (id) => document.getElementById(id);

async function api(path, body) {
  const url = path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token);
  const r = await fetch(url, body === undefined ? {} : { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
  const j = await r.json().catch(() => ({ error: 'HTTP ' + r.status }));
  if (!r.ok) throw new Error(j.error || 'HTTP ' + r.status);
  return j;
}

// The run's status beside Simulate, in a box of fixed width (style.css) so that the button does
// not move as the text changes (a press as a run ended landed beside it); the whole text as its
// tooltip.
function simStatus(text) {
  const e = $('simText');
  e.textContent = text;
  e.title = text;
}

const live = (window.galeLive = { fieldUpdates: 0, stateUpdates: 0, errors: [], ready: false, simFrameShown: null, colliderTime: null, simFramesDrawn: [], colliderTimes: [] });
const view = new View($('view'));
live.screenBox = (name) => view.screenBox(name);
live.setTime = (t) => setTime(t);
const timeline = new Timeline($('timeline'), (t) => setTime(t));
let state = null, scene = null, fieldData = null, currentFile = null;
let time = 0, playing = false, simFrames = [], shownFrame = null, simRun = 0, endedRun = null, previousRun = null;

function sliceRequest() {
  const axis = Number($('sliceAxis').value);
  const box = scene.box;
  const plane = box.lo[axis] + Number($('slicePos').value) * (box.hi[axis] - box.lo[axis]);
  $('slicePosText').textContent = 'xyz'[axis] + ' = ' + fmt(plane, 2) + ' m';
  const a = view.rake.a, b = view.rake.b;
  const arrows = $('showArrows').checked ? $('arrowCount').value : 0;
  const lines = $('showLines').checked ? $('lineCount').value : 0;
  return `/api/field?t=${time}&axis=${axis}&plane=${plane}&res=128&arrows=${arrows}&lines=${lines}` +
    `&ax=${a.x}&ay=${a.y}&az=${a.z}&bx=${b.x}&by=${b.y}&bz=${b.z}`;
}

// One field request in flight at a time; a newer wish replaces a queued one.
let inFlight = false, queued = false;
async function refreshField() {
  if (!scene || !state || !state.ok) return;
  if (inFlight) { queued = true; return; }
  inFlight = true;
  try {
    const t0 = performance.now();
    fieldData = await api(sliceRequest());
    const t1 = performance.now();
    const s = fieldData.slice, map = s.colormap;
    view.setSlice(s, map);
    view.setArrows(fieldData.arrows, map, s.top);
    view.setStreamlines(fieldData.streamlines, map, s.top);
    view.setRigs(fieldData.overlays);
    view.render();
    renderLegend($('legendBar'), $('legendTicks'), $('legendMax'), map, s.top, s.max);
    const w = fieldData.overlays.windicator;
    $('windicator').textContent = w.present ? `windicator ${fmt(w.speed, 2)} m/s → [${w.direction.map((c) => fmt(c, 2)).join(', ')}]` : '';
    timeline.set(fieldData.overlays.timeline, state.fps, state.frames, state.timeZero || 0);
    live.fieldUpdates++;
    live.lastFieldMs = { fetch: t1 - t0, draw: performance.now() - t1 };
  } catch (e) {
    live.errors.push(String(e.message || e));
  } finally {
    inFlight = false;
    if (queued) { queued = false; refreshField(); }
  }
}

function showStatus() {
  const errs = state.diagnostics.filter((d) => d.severity === 'error');
  $('status').textContent = state.ok ? 'compiled' : `${errs.length || 1} error${errs.length === 1 ? '' : 's'}`;
  $('status').className = 'pill ' + (state.ok ? 'ok' : 'err');
  const banner = $('diagBanner');
  banner.textContent = state.diagnostics.map((d) => d.line ? `${d.file}:${d.line}:${d.col}: ${d.severity}: ${d.message}` : `${d.file}: ${d.severity}: ${d.message}`).join('\n');
  banner.classList.toggle('hidden', state.diagnostics.length === 0);
}

async function showFile(path) {
  currentFile = path;
  for (const b of $('fileTabs').children) b.classList.toggle('on', b.dataset.path === path);
  try {
    const f = await api('/api/file?path=' + encodeURIComponent(path));
    renderSource($('source'), path, f.text, state.diagnostics);
  } catch (e) {
    $('source').textContent = String(e.message || e);
  }
}

async function refreshState(s) {
  state = s || (await api('/api/state'));
  $('input').textContent = shortPath(state.input);
  $('input').title = state.input;
  showStatus();
  renderParams($('params'), state.params, async (p, value) => {
    try {
      state = await api('/api/param', { name: p.name, field: p.field, value });
      showStatus();
    } catch (e) {
      live.errors.push(String(e.message || e));
    }
  });
  renderRamps($('ramps'), state.ramps, async (r, points) => {
    try {
      state = await api('/api/ramp', { id: r.id, points });
      showStatus();
    } catch (e) {
      live.errors.push(String(e.message || e));
    }
  });
  const texts = state.files.filter((f) => /\.(se|toml)$/i.test(f));
  const tabs = $('fileTabs');
  tabs.replaceChildren(...texts.map((f) => {
    const b = document.createElement('button');
    b.textContent = shortPath(f).split('/').pop();
    b.dataset.path = f;
    b.onclick = () => showFile(f);
    return b;
  }));
  // Show the file with the first error, else the one shown, else the first expression.
  const bad = state.diagnostics.find((d) => texts.includes(d.file));
  const pick = bad ? bad.file : texts.includes(currentFile) ? currentFile : texts.find((f) => f.endsWith('.se')) || texts[0];
  if (pick) await showFile(pick);
  live.stateUpdates++;
}

async function refreshScene() {
  scene = await api('/api/scene');
  view.setBox(scene.box);
  view.setBodies(scene.rest, scene.colliders);
  colliderShown = null;
  showColliders(colliderWanted === null ? 0 : colliderWanted);
}

// The colliders at time t (the shown frame's time while a simulation's frame is shown): one
// request in flight, the newest wish kept.
let colliderWanted = null, colliderShown = null, colliderBusy = false;
async function showColliders(t) {
  colliderWanted = t;
  if (!scene || !scene.colliders.length || colliderBusy || t === colliderShown) return;
  colliderBusy = true;
  try {
    const c = await api('/api/colliders?t=' + t);
    view.setColliderPoses(c.colliders);
    colliderShown = t;
    live.colliderTime = t;
    live.colliderTimes.push(t);
  } catch (e) {
    live.errors.push(String(e.message || e));
  } finally {
    colliderBusy = false;
    if (colliderWanted !== colliderShown) showColliders(colliderWanted);
  }
}

// Frame F is at t = (F − time_zero) / fps (the scene's [scene] time_zero), and back.
const frameTime = (f) => (f - (state ? state.timeZero || 0 : 0)) / (state ? state.fps : 24);
const frameAt = (t) => t * (state ? state.fps : 24) + (state ? state.timeZero || 0 : 0);

function setTime(t) {
  time = Math.max(0, t);
  timeline.t = time;
  timeline.draw();
  $('timeText').textContent = `t = ${time.toFixed(3)} s · frame ${fmt(frameAt(time), 1)}`;
  if (simFrames.length) showSimFrame(Math.round(frameAt(time)));
  else showColliders(time);
  refreshField();
}

// One frame request in flight; frames that arrive meanwhile are skipped to the newest wish.
let frameObjects = [], frameBusy = false, frameWanted = null;
async function showSimFrame(f) {
  const have = simFrames.filter((x) => x <= f);
  const n = have.length ? have[have.length - 1] : null;
  if (n === null || n === shownFrame) return;
  if (frameBusy) { frameWanted = f; return; }
  frameBusy = true;
  shownFrame = n;
  showColliders(frameTime(n));
  try {
    const fr = await api('/api/frame?n=' + n);
    if (fr.run === simRun) {
      frameObjects = fr.objects;
      drawSimFrame();
      live.simFrameShown = n;
      live.simFramesDrawn.push(n);
      live.simFrameRun = fr.run;
      showCompare(n);
    } else {
      shownFrame = null; // (a frame of a replaced run: ask again)
    }
  } catch (e) {
    live.errors.push(String(e.message || e));
    shownFrame = null;
  } finally {
    frameBusy = false;
    if (frameWanted !== null) { const w = frameWanted; frameWanted = null; showSimFrame(w); }
  }
}

// Compare: the same frame of the run the last edit replaced, over the shown one.
async function showCompare(n) {
  if (!$('showCompare').checked || !previousRun || n === null) {
    view.setCompareFrame([]);
    live.compareShown = null;
    return;
  }
  try {
    const fr = await api(`/api/frame?n=${n}&run=${previousRun}`);
    if (shownFrame !== n) return;
    view.setCompareFrame(fr.objects);
    live.compareShown = { run: fr.run, frame: n };
  } catch (e) {
    view.setCompareFrame([]); // (that run did not reach frame n)
    live.compareShown = null;
  }
}

// The shown frame, coloured by strain when that is on (with its legend).
function drawSimFrame(stale = false) {
  const strain = $('showStrain').checked;
  view.setSimFrame(frameObjects, { strain, stale });
  const has = strain && !stale && frameObjects.some((o) => o.strain);
  $('strainLegend').classList.toggle('hidden', !has);
  live.strainShown = has;
}

// run.json's per-frame summary (/api/run) on the timeline and in the Run panel; at most one
// request in flight, again when more frames came meanwhile.
let runBusy = false, runAgain = false;
async function refreshRun() {
  if (runBusy) { runAgain = true; return; }
  runBusy = true;
  try {
    const run = await api('/api/run');
    timeline.run = run;
    timeline.draw();
    renderRunEvents($('runEvents'), run, (f) => setTime(frameTime(f)));
    live.run = run;
  } catch (e) {
    // (no simulation yet)
  } finally {
    runBusy = false;
    if (runAgain) { runAgain = false; setTimeout(refreshRun, 300); }
  }
}

// Playing advances $t in real time; the view shows the newest field that has arrived.
let last = null;
function tick(now) {
  if (playing) {
    if (last !== null) {
      const [t0, t1] = timeline.range;
      let t = time + (now - last) / 1000;
      if (t > t1) t = t0;
      setTime(t);
    }
    last = now;
    requestAnimationFrame(tick);
  } else {
    last = null;
  }
}

function events() {
  const es = new EventSource('/api/events?token=' + encodeURIComponent(token));
  // (The tests read when each event arrived: [type, ms since the page loaded].)
  live.events = [];
  live.simLog = []; // (every sim event and Simulate press, for a test's failure report)
  for (const type of ['field', 'diagnostics', 'frame', 'sim']) es.addEventListener(type, () => live.events.push([type, performance.now()]));
  es.addEventListener('error', () => live.events.push(['error', performance.now()]));
  es.addEventListener('field', async () => {
    await refreshState();
    await refreshScene();
    refreshField();
  });
  es.addEventListener('diagnostics', () => refreshState());
  es.addEventListener('frame', (e) => {
    const d = JSON.parse(e.data), f = d.frame;
    if (d.run !== undefined && d.run !== simRun) return; // a frame of a run that was replaced
    simFrames.push(f);
    timeline.simFrames = simFrames;
    simStatus(`frame ${f} of ${state.frames[1]}` + (simRun > 1 ? ` (run ${simRun})` : ''));
    live.framesOfRun = simFrames.length;
    if (!playing) setTime(frameTime(f));
    refreshRun();
  });
  es.addEventListener('sim', (e) => {
    const s = JSON.parse(e.data);
    live.simLog.push(['event', simRun, $('simulate').textContent, { ...s, log: undefined }]);
    if (s.running && s.run !== undefined) {
      if (s.restart) {
        // An edit restarted the simulation: the old run's frames stay, greyed, until replaced.
        timeline.staleFrames = [...new Set([...(timeline.staleFrames || []), ...simFrames])];
        simFrames = [];
        timeline.simFrames = simFrames;
        timeline.run = null;
        shownFrame = null;
        drawSimFrame(true);
        live.restarts = (live.restarts || 0) + 1;
      }
      simRun = s.run;
      live.simRun = s.run;
      previousRun = s.previous || null;
      live.previousRun = previousRun;
    }
    if (s.run !== undefined && s.run !== simRun) return;
    $('simulate').textContent = s.running || s.on ? 'Stop' : 'Simulate';
    if (!s.running) {
      endedRun = s.run;
      simStatus(s.exit === 0 ? `done: ${simFrames.length} frames` : s.exit === -1 ? 'stopped' : `gale sim failed (exit ${s.exit}): ` + (s.log || '').trim().split('\n').pop());
      refreshRun();
    }
  });
  es.onerror = () => { $('status').textContent = 'reconnecting…'; };
  es.onopen = () => { if (state) showStatus(); };
}

function wire() {
  $('sliceAxis').onchange = refreshField;
  $('arrowCount').onchange = refreshField;
  $('lineCount').onchange = refreshField;
  $('slicePos').oninput = refreshField;
  for (const [id, group] of [['showSlice', 'slice'], ['showArrows', 'arrows'], ['showLines', 'lines'], ['showBodies', 'bodies'], ['showRigs', 'rigs']])
    $(id).onchange = () => {
      view.setVisible(group, $(id).checked);
      if (group === 'arrows' || group === 'lines') refreshField(); // (not computed while hidden)
    };
  $('play').onclick = () => {
    playing = !playing;
    $('play').textContent = playing ? '❚❚' : '▶';
    if (playing) requestAnimationFrame(tick);
  };
  $('simulate').onclick = async () => {
    try {
      const running = $('simulate').textContent === 'Stop';
      if (!running) {
        simFrames = [];
        shownFrame = null;
        timeline.simFrames = simFrames;
        timeline.staleFrames = [];
        timeline.run = null;
        frameObjects = [];
        drawSimFrame();
      }
      const r = await api('/api/simulate', { action: running ? 'stop' : 'start' });
      live.simLog.push(['press', simRun, running ? 'Stop' : 'Simulate', r]);
      // The button follows `on` (Simulate pressed and not stopped: a run that ended by itself
      // leaves it on, and edits re-simulate), so a Stop after the run's end turns it off.
      $('simulate').textContent = r.running || r.on ? 'Stop' : 'Simulate';
      // (A short run may have ended, and its event been shown, before this reply.)
      if (r.run !== endedRun) simStatus(r.running ? 'simulating…' : '');
    } catch (e) {
      live.simLog.push(['press failed', simRun, String(e.message || e)]);
      simStatus(String(e.message || e));
    }
  };
  $('showStrain').onchange = () => drawSimFrame();
  $('showCompare').onchange = () => showCompare(shownFrame);
  renderStrainLegend($('strainBar'), $('strainTicks'));
  view.onRakeMoved = refreshField;
  draggable($('legend'));
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT') return;
    if (e.key === ' ') { e.preventDefault(); $('play').click(); }
  });
}

(async () => {
  live.loadedAt = performance.now();
  try {
    wire();
    events();
    await refreshScene();
    await refreshState();
    setTime(0);
    live.ready = true;
  } catch (e) {
    live.errors.push(String(e.message || e));
    $('status').textContent = String(e.message || e);
    $('status').className = 'pill err';
  }
})();

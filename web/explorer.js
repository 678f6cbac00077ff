// rastray explorer: the page of `rastray serve`. The settings on the left
// become the query of /api/frame (images, maps, work) and /api/explain (one
// pixel); the server parses them as `rastray render` / `crossval` /
// `explain` would and shows the equivalent command line. Plain script, no
// build step, nothing loaded from elsewhere.
'use strict';

const $ = (id) => document.getElementById(id);

const state = {
  scene: '',
  renderer: 'raster',
  view: 'image',
  pair: 'raster',
  swipeWith: 'raytrace',
  size: [640, 480],
  options: {}, // render option name -> value, only those set away from the default
  camera: null, // null: the chosen file camera; else {eye, target, up} (given on top of it)
  cameraIndex: null, // the file camera (--camera N); null: the first (the default)
  sceneInfo: null,
};
let optionTable = [];
let applicability = [];
const client = Math.random().toString(36).slice(2, 10);
let seq = 0;
let lastFrame = null; // the last final frame shown: {width, height}
let explainedPixel = null;

// ---- small vector helpers (camera) ----------------------------------------
const add = (a, b) => a.map((v, i) => v + b[i]);
const sub = (a, b) => a.map((v, i) => v - b[i]);
const mul = (a, s) => a.map((v) => v * s);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => mul(a, 1 / Math.hypot(a[0], a[1], a[2]));
// Rodrigues: v turned by `angle` around unit `axis`.
function rotate(v, axis, angle) {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(mul(v, c), mul(cross(axis, v), s)), mul(axis, dot(axis, v) * (1 - c)));
}
// Numbers as the command line shows them: 9 significant digits, no noise.
const fmt = (x) => String(Number(x.toPrecision(9)));

// ---- which options apply ------------------------------------------------------
// The server's answer (/api/options "applicability", from
// RenderSettings::applies) for each renderer, or 'all', under each --shadows
// value and wireframe setting: the page keeps no copy of the rules.
function applicabilityEntry(target, shadows) {
  const wireframe = state.options.wireframe === 'on';
  return applicability.find((a) => a.renderer === target && a.shadows === (shadows || '') &&
    a.wireframe === wireframe);
}

function applies(opt, all, renderer) {
  const entry = applicabilityEntry(all ? 'all' : renderer, state.options.shadows);
  return !!entry && entry.applies.includes(opt.name);
}

// Whether `renderer` (or, with all, the views running every renderer) takes
// --shadows `value`.
function shadowsValid(value, renderer, all) {
  const entry = applicabilityEntry(all ? 'all' : renderer, value);
  return !!entry && entry.valid;
}

function optionApplies(name, all, renderer) {
  const opt = optionTable.find((o) => o.name === name);
  if (!opt || !applies(opt, all, renderer)) return false;
  if (name === 'shadows') return shadowsValid(state.options.shadows, renderer, all);
  return true;
}

// ---- the query of a request -------------------------------------------------
// all: the maps and explain run every renderer (no renderer parameter).
function renderQuery(all, renderer, overrides) {
  const q = new URLSearchParams();
  q.set('scene', state.scene);
  if (!all) q.set('renderer', renderer);
  q.set('size', state.size.join(','));
  if (state.cameraIndex !== null) q.set('camera', String(state.cameraIndex));
  if (state.camera) {
    for (const k of ['eye', 'target', 'up']) q.set(k, state.camera[k].map(fmt).join(','));
  }
  const options = Object.assign({}, state.options, overrides || {});
  for (const [name, value] of Object.entries(options)) {
    if (value !== undefined && value !== '' && optionApplies(name, all, renderer)) q.set(name, value);
  }
  return q;
}

async function getJson(url, signal) {
  const res = await fetch(url, {signal});
  if (res.status === 409) throw new DOMException('superseded', 'AbortError');
  if (!res.ok) throw new Error((await res.text()).trim() || res.statusText);
  return res.json();
}

function setStatus(text, isError) {
  $('status').textContent = text;
  $('status').classList.toggle('error', !!isError);
}

// ---- frames -----------------------------------------------------------------
let frameAbort = null;
let previewBusy = false;
let previewAgain = false;
let dragging = false;
let firstFrameDone = null; // resolves when the first final frame is on screen (selftest)
const firstFrame = new Promise((resolve) => { firstFrameDone = resolve; });
const frameWaiters = []; // resolved after the next final frame (selftest)

async function fetchFrame(query, signal) {
  query.set('client', client);
  query.set('seq', String(++seq));
  return getJson('/api/frame?' + query.toString(), signal);
}

function loadImage(img, src) {
  return new Promise((resolve, reject) => {
    img.onload = () => resolve();
    img.onerror = () => reject(new Error('the image did not decode'));
    img.src = src;
  });
}

// preview: 1 spp of the image view while the camera moves; else the view
// and settings chosen.
async function requestFrame(preview) {
  if (!state.scene) return;
  if (preview && previewBusy) { previewAgain = true; return; }
  if (frameAbort) frameAbort.abort();
  const ctl = new AbortController();
  frameAbort = ctl;
  previewBusy = preview;
  setStatus(preview ? 'preview (1 spp)…' : 'rendering…');
  const started = performance.now();
  try {
    if (preview) await showPreview(ctl.signal);
    else await showFinal(ctl.signal);
    const ms = Math.round(performance.now() - started);
    setStatus((preview ? 'preview, ' : '') + ms + ' ms');
    if (!preview) {
      firstFrameDone();
      for (const resolve of frameWaiters.splice(0)) resolve();
    }
  } catch (e) {
    if (e.name !== 'AbortError') setStatus(e.message, true);
    if (e.name !== 'AbortError' && !preview) failSelftest('frame: ' + e.message);
  } finally {
    if (frameAbort === ctl) frameAbort = null;
    if (preview) {
      previewBusy = false;
      if (previewAgain && dragging) { previewAgain = false; requestFrame(true); }
    }
  }
}

let previewsShown = 0; // previews on screen so far (the selftest's orbit:MS counts them)

async function showPreview(signal) {
  const query = renderQuery(false, state.renderer, {spp: '1'});
  query.set('png', 'quick'); // the same pixels, encoded in a seventh of the time
  const j = await fetchFrame(query, signal);
  await loadImage($('image-a'), j.image);
  ++previewsShown;
  $('image-b').hidden = true;
  for (const id of ['swipe-line', 'label-a', 'label-b']) $(id).hidden = true;
}

async function showFinal(signal) {
  const view = state.view;
  const all = view !== 'image' && view !== 'swipe';
  const query = renderQuery(all, state.renderer);
  if (all) { query.set('view', view); query.set('pair', state.pair); }
  const a = await fetchFrame(query, signal);
  let b = null;
  if (view === 'swipe') b = await fetchFrame(renderQuery(false, state.swipeWith), signal);
  await loadImage($('image-a'), a.image);
  if (b) await loadImage($('image-b'), b.image);
  $('image-b').hidden = !b;
  applySwipe();
  lastFrame = {width: a.size[0], height: a.size[1]};
  sizeOverlay();
  $('command').textContent = a.command + (b ? '\n' + b.command : '');
  showLegend(a);
  showWork(a, b);
  rememberInUrl();
  if (explainedPixel) clearExplain();
}

function applySwipe() {
  // The second renderer shows right of the slider.
  const swipe = state.view === 'swipe';
  $('image-b').style.clipPath = 'inset(0 0 0 ' + $('swipe').value + '%)';
  $('swipe-line').style.left = $('swipe').value + '%';
  for (const id of ['swipe', 'swipe-line', 'label-a', 'label-b']) $(id).hidden = !swipe;
  $('label-a').textContent = state.renderer;
  $('label-b').textContent = state.swipeWith;
}

function sizeOverlay() {
  if (!lastFrame) return;
  $('overlay').setAttribute('viewBox', '0 0 ' + lastFrame.width + ' ' + lastFrame.height);
}

// ---- legend and work -------------------------------------------------------
function el(tag, text, cls) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (cls) e.className = cls;
  return e;
}

function showLegend(j) {
  const box = $('legend');
  box.replaceChildren();
  if (j.legend) {
    const counts = j.comparison.visibility.mismatches;
    for (const entry of j.legend) {
      const item = el('span', '', 'legend-item');
      const swatch = el('span', '', 'swatch');
      swatch.style.background = entry.color;
      item.append(swatch, entry.label + (entry.key in counts ? ' (' + counts[entry.key] + ')' : ''));
      box.append(item);
    }
  } else if (j.colorBar) {
    const bar = el('span', '', 'colorbar');
    bar.style.background = j.colorBar.gradient;
    const missing = el('span', '', 'swatch');
    missing.style.background = j.colorBar.missing;
    box.append(el('span', j.colorBar.quantity + ': ' + fmt(j.colorBar.lo) + ' '), bar,
               el('span', ' ' + fmt(j.colorBar.hi) + '  '), missing, el('span', ' no value'));
  }
}

function table(rows, head) {
  const t = el('table');
  if (head) {
    const tr = el('tr');
    for (const h of head) tr.append(el('th', h));
    t.append(tr);
  }
  for (const row of rows) {
    const tr = el('tr');
    for (const cell of row) tr.append(cell instanceof Node ? cell : el('td', String(cell)));
    t.append(tr);
  }
  return t;
}

function workOf(render) {
  const box = el('details');
  box.open = true;
  box.append(el('summary', render.renderer + ': ' + (render.seconds * 1000).toFixed(1) + ' ms' +
                (render.preparation && render.preparation !== 'none' ? ' (BVH ' + render.preparation + ')' : '')));
  const left = el('ul', '', 'left-out');
  for (const p of render.passesLeftOut) left.append(el('li', p));
  const run = el('ul', '', 'passes-run');
  for (const p of render.passesRun) run.append(el('li', p));
  box.append(el('h3', 'left out'), left, el('h3', 'passes run'), run);
  const counters = Object.entries(render.counters).filter(([, v]) => v !== 0);
  box.append(el('h3', 'counters (non-zero)'), table(counters.map(([k, v]) => [k, v.toLocaleString('en')])));
  box.append(el('h3', 'timings'), table(Object.entries(render.timings).map(([k, v]) => [k, (v * 1000).toFixed(2) + ' ms'])));
  return box;
}

function showWork(a, b) {
  const body = $('work-body');
  body.replaceChildren();
  if (a.comparison) {
    const v = a.comparison.visibility;
    const c = a.comparison.color;
    const classes = Object.entries(v.mismatches).filter(([, n]) => n > 0).map(([k, n]) => k + ' ' + n).join(', ');
    body.append(el('p', a.comparison.pair.join(' vs ') + ': ' + (v.agreement * 100).toFixed(4) + '% of ' +
                        v.compared.toLocaleString('en') + ' layers agree' + (classes ? '; ' + classes : '') +
                        (v.cutOff ? '; cut off ' + v.cutOff : '') + '. Colour RMS ' + c.rms.toPrecision(3) +
                        (c.psnr >= 0 ? ', PSNR ' + c.psnr.toFixed(1) + ' dB' : ', identical') + '.', 'summary'));
  }
  for (const r of a.renders.concat(b ? b.renders : [])) body.append(workOf(r));
}

// ---- pixel inspection -------------------------------------------------------
let explainAbort = null;
let explainShown = null; // resolves the selftest's wait
const SVG = 'http://www.w3.org/2000/svg';

function clearExplain() {
  explainedPixel = null;
  $('overlay').replaceChildren();
  $('explain-body').replaceChildren();
  $('explain-hint').hidden = false;
}

async function explainPixel(x, y) {
  if (explainAbort) explainAbort.abort();
  const ctl = new AbortController();
  explainAbort = ctl;
  const q = renderQuery(true);
  q.set('x', String(x));
  q.set('y', String(y));
  q.set('client', client + '-explain');
  q.set('seq', String(++seq));
  setStatus('explaining pixel (' + x + ', ' + y + ')…');
  try {
    const j = await getJson('/api/explain?' + q.toString(), ctl.signal);
    explainedPixel = [x, y];
    showExplain(j);
    drawRays(j.rays, x, y);
    setStatus('pixel (' + x + ', ' + y + ')');
    if (explainShown) explainShown(j);
  } catch (e) {
    if (e.name !== 'AbortError') {
      setStatus(e.message, true);
      failSelftest('explain: ' + e.message);
    }
  }
}

function hitText(h) {
  return h ? '(' + h.instance + ', ' + h.triangle + ') Z ' + Number(h.depth).toPrecision(7) : 'nothing';
}

function hitsTable(samples) {
  const rows = [];
  for (const s of samples) {
    s.layers.forEach((layer, k) => {
      const verdict = el('td', layer.verdict, layer.verdict === 'agree' ? 'agree' : 'mismatch');
      rows.push([k === 0 ? s.sample + ' (' + s.position.map((p) => p.toFixed(3)).join(', ') + ')' : '',
                 k, hitText(layer.raster), hitText(layer.raytrace), verdict]);
    });
  }
  return table(rows, ['sample', 'layer', 'raster', 'raytrace', 'verdict']);
}

function rayTree(events) {
  const list = el('ul', '', 'ray-tree');
  for (const e of events.filter((ev) => ev.stage === 'ray')) {
    const v = e.values;
    const where = e.instance !== null ? ' (' + e.instance + ', ' + e.triangle + ')' : '';
    const li = el('li', (e.sample !== null ? 's' + e.sample + ' ' : '') + v.kind + ' → ' + e.outcome + where +
                        (v.t ? ' t ' + v.t : '') + ' ' + (v.contribution || v.transmittance || ''), 'ray-' + v.kind);
    li.style.paddingLeft = (e.depth * 1.2) + 'em';
    list.append(li);
  }
  return list;
}

function showExplain(j) {
  const e = j.explain;
  const body = $('explain-body');
  $('explain-hint').hidden = true;
  body.replaceChildren(el('p', 'pixel (' + e.pixel.join(', ') + ') of ' + e.size.join('×') + ', ' + e.spp + ' spp'),
                       el('code', j.command, 'command-small'));
  body.append(el('h3', 'hits per sample'), hitsTable(e.samples));
  const rays = e.raytrace.events.filter((ev) => ev.stage === 'ray').length;
  body.append(el('h3', 'ray tree (' + rays + ' rays)'), rayTree(e.raytrace.events));
  const text = el('details');
  text.append(el('summary', 'full explain output (rasterizer: ' + e.raster.events.length + ' events)'), el('pre', j.text));
  body.append(text);
  body.append(el('div', 'explained', 'explain-done'));
}

function drawRays(rays, x, y) {
  const svg = $('overlay');
  svg.replaceChildren();
  // The pixel, and a ring around it that stays visible on a large image.
  const radius = Math.max(4, lastFrame.width / 60);
  const mark = document.createElementNS(SVG, 'rect');
  for (const [k, v] of [['x', x], ['y', y], ['width', 1], ['height', 1], ['class', 'pixel-mark']]) mark.setAttribute(k, v);
  const ring = document.createElementNS(SVG, 'circle');
  for (const [k, v] of [['cx', x + 0.5], ['cy', y + 0.5], ['r', radius], ['class', 'pixel-mark']]) ring.setAttribute(k, v);
  svg.append(mark, ring);
  for (const r of rays) {
    if (r.kind === 'primary') {
      const dot = document.createElementNS(SVG, 'circle');
      for (const [k, v] of [['cx', r.to[0]], ['cy', r.to[1]], ['r', 0.8], ['class', 'ray ray-primary']]) dot.setAttribute(k, v);
      svg.append(dot);
      continue;
    }
    const line = document.createElementNS(SVG, 'line');
    const attrs = [['x1', r.from[0]], ['y1', r.from[1]], ['x2', r.to[0]], ['y2', r.to[1]],
                   ['class', 'ray ray-' + r.kind + ' ' + r.outcome]];
    for (const [k, v] of attrs) line.setAttribute(k, v);
    const title = document.createElementNS(SVG, 'title');
    title.textContent = 'sample ' + r.sample + ': ' + r.kind + ' ray, ' + r.outcome;
    line.append(title);
    svg.append(line);
  }
}

// ---- camera: orbit, pan, zoom ----------------------------------------------
// The file camera chosen (its view as /api/scene describes it), or the
// scene's default camera.
function chosenCamera() {
  const cams = state.sceneInfo.cameras || [];
  const c = state.cameraIndex !== null ? cams[state.cameraIndex] : null;
  return c && c.eye ? c : state.sceneInfo.camera;
}

function currentCamera() {
  if (state.camera) return state.camera;
  const c = chosenCamera();
  return {eye: c.eye.slice(), target: c.target.slice(), up: c.up.slice()};
}

function orbit(dx, dy) {
  const cam = currentCamera();
  const up = norm(cam.up);
  let offset = sub(cam.eye, cam.target);
  offset = rotate(offset, up, -dx * 0.01);
  const right = norm(cross(up, offset));
  const turned = rotate(offset, right, -dy * 0.01);
  // Stop short of the poles, where up and the view direction align.
  const cosine = dot(norm(turned), up);
  if (Math.abs(cosine) < 0.995) offset = turned;
  state.camera = {eye: add(cam.target, offset), target: cam.target, up: cam.up};
}

function pan(dx, dy) {
  const cam = currentCamera();
  const forward = norm(sub(cam.target, cam.eye));
  const right = norm(cross(forward, cam.up));
  const up = cross(right, forward);
  const distance = Math.hypot(...sub(cam.eye, cam.target));
  const yfov = (chosenCamera().yfovDegrees || 45) * Math.PI / 180;
  const perPixel = 2 * distance * Math.tan(yfov / 2) / $('image-a').getBoundingClientRect().height;
  const move = add(mul(right, -dx * perPixel), mul(up, dy * perPixel));
  state.camera = {eye: add(cam.eye, move), target: add(cam.target, move), up: cam.up};
}

function zoom(steps) {
  const cam = currentCamera();
  const offset = mul(sub(cam.eye, cam.target), Math.pow(1.1, steps));
  state.camera = {eye: add(cam.target, offset), target: cam.target, up: cam.up};
}

// The image pixel under a mouse event, or null outside the image.
function pixelAt(ev) {
  const rect = $('image-a').getBoundingClientRect();
  if (!lastFrame || rect.width === 0) return null;
  const x = Math.floor((ev.clientX - rect.left) / rect.width * lastFrame.width);
  const y = Math.floor((ev.clientY - rect.top) / rect.height * lastFrame.height);
  if (x < 0 || y < 0 || x >= lastFrame.width || y >= lastFrame.height) return null;
  return [x, y];
}

let press = null;
function onMouseDown(ev) {
  ev.preventDefault();
  press = {x: ev.clientX, y: ev.clientY, lastX: ev.clientX, lastY: ev.clientY,
           pan: ev.button === 2 || ev.button === 1 || ev.shiftKey};
}

function onMouseMove(ev) {
  if (!press) return;
  const dx = ev.clientX - press.lastX, dy = ev.clientY - press.lastY;
  if (!dragging && Math.hypot(ev.clientX - press.x, ev.clientY - press.y) < 4) return;
  dragging = true;
  press.lastX = ev.clientX;
  press.lastY = ev.clientY;
  if (press.pan) pan(dx, dy); else orbit(dx, dy);
  cameraMoved();
  requestFrame(true);
}

function onMouseUp(ev) {
  if (!press) return;
  const wasDrag = dragging;
  dragging = false;
  press = null;
  if (wasDrag) { requestFrame(false); return; }
  const p = pixelAt(ev);
  if (p) explainPixel(p[0], p[1]);
}

let wheelTimer = null;
function onWheel(ev) {
  ev.preventDefault();
  zoom(ev.deltaY > 0 ? 1 : -1);
  cameraMoved();
  dragging = true;
  requestFrame(true);
  clearTimeout(wheelTimer);
  wheelTimer = setTimeout(() => { dragging = false; requestFrame(false); }, 350);
}

function cameraMoved() {
  $('camera-pick').value = 'moved';
  clearExplain();
}

// ---- controls -----------------------------------------------------------------
function controls() { return Array.from(document.querySelectorAll('[data-option]')); }
function optionInfo(name) { return optionTable.find((o) => o.name === name); }

// The settings the controls show, leaving out every value equal to the
// command's default: the command line then holds only what differs.
function readControls() {
  const o = {};
  // Options the page has no control for (from the URL) stay as given.
  for (const [k, v] of Object.entries(state.options)) if (!controls().some((c) => c.dataset.option === k)) o[k] = v;
  for (const c of controls()) {
    const name = c.dataset.option;
    if (name === 'shadow-bias') continue;
    if (name === 'time' && $('time-label').hidden) { delete o.time; continue; } // no animations
    if (c.type === 'checkbox') { if (c.checked) o[name] = 'on'; continue; }
    o[name] = name === 'transparency' && c.value === 'peel' ? 'peel:' + $('peel-layers').value : c.value;
  }
  const bias = controls().filter((c) => c.dataset.option === 'shadow-bias').map((c) => c.value);
  if (bias.every((v) => v !== '')) o['shadow-bias'] = bias.join(',');
  if (state.sceneInfo) { // the checkboxes exist once the scene is known
    const lights = readLights();
    if (lights === null) delete o.lights; else o.lights = lights;
  }
  for (const [k, v] of Object.entries(o)) {
    const info = optionInfo(k);
    if (v === '' || (info && info.default === v)) delete o[k];
  }
  state.options = o;
  state.size = [Number($('width').value), Number($('height').value)];
}

function writeControls() {
  for (const c of controls()) {
    const name = c.dataset.option;
    const info = optionInfo(name);
    const value = state.options[name] !== undefined ? state.options[name] : (info ? info.default : '');
    if (c.type === 'checkbox') c.checked = value === 'on';
    else if (name === 'shadow-bias') c.value = value ? value.split(',')[Number(c.dataset.index)] || '' : '';
    else if (name === 'time') { c.value = value || '0'; $('time-value').textContent = c.value; }
    else if (name === 'transparency' && value.startsWith('peel:')) { c.value = 'peel'; $('peel-layers').value = value.slice(5); }
    else if (c.tagName === 'INPUT') c.value = value;
    else if (value !== '' || name === 'shadows') c.value = value;
  }
  $('width').value = state.size[0];
  $('height').value = state.size[1];
  for (const id of ['renderer', 'view', 'pair']) $(id).value = state[id];
  $('swipe-with').value = state.swipeWith;
}

// Greys out what does not apply to the chosen renderer or view (the server
// would refuse it, as `rastray render` does) and says where it applies.
function updateApplicability() {
  const all = state.view !== 'image' && state.view !== 'swipe';
  const renderers = all ? [null] : state.view === 'swipe' ? [state.renderer, state.swipeWith] : [state.renderer];
  for (const c of controls()) {
    const info = optionInfo(c.dataset.option);
    const ok = !!info && renderers.some((r) => applies(info, all, r));
    c.disabled = !ok;
    c.closest('label').classList.toggle('na', !ok);
    c.closest('label').title = info ? info.help + (ok ? '' : ' (applies to ' + info.applies + ')') : '';
  }
  for (const opt of document.querySelectorAll('[data-option="shadows"] option')) {
    opt.disabled = opt.value !== '' && !renderers.every((r) => shadowsValid(opt.value, r, all));
  }
  $('peel-layers').hidden = state.options.transparency === undefined || !state.options.transparency.startsWith('peel');
  $('renderer-label').hidden = all;
  $('swipe-label').hidden = state.view !== 'swipe';
  $('pair-label').hidden = !all;
}

function settingsChanged() {
  readControls();
  state.renderer = $('renderer').value;
  state.view = $('view').value;
  state.pair = $('pair').value;
  state.swipeWith = $('swipe-with').value;
  updateApplicability();
  clearExplain();
  requestFrame(false);
}

// The page's state as its own URL, so a view can be bookmarked or shared.
function rememberInUrl() {
  const all = state.view !== 'image' && state.view !== 'swipe';
  const q = renderQuery(all, state.renderer);
  if (!all) q.delete('renderer');
  q.set('renderer', state.renderer);
  q.set('view', state.view);
  if (all) q.set('pair', state.pair);
  if (state.view === 'swipe') q.set('swipe', state.swipeWith);
  history.replaceState(null, '', '?' + q.toString());
}

function readUrl(params, scenes) {
  state.scene = scenes.includes(params.get('scene')) ? params.get('scene') : scenes[0] || '';
  for (const k of ['renderer', 'view', 'pair']) if (params.get(k)) state[k] = params.get(k);
  if (params.get('swipe')) state.swipeWith = params.get('swipe');
  if (params.get('size')) state.size = params.get('size').split(',').map(Number);
  if (params.get('eye') && params.get('target') && params.get('up')) {
    const vec = (k) => params.get(k).split(',').map(Number);
    state.camera = {eye: vec('eye'), target: vec('target'), up: vec('up')};
  }
  if (/^\d+$/.test(params.get('camera') || '')) state.cameraIndex = Number(params.get('camera'));
  for (const info of optionTable) {
    if (params.has(info.name) && !['size', 'eye', 'target', 'up', 'camera'].includes(info.name)) {
      state.options[info.name] = params.get(info.name);
    }
  }
}

// ---- lights: one checkbox per light of the scene (--lights) -------------------
// The --lights value the checkboxes say: null when all are on (the default),
// 'none' when all are off, else the indices kept, e.g. '0,2'.
function readLights() {
  const boxes = Array.from(document.querySelectorAll('#lights-list input'));
  const kept = boxes.filter((b) => b.checked).map((b) => b.dataset.light);
  if (kept.length === boxes.length) return null;
  return kept.length === 0 ? 'none' : kept.join(',');
}

function writeLights() {
  const list = $('lights-list');
  const value = state.options.lights || 'all';
  const kept = value === 'all' || value === 'none' ? null : value.split(',');
  const lights = state.sceneInfo.lightList || [];
  list.replaceChildren();
  if (lights.length === 0) {
    const p = document.createElement('p');
    p.className = 'hint';
    p.textContent = 'The scene has no lights: the eye light shines.';
    list.append(p);
  }
  for (const l of lights) {
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.dataset.light = String(l.index);
    box.checked = value === 'all' || (kept !== null && kept.includes(String(l.index)));
    box.addEventListener('change', settingsChanged);
    const label = document.createElement('label');
    label.append(box, ' ' + l.index + ': ' + (l.name || '(unnamed)') + ' (' + l.type + ')');
    list.append(label);
  }
}

// ---- the scene ----------------------------------------------------------------
// The camera select: every camera node of the file (--camera N; the first
// is the default and needs no option), or the default camera of a file
// without one; 'moved' once the view is dragged away from it.
function writeCameraPick() {
  const pick = $('camera-pick');
  const cams = state.sceneInfo.cameras || [];
  const options = cams.length === 0 ? [new Option(state.sceneInfo.camera.origin, 'scene')]
    : cams.map((c) => {
      const o = new Option('camera ' + c.index + ': ' + c.origin + (c.error ? ' (' + c.error + ')' : ''),
                           c.index === 0 ? 'scene' : String(c.index));
      o.disabled = !!c.error;
      return o;
    });
  pick.replaceChildren(...options, new Option('moved (drag, pan, zoom)', 'moved'));
  pick.value = state.camera ? 'moved' : state.cameraIndex ? String(state.cameraIndex) : 'scene';
}

async function loadScene(keepCamera) {
  const q = new URLSearchParams({scene: state.scene, size: state.size.join(',')});
  state.sceneInfo = await getJson('/api/scene?' + q.toString());
  if (!keepCamera) { state.camera = null; state.cameraIndex = null; }
  if (state.cameraIndex !== null && !(state.cameraIndex < (state.sceneInfo.cameras || []).length)) state.cameraIndex = null;
  writeCameraPick();
  writeLights();
  writeTimeSlider();
}

// The time slider (--time) runs over the scene's longest animation, as
// /api/scene reports it; hidden for a scene without animations.
function writeTimeSlider() {
  const duration = state.sceneInfo.duration || 0;
  const slider = document.querySelector('[data-option="time"]');
  $('time-label').hidden = !(state.sceneInfo.animations || []).length;
  slider.max = String(duration > 0 ? duration : 1);
  slider.step = String((duration > 0 ? duration : 1) / 200);
  if (state.options.time !== undefined) slider.value = state.options.time;
  $('time-value').textContent = slider.value;
}

function bindEvents() {
  for (const c of controls().concat([$('peel-layers'), $('width'), $('height'), $('renderer'),
                                      $('view'), $('pair'), $('swipe-with')])) {
    c.addEventListener('change', settingsChanged);
  }
  $('scene').addEventListener('change', async () => {
    state.scene = $('scene').value;
    clearExplain();
    delete state.options.lights; // another scene's light indices
    delete state.options.time; // and its animations
    delete state.options.animation;
    await loadScene(false);
    requestFrame(false);
  });
  $('camera-pick').addEventListener('change', () => {
    const value = $('camera-pick').value;
    if (value === 'moved') return;
    state.camera = null;
    state.cameraIndex = value === 'scene' ? null : Number(value);
    clearExplain();
    requestFrame(false);
  });
  $('swipe').addEventListener('input', applySwipe);
  const time = document.querySelector('[data-option="time"]');
  time.addEventListener('input', () => { $('time-value').textContent = time.value; });
  $('copy').addEventListener('click', () => navigator.clipboard.writeText($('command').textContent));
  const stage = $('stage');
  stage.addEventListener('mousedown', onMouseDown);
  stage.addEventListener('contextmenu', (ev) => ev.preventDefault());
  stage.addEventListener('wheel', onWheel, {passive: false});
  window.addEventListener('mousemove', onMouseMove);
  window.addEventListener('mouseup', onMouseUp);
}

// ---- self test (?selftest=STEP;STEP...) ----------------------------------
// For the headless-browser test and the README screenshot. After the first
// image, each step acts through the same mouse handlers a user reaches:
// drag:DX,DY orbits (left button, from the image centre, DX, DY CSS pixels)
// and waits for the refined image; click:X,Y clicks image pixel (X, Y) and
// waits for the explain panel; orbit:MS holds the button down and moves
// the mouse 4 CSS pixels every 16 ms (a hand orbiting at 60 Hz) for MS
// milliseconds of real time, and reports the previews shown per second
// (bench/explorer_previews.sh). The outcome goes to #selftest-result.
let selftestOn = false;
function failSelftest(message) {
  if (!selftestOn) return;
  const r = $('selftest-result');
  if (r.dataset.status) return;
  r.dataset.status = 'fail';
  r.textContent = 'selftest failed: ' + message;
}

// A whole-number client coordinate (mouse events carry integers) inside
// image pixel `p` along `axis`.
function clientCoordinate(axis, p) {
  const rect = $('image-a').getBoundingClientRect();
  const start = axis === 'x' ? rect.left : rect.top;
  const scale = (axis === 'x' ? rect.width / lastFrame.width : rect.height / lastFrame.height);
  const target = start + (p + 0.5) * scale;
  for (const c of [Math.floor(target), Math.ceil(target)]) {
    if (Math.floor((c - start) / scale) === p) return c;
  }
  return target;
}

function mouse(target, type, x, y) {
  target.dispatchEvent(new MouseEvent(type, {clientX: x, clientY: y, button: 0, bubbles: true}));
}

async function selftestDrag(dx, dy) {
  const refined = new Promise((resolve) => { frameWaiters.push(resolve); });
  const rect = $('image-a').getBoundingClientRect();
  const x = Math.round(rect.left + rect.width / 2), y = Math.round(rect.top + rect.height / 2);
  mouse($('stage'), 'mousedown', x, y);
  for (let i = 1; i <= 4; ++i) mouse(window, 'mousemove', x + Math.round(dx * i / 4), y + Math.round(dy * i / 4));
  mouse(window, 'mouseup', x + dx, y + dy);
  await refined;
  const eye = / --eye (\S+ \S+ \S+)/.exec($('command').textContent);
  if (!eye) throw new Error('the command line has no --eye after orbiting');
  return 'drag to eye ' + eye[1];
}

async function selftestClick(px, py) {
  const explained = new Promise((resolve) => { explainShown = resolve; });
  const x = clientCoordinate('x', px), y = clientCoordinate('y', py);
  mouse($('stage'), 'mousedown', x, y);
  mouse($('stage'), 'mouseup', x, y);
  const j = await explained;
  if (!$('explain-body').querySelector('.explain-done') || j.explain.samples.length === 0) {
    throw new Error('the explain panel stayed empty');
  }
  return 'pixel (' + j.explain.pixel.join(', ') + '), ' + j.explain.samples.length + ' samples, ' +
         $('overlay').querySelectorAll('.ray').length + ' rays drawn';
}

async function selftestOrbit(ms) {
  const refined = new Promise((resolve) => { frameWaiters.push(resolve); });
  const rect = $('image-a').getBoundingClientRect();
  const x = Math.round(rect.left + rect.width / 2), y = Math.round(rect.top + rect.height / 2);
  mouse($('stage'), 'mousedown', x, y);
  const before = previewsShown, start = performance.now();
  let step = 0;
  while (performance.now() - start < ms) {
    mouse(window, 'mousemove', x + 4 * (++step), y);
    await new Promise((resolve) => setTimeout(resolve, 16));
  }
  const shown = previewsShown - before, seconds = (performance.now() - start) / 1000;
  mouse(window, 'mouseup', x + 4 * step, y);
  await refined;
  return 'orbit ' + shown + ' previews in ' + seconds.toFixed(2) + ' s: ' + (shown / seconds).toFixed(1) +
         ' previews/s';
}

async function runSelftest(spec) {
  selftestOn = true;
  const timer = setTimeout(() => failSelftest('timed out'), 60000);
  try {
    await firstFrame;
    const done = [];
    for (const step of spec.split(';')) {
      const o = /^orbit:(\d+)$/.exec(step);
      if (o) { done.push(await selftestOrbit(Number(o[1]))); continue; }
      const m = /^(click|drag):(-?\d+),(-?\d+)$/.exec(step);
      if (!m) throw new Error('unknown step ' + step);
      done.push(await (m[1] === 'click' ? selftestClick : selftestDrag)(Number(m[2]), Number(m[3])));
    }
    const r = $('selftest-result');
    if (!r.dataset.status) {
      r.dataset.status = 'ok';
      r.textContent = 'selftest ok: ' + done.join('; ');
    }
  } catch (e) {
    failSelftest(e.message);
  } finally {
    clearTimeout(timer);
  }
}

// ---- start --------------------------------------------------------------------
async function init() {
  const params = new URLSearchParams(location.search);
  try {
    const [opts, scenes] = await Promise.all([getJson('/api/options'), getJson('/api/scenes')]);
    optionTable = opts.options;
    applicability = opts.applicability;
    const spp = document.querySelector('[data-option="spp"]');
    for (const n of opts.sppValues) spp.append(new Option(String(n), String(n)));
    for (const s of scenes.scenes) $('scene').append(new Option(s, s));
    readUrl(params, scenes.scenes);
    $('scene').value = state.scene;
    writeControls();
    bindEvents();
    updateApplicability();
    if (params.get('selftest')) runSelftest(params.get('selftest'));
    if (!state.scene) { setStatus('no scene: start rastray serve with a scene or --root', true); return; }
    await loadScene(!!state.camera || state.cameraIndex !== null);
    readControls();
    requestFrame(false);
  } catch (e) {
    setStatus(e.message, true);
    failSelftest('start: ' + e.message);
  }
}

init();

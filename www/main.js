// The demo: a program in the expression language (typed, or loaded from the scene gallery) meshed
// by two methods side by side, EMC on the left and DMC on the right by default, with their numbers.
// The page keeps its state (local storage, and the address bar as a link to share), re-meshes as
// you type, and draws only when something changed.
import init, { compile, sceneNames, sceneSource, sceneBounds, languageReference } from './pkg/isoforge.js';
import * as THREE from 'three';
import { Editor } from './editor.js';
import { Pane } from './pane.js';
import * as session from './session.js';
import { showReference } from './reference.js';

const $ = (id) => document.getElementById(id);
const DEFAULT_SCENE = 'cube_minus_sphere';
/** Options kept in the session and the link, by input id. */
const FIELDS = ['bounds', 'res', 'theta', 'phi', 'tol', 'depth', 'decimate', 'decimate-error', 'smooth'];
const CHECKS = ['auto-bounds', 'live', 'wireframe', 'features', 'normals', 'bad'];

await init();

/** The views to draw at the next frame (a set while one is asked for, else null). */
let toDraw = null;
/**
 * Draws `pane`'s view at the next frame, or every view (the shared camera moved), once however
 * many changes asked. A mesh arriving in one pane redraws that pane alone: in a browser drawing
 * WebGL on the CPU (no GPU, as in headless Chromium) a frame of both 64-cell gears holds the
 * main thread for over 100 ms, and with it the other pane's mesh arriving from its worker.
 */
const requestRender = (pane) => {
  if (!toDraw) {
    toDraw = new Set();
    requestAnimationFrame(() => {
      const drawing = toDraw;
      toDraw = null;
      for (const p of panes) if (drawing.has(p)) p.render();
    });
  }
  for (const p of pane ? [pane] : panes) toDraw.add(p);
};

let scene = null;
let liveTimer = 0;
const editor = new Editor($('source'), $('editor-error'), compile, () => {
  scene = null;
  remember();
  if ($('live').checked) {
    clearTimeout(liveTimer);
    liveTimer = setTimeout(() => { if (!editor.check()) run(); }, 500);
  }
});
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
const target = new THREE.Vector3();
const fileName = () => scene ?? 'isoforge-program';
const panes = [['emc', 0x4f86c6], ['dmc', 0x5c9e6e]].map(([method, color]) => {
  const root = $('pane-template').content.firstElementChild.cloneNode(true);
  root.dataset.side = method === 'emc' ? 'left' : 'right';
  $('panes').append(root);
  const onWayOut = (res) => { $('res').value = String(res); syncSlider(); run(); };
  return new Pane(root, { camera, target, method, color, onChange: requestRender, onWayOut, fileName });
});

/** Points the shared camera at the box `lo`..`hi` (THREE.Vector3s) from the usual side. */
function frame(lo, hi) {
  target.copy(lo).add(hi).multiplyScalar(0.5);
  const r = Math.max(hi.distanceTo(lo) / 2, 1e-3);
  camera.position.copy(target).add(new THREE.Vector3(0.75, 0.55, 0.9).multiplyScalar(r * 1.6));
  camera.near = r / 100;
  camera.far = r * 20;
  for (const p of panes) p.controls.update();
  requestRender();
}

const frameBounds = (b) => frame(new THREE.Vector3(b[0], b[1], b[2]), new THREE.Vector3(b[3], b[4], b[5]));

/** Frames what the panes show (or the bounds, before anything is shown). */
function fitView() {
  const box = new THREE.Box3();
  for (const p of panes) { const b = p.box(); if (b) box.union(b); }
  if (box.isEmpty()) frameBounds(readBounds() ?? [-1, -1, -1, 1, 1, 1]);
  else frame(box.min, box.max);
}

/** The bounds field as six numbers with each low below its high, or null. */
function readBounds() {
  const b = $('bounds').value.trim().split(/[\s,]+/).map(Number);
  const ok = b.length === 6 && b.every(Number.isFinite) && b[0] < b[3] && b[1] < b[4] && b[2] < b[5];
  return ok ? b : null;
}

const showBounds = (b) => { $('bounds').value = b.map((v) => +v.toPrecision(4)).join(' '); };

/** Fits the bounds field to the program's inside; returns an error message or null. */
function fitBounds() {
  let shape;
  try {
    shape = compile(editor.text);
    showBounds(shape.autoBounds());
    return null;
  } catch (e) {
    return String(e.message ?? e);
  } finally {
    shape?.free();
  }
}

/** Options for one pane's method: grid methods take a resolution, DMC a tolerance and depth. */
function options(method, bounds) {
  // The error numbers come after the mesh is shown (Pane.measure), not with it.
  const target = Number($('decimate').value);
  const passes = Math.min(100, Math.floor(Number($('smooth').value)));
  // Quads would be broken up by decimation and smoothing, which the library refuses for them.
  const common = { bounds };
  if (method !== 'quad') {
    if (target >= 1) common.decimate = Math.floor(target);
    const bound = Number($('decimate-error').value);
    if (target >= 1 && bound > 0) common.decimateError = bound;
    if (passes >= 1) common.smooth = passes;
  }
  if (method === 'dmc') {
    return { ...common, tolerance: Number($('tol').value), maxDepth: Number($('depth').value) };
  }
  const grid = { ...common, res: Number($('res').value) };
  if (method === 'emc') return { ...grid, thetaSharp: Number($('theta').value), phiCorner: Number($('phi').value) };
  return grid;
}

function setStatus(state, text) {
  $('status').textContent = text;
  $('status').dataset.state = state;
}

async function run(event) {
  event?.preventDefault();
  clearTimeout(liveTimer);
  if (editor.check()) {
    setStatus('error', 'fix the program first');
    return;
  }
  let note = '';
  if ($('auto-bounds').checked) {
    const before = $('bounds').value;
    const error = fitBounds();
    if (error) note = `bounds not fitted: ${error}`;
    else if ($('bounds').value !== before) frameBounds(readBounds());
  }
  const bounds = readBounds();
  if (!bounds) {
    setStatus('error', 'bounds: give six numbers x0 y0 z0 x1 y1 z1, each low below its high');
    return;
  }
  remember();
  setStatus('busy', 'meshing…');
  await Promise.all(panes.map((p) => p.mesh(editor.text, options(p.method, bounds))));
  // After every picture is up, not as each arrives (Pane.measureShown says why).
  for (const p of panes) p.measureShown();
  if (panes.every((p) => p.root.dataset.state !== 'busy')) setStatus(note ? 'error' : 'done', note);
}

function stop() {
  clearTimeout(liveTimer);
  for (const p of panes) p.cancel();
}

/** The page's state, as saved and shared. */
function collect() {
  const s = { program: editor.text, scene, methods: panes.map((p) => p.method) };
  for (const id of FIELDS) s[id] = $(id).value;
  for (const id of CHECKS) s[id] = $(id).checked;
  return s;
}

/** Saves the state and puts it in the address bar (replacing, so Back still leaves the page). */
function remember() {
  const s = collect();
  session.save(s);
  history.replaceState(null, '', session.shareUrl(s));
}

function apply(s) {
  for (const id of FIELDS) if (typeof s[id] === 'string') $(id).value = s[id];
  for (const id of CHECKS) if (typeof s[id] === 'boolean') $(id).checked = s[id];
  (s.methods ?? []).forEach((m, i) => { if (panes[i] && [...panes[i].methodSelect.options].some((o) => o.value === m)) panes[i].methodSelect.value = m; });
  scene = typeof s.scene === 'string' && sceneNames().includes(s.scene) ? s.scene : null;
  editor.text = s.program;
  for (const p of panes) for (const name of ['wireframe', 'features', 'normals', 'bad']) p.toggle(name, $(name).checked);
  syncSlider();
  showAngles();
  markGallery();
}

function markGallery() {
  for (const b of $('gallery').children) b.setAttribute('aria-pressed', String(b.dataset.scene === scene));
}

/** Loads a gallery scene: its program (undoable in the editor), its bounds, and a view of them. */
function load(name) {
  scene = name;
  markGallery();
  const bounds = sceneBounds(name);
  showBounds(bounds);
  $('auto-bounds').checked = false;
  editor.replace(sceneSource(name));
  frameBounds(bounds);
  run();
}

/** Sliders follow their number fields (the fields are what the options read). */
const syncSlider = () => {
  $('res-slider').value = $('res').value;
  $('depth-slider').value = $('depth').value;
};

/** The angles the cosines θ and φ stand for, beside them and on their sliders (in degrees). */
function showAngles() {
  for (const id of ['theta', 'phi']) {
    const c = Number($(id).value);
    const degrees = (Math.acos(c) * 180) / Math.PI;
    $(`${id}-deg`).textContent = Math.abs(c) <= 1 ? `= ${degrees.toFixed(1)}°` : '';
    if (Math.abs(c) <= 1) $(`${id}-slider`).value = String(degrees);
  }
}

/** Re-meshes after an option changed, when live updates are on. */
function optionChanged() {
  remember();
  if ($('live').checked) {
    clearTimeout(liveTimer);
    liveTimer = setTimeout(run, 300);
  }
}

for (const name of sceneNames()) {
  const button = Object.assign(document.createElement('button'), { type: 'button', textContent: name.replaceAll('_', ' ') });
  button.dataset.scene = name;
  button.addEventListener('click', () => load(name));
  $('gallery').append(button);
}
showReference($('reference-list'), languageReference(), (text) => {
  const t = $('source');
  t.focus();
  document.execCommand('insertText', false, text);
});
$('controls').addEventListener('submit', run);
$('stop').addEventListener('click', stop);
$('fit-view').addEventListener('click', fitView);
$('fit-bounds').addEventListener('click', () => {
  const error = fitBounds();
  if (error) { setStatus('error', error); return; }
  frameBounds(readBounds());
  optionChanged();
});
$('share').addEventListener('click', async () => {
  remember();
  const url = location.href;
  Object.assign($('share-url'), { value: url, hidden: false }).select();
  try {
    await navigator.clipboard.writeText(url);
    setStatus('done', 'link copied');
  } catch {
    setStatus('done', 'copy the link above');
  }
});
for (const id of ['res', 'depth']) {
  $(`${id}-slider`).addEventListener('input', () => { $(id).value = $(`${id}-slider`).value; });
  $(`${id}-slider`).addEventListener('change', optionChanged);
}
// Angle sliders in degrees set the cosine fields.
for (const id of ['theta', 'phi']) {
  $(`${id}-slider`).addEventListener('input', () => {
    $(id).value = Math.cos((Number($(`${id}-slider`).value) * Math.PI) / 180).toFixed(3);
    showAngles();
  });
  $(`${id}-slider`).addEventListener('change', optionChanged);
}
for (const id of FIELDS) {
  $(id).addEventListener('change', () => { syncSlider(); showAngles(); optionChanged(); });
}
for (const id of ['theta', 'phi']) $(id).addEventListener('input', showAngles);
$('auto-bounds').addEventListener('change', optionChanged);
$('live').addEventListener('change', remember);
for (const p of panes) p.methodSelect.addEventListener('change', () => { remember(); run(); });
for (const name of ['wireframe', 'features', 'normals', 'bad']) {
  $(name).addEventListener('change', (e) => { for (const p of panes) p.toggle(name, e.target.checked); remember(); });
}
document.addEventListener('keydown', (e) => {
  if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) run(e);
  else if (e.key === 'Escape') stop();
  else if ((e.key === 'f' || e.key === 'F') && !e.ctrlKey && !e.metaKey && !(e.target instanceof HTMLInputElement || e.target instanceof HTMLTextAreaElement)) fitView();
});
matchMedia('(prefers-color-scheme: dark)').addEventListener('change', () => requestRender());

showAngles();
// A link wins over the last visit; a first visit gets the default scene.
const start = session.fromHash(location.hash) ?? session.restore();
if (start) {
  apply(start);
  const b = readBounds();
  if (b) frameBounds(b);
  run();
} else {
  load(DEFAULT_SCENE);
}

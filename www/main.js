// The demo: a program in the expression language (typed, or loaded from the scene gallery) meshed
// by two methods side by side, EMC on the left and DMC on the right by default, with their numbers.
import init, { compile, sceneNames, sceneSource, sceneBounds } from './pkg/isoforge.js';
import * as THREE from 'three';
import { Editor } from './editor.js';
import { Pane } from './pane.js';

const $ = (id) => document.getElementById(id);

await init();
const editor = new Editor($('source'), $('editor-error'), compile);
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
const target = new THREE.Vector3();
const panes = [['emc', 0x4f86c6], ['dmc', 0x5c9e6e]].map(([method, color]) => {
  const root = $('pane-template').content.firstElementChild.cloneNode(true);
  root.dataset.side = method === 'emc' ? 'left' : 'right';
  $('panes').append(root);
  return new Pane(root, { camera, target, method, color });
});
const render = () => {
  for (const p of panes) { p.controls.update(); p.render(); }
};
let bounds = [-1, -1, -1, 1, 1, 1];

function frame(b) {
  const lo = new THREE.Vector3(b[0], b[1], b[2]);
  const hi = new THREE.Vector3(b[3], b[4], b[5]);
  target.copy(lo).add(hi).multiplyScalar(0.5);
  const r = hi.distanceTo(lo) / 2;
  camera.position.copy(target).add(new THREE.Vector3(0.75, 0.55, 0.9).multiplyScalar(r * 1.6));
  camera.near = r / 100;
  camera.far = r * 20;
}

/** Options for one pane's method: grid methods take a resolution, DMC a tolerance and depth. */
function options(method) {
  const common = { bounds, surfaceError: true };
  if (method === 'dmc') {
    return { ...common, tolerance: Number($('tol').value), maxDepth: Number($('depth').value) };
  }
  const grid = { ...common, res: Number($('res').value) };
  if (method === 'emc') return { ...grid, thetaSharp: Number($('theta').value), phiCorner: Number($('phi').value) };
  return grid;
}

async function run(event) {
  event?.preventDefault();
  const status = $('status');
  if (editor.check()) {
    status.textContent = 'fix the program first';
    status.dataset.state = 'error';
    return;
  }
  status.textContent = 'meshing…';
  status.dataset.state = 'busy';
  await Promise.all(panes.map((p) => p.mesh(editor.text, options(p.method))));
  if (panes.every((p) => p.root.dataset.state !== 'busy')) {
    status.textContent = '';
    status.dataset.state = 'done';
  }
}

function load(name) {
  for (const b of $('gallery').children) b.setAttribute('aria-pressed', String(b.dataset.scene === name));
  bounds = sceneBounds(name);
  editor.text = sceneSource(name);
  frame(bounds);
  run();
}

for (const name of sceneNames()) {
  const button = Object.assign(document.createElement('button'), { type: 'button', textContent: name.replaceAll('_', ' ') });
  button.dataset.scene = name;
  button.addEventListener('click', () => load(name));
  $('gallery').append(button);
}
$('controls').addEventListener('submit', run);
$('source').addEventListener('keydown', (e) => {
  if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) run(e);
});
for (const p of panes) p.methodSelect.addEventListener('change', () => p.mesh(editor.text, options(p.method)));
for (const name of ['wireframe', 'features', 'normals']) {
  $(name).addEventListener('change', (e) => { for (const p of panes) p.toggle(name, e.target.checked); render(); });
}
new ResizeObserver(render).observe($('panes'));
// Draw every frame while anything may change (results arrive asynchronously); cheap for two views.
const loop = () => { render(); requestAnimationFrame(loop); };
requestAnimationFrame(loop);
load('cube_minus_sphere');

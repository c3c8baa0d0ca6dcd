// The demo page: mesh a built-in scene (or its program, edited) with the wasm library and draw it
// with three.js, feature lines found by EMC included.
import init, { meshScene, meshExpr, sceneNames, sceneSource, sceneBounds } from './pkg/isoforge.js';
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const $ = (id) => document.getElementById(id);
const viewport = $('viewport');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
viewport.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f5f7);
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
camera.position.set(2.2, 1.6, 2.6);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(3, 5, 4);
scene.add(sun);
const material = new THREE.MeshStandardMaterial({ color: 0x4f86c6, flatShading: true, roughness: 0.55, metalness: 0.05,
  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
const featureMaterial = new THREE.LineBasicMaterial({ color: 0xd9480f });
let meshObject = null;
let featureObject = null;
// The scene's program as loaded; when the editor holds something else, that is meshed instead.
let loadedSource = '';

function resize() {
  const { clientWidth: w, clientHeight: h } = viewport;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
new ResizeObserver(resize).observe(viewport);
renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene, camera); });

function show(result) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(result.positions, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(result.normals, 3));
  geometry.setIndex(new THREE.BufferAttribute(result.indices, 1));
  if (meshObject) { meshObject.geometry.dispose(); scene.remove(meshObject); }
  meshObject = new THREE.Mesh(geometry, material);
  scene.add(meshObject);
  if (featureObject) { featureObject.geometry.dispose(); scene.remove(featureObject); featureObject = null; }
  if (result.featureEdges.length > 0) {
    const lines = new THREE.BufferGeometry();
    lines.setAttribute('position', geometry.getAttribute('position'));
    lines.setIndex(new THREE.BufferAttribute(result.featureEdges, 1));
    featureObject = new THREE.LineSegments(lines, featureMaterial);
    scene.add(featureObject);
  }
}

const fmt = (v, digits = 3) => v === null || v === undefined ? '—'
  : typeof v === 'boolean' ? (v ? 'yes' : 'no')
  : Number.isInteger(v) ? v.toLocaleString('en') : Number(v).toPrecision(digits);

function showStats(s) {
  const rows = [
    ['triangles', s.triangles], ['vertices', s.vertices], ['closed manifold', s.closed_manifold],
    ['Euler characteristic', s.euler], ['genus', s.genus], ['components', s.components],
    ['smallest angle (°)', s.min_angle_deg], ['largest angle (°)', s.max_angle_deg],
    ['max distance', s.dist_max], ['RMS distance', s.dist_rms],
    ['normal deviation p95 (°)', s.normal_dev_deg_p95],
    ['feature edges', s.feature_edges],
    ['meshing (ms)', s.ms_total],
    ...Object.entries(s.phases_ms).map(([k, v]) => [`  ${k} (ms)`, v]),
  ];
  $('stats').replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    tr.dataset.key = k;
    tr.innerHTML = `<td>${k}</td><td>${fmt(v)}</td>`;
    return tr;
  }));
}

function run(event) {
  event?.preventDefault();
  const status = $('status');
  status.className = '';
  status.textContent = 'meshing…';
  // Let the status paint before the (synchronous) meshing call.
  requestAnimationFrame(() => setTimeout(() => {
    try {
      const options = { method: $('method').value, res: Number($('res').value), topology: $('topology').value };
      const text = $('source').value;
      const name = $('scene').value;
      // An edited program is meshed in the bounds of the scene it started from.
      const result = text === loadedSource ? meshScene(name, options)
        : meshExpr(text, { ...options, bounds: sceneBounds(name) });
      show(result);
      showStats(result.stats);
      status.textContent = `${result.stats.triangles.toLocaleString('en')} triangles in ${result.stats.ms_total.toFixed(1)} ms`;
      status.dataset.state = 'done';
    } catch (e) {
      status.className = 'error';
      status.textContent = String(e.message ?? e);
      status.dataset.state = 'error';
    }
  }));
}

function loadSource() {
  loadedSource = sceneSource($('scene').value);
  $('source').value = loadedSource;
}

await init();
for (const name of sceneNames()) $('scene').add(new Option(name, name));
$('scene').value = 'cube_minus_sphere';
loadSource();
$('controls').addEventListener('submit', run);
$('scene').addEventListener('change', () => { loadSource(); run(); });
$('source').addEventListener('keydown', (e) => {
  if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) run(e);
});
$('wireframe').addEventListener('change', (e) => { material.wireframe = e.target.checked; });
resize();
run();

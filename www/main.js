// The demo page: mesh a built-in scene with the wasm library and draw it with three.js.
import init, { meshScene, sceneNames } from './pkg/isoforge.js';
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
const material = new THREE.MeshStandardMaterial({ color: 0x4f86c6, flatShading: true, roughness: 0.55, metalness: 0.05 });
let meshObject = null;

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
      const result = meshScene($('scene').value, {
        method: $('method').value,
        res: Number($('res').value),
        topology: $('topology').value,
      });
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

await init();
for (const name of sceneNames()) $('scene').add(new Option(name, name));
$('scene').value = 'cube_minus_sphere';
$('controls').addEventListener('submit', run);
$('scene').addEventListener('change', run);
$('wireframe').addEventListener('change', (e) => { material.wireframe = e.target.checked; });
resize();
run();

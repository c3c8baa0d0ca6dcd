// What an npm user writes: the package by its name, three.js beside it, bundled by Vite.
import init, { meshScene } from 'isoforge';
import { createMesher } from 'isoforge/mesher';
import { toBufferGeometry } from 'isoforge/three';
import * as THREE from 'three';

try {
  await init();
  const result = meshScene('torus', { method: 'emc', res: 32 });
  // The package's subpath export: a BufferGeometry wrapping the result's arrays.
  const geometry = toBufferGeometry(result);

  const canvas = document.getElementById('view');
  // preserveDrawingBuffer: the test reads the pixels back after the frame is shown.
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  scene.add(new THREE.Mesh(geometry, new THREE.MeshNormalMaterial({ flatShading: true })));
  const { center, radius } = geometry.boundingSphere;
  const camera = new THREE.PerspectiveCamera(45, canvas.width / canvas.height, radius / 10, radius * 10);
  camera.position.copy(center).add(new THREE.Vector3(1, 0.8, 1.4).setLength(radius * 3));
  camera.lookAt(center);
  renderer.render(scene, camera);
  document.getElementById('triangles').textContent = String(result.stats.triangles);
} catch (e) {
  document.getElementById('error').textContent = `failed: ${e.message}`;
  throw e;
}

// The worker helper: the same request meshed off the main thread (so its worker script must
// survive bundling). Same request, same mesh: the test compares the triangle counts.
const worker = document.getElementById('worker');
createMesher().meshScene('torus', { method: 'emc', res: 32 }).then(
  (r) => { worker.textContent = String(r.stats.triangles); },
  (e) => { worker.textContent = `failed: ${e.message}`; },
);

// What an npm user writes: the package by its name, three.js beside it, bundled by Vite.
import init, { meshScene } from 'isoforge';
import * as THREE from 'three';

try {
  await init();
  const { positions, normals, indices, stats } = meshScene('torus', { method: 'emc', res: 32 });
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(normals, 3));
  geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  geometry.computeBoundingSphere();

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
  document.getElementById('triangles').textContent = String(stats.triangles);
} catch (e) {
  document.getElementById('error').textContent = `failed: ${e.message}`;
  throw e;
}

// One side of the comparison: a method picker, a three.js view, and the numbers of the last mesh.
// Each pane meshes in its own worker (createMesher), so the two sides run in parallel and a new
// request cancels only what is stale.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { createMesher } from './pkg/mesher.js';
import { toBufferGeometry, featureLines, normalLines } from './pkg/three.js';
import { drawHistogram, statsRows } from './numbers.js';

const MATERIAL = { flatShading: true, roughness: 0.55, metalness: 0.05, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 };

export class Pane {
  /** `camera` and `target` are shared by all panes: orbiting one view moves the others. */
  constructor(root, { camera, target, method, color }) {
    this.root = root;
    this.camera = camera;
    this.methodSelect = root.querySelector('.method');
    this.methodSelect.value = method;
    this.view = root.querySelector('.view');
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.view.prepend(this.renderer.domElement);
    this.controls = new OrbitControls(camera, this.renderer.domElement);
    this.controls.target = target;
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xf4f5f7);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(3, 5, 4);
    this.scene.add(sun);
    this.material = new THREE.MeshStandardMaterial({ color, ...MATERIAL });
    this.objects = [];
    this.result = null;
    this.mesher = createMesher();
    this.show = { wireframe: false, features: true, normals: false };
    root.querySelector('.download').addEventListener('click', () => this.download());
    new ResizeObserver(() => this.resize()).observe(this.view);
  }

  get method() {
    return this.methodSelect.value;
  }

  resize() {
    const { clientWidth: w, clientHeight: h } = this.view;
    this.renderer.setSize(w, h, false);
  }

  render() {
    const { clientWidth: w, clientHeight: h } = this.view;
    this.camera.aspect = w / Math.max(h, 1);
    this.camera.updateProjectionMatrix();
    this.renderer.render(this.scene, this.camera);
  }

  setState(state, text) {
    this.root.dataset.state = state;
    const el = this.root.querySelector('.state');
    el.textContent = text;
    el.className = `state ${state}`;
  }

  /** Meshes `text` with this pane's method; a newer call cancels this one (its promise then resolves quietly). */
  async mesh(text, options) {
    this.mesher.cancel();
    const started = performance.now();
    const busy = this.root.querySelector('.progress');
    busy.hidden = false;
    const tick = setInterval(() => {
      busy.querySelector('.elapsed').textContent = `${((performance.now() - started) / 1000).toFixed(1)} s`;
    }, 100);
    this.setState('busy', 'meshing…');
    try {
      const result = await this.mesher.meshExpr(text, { ...options, method: this.method });
      this.display(result);
      this.setState('done', `${result.stats.triangles.toLocaleString('en')} triangles, ${result.stats.ms_total.toFixed(0)} ms`);
    } catch (e) {
      if (e.name === 'AbortError') return;
      this.setState('error', e.message);
    } finally {
      clearInterval(tick);
      if (this.root.dataset.state !== 'busy') busy.hidden = true;
    }
  }

  display(result) {
    for (const o of this.objects) { o.geometry.dispose(); this.scene.remove(o); }
    this.result = result;
    const geometry = toBufferGeometry(result);
    const mesh = new THREE.Mesh(geometry, this.material);
    const lines = featureLines(result, geometry);
    const size = geometry.boundingSphere?.radius ?? 1;
    const normals = normalLines(result, 0.03 * size);
    this.objects = [mesh, ...(lines ? [lines] : []), normals];
    this.scene.add(...this.objects);
    this.features = lines;
    this.normals = normals;
    this.applyToggles();
    this.root.querySelector('.stats').replaceChildren(...statsRows(result.stats));
    drawHistogram(this.root.querySelector('.histogram'), result.stats.angle_histogram_5deg);
    this.root.querySelector('.download').disabled = false;
  }

  toggle(name, on) {
    this.show[name] = on;
    this.applyToggles();
  }

  applyToggles() {
    this.material.wireframe = this.show.wireframe;
    if (this.features) this.features.visible = this.show.features;
    if (this.normals) this.normals.visible = this.show.normals;
  }

  async download() {
    if (!this.result) return;
    const format = this.root.querySelector('.format').value;
    try {
      const bytes = await this.mesher.exportMesh(this.result, format);
      const url = URL.createObjectURL(new Blob([bytes], { type: 'application/octet-stream' }));
      const a = Object.assign(document.createElement('a'), { href: url, download: `isoforge-${this.method}.${format}` });
      a.click();
      setTimeout(() => URL.revokeObjectURL(url), 1000);
    } catch (e) {
      if (e.name !== 'AbortError') this.setState('error', e.message);
    }
  }
}

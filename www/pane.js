// One side of the comparison: a method picker, a three.js view, and the numbers of the last mesh.
// Each pane meshes in its own warm worker (createMesher), so the two sides run in parallel and a
// new request cancels only what is stale. Views draw only when asked (`onChange`): the page is
// idle, and costs nothing, while nobody touches it.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { exportMesh } from './pkg/isoforge.js';
import { createMesher } from './pkg/mesher.js';
import { toBufferGeometry, featureLines, normalLines } from './pkg/three.js';
import { drawHistogram, statsRows } from './numbers.js';
import { badTriangles } from './bad.js';

const MATERIAL = { flatShading: true, roughness: 0.55, metalness: 0.05, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 };
const BAD = { sliver: 0xe03131, edge: 0xf08c00, crossing: 0x9c36b5 };

/** `{ cells, maxCells }` from a too-large error's message, or null. */
export function tooLarge(message) {
  const m = /grid of (\d+) cells is larger than the limit of (\d+) cells/.exec(message);
  return m ? { cells: Number(m[1]), maxCells: Number(m[2]) } : null;
}

export class Pane {
  /**
   * `camera` and `target` are shared by all panes: orbiting one view moves the others.
   * `onChange(pane)` asks for a redraw of `pane`, `onChange()` of every view; `onWayOut(res)`
   * re-meshes at a resolution that fits.
   */
  constructor(root, { camera, target, method, color, onChange, onWayOut, fileName }) {
    this.root = root;
    this.camera = camera;
    this.onChange = () => onChange(this);
    this.fileName = fileName;
    this.methodSelect = root.querySelector('.method');
    this.methodSelect.value = method;
    this.view = root.querySelector('.view');
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.view.prepend(this.renderer.domElement);
    this.controls = new OrbitControls(camera, this.renderer.domElement);
    this.controls.target = target;
    this.controls.addEventListener('change', () => onChange());
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(3, 5, 4);
    this.scene.add(sun);
    this.material = new THREE.MeshStandardMaterial({ color, ...MATERIAL });
    this.objects = [];
    this.result = null;
    this.mesher = createMesher();
    this.show = { wireframe: false, features: true, normals: false, bad: false };
    this.wayOut = root.querySelector('.way-out');
    this.wayOut.addEventListener('click', () => onWayOut(Number(this.wayOut.dataset.res)));
    root.querySelector('.download').addEventListener('click', () => this.download());
    root.querySelector('.cancel').addEventListener('click', () => this.cancel());
    new ResizeObserver(() => { this.resize(); this.onChange(); }).observe(this.view);
  }

  get method() {
    return this.methodSelect.value;
  }

  resize() {
    const { clientWidth: w, clientHeight: h } = this.view;
    this.renderer.setSize(w, h, false);
  }

  /** Draws the view once, in the page's colours (light or dark). */
  render() {
    const { clientWidth: w, clientHeight: h } = this.view;
    this.scene.background = new THREE.Color(getComputedStyle(this.view).getPropertyValue('--view-bg').trim() || '#f4f5f7');
    this.camera.aspect = w / Math.max(h, 1);
    this.camera.updateProjectionMatrix();
    this.renderer.render(this.scene, this.camera);
    this.root.dataset.frames = String(Number(this.root.dataset.frames ?? 0) + 1);
  }

  setState(state, text) {
    this.root.dataset.state = state;
    const el = this.root.querySelector('.state');
    el.textContent = text;
    el.className = `state ${state}`;
  }

  /** Stops this pane's meshing; the last mesh stays. */
  cancel() {
    this.mesher.cancel();
  }

  /** Meshes `text` with this pane's method; a newer call cancels this one (its promise then resolves quietly). */
  async mesh(text, options) {
    this.mesher.cancel();
    const call = Symbol('mesh');
    this.call = call;
    const started = performance.now();
    const busy = this.root.querySelector('.progress');
    const bar = busy.querySelector('progress');
    bar.removeAttribute('value');
    busy.hidden = false;
    this.wayOut.hidden = true;
    const tick = setInterval(() => {
      busy.querySelector('.elapsed').textContent = `${((performance.now() - started) / 1000).toFixed(1)} s`;
    }, 100);
    this.setState('busy', 'meshing…');
    const onProgress = ({ phase, fraction }) => {
      bar.value = fraction;
      busy.querySelector('.phase').textContent = phase;
    };
    let result;
    try {
      result = await this.mesher.meshExpr(text, { ...options, method: this.method }, { onProgress });
      this.display(result);
      this.setState('done', `${result.stats.triangles.toLocaleString('en')} triangles, ${result.stats.ms_total.toFixed(0)} ms`);
    } catch (e) {
      if (e.name === 'AbortError') {
        if (this.call === call) this.setState('stopped', 'stopped; the last mesh is still shown');
        return;
      }
      this.fail(e.message, options);
    } finally {
      clearInterval(tick);
      if (this.call === call) busy.hidden = true;
    }
    if (result && this.call === call) {
      this.root.dataset.measured = 'pending';
      this.unmeasured = { text, result, call };
    }
  }

  /**
   * Measures the mesh shown (its distance and normal error against the program, and the
   * triangles that cross). The page calls it once every pane shows its mesh: the numbers cost as
   * much as meshing, and on a machine with few cores one pane's numbers would hold up the other
   * pane's picture. `data-measured` is "pending" from the mesh's arrival until they are in, then "yes".
   */
  async measureShown() {
    const job = this.unmeasured;
    this.unmeasured = null;
    if (!job || this.call !== job.call) return;
    const { text, result, call } = job;
    try {
      const measured = await this.mesher.analyzeMesh(result, { expr: text, checkIntersections: true });
      if (this.call !== call) return;
      const { self_intersecting_pairs: pairs, ...numbers } = measured;
      Object.assign(result.stats, numbers, { ms_analysis: result.stats.ms_analysis + numbers.ms_analysis });
      this.crossing = pairs;
      this.root.querySelector('.stats').replaceChildren(...statsRows(result.stats));
      if (this.bad) this.refreshBad();
      this.root.dataset.measured = 'yes';
    } catch (e) {
      // A newer request cancelled it: that one measures its own mesh.
      if (e.name !== 'AbortError' && this.call === call) this.root.dataset.measured = `failed: ${e.message}`;
    }
  }

  /** Shows an error in place of the mesh (an old mesh left up would pass for the answer). */
  fail(message, options = {}) {
    this.clear();
    const big = tooLarge(message);
    if (big && options.res) {
      const res = Math.floor(options.res * Math.cbrt(big.maxCells / big.cells));
      this.setState('error', `${options.res} cells per side is ${big.cells.toLocaleString('en')} cells, more than this page meshes (${big.maxCells.toLocaleString('en')}).`);
      this.wayOut.textContent = `Mesh at ${res}`;
      this.wayOut.dataset.res = String(res);
      this.wayOut.hidden = false;
    } else {
      this.setState('error', message);
    }
  }

  clear() {
    for (const o of this.objects) { o.geometry.dispose(); this.scene.remove(o); }
    this.objects = [];
    this.result = null;
    this.features = this.normals = this.bad = this.crossing = null;
    this.root.querySelector('.stats').replaceChildren();
    drawHistogram(this.root.querySelector('.histogram'), null);
    this.root.querySelector('.download').disabled = true;
    this.onChange();
  }

  display(result) {
    this.clear();
    this.result = result;
    const geometry = toBufferGeometry(result);
    const mesh = new THREE.Mesh(geometry, this.material);
    const lines = featureLines(result, geometry);
    const size = geometry.boundingSphere?.radius ?? 1;
    this.normals = normalLines(result, 0.03 * size);
    this.features = lines;
    this.objects = [mesh, ...(lines ? [lines] : []), this.normals];
    this.scene.add(...this.objects);
    this.applyToggles();
    this.root.querySelector('.stats').replaceChildren(...statsRows(result.stats));
    drawHistogram(this.root.querySelector('.histogram'), result.stats.angle_histogram_5deg);
    this.root.querySelector('.download').disabled = false;
    this.onChange();
  }

  /** The box of the mesh shown, or null. */
  box() {
    const mesh = this.objects[0];
    if (!mesh) return null;
    mesh.geometry.computeBoundingBox();
    return mesh.geometry.boundingBox;
  }

  toggle(name, on) {
    this.show[name] = on;
    this.applyToggles();
    this.onChange();
  }

  applyToggles() {
    this.material.wireframe = this.show.wireframe;
    if (this.features) this.features.visible = this.show.features;
    if (this.normals) this.normals.visible = this.show.normals;
    if (this.show.bad && !this.bad && this.result) this.addBad();
    if (this.bad) for (const o of this.bad) o.visible = this.show.bad;
  }

  /**
   * Overlays slivers (red), open or non-manifold edges (orange) and, once the mesh is measured,
   * triangles that cross another (purple), counted in `data-bad` (`crossing` is null until then).
   */
  addBad() {
    const found = badTriangles(this.result, this.crossing);
    const position = this.objects[0].geometry.getAttribute('position');
    const faces = (indices) => {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', position);
      geometry.setIndex(new THREE.BufferAttribute(indices, 1));
      return geometry;
    };
    const edges = faces(Uint32Array.from([...found.openEdges, ...found.nonManifoldEdges]));
    this.bad = [
      new THREE.Mesh(faces(found.slivers), new THREE.MeshBasicMaterial({ color: BAD.sliver, side: THREE.DoubleSide })),
      new THREE.Mesh(faces(found.crossing), new THREE.MeshBasicMaterial({ color: BAD.crossing, side: THREE.DoubleSide })),
      new THREE.LineSegments(edges, new THREE.LineBasicMaterial({ color: BAD.edge })),
    ];
    this.objects.push(...this.bad);
    this.scene.add(...this.bad);
    this.root.dataset.bad = JSON.stringify({
      slivers: found.slivers.length / 3, openEdges: found.openEdges.length / 2, nonManifoldEdges: found.nonManifoldEdges.length / 2,
      crossing: this.crossing ? found.crossing.length / 3 : null,
    });
  }

  /** Rebuilds the overlay (the crossing triangles came in after it was drawn). */
  refreshBad() {
    for (const o of this.bad) {
      o.geometry.dispose();
      this.scene.remove(o);
      this.objects.splice(this.objects.indexOf(o), 1);
    }
    this.bad = null;
    this.applyToggles();
    this.onChange();
  }

  /** Saves the mesh shown; the bytes are made here, on the main thread, in milliseconds. */
  download() {
    if (!this.result) return;
    const format = this.root.querySelector('.format').value;
    try {
      const bytes = exportMesh(this.result, format);
      const url = URL.createObjectURL(new Blob([bytes], { type: 'application/octet-stream' }));
      const a = Object.assign(document.createElement('a'), { href: url, download: `${this.fileName()}-${this.method}.${format}` });
      a.click();
      setTimeout(() => URL.revokeObjectURL(url), 1000);
    } catch (e) {
      this.setState('error', e.message);
    }
  }
}

// The built package without a bundler: imported by a plain page's <script type="module"> (its
// relative imports and the wasm file must resolve from the files alone), the npm README's three.js
// example run as written under an import map, and exportMesh's GLB read by three.js's own
// GLTFLoader. Needs pkg/ built and the dev node_modules (three) installed by scripts/setup.sh.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { serve, launch, canvasColours } from '../../scripts/browser.mjs';

let server;
let browser;

before(async () => {
  assert.ok(existsSync('pkg/isoforge.js'), 'pkg/ is not built: run scripts/build-wasm.sh first');
  // The repository root, so the page reaches ../../pkg/ as it sits in the tree.
  server = await serve('.');
  browser = await launch();
});

after(async () => {
  await browser?.close();
  server?.close();
});

test('a plain module script imports pkg/isoforge.js and pkg/csg.js, meshes and exports', async () => {
  const page = await browser.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('response', (r) => r.status() >= 400 && !r.url().endsWith('/favicon.ico') && errors.push(`${r.status()} ${r.url()}`));
  await page.goto(`${server.url}tests/plain-page/index.html`);
  await page.waitForFunction(() => /^\d+$/.test(document.getElementById('glb').textContent)
    || document.getElementById('error').textContent !== '');
  assert.deepEqual(errors, []);
  assert.equal(await page.textContent('#error'), '');
  const triangles = Number(await page.textContent('#triangles'));
  const glb = Number(await page.textContent('#glb'));
  assert.ok(triangles > 0, `${triangles} triangles`);
  // At least the indices and the positions of a third as many vertices as triangles.
  assert.ok(glb > 12 * triangles + 4 * triangles, `${glb} GLB bytes for ${triangles} triangles`);
  await page.close();
});

// Bare names resolved the way npm installs them, by an import map over the repository's files.
const IMPORTS = {
  isoforge: '/pkg/isoforge.js',
  'isoforge/three': '/pkg/three.js',
  three: '/node_modules/three/build/three.module.js',
  'three/addons/': '/node_modules/three/examples/jsm/',
};

/**
 * A page at `name` running `script` as a module under IMPORTS. `finished` resolves at the first
 * console.log (its text in `logged`) or uncaught error (in `errors`): scripts end by logging.
 */
async function modulePage(name, script) {
  const page = await browser.newPage();
  const errors = [];
  const logged = [];
  const finished = new Promise((resolve) => {
    page.on('pageerror', (e) => { errors.push(e.message); resolve(); });
    page.on('console', (m) => { if (m.type() === 'log') { logged.push(m.text()); resolve(); } });
  });
  // Read the pixels back after a frame: keep the drawing buffer of every WebGL context.
  await page.addInitScript(() => {
    const getContext = HTMLCanvasElement.prototype.getContext;
    HTMLCanvasElement.prototype.getContext = function (type, options) {
      return getContext.call(this, type, { ...options, preserveDrawingBuffer: true });
    };
  });
  const html = `<!doctype html><meta charset="utf-8"><body style="margin:0">
    <script type="importmap">${JSON.stringify({ imports: IMPORTS })}</script>
    <script type="module">${script}</script>`;
  await page.route(`${server.url}${name}`, (route) => route.fulfill({ contentType: 'text/html', body: html }));
  await page.setViewportSize({ width: 320, height: 240 });
  await page.goto(`${server.url}${name}`);
  await finished;
  return { page, errors, logged };
}

test("the npm README's three.js example runs as written and draws the mesh", async () => {
  const readme = readFileSync('pkg-config/README.md', 'utf8');
  const example = readme.match(/```js\n([\s\S]*?)```/)[1];
  assert.match(example, /from 'three'/);
  const { page, errors, logged } = await modulePage('readme-example.html', example);
  assert.deepEqual(errors, []);
  const [triangles, closed] = logged[0].split(' ');
  assert.ok(Number(triangles) > 0, logged[0]);
  assert.equal(closed, 'true', 'the example shape is a closed manifold');
  const { colours } = await canvasColours(page, 'canvas');
  assert.ok(colours > 8, `only ${colours} distinct colours: the example drew nothing`);
  await page.screenshot({ path: 'target/readme-example.png' });
  await page.close();
});

test("the README's JavaScript quick start runs as written and prints what its comment says", async () => {
  const readme = readFileSync('README.md', 'utf8');
  const quick = readme.slice(readme.indexOf('## Quick start'));
  const example = quick.match(/```js\n([\s\S]*?)```/)[1];
  const promised = /console\.log\(.*\/\/ (.*)$/m.exec(example)[1].trim();
  const { page, errors, logged } = await modulePage('readme-quick-start.html', example);
  assert.deepEqual(errors, []);
  assert.equal(logged[0], promised);
  await page.close();
});

test("three.js's own GLTFLoader reads exportMesh's GLB back to the same mesh", async () => {
  const { page, errors, logged } = await modulePage('gltf-loader.html', `
    import init, { meshScene, exportMesh } from 'isoforge';
    import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
    await init();
    const result = meshScene('rocket', { method: 'emc', res: 32, surfaceError: false });
    const gltf = await new GLTFLoader().parseAsync(exportMesh(result, 'glb').slice().buffer, '');
    const meshes = [];
    gltf.scene.traverse((o) => o.isMesh && meshes.push(o));
    const g = meshes[0].geometry;
    const same = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);
    const n = g.attributes.normal.array;
    let worst = 1;
    for (let i = 0; i < n.length; i += 3) {
      const r = result.normals;
      worst = Math.min(worst, (n[i] * r[i] + n[i + 1] * r[i + 1] + n[i + 2] * r[i + 2]) / Math.hypot(r[i], r[i + 1], r[i + 2]));
    }
    console.log(JSON.stringify({
      meshes: meshes.length, triangles: result.indices.length / 3,
      positions: same(g.attributes.position.array, result.positions),
      indices: same(g.index.array, result.indices), normalCount: g.attributes.normal.count,
      vertices: result.positions.length / 3, worstNormalDot: worst,
    }));`);
  assert.deepEqual(errors, []);
  const r = JSON.parse(logged[0]);
  assert.equal(r.meshes, 1);
  assert.ok(r.triangles > 1000, `${r.triangles} triangles`);
  assert.ok(r.positions, 'positions read back exactly');
  assert.ok(r.indices, 'indices read back exactly');
  assert.equal(r.normalCount, r.vertices);
  assert.ok(r.worstNormalDot > 0.9999, `a normal turned by acos(${r.worstNormalDot})`);
  await page.close();
});

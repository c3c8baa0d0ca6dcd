// The built package imported by a plain page's <script type="module"> (no bundler, no import map):
// its relative imports and the wasm file must resolve from the files alone. Needs pkg/ built.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { serve, launch } from '../../scripts/browser.mjs';

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

test("the npm README's three.js example runs as written and draws the mesh", async () => {
  const readme = readFileSync('pkg-config/README.md', 'utf8');
  const example = readme.match(/```js\n([\s\S]*?)```/)[1];
  assert.match(example, /from 'three'/);
  const page = await browser.newPage();
  const errors = [];
  const logged = [];
  // The example ends by logging the triangle count and closed_manifold; an error ends it too.
  const finished = new Promise((resolve) => {
    page.on('pageerror', (e) => { errors.push(e.message); resolve(); });
    page.on('console', (m) => { if (m.type() === 'log') { logged.push(m.text()); resolve(); } });
  });
  // Read the pixels back after the frame: keep the drawing buffer of every WebGL context.
  await page.addInitScript(() => {
    const getContext = HTMLCanvasElement.prototype.getContext;
    HTMLCanvasElement.prototype.getContext = function (type, options) {
      return getContext.call(this, type, { ...options, preserveDrawingBuffer: true });
    };
  });
  // The bare names resolved the way npm would install them, by an import map.
  const imports = {
    isoforge: '/pkg/isoforge.js',
    'isoforge/three': '/pkg/three.js',
    three: '/node_modules/three/build/three.module.js',
  };
  const html = `<!doctype html><meta charset="utf-8"><body style="margin:0">
    <script type="importmap">${JSON.stringify({ imports })}</script>
    <script type="module">${example}</script>`;
  await page.route(`${server.url}readme-example.html`, (route) => route.fulfill({ contentType: 'text/html', body: html }));
  await page.setViewportSize({ width: 320, height: 240 });
  await page.goto(`${server.url}readme-example.html`);
  await finished;
  assert.deepEqual(errors, []);
  const [triangles, closed] = logged[0].split(' ');
  assert.ok(Number(triangles) > 0, logged[0]);
  assert.equal(closed, 'true', 'the example shape is a closed manifold');
  const colours = await page.$eval('canvas', (src) => {
    const c = document.createElement('canvas');
    c.width = 64; c.height = 48;
    const ctx = c.getContext('2d');
    ctx.drawImage(src, 0, 0, 64, 48);
    const data = ctx.getImageData(0, 0, 64, 48).data;
    const seen = new Set();
    for (let i = 0; i < data.length; i += 4) seen.add((data[i] >> 4) << 8 | (data[i + 1] >> 4) << 4 | (data[i + 2] >> 4));
    return seen.size;
  });
  assert.ok(colours > 8, `only ${colours} distinct colours: the example drew nothing`);
  await page.screenshot({ path: 'target/readme-example.png' });
  await page.close();
});

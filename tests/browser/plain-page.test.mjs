// The built package imported by a plain page's <script type="module"> (no bundler, no import map):
// its relative imports and the wasm file must resolve from the files alone. Needs pkg/ built.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
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

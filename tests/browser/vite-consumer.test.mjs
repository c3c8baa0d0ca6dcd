// The package as an npm user gets it: tests/vite-consumer installs the built pkg/ (packed, as from
// the registry: see its .npmrc) next to Vite and three.js from the npm registry, Vite bundles it,
// and the bundle must load in headless Chromium and draw the mesh. Needs pkg/ built
// (scripts/build-wasm.sh) and access to the npm registry; run by scripts/test.sh.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFile } from 'node:child_process';
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { promisify } from 'node:util';
import { serve, launch, canvasColours } from '../../scripts/browser.mjs';

const APP = 'tests/vite-consumer';
const run = promisify(execFile);
const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';

let server;
let browser;

before(async () => {
  assert.ok(existsSync('pkg/isoforge.js'), 'pkg/ is not built: run scripts/build-wasm.sh first');
  // npm ci: the committed lockfile pins Vite and three.js; the package itself is packed afresh
  // from pkg/ on every run, so the test always sees the current build.
  await run(npm, ['ci', '--no-audit', '--no-fund', '--loglevel=error'], { cwd: APP });
  await run(npm, ['run', 'build', '--silent'], { cwd: APP });
  server = await serve(`${APP}/dist`);
  browser = await launch();
});

after(async () => {
  await browser?.close();
  server?.close();
});

test('the installed package has every file its package.json and its JavaScript point to', () => {
  const installed = `${APP}/node_modules/isoforge`;
  const manifest = JSON.parse(readFileSync(`${installed}/package.json`, 'utf8'));
  const targets = [manifest.main, manifest.module, manifest.types, 'README.md'];
  const walk = (v) => (typeof v === 'string' ? targets.push(v) : Object.values(v).forEach(walk));
  walk(manifest.exports);
  assert.ok(targets.length > 8, `${targets}`);
  for (const file of targets) {
    assert.ok(existsSync(`${installed}/${file}`), `${file} is named by package.json but was not installed`);
  }
  // And every file the shipped JavaScript loads by a relative path (imports, the wasm, the worker).
  const relative = /(?:from\s*|import\s*\(\s*|new URL\(\s*)['"]((?:\.\/)?[\w.-]+\.(?:js|wasm))['"]/g;
  let seen = 0;
  for (const file of readdirSync(installed).filter((f) => f.endsWith('.js'))) {
    for (const [, path] of readFileSync(`${installed}/${file}`, 'utf8').matchAll(relative)) {
      seen++;
      assert.ok(existsSync(`${installed}/${path}`), `${file} loads ${path}, which was not installed`);
    }
  }
  assert.ok(seen >= 3, `only ${seen} relative loads found: the pattern no longer matches the package`);
});

/** The app's page, with every failed request and uncaught error collected into `errors`. */
async function openApp() {
  const page = await browser.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  // Every file the bundle asks for must exist (the browser's own favicon request aside).
  page.on('response', (r) => r.status() >= 400 && !r.url().endsWith('/favicon.ico') && errors.push(`${r.status()} ${r.url()}`));
  await page.goto(server.url);
  return { page, errors };
}

test('the Vite bundle loads, meshes a scene and draws it with three.js', async () => {
  const { page, errors } = await openApp();
  await page.waitForFunction(() => /^\d+$/.test(document.getElementById('triangles').textContent)
    || document.getElementById('error').textContent !== '');
  assert.deepEqual(errors, []);
  assert.equal(await page.textContent('#error'), '');
  const triangles = Number(await page.textContent('#triangles'));
  assert.ok(triangles > 0, `${triangles} triangles`);
  // The canvas is not blank: the flat-shaded normal material paints many colours on white.
  const { colours, covered } = await canvasColours(page, '#view');
  assert.ok(colours > 8, `only ${colours} distinct colours: the mesh was not drawn`);
  assert.ok(covered > 0.05 && covered < 0.95, `the mesh covers ${(100 * covered).toFixed(1)}% of the canvas`);
  await page.locator('#view').screenshot({ path: 'target/vite-consumer.png' });
  await page.close();
});

test('createMesher works from the Vite bundle', async () => {
  const { page } = await openApp();
  await page.waitForFunction(() => document.getElementById('worker').textContent !== '…');
  const inWorker = await page.textContent('#worker');
  await page.waitForFunction(() => /^\d+$/.test(document.getElementById('triangles').textContent));
  assert.equal(inWorker, await page.textContent('#triangles'), 'the worker meshes the same torus');
  await page.close();
});

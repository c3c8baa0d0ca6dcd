// The package under Node, as npm installs it: the npm README's Node example, run as written in a
// scratch project whose node_modules/isoforge is the built pkg/, must write two STL files whose
// triangle counts are the ones it prints, and exit by itself (the mesher's worker lets it).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, mkdirSync, readFileSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';

/**
 * Runs `script` with Node in a scratch project that has the built package installed, as `file`
 * (its extension picks ES module or CommonJS); its stdout.
 */
function runInProject(script, file = 'script.mjs') {
  assert.ok(existsSync('pkg/node.js'), 'pkg/ is not built: run scripts/build-wasm.sh first');
  const dir = mkdtempSync(join(tmpdir(), 'isoforge-node-'));
  mkdirSync(join(dir, 'node_modules'));
  symlinkSync(resolve('pkg'), join(dir, 'node_modules', 'isoforge'), 'dir');
  writeFileSync(join(dir, file), script);
  return { dir, out: execFileSync(process.execPath, [file], { cwd: dir, encoding: 'utf8', timeout: 120_000 }) };
}

test("the npm README's Node example writes STL files and exits", () => {
  const readme = readFileSync('pkg-config/README.md', 'utf8');
  const example = readme.slice(readme.indexOf('## Node')).match(/```js\n([\s\S]*?)```/)[1];
  const { dir, out } = runInProject(example);
  const [part, ring] = out.trim().split(' ').map(Number);
  for (const [file, triangles] of [['part.stl', part], ['ring.stl', ring]]) {
    const stl = readFileSync(join(dir, file));
    assert.ok(triangles > 1000, `${file}: ${out}`);
    assert.equal(stl.readUInt32LE(80), triangles, file);
    assert.equal(stl.length, 84 + 50 * triangles, file);
  }
});

test('under Node, cancel() stops a running call at its next checkpoint and the worker stays', () => {
  const { out } = runInProject(`
    import { createMesher } from 'isoforge/mesher';
    const mesher = createMesher();
    const ripples = Array.from({ length: 300 }, (_, i) => 'sin(' + (1 + i / 7) + ' * x + y)').join(' + ');
    const long = mesher.meshExpr('sphere(0.7) + 0.0000001 * (' + ripples + ')', { res: 256 });
    setTimeout(() => mesher.cancel(), 300);
    const stopped = await long.then(() => 'finished', (e) => e.name);
    const t = performance.now();
    const next = await mesher.meshExpr('sphere(0.5)', { res: 24 });
    console.log(JSON.stringify({ stopped, stopsAtOnce: mesher.stopsAtOnce, euler: next.stats.euler, ms: performance.now() - t }));
  `);
  const r = JSON.parse(out);
  assert.equal(r.stopped, 'AbortError');
  assert.equal(r.stopsAtOnce, true);
  assert.equal(r.euler, 2);
});

test('CommonJS: require() loads the package and its mesher (Node ≥ 20.19)', () => {
  const { out } = runInProject(`
    const { default: init, meshExpr, analyzeMesh } = require('isoforge');
    const { createMesher } = require('isoforge/mesher');
    (async () => {
      await init();
      const part = meshExpr('sphere(0.5)', { res: 24 });
      const measured = analyzeMesh(part, { expr: 'sphere(0.5)', checkIntersections: true });
      const ring = await createMesher().meshExpr('torus(0.6, 0.2)', { res: 32 });
      console.log(JSON.stringify({ euler: part.stats.euler, ring: ring.stats.euler, dist: measured.dist_max, crossing: measured.self_intersections }));
    })();
  `, 'script.cjs');
  const r = JSON.parse(out);
  assert.equal(r.euler, 2);
  assert.equal(r.ring, 0);
  // 24 cells over [-1, 1]: MC's vertices lie within a small fraction of a cell (1/12) of the sphere.
  assert.ok(r.dist > 0 && r.dist < 0.01, `dist_max ${r.dist}`);
  assert.equal(r.crossing, 0);
});

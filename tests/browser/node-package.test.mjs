// The package under Node, as npm installs it: the npm README's Node example, run as written in a
// scratch project whose node_modules/isoforge is the built pkg/, must write two STL files whose
// triangle counts are the ones it prints, and exit by itself (the mesher's worker lets it).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, mkdirSync, readFileSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';

/** Runs `script` with Node in a scratch project that has the built package installed; its stdout. */
function runInProject(script) {
  assert.ok(existsSync('pkg/node.js'), 'pkg/ is not built: run scripts/build-wasm.sh first');
  const dir = mkdtempSync(join(tmpdir(), 'isoforge-node-'));
  mkdirSync(join(dir, 'node_modules'));
  symlinkSync(resolve('pkg'), join(dir, 'node_modules', 'isoforge'), 'dir');
  writeFileSync(join(dir, 'script.mjs'), script);
  return { dir, out: execFileSync(process.execPath, ['script.mjs'], { cwd: dir, encoding: 'utf8', timeout: 120_000 }) };
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

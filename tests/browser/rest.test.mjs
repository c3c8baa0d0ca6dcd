// The CSG builder (isoforge/csg), meshFunction (a JavaScript function as a field) and the
// gradient option of meshGrid, in headless Chromium. Run by scripts/test.sh after the wasm
// package is built.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { sharedPackagePage } from '../../scripts/browser.mjs';

/** Runs `body(m, arg)` in the page with the initialised package module `m`. */
const inPage = sharedPackagePage({ before, after });

test('the CSG builder makes the JSON meshCsg takes, meshing like the same text', async () => {
  const r = await inPage(async (m) => {
    const c = await import('./pkg/csg.js');
    const part = c.sphere(0.8).subtract(c.box(0.3, 0.3, 2).rotate([1, 0, 0], 30)).translate([0, 0, 0.1]);
    const text = 'translate(subtract(sphere(0.8), rotate(box(0.3, 0.3, 2), 1, 0, 0, 30)), 0, 0, 0.1)';
    const fromBuilder = m.meshCsg(part, { res: 24 }).stats;
    const fromJson = m.meshCsg(JSON.stringify(part), { res: 24 }).stats;
    const fromText = m.meshExpr(text, { res: 24 }).stats;
    // Every op once, each checked by the compiler.
    const all = c.union(
      c.roundedBox(0.3, 0.2, 0.1, 0.05).smoothUnion(c.torus(0.4, 0.1), 0.1),
      c.cylinder(0.2, 0.5).intersect(c.plane([0, 0, 1], 0.2)).smoothIntersect(c.sphere(0.5), 0.05),
      c.cone(0.3, 0.6).smoothSubtract(c.capsule([0, 0, 0], [0, 0, 0.5], 0.1), 0.05).mirrorY().mirrorZ(),
      c.sphere(0.2).shell(0.02).offset(0.01).scale(1.5).mirrorX().union(c.fromJSON({ op: 'sphere', radius: 0.1 })),
    );
    const allText = 'union(smooth_union(rounded_box(0.3, 0.2, 0.1, 0.05), torus(0.4, 0.1), 0.1),'
      + ' smooth_intersect(intersect(cylinder(0.2, 0.5), plane(0, 0, 1, 0.2)), sphere(0.5), 0.05),'
      + ' mirror_z(mirror_y(smooth_subtract(cone(0.3, 0.6), capsule(0, 0, 0, 0, 0, 0.5, 0.1), 0.05))),'
      + ' union(mirror_x(scale(offset(shell(sphere(0.2), 0.02), 0.01), 1.5)), sphere(0.1)))';
    const ops = new Set();
    const walk = (n) => { ops.add(n.op); (n.args ?? []).forEach(walk); if (n.shape) walk(n.shape); };
    walk(all.toJSON());
    walk(part.toJSON());
    let badArg = null;
    try { c.sphere('1'); } catch (e) { badArg = `${e.name}: ${e.message}`; }
    return {
      builder: fromBuilder.triangles, json: fromJson.triangles, text: fromText.triangles, euler: fromBuilder.euler,
      all: m.meshCsg(all, { res: 32 }).stats.triangles, allText: m.meshExpr(allText, { res: 32 }).stats.triangles,
      ops: [...ops].sort(), node: c.sphere(1).translate([1, 2, 3]).toJSON(), badArg,
    };
  });
  assert.ok(r.builder > 100);
  assert.equal(r.builder, r.text);
  assert.equal(r.json, r.text);
  assert.equal(r.euler, 0, 'the bar drills a tunnel through the sphere: genus 1');
  assert.ok(r.all > 100);
  assert.equal(r.all, r.allText);
  assert.deepEqual(r.ops, ['box', 'capsule', 'cone', 'cylinder', 'intersect', 'mirror_x', 'mirror_y', 'mirror_z',
    'offset', 'plane', 'rotate', 'rounded_box', 'scale', 'shell', 'smooth_intersect', 'smooth_subtract',
    'smooth_union', 'sphere', 'subtract', 'torus', 'translate', 'union']);
  assert.deepEqual(r.node, { op: 'translate', shape: { op: 'sphere', radius: 1 }, offset: [1, 2, 3] });
  assert.match(r.badArg, /TypeError: sphere radius must be a finite number/);
});

test('meshFunction meshes a JavaScript function called once per z-slab', async () => {
  const r = await inPage((m) => {
    let calls = 0;
    const sphere = (pts) => {
      calls += 1;
      const out = new Float32Array(pts.length / 3);
      for (let i = 0; i < out.length; i++) {
        out[i] = Math.hypot(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]) - 0.7;
      }
      return out;
    };
    const s = m.meshFunction(sphere, [-1, -1, -1, 1, 1, 1], { res: 20 }).stats;
    const viaExpr = m.meshExpr('sphere(0.7)', { res: 20 }).stats;
    const err = (f, opts) => { try { m.meshFunction(f, [-1, -1, -1, 1, 1, 1], opts ?? { res: 8 }); return null; } catch (e) { return `${e.constructor.name}: ${e.message}`; } };
    return {
      closed: s.closed_manifold, euler: s.euler, triangles: s.triangles, exprTriangles: viaExpr.triangles, calls,
      emc: m.meshFunction(sphere, [-1, -1, -1, 1, 1, 1], { res: 16, method: 'emc' }).stats.euler,
      thrown: err(() => { throw new Error('my field broke'); }),
      short: err(() => new Float32Array(3)),
      nan: err((pts) => new Float32Array(pts.length / 3).fill(NaN)),
      notArray: err(() => 42),
      array: err((pts) => Array.from({ length: pts.length / 3 }, () => 1)),
    };
  });
  assert.equal(r.closed, true);
  assert.equal(r.euler, 2);
  // Sampled, then meshed as a volume: close to the compiled path, not identical.
  assert.ok(Math.abs(r.triangles - r.exprTriangles) < 0.05 * r.exprTriangles, `${r.triangles} vs ${r.exprTriangles}`);
  assert.equal(r.calls, 21, 'one call per z-slab of a 21³-point grid');
  assert.equal(r.emc, 2);
  assert.match(r.thrown, /^Error: field function: it threw: my field broke/);
  assert.match(r.short, /^Error: field function: it returned 3 values for 81 points/);
  assert.match(r.nan, /^Error: sample \(0, 0, 0\) .* is NaN/);
  assert.match(r.notArray, /^Error: field function: it must return a Float32Array/);
  assert.equal(r.array, null);
});

test('meshGrid takes a gradient option, trilinear or central', async () => {
  const r = await inPage((m) => {
    const n = 17;
    const values = new Float32Array(n * n * n);
    for (let k = 0; k < n; k++) for (let j = 0; j < n; j++) for (let i = 0; i < n; i++) {
      const p = [i, j, k].map((t) => -1 + (2 * t) / (n - 1));
      values[i + n * (j + n * k)] = Math.hypot(...p) - 0.7;
    }
    const run = (gradient) => m.meshGrid(values, [n, n, n], [-1, -1, -1, 1, 1, 1], { surfaceError: true, ...(gradient ? { gradient } : {}) }).stats;
    const err = (f) => { try { f(); return null; } catch (e) { return e.message; } };
    return {
      central: run('central'), trilinear: run('trilinear'), dflt: run(undefined),
      bad: err(() => run('sobel')),
      elsewhere: err(() => m.meshExpr('sphere(1)', { gradient: 'central' })),
    };
  });
  assert.equal(r.central.triangles, r.trilinear.triangles);
  assert.deepEqual(r.dflt.normal_dev_deg_p95, r.central.normal_dev_deg_p95);
  assert.notEqual(r.central.normal_dev_deg_max, r.trilinear.normal_dev_deg_max, 'the option reaches the stats');
  assert.match(r.bad, /unknown gradient 'sobel'; known: trilinear, central/);
  assert.match(r.elsewhere, /gradient is an option of meshGrid only/);
});

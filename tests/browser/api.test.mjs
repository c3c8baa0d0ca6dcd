// The JavaScript API as a page uses it: the built package loaded in headless Chromium (Debian's),
// every export called with real typed arrays, objects and strings. Run by scripts/test.sh after
// the wasm package is built.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { sharedPackagePage } from '../../scripts/browser.mjs';

/** Runs `body(m, arg)` in the page with the initialised package module `m`. */
const inPage = sharedPackagePage({ before, after });

test('compile returns a reusable shape that meshes at several resolutions', async () => {
  const r = await inPage((m) => {
    const s = m.compile('r = 0.5; sphere(r)');
    const coarse = m.meshShape(s, { res: 12 });
    const fine = m.meshShape(s, { res: 24 });
    const out = {
      value: s.value(0, 0, 0), grad: Array.from(s.valueAndGradient(1, 0, 0)), instructions: s.instructionCount,
      coarse: coarse.stats.triangles, fine: fine.stats.triangles, euler: fine.stats.euler,
      types: [fine.positions, fine.normals, fine.indices, fine.featureEdges].map((a) => a.constructor.name),
      features: fine.featureEdges.length,
    };
    s.free();
    return out;
  });
  assert.equal(r.value, -0.5);
  assert.deepEqual(r.grad, [0.5, 1, 0, 0]);
  assert.ok(r.instructions > 0);
  assert.ok(r.fine > r.coarse && r.coarse > 0);
  assert.equal(r.euler, 2);
  assert.deepEqual(r.types, ['Float32Array', 'Float32Array', 'Uint32Array', 'Uint32Array']);
  assert.equal(r.features, 0, 'Marching Cubes finds no feature lines');
});

test('parse errors throw an Error with line, column and caret', async () => {
  const r = await inPage((m) => {
    const messages = [];
    for (const f of [() => m.compile('union(sphere(1),\n  bx(1, 1, 1))'), () => m.meshExpr('sphere(0.5) +')]) {
      try { f(); messages.push(null); } catch (e) { messages.push({ isError: e instanceof Error, message: e.message }); }
    }
    return messages;
  });
  assert.equal(r[0].isError, true);
  assert.equal(r[0].message, "2:3: unknown function 'bx'; did you mean 'box'?\n  bx(1, 1, 1))\n  ^");
  assert.match(r[1].message, /^1:\d+: /);
});

test('meshExpr and meshCsg mesh in [-1, 1]³ or the given bounds', async () => {
  const r = await inPage((m) => {
    const tree = { op: 'subtract', args: [{ op: 'box', half: [0.6, 0.6, 0.6] }, { op: 'sphere', radius: 0.75 }] };
    let csgError = null;
    try { m.meshCsg({ op: 'sphere', radius: 1, radiuss: 2 }); } catch (e) { csgError = e.message; }
    return {
      expr: m.meshExpr('subtract(box(0.6, 0.6, 0.6), sphere(0.75))', { res: 24 }).stats.euler,
      big: m.meshExpr('sphere(2)', { res: 16, bounds: [-2.5, -2.5, -2.5, 2.5, 2.5, 2.5] }).stats.euler,
      clipped: m.meshExpr('sphere(2)', { res: 16 }).stats.triangles,
      object: m.meshCsg(tree, { res: 24 }).stats.euler,
      string: m.meshCsg(JSON.stringify(tree), { res: 24 }).stats.triangles,
      shape: m.meshShape(m.compileCsg(tree), { res: 24 }).stats.triangles,
      csgError,
    };
  });
  assert.equal(r.expr, -8);
  assert.equal(r.big, 2);
  assert.equal(r.clipped, 0, 'a ball around the default bounds [-1, 1]³ has no surface in them');
  assert.equal(r.object, -8);
  assert.equal(r.string, r.shape);
  assert.match(r.csgError, /unknown field `radiuss`/);
});

test('scenes come with their source text, which meshes the same', async () => {
  const r = await inPage((m) => {
    const names = m.sceneNames();
    const src = m.sceneSource('torus');
    let unknown = null;
    try { m.sceneSource('tours'); } catch (e) { unknown = e.message; }
    return {
      names, src, unknown,
      scene: m.meshScene('gyroid', { res: 20 }).stats.triangles,
      text: m.meshExpr(m.sceneSource('gyroid'), { res: 20, bounds: m.sceneBounds('gyroid') }).stats.triangles,
      bounds: m.sceneBounds('fandisk'),
    };
  });
  for (const n of ['sphere', 'torus', 'gyroid', 'cube_minus_sphere', 'two_spheres_touching', 'rotated_box',
    'fandisk', 'thin_room', 'rocket', 'milling', 'cube_with_cutouts']) assert.ok(r.names.includes(n), n);
  assert.match(r.src, /torus\(0\.6, 0\.25\)/);
  assert.match(r.unknown, /unknown scene 'tours'/);
  assert.equal(r.scene, r.text);
  assert.deepEqual(r.bounds.map((v) => Math.round(v * 100) / 100), [-0.9, -0.6, -0.55, 0.9, 0.6, 0.55]);
});

test('meshGrid takes Float32Array, Uint8Array, Uint16Array and raw bytes with a dtype', async () => {
  const r = await inPage((m) => {
    // 21³ samples over [-1, 1]³ of 200 |p|: iso 120 is the sphere of radius 0.6.
    const n = 21;
    const f = new Float32Array(n * n * n);
    for (let k = 0, i = 0; k < n; k++) for (let j = 0; j < n; j++) for (let x = 0; x < n; x++, i++) {
      const p = [x, j, k].map((c) => -1 + 0.1 * c);
      f[i] = Math.min(255, 200 * Math.hypot(...p));
    }
    const u8 = Uint8Array.from(f, Math.round);
    const u16 = Uint16Array.from(f, (v) => Math.round(v * 100));
    const bytes = new Uint8Array(u16.buffer.slice(0));
    const dims = [n, n, n];
    const bounds = [-1, -1, -1, 1, 1, 1];
    const run = (values, options) => {
      try {
        const s = m.meshGrid(values, dims, bounds, options).stats;
        return { euler: s.euler, volume: s.volume, closed: s.closed_manifold };
      } catch (e) { return { error: e.message }; }
    };
    return {
      f32: run(f, { iso: 120 }),
      u8: run(u8, { iso: 120 }),
      u16: run(u16, { iso: 12000 }),
      rawU16: run(bytes, { iso: 12000, dtype: 'u16' }),
      buffer: run(u16.buffer, { iso: 12000, dtype: 'u16' }),
      array: run(Array.from(f), { iso: 120 }),
      mismatch: run(f, { iso: 120, dtype: 'u8' }),
      noDtype: run(u16.buffer, { iso: 12000 }),
      shortBytes: run(bytes.subarray(1), { iso: 12000, dtype: 'u16' }),
      elsewhere: (() => { try { m.meshScene('sphere', { dtype: 'u8' }); } catch (e) { return e.message; } })(),
    };
  });
  const expected = 4 / 3 * Math.PI * 0.6 ** 3;
  for (const k of ['f32', 'u8', 'u16', 'rawU16', 'buffer', 'array']) {
    assert.equal(r[k].closed, true, `${k}: ${JSON.stringify(r[k])}`);
    assert.equal(r[k].euler, 2, k);
    assert.ok(Math.abs(r[k].volume - expected) < 0.05 * expected, `${k}: volume ${r[k].volume}`);
  }
  assert.match(r.mismatch.error, /dtype "u8" does not match a Float32Array/);
  assert.match(r.noDtype.error, /needs a dtype/);
  assert.match(r.shortBytes.error, /take 18522 bytes, got 18521/);
  assert.match(r.elsewhere, /dtype is an option of meshGrid only/);
});

test('EMC options are passed through and feature edges come back', async () => {
  const r = await inPage((m) => {
    const emc = m.meshScene('rotated_box', { method: 'emc', res: 24, thetaSharp: 0.9, phiCorner: 0.7, directed: true });
    const errors = [];
    for (const o of [{ method: 'emc', thetaSharp: 2 }, { method: 'dc' }, { thetaSharpe: 0.5 }]) {
      try { m.meshScene('sphere', { res: 8, ...o }); errors.push(null); } catch (e) { errors.push(e.message); }
    }
    const f = emc.featureEdges;
    // Resampled creases (the default) against the paper's tangent-plane points on curved creases.
    const resampled = m.meshScene('fandisk', { method: 'emc', res: 32, surfaceError: true }).stats.dist_max;
    const paper = m.meshScene('fandisk', { method: 'emc', res: 32, resampleCreases: false, surfaceError: true }).stats.dist_max;
    // Flat merges (the default) against every fan's two extra triangles kept.
    const kept = m.meshScene('rotated_box', { method: 'emc', res: 24, mergeFlat: false }).stats;
    return {
      method: emc.stats.method, closed: emc.stats.closed_manifold, euler: emc.stats.euler,
      pairs: f.length / 2, even: f.length % 2 === 0, counted: emc.stats.feature_edges,
      inRange: f.every((i) => i < emc.positions.length / 3), errors, resampled, paper,
      merges: emc.stats.flat_merges, triangles: emc.stats.triangles, keptMerges: kept.flat_merges,
      keptTriangles: kept.triangles,
    };
  });
  assert.equal(r.method, 'emc');
  assert.equal(r.closed, true);
  assert.equal(r.euler, 2);
  assert.ok(r.pairs > 0 && r.even && r.inRange);
  assert.equal(r.pairs, r.counted);
  assert.ok(r.merges > 0, `${r.merges} flat merges`);
  assert.equal(r.keptMerges, 0);
  assert.equal(r.triangles + 2 * r.merges, r.keptTriangles);
  assert.match(r.errors[0], /thetaSharp/);
  assert.match(r.errors[1], /unknown method 'dc'/);
  assert.match(r.errors[2], /unknown field `thetaSharpe`, expected one of .*`thetaSharp`/);
  assert.ok(r.resampled < r.paper, `resampled creases ${r.resampled} against tangent planes ${r.paper}`);
});

test('DMC keeps the thin-walled room whole within 1 %, and refuses the options it no longer has', async () => {
  const room = 'b = max(abs(x) - 0.8, abs(y) - 0.8, abs(z) - 0.5); room = abs(b) - 0.008; '
    + 'door = translate(max(abs(x) - 0.2, abs(y) - 0.1, abs(z) - 0.325), 0, -0.8, -0.125); max(room, -door)';
  const r = await inPage((m, room) => {
    const base = { method: 'dmc', maxDepth: 6, bounds: [-1, -1, -0.7, 1, 1, 0.7], checkIntersections: true, surfaceError: true };
    const stats = m.meshExpr(room, base).stats;
    const bad = [];
    for (const key of ['vertexReach', 'paperOnly', 'accuracyRule']) {
      try { m.meshExpr(room, { ...base, [key]: 1 }); } catch (e) { bad.push(e.message); }
    }
    return { stats, bad };
  }, room);
  const { stats } = r;
  assert.equal(stats.method, 'dmc');
  assert.ok(stats.closed_manifold && stats.euler === 2 && stats.components === 1, JSON.stringify(stats));
  assert.equal(stats.self_intersections, 0);
  // The room is 1.6 across: 1 % is 0.016.
  assert.ok(stats.dist_max < 0.016, `max distance ${stats.dist_max}`);
  assert.equal(r.bad.length, 3);
  for (const message of r.bad) assert.match(message, /unknown field/);
});

test('mcq meshes through the same options and snapping can be turned off', async () => {
  const r = await inPage((m) => {
    const sphere = (o) => m.meshExpr('sphere(0.8)', { res: 9, ...o }).stats;
    const [mc, mcq, perCell] = [sphere({}), sphere({ method: 'mcq' }), sphere({ method: 'mcq', snap: 0, project: false })];
    let bad = null;
    try { sphere({ method: 'mcq', snap: 0.7 }); } catch (e) { bad = e.message; }
    return { mc: mc.triangles, mcq, perCell: perCell.triangles, bad };
  });
  assert.equal(r.mc, 524);
  assert.equal(r.mcq.method, 'mcq');
  assert.equal(r.mcq.closed_manifold, true);
  assert.ok(r.mcq.min_angle_deg >= 20 && r.mcq.max_angle_deg <= 130, JSON.stringify(r.mcq));
  assert.equal(r.mcq.angle_histogram_5deg.length, 36);
  assert.notEqual(r.perCell, r.mcq.triangles);
  assert.match(r.bad, /snap must be in/);
});

test('analyzeMesh measures a result after the fact: the same error as surfaceError, and the crossing pairs', async () => {
  const r = await inPage((m) => {
    const text = 'subtract(box(0.6, 0.6, 0.6), sphere(0.75))';
    const withStats = m.meshExpr(text, { method: 'emc', res: 24, surfaceError: true, checkIntersections: true });
    const plain = m.meshExpr(text, { method: 'emc', res: 24 });
    const after = m.analyzeMesh(plain, { expr: text, checkIntersections: true });
    const fromCsg = m.analyzeMesh(plain, { csg: { op: 'subtract', args: [{ op: 'box', half: [0.6, 0.6, 0.6] }, { op: 'sphere', radius: 0.75 }] } });
    // Two triangles that cross through each other's middles, and a third far away.
    const positions = new Float32Array([-1, -1, 0, 1, -1, 0, 0, 1, 0, 0, 0, -1, 0, 0.2, 1, 0, -0.8, 1, 5, 5, 5, 6, 5, 5, 5, 6, 5]);
    const crossing = m.analyzeMesh({ positions, indices: new Uint32Array([0, 1, 2, 3, 4, 5, 6, 7, 8]) }, { checkIntersections: true });
    const errors = [];
    for (const [arrays, options] of [
      [plain, { exp: text }],
      [plain, { expr: text, csg: '{}' }],
      [plain, { expr: 'sphere(' }],
      [{ positions, indices: new Uint32Array([0, 1, 9]) }, {}],
      [{ positions: new Float32Array([0, 0, NaN, 1, 0, 0, 0, 1, 0]), indices: new Uint32Array([0, 1, 2]) }, {}],
      [plain, { checkIntersections: 'yes' }],
    ]) {
      try { m.analyzeMesh(arrays, options); errors.push(null); } catch (e) { errors.push(e.message); }
    }
    const pick = (o) => [o.dist_max, o.dist_rms, o.normal_dev_deg_p95, o.crease_faces, o.self_intersections];
    return {
      withStats: pick(withStats.stats), after: pick(after), csg: pick(fromCsg), plain: pick(plain.stats),
      afterPairs: after.self_intersecting_pairs.length, csgPairs: fromCsg.self_intersecting_pairs.constructor.name,
      crossing: [crossing.self_intersections, Array.from(crossing.self_intersecting_pairs), crossing.dist_max],
      errors,
    };
  });
  // Measured after the fact, on the same mesh, against the same program: the same numbers.
  assert.deepEqual(r.after, r.withStats);
  assert.deepEqual(r.csg.slice(0, 4), r.withStats.slice(0, 4));
  assert.equal(r.csg[4], null, 'crossings only when asked');
  assert.deepEqual(r.plain, [null, null, null, null, null], 'a plain mesh call measures nothing');
  assert.ok(r.after[0] > 0 && r.after[0] < 2 / 24, `dist_max ${r.after[0]} within a cell`);
  assert.equal(r.afterPairs, 2 * r.after[4]);
  assert.equal(r.csgPairs, 'Uint32Array');
  assert.deepEqual(r.crossing, [1, [0, 1], null]);
  assert.match(r.errors[0], /unknown analyzeMesh option `exp`/);
  assert.match(r.errors[1], /expr or csg, not both/);
  assert.match(r.errors[2], /^1:\d+: /);
  assert.match(r.errors[3], /refers past the 9 vertices/);
  assert.match(r.errors[4], /vertex 0 is not finite/);
  assert.match(r.errors[5], /checkIntersections must be a boolean/);
});

test('decimate, decimateError and smooth pass through to the mesh, and bad values are refused by name', async () => {
  const r = await inPage((m) => {
    const text = 'subtract(box(0.6, 0.6, 0.6), sphere(0.75))';
    const plain = m.meshExpr(text, { method: 'emc', res: 40, surfaceError: true });
    const fewer = m.meshExpr(text, { method: 'emc', res: 40, decimate: 2500 });
    const bounded = m.meshExpr(text, { method: 'emc', res: 40, decimate: 1, decimateError: 0.1, surfaceError: true });
    const smooth = m.meshExpr(text, { method: 'emc', res: 40, smooth: 3 });
    const errors = [];
    for (const o of [{ decimate: -1 }, { decimateError: -0.5 }, { smooth: 1.5 }]) {
      try { m.meshExpr(text, { method: 'emc', res: 16, ...o }); errors.push(null); } catch (e) { errors.push(e.message); }
    }
    const pick = (x) => ({ triangles: x.stats.triangles, closed: x.stats.closed_manifold, euler: x.stats.euler, features: x.featureEdges.length, phases: Object.keys(x.stats.phases_ms) });
    return { plain: { ...pick(plain), dist: plain.stats.dist_max }, fewer: pick(fewer), bounded: { ...pick(bounded), dist: bounded.stats.dist_max }, smooth: pick(smooth), errors };
  });
  for (const x of [r.fewer, r.bounded, r.smooth]) {
    assert.equal(x.closed, true);
    assert.equal(x.euler, -8);
    assert.ok(x.features > 0, 'feature lines kept');
  }
  assert.ok(r.fewer.triangles <= 2500 && r.plain.triangles > 2 * 2500, `${r.plain.triangles} -> ${r.fewer.triangles}`);
  assert.ok(r.fewer.phases.includes('decimate') && r.smooth.phases.includes('smooth'));
  // No farther from the surface than a tenth of a cell (2 / 40) or EMC's own farthest point,
  // with far fewer triangles than EMC's.
  assert.ok(r.bounded.dist <= Math.max(0.1 * 2 / 40, r.plain.dist) * 1.001, JSON.stringify([r.bounded, r.plain]));
  assert.ok(r.bounded.triangles < r.plain.triangles / 2, JSON.stringify(r.bounded));
  assert.equal(r.smooth.triangles, r.plain.triangles, 'smoothing moves vertices, it does not remesh');
  for (const [e, name] of [[r.errors[0], /decimate/], [r.errors[1], /decimateError/], [r.errors[2], /smooth/]]) assert.match(String(e), name);
});

// exportMesh in headless Chromium: a meshed scene exported in every format, each file read back
// by a small reader written here from the format's description, and bad input refused with a
// message naming the problem. Run by scripts/test.sh after the wasm package is built.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { sharedPackagePage } from '../../scripts/browser.mjs';

/** Runs `body(m, arg)` in the page with the initialised package module `m`. */
const inPage = sharedPackagePage({ before, after });

test('a meshed scene exports as OBJ, STL, PLY and GLB that read back consistently', async () => {
  const r = await inPage((m) => {
    const result = m.meshScene('torus', { method: 'emc', res: 24, surfaceError: false });
    const vertices = result.positions.length / 3;
    const triangles = result.indices.length / 3;
    const files = Object.fromEntries(['obj', 'stl', 'ply', 'glb'].map((f) => [f, m.exportMesh(result, f)]));
    const text = (bytes) => new TextDecoder().decode(bytes);
    const u32 = (bytes, at) => new DataView(bytes.buffer, bytes.byteOffset).getUint32(at, true);

    const objLines = text(files.obj).split('\n');
    const count = (prefix) => objLines.filter((l) => l.startsWith(prefix)).length;
    const firstV = objLines.find((l) => l.startsWith('v ')).slice(2).split(' ').map((x) => Math.fround(Number(x)));

    const plyEnd = text(files.ply).indexOf('end_header\n') + 'end_header\n'.length;
    const plyHeader = text(files.ply.subarray(0, plyEnd));

    const glb = files.glb;
    const jsonLength = u32(glb, 12);
    const json = JSON.parse(text(glb.subarray(20, 20 + jsonLength)));
    const binAt = 20 + jsonLength;
    const primitive = json.meshes[0].primitives[0];
    const position = json.accessors[primitive.attributes.POSITION];
    const view = json.bufferViews[position.bufferView];
    const glbPositions = new Float32Array(glb.slice(binAt + 8 + view.byteOffset, binAt + 8 + view.byteOffset + view.byteLength).buffer);
    const min = [0, 1, 2].map((a) => Math.min(...result.positions.filter((_, i) => i % 3 === a)));
    const max = [0, 1, 2].map((a) => Math.max(...result.positions.filter((_, i) => i % 3 === a)));
    return {
      vertices, triangles,
      types: Object.values(files).map((b) => b.constructor.name),
      obj: { v: count('v '), vn: count('vn '), f: count('f '), firstV, firstP: Array.from(result.positions.slice(0, 3)) },
      stl: { length: files.stl.length, count: u32(files.stl, 80) },
      ply: { header: plyHeader, length: files.ply.length, headerLength: plyEnd },
      glb: {
        magic: text(glb.subarray(0, 4)), version: u32(glb, 4), length: u32(glb, 8), total: glb.length,
        jsonLength, jsonType: u32(glb, 16), binLength: u32(glb, binAt), binType: u32(glb, binAt + 4),
        bufferLength: json.buffers[0].byteLength, positionCount: position.count,
        normalCount: json.accessors[primitive.attributes.NORMAL].count,
        indexCount: json.accessors[primitive.indices].count,
        positionsEqual: glbPositions.every((x, i) => x === result.positions[i]) && glbPositions.length === result.positions.length,
        min: position.min, max: position.max, wantMin: min, wantMax: max,
      },
    };
  });
  assert.ok(r.triangles > 500, `${r.triangles} triangles`);
  assert.deepEqual(r.types, ['Uint8Array', 'Uint8Array', 'Uint8Array', 'Uint8Array']);
  assert.deepEqual([r.obj.v, r.obj.vn, r.obj.f], [r.vertices, r.vertices, r.triangles]);
  assert.deepEqual(r.obj.firstV, r.obj.firstP, 'OBJ coordinates read back to the same f32');
  assert.equal(r.stl.length, 84 + 50 * r.triangles);
  assert.equal(r.stl.count, r.triangles);
  assert.match(r.ply.header, new RegExp(`element vertex ${r.vertices}\n`));
  assert.match(r.ply.header, new RegExp(`element face ${r.triangles}\n`));
  assert.equal(r.ply.length, r.ply.headerLength + 24 * r.vertices + 13 * r.triangles);
  const g = r.glb;
  assert.equal(g.magic, 'glTF');
  assert.equal(g.version, 2);
  assert.equal(g.length, g.total);
  assert.equal(g.jsonType, 0x4e4f534a);
  assert.equal(g.binType, 0x004e4942);
  assert.equal(g.jsonLength % 4, 0);
  assert.equal(g.total, 12 + 8 + g.jsonLength + 8 + g.binLength);
  assert.equal(g.bufferLength, g.binLength);
  assert.equal(g.binLength, 4 * (6 * r.vertices + 3 * r.triangles));
  assert.deepEqual([g.positionCount, g.normalCount, g.indexCount], [r.vertices, r.vertices, 3 * r.triangles]);
  assert.ok(g.positionsEqual, 'GLB positions are the result positions');
  assert.deepEqual(g.min, g.wantMin);
  assert.deepEqual(g.max, g.wantMax);
});

test('exportMesh accepts a result without normals and refuses bad formats and arrays', async () => {
  const r = await inPage((m) => {
    const { positions, indices } = m.meshScene('torus', { res: 12, surfaceError: false });
    const noNormals = { positions, normals: new Float32Array(0), indices };
    const obj = new TextDecoder().decode(m.exportMesh(noNormals, 'OBJ'));
    const message = (f) => { try { f(); return null; } catch (e) { return `${e.constructor.name}: ${e.message}`; } };
    return {
      vn: obj.split('\n').filter((l) => l.startsWith('vn ')).length,
      f: obj.split('\n').filter((l) => l.startsWith('f ')).length,
      triangles: indices.length / 3,
      format: message(() => m.exportMesh(noNormals, 'gltf')),
      ragged: message(() => m.exportMesh({ ...noNormals, positions: positions.subarray(1) }, 'stl')),
      normals: message(() => m.exportMesh({ ...noNormals, normals: new Float32Array(3) }, 'ply')),
      pastEnd: message(() => m.exportMesh({ ...noNormals, indices: Uint32Array.of(0, 1, positions.length) }, 'glb')),
      plain: message(() => m.exportMesh({ ...noNormals, positions: Array.from(positions) }, 'obj')),
      notObject: message(() => m.exportMesh(null, 'obj')),
    };
  });
  assert.equal(r.vn, 0);
  assert.equal(r.f, r.triangles);
  assert.match(r.format, /^Error: .*gltf.*glb/);
  assert.match(r.ragged, /^Error: .*positions holds \d+ numbers, not a multiple of 3/);
  assert.match(r.normals, /^Error: .*1 normals for \d+ vertices/);
  assert.match(r.pastEnd, /^Error: .*triangle 0 .*refers past the \d+ vertices/);
  assert.match(r.plain, /^Error: .*positions must be a Float32Array/);
  assert.match(r.notObject, /^Error: .*needs a mesh result/);
});

// The demo in a real browser: headless Chromium (Debian's) driven by playwright-core against the
// page served on localhost. Run by scripts/test.sh after the wasm package is built.
import { test, before, after, afterEach } from 'node:test';
import assert from 'node:assert/strict';
import { canvasColours } from '../../scripts/browser.mjs';
import { demoSuite, settled, stat, count, LEFT, RIGHT } from './demo-page.mjs';

const { openDemo } = demoSuite({ before, after, afterEach });

test('both viewports mesh the default scene, EMC and DMC, as closed manifolds with their numbers', async () => {
  const { page, errors } = await openDemo();
  assert.equal(await page.$eval(`${LEFT} .method`, (s) => s.value), 'emc');
  assert.equal(await page.$eval(`${RIGHT} .method`, (s) => s.value), 'dmc');
  for (const side of [LEFT, RIGHT]) {
    assert.ok(await count(page, side, 'triangles') > 0);
    assert.equal(await stat(page, side, 'closed manifold'), 'yes');
    // The cube minus a ball that pokes through all six faces is a frame of genus 5.
    assert.equal(await stat(page, side, 'Euler characteristic'), '-8');
    for (const key of ['max distance', 'RMS distance', 'normal deviation p95 (°)', 'at sharp edges (°)', 'worst face (°)', 'smallest angle (°)', 'meshing (ms)']) {
      assert.ok(Number.isFinite(await count(page, side, key)), `${side} ${key}`);
    }
    assert.ok(await page.$eval(`${side} .histogram`, (c) => Number(c.dataset.bins)) > 3, 'angle histogram drawn');
  }
  assert.ok(await count(page, LEFT, 'feature edges') > 0, 'EMC finds the sharp edges');
  assert.deepEqual(errors, []);
  await page.close();
});

test('gallery scenes load into the editor and re-mesh both sides with their own topology', async () => {
  const { page, errors } = await openDemo();
  await page.click('#gallery button[data-scene="torus"]');
  await settled(page);
  assert.match(await page.inputValue('#source'), /torus/);
  for (const side of [LEFT, RIGHT]) {
    assert.equal(await stat(page, side, 'Euler characteristic'), '0');
    assert.equal(await stat(page, side, 'closed manifold'), 'yes');
  }
  for (const [scene, source] of [['fandisk', /cylinder/], ['rocket', /fin/]]) {
    await page.click(`#gallery button[data-scene="${scene}"]`);
    await settled(page);
    assert.match(await page.inputValue('#source'), source);
    for (const side of [LEFT, RIGHT]) {
      assert.equal(await stat(page, side, 'Euler characteristic'), '2', `${scene} ${side}`);
      assert.equal(await stat(page, side, 'components'), '1', `${scene} ${side}`);
    }
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('DMC keeps the thin-walled room whole within 1 %, where its walls are half a cell thick', async () => {
  const { page, errors } = await openDemo();
  await page.fill('#source', 'b = max(abs(x) - 0.8, abs(y) - 0.8, abs(z) - 0.5);\nroom = abs(b) - 0.008;\n'
    + 'door = translate(max(abs(x) - 0.2, abs(y) - 0.1, abs(z) - 0.325), 0, -0.8, -0.125);\nmax(room, -door)');
  await page.fill('#tol', '0.001');
  await page.fill('#depth', '6');
  await page.click('#run');
  await settled(page);
  assert.equal(await stat(page, RIGHT, 'closed manifold'), 'yes');
  assert.equal(await stat(page, RIGHT, 'Euler characteristic'), '2');
  assert.equal(await stat(page, RIGHT, 'components'), '1');
  // The room is 1.6 across: 1 % is 0.016.
  assert.ok(await count(page, RIGHT, 'max distance') < 0.016);
  assert.deepEqual(errors, []);
  await page.close();
});

test('either side can show plain Marching Cubes instead, without feature lines', async () => {
  const { page } = await openDemo();
  await page.selectOption(`${RIGHT} .method`, 'mc');
  await settled(page);
  assert.equal(await stat(page, RIGHT, 'feature edges'), '0');
  assert.equal(await stat(page, RIGHT, 'closed manifold'), 'yes');
  await page.close();
});

test('the viewports draw the meshes (not blank canvases)', async () => {
  const { page } = await openDemo();
  await page.waitForTimeout(300);
  for (const side of [LEFT, RIGHT]) {
    const { colours } = await canvasColours(page, `${side} canvas`, 64, 64);
    assert.ok(colours > 8, `${side}: only ${colours} distinct colours, the mesh was not drawn`);
  }
  await page.screenshot({ path: 'target/demo-screenshot.png' });
  await page.close();
});

test('a broken program shows its error inline at its line and column, and nothing is meshed', async () => {
  const { page, errors } = await openDemo();
  const before = await count(page, LEFT, 'triangles');
  await page.fill('#source', 'union(sphere(0.5),\n  bx(1, 1, 1))');
  await page.waitForSelector('#editor-error:not([hidden])');
  assert.match(await page.textContent('#editor-error'), /^2:3: unknown function 'bx'/);
  assert.equal(await page.$eval('#editor-error', (e) => e.dataset.line), '2');
  assert.equal(await page.$eval('#editor-error', (e) => e.dataset.column), '3');
  // The box sits below the second line of text, not the first.
  const [boxTop, areaTop, lineHeight] = await page.evaluate(() => {
    const area = document.querySelector('#source');
    return [document.querySelector('#editor-error').getBoundingClientRect().top, area.getBoundingClientRect().top,
      parseFloat(getComputedStyle(area).lineHeight)];
  });
  assert.ok(boxTop - areaTop > 1.5 * lineHeight && boxTop - areaTop < 3.5 * lineHeight, `${boxTop - areaTop} vs ${lineHeight}`);
  await page.click('#run');
  assert.equal(await page.$eval('#status', (s) => s.dataset.state), 'error');
  assert.equal(await count(page, LEFT, 'triangles'), before);
  await page.fill('#source', 'torus(0.5, 0.2)');
  await page.waitForSelector('#editor-error', { state: 'hidden' });
  await page.click('#run');
  await settled(page);
  assert.equal(await stat(page, LEFT, 'Euler characteristic'), '0');
  assert.deepEqual(errors, []);
  await page.close();
});

test('the page answers clicks while a large mesh is computed, and a new request cancels it', async () => {
  const { page, errors } = await openDemo();
  // 48 balls at 256 cells, each point also paying for 300 sines too small (1e-7 each) to move the
  // surface and impossible to prune: seconds of work, so it is still running after the clicks
  // below, while the meshes stay small (a surface filling the box made the software-rendered
  // page crawl once the other pane showed it).
  const balls = Array.from({ length: 48 }, (_, i) => {
    const [a, z] = [i * 2.4, -0.8 + (1.6 * i) / 47];
    return `translate(sphere(0.15), ${(0.6 * Math.cos(a)).toFixed(3)}, ${(0.6 * Math.sin(a)).toFixed(3)}, ${z.toFixed(3)})`;
  });
  const ripples = Array.from({ length: 300 }, (_, i) => `sin(${(1 + i / 7).toFixed(3)} * x + ${(2 + i / 11).toFixed(3)} * y + z)`);
  await page.fill('#source', `union(${balls.join(',\n')}) + 0.0000001 * (${ripples.join(' + ')})`);
  await page.fill('#res', '256');
  await page.click('#run');
  // State and progress bar read in one go, so that they describe the same moment.
  const left = () => page.$eval(LEFT, (p) => ({ state: p.dataset.state, progress: !p.querySelector('.progress').hidden }));
  assert.deepEqual(await left(), { state: 'busy', progress: true });
  // The click is handled while the left side is still meshing: the main thread is free.
  await page.click('#wireframe');
  assert.equal(await page.isChecked('#wireframe'), true);
  assert.deepEqual(await left(), { state: 'busy', progress: true });
  await page.fill('#res', '24');
  await page.click('#gallery button[data-scene="sphere"]');
  await settled(page);
  assert.equal(await stat(page, LEFT, 'Euler characteristic'), '2');
  assert.deepEqual(errors, []);
  await page.close();
});

test('a too-large request gets a clear message and a way out, and the old mesh goes', async () => {
  const { page } = await openDemo();
  await page.fill('#res', '2048');
  await page.click('#run');
  await settled(page, { allowErrors: true });
  assert.equal(await page.$eval(LEFT, (p) => p.dataset.state), 'error');
  assert.match(await page.textContent(`${LEFT} .state`), /2048 cells per side is 8,589,934,592 cells, more than this page meshes/);
  // No stale mesh or numbers left up to pass for the answer.
  assert.equal(await page.$$eval(`${LEFT} .stats tr`, (rows) => rows.length), 0);
  const way = await page.textContent(`${LEFT} .way-out`);
  const res = Number(/Mesh at (\d+)/.exec(way)[1]);
  assert.ok(res > 48 && res ** 3 <= 72_000_000, way);
  // The way out re-meshes at the largest resolution that fits (a shallower one keeps it quick here).
  await page.$eval(`${LEFT} .way-out`, (b) => { b.dataset.res = '40'; });
  await page.click(`${LEFT} .way-out`);
  await settled(page);
  assert.equal(await page.inputValue('#res'), '40');
  assert.equal(await stat(page, LEFT, 'Euler characteristic'), '-8');
  await page.close();
});

test('the current mesh downloads as OBJ, STL, PLY and GLB', async () => {
  const { page } = await openDemo();
  const triangles = await count(page, LEFT, 'triangles');
  const sizes = {};
  for (const format of ['obj', 'stl', 'ply', 'glb']) {
    await page.selectOption(`${LEFT} .format`, format);
    const [download] = await Promise.all([page.waitForEvent('download'), page.click(`${LEFT} .download`)]);
    assert.equal(download.suggestedFilename(), `cube_minus_sphere-emc.${format}`);
    const chunks = [];
    for await (const chunk of await download.createReadStream()) chunks.push(chunk);
    const bytes = Buffer.concat(chunks);
    sizes[format] = bytes.length;
    if (format === 'glb') assert.equal(bytes.toString('latin1', 0, 4), 'glTF');
    if (format === 'stl') assert.equal(bytes.readUInt32LE(80), triangles);
    if (format === 'obj') assert.equal(bytes.toString().split('\n').filter((l) => l.startsWith('f ')).length, triangles);
    if (format === 'ply') assert.match(bytes.toString('latin1', 0, 200), new RegExp(`element face ${triangles}`));
  }
  await page.close();
});

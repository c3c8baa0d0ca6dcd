// The demo as a modeller keeps using it: programs kept across gallery clicks and reloads, a link
// that reopens the same shape, bounds fitted to a typed shape, live re-meshing, stop, drawing only
// on change, a phone layout, bad triangles and the language reference. Headless Chromium.
import { test, before, after, afterEach } from 'node:test';
import assert from 'node:assert/strict';
import { demoSuite, settled, stat, count, statsChanged, reopen, LEFT, RIGHT } from './demo-page.mjs';

const { openDemo } = demoSuite({ before, after, afterEach });

const TORUS_FAR = 'translate(torus(0.6, 0.2), 4, -2, 1)';

test('a gallery click is undone by Ctrl+Z, and the program and options survive a reload', async () => {
  const { page, errors } = await openDemo();
  await page.fill('#source', 'sphere(0.6)');
  await page.fill('#res', '30');
  await page.click('#run');
  await settled(page);
  await page.click('#gallery button[data-scene="torus"]');
  await settled(page);
  assert.match(await page.inputValue('#source'), /torus/);
  await page.focus('#source');
  await page.keyboard.press('Control+z');
  assert.equal(await page.inputValue('#source'), 'sphere(0.6)');
  await page.click('#run');
  await settled(page);
  await page.reload();
  await settled(page);
  assert.equal(await page.inputValue('#source'), 'sphere(0.6)');
  assert.equal(await page.inputValue('#res'), '30');
  assert.equal(await stat(page, LEFT, 'Euler characteristic'), '2');
  assert.deepEqual(errors, []);
});

test('the address bar is a link that opens the same shape and options elsewhere', async () => {
  const { page } = await openDemo();
  await page.fill('#source', 'torus(0.5, 0.15)');
  await page.fill('#res', '36');
  await page.selectOption(`${RIGHT} .method`, 'mc');
  await settled(page);
  await page.click('#run');
  await settled(page);
  await page.click('#share');
  const link = await page.inputValue('#share-url');
  assert.equal(link, page.url());
  const triangles = await count(page, LEFT, 'triangles');
  // A fresh context: no local storage, only the link.
  const { page: other } = await openDemo({ url: link });
  assert.equal(await other.inputValue('#source'), 'torus(0.5, 0.15)');
  assert.equal(await other.inputValue('#res'), '36');
  assert.equal(await other.$eval(`${RIGHT} .method`, (s) => s.value), 'mc');
  assert.equal(await count(other, LEFT, 'triangles'), triangles);
});

test('a typed shape far from the origin is meshed whole in bounds fitted to it, and re-meshes as you type', async () => {
  const { page, errors } = await openDemo();
  await page.check('#auto-bounds');
  // No click: the page re-meshes by itself once typing pauses.
  await page.fill('#source', TORUS_FAR);
  await page.waitForFunction(() => document.querySelector('#bounds').value.startsWith('3.'));
  await settled(page);
  const b = (await page.inputValue('#bounds')).split(' ').map(Number);
  // The torus spans x 3.2..4.8, y -2.8..-1.2, z 0.8..1.2; the fit holds it with a small margin.
  const inside = [3.2, -2.8, 0.8, 4.8, -1.2, 1.2];
  for (let i = 0; i < 3; i++) {
    assert.ok(b[i] < inside[i] && b[i] > inside[i] - 0.2, `lo ${b}`);
    assert.ok(b[i + 3] > inside[i + 3] && b[i + 3] < inside[i + 3] + 0.2, `hi ${b}`);
  }
  for (const side of [LEFT, RIGHT]) {
    assert.equal(await stat(page, side, 'closed manifold'), 'yes', side);
    assert.equal(await stat(page, side, 'Euler characteristic'), '0', side);
  }
  // An unbounded shape keeps the bounds and says why.
  await page.fill('#source', 'z - 0.3');
  await page.waitForFunction(() => /unbounded along/.test(document.querySelector('#status').textContent), null, { timeout: 60_000 });
  assert.deepEqual(errors, []);
});

test('Stop ends a long job and leaves the page usable', async () => {
  const { page } = await openDemo();
  const ripples = Array.from({ length: 300 }, (_, i) => `sin(${(1 + i / 7).toFixed(3)} * x + y)`);
  await page.uncheck('#live');
  await page.fill('#source', `sphere(0.7) + 0.0000001 * (${ripples.join(' + ')})`);
  await page.fill('#res', '200');
  await page.click('#run');
  assert.equal(await page.$eval(LEFT, (p) => p.dataset.state), 'busy');
  await page.click(`${LEFT} .cancel`);
  await page.waitForFunction(() => document.querySelector('.pane[data-side="left"]').dataset.state === 'stopped');
  await page.keyboard.press('Escape');
  await settled(page, { allowErrors: true });
  await page.fill('#res', '24');
  await page.click('#run');
  await settled(page);
  assert.equal(await stat(page, LEFT, 'Euler characteristic'), '2');
});

test('the views draw only when something changed: idle costs no frames, a drag does', async () => {
  const { page } = await openDemo();
  const frames = () => page.$$eval('.pane', (ps) => ps.map((p) => Number(p.dataset.frames)));
  await page.waitForTimeout(300);
  const idle = await frames();
  await page.waitForTimeout(700);
  assert.deepEqual(await frames(), idle, 'an idle page redrew');
  const box = await page.locator(`${LEFT} .view canvas`).boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 80, box.y + box.height / 2 + 20, { steps: 5 });
  await page.mouse.up();
  await page.waitForTimeout(100);
  const dragged = await frames();
  // Both views share the camera, so both redraw.
  assert.ok(dragged[0] > idle[0] && dragged[1] > idle[1], `${idle} -> ${dragged}`);
});

test('on a 390 px phone each view takes the full width', async () => {
  const { page } = await openDemo({ viewport: { width: 390, height: 844 } });
  for (const side of [LEFT, RIGHT]) {
    const box = await page.locator(`${side} .view canvas`).boundingBox();
    assert.ok(box.width > 350 && box.height > 250, `${side}: ${JSON.stringify(box)}`);
  }
});

test('bad triangles are counted and shown where the numbers say they are', async () => {
  const { page } = await openDemo();
  await page.check('#bad');
  for (const side of [LEFT, RIGHT]) {
    const bad = JSON.parse(await page.$eval(side, (p) => p.dataset.bad));
    const smallest = await count(page, side, 'smallest angle (°)');
    // Slivers are the triangles with a corner under 10°: there are some exactly when the smallest
    // angle reported is under 10°. A closed manifold has no open or non-manifold edge.
    assert.equal(bad.slivers > 0, smallest < 10, `${side}: ${JSON.stringify(bad)} vs ${smallest}`);
    assert.equal(bad.openEdges + bad.nonManifoldEdges, 0, side);
    // Crossing triangles are those of the pairs the analysis counted (settled() waited for it).
    const pairs = await count(page, side, 'crossing pairs');
    assert.ok(Number.isInteger(bad.crossing), `${side}: crossing not measured: ${JSON.stringify(bad)}`);
    assert.equal(bad.crossing > 0, pairs > 0, side);
    assert.ok(bad.crossing <= 2 * pairs, side);
  }
});

test('a long parse error wraps inside the editor, and the reference inserts a function', async () => {
  const { page } = await openDemo();
  await page.uncheck('#live');
  await page.fill('#source', 'union(sphere(0.5), translate(sphere(0.2), 0.5, 0.5, 0.5), rounded_bx(1, 1, 1, 0.1))');
  await page.waitForSelector('#editor-error:not([hidden])');
  const text = await page.textContent('#editor-error');
  assert.match(text, /did you mean 'rounded_box'\?/);
  const [box, area] = await page.evaluate(() => ['#editor-error', '#source'].map((s) => document.querySelector(s).getBoundingClientRect().toJSON()));
  assert.ok(box.right <= area.right + 1 && box.left >= area.left - 1, `${JSON.stringify(box)} in ${JSON.stringify(area)}`);
  await page.fill('#source', '');
  await page.click('#reference summary');
  await page.click('#reference button[data-name="torus"]');
  assert.equal(await page.inputValue('#source'), 'torus(R, r)');
  assert.ok(await page.$$eval('#reference dt', (d) => d.length) >= 40);
});

test('sliders set the options they stand beside: an angle in degrees becomes its cosine', async () => {
  const { page } = await openDemo();
  await page.uncheck('#live');
  await page.$eval('#theta-slider', (s) => { s.value = '60'; s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change')); });
  assert.equal(await page.inputValue('#theta'), '0.500');
  assert.equal(await page.textContent('#theta-deg'), '= 60.0°');
  await page.fill('#res', '40');
  await page.dispatchEvent('#res', 'change');
  assert.equal(await page.inputValue('#res-slider'), '40');
  await page.click('#run');
  await settled(page);
  // A looser θ finds fewer sharp edges on the same shape (60° between normals, not 25.8°).
  const loose = await count(page, LEFT, 'feature edges');
  await page.$eval('#theta-slider', (s) => { s.value = '25'; s.dispatchEvent(new Event('input')); });
  await page.click('#run');
  await settled(page);
  assert.ok(await count(page, LEFT, 'feature edges') >= loose);
});

test('"Smooth" relaxes both sides without moving a feature line or opening the mesh, and is kept in the link', async () => {
  const { page } = await openDemo();
  const edges = await count(page, LEFT, 'feature edges');
  const triangles = await count(page, LEFT, 'triangles');
  const shape = async () => [await stat(page, RIGHT, 'smallest angle (°)'), await stat(page, RIGHT, 'RMS distance')];
  const unsmoothed = await shape();
  await page.fill('#smooth', '3');
  await page.click('#run');
  await statsChanged(page, RIGHT, ['smallest angle (°)', 'RMS distance'], unsmoothed);
  await settled(page);
  for (const side of [LEFT, RIGHT]) {
    assert.equal(await stat(page, side, 'closed manifold'), 'yes', side);
    assert.equal(await stat(page, side, 'Euler characteristic'), '-8', side);
    assert.equal(await count(page, side, 'crossing pairs'), 0, side);
  }
  assert.equal(await count(page, LEFT, 'feature edges'), edges, 'EMC keeps its feature lines');
  assert.equal(await count(page, LEFT, 'triangles'), triangles, 'smoothing moves vertices only');
  assert.notDeepEqual(await shape(), unsmoothed, 'the right pane\'s triangles changed shape');
  const link = page.url();
  const again = await reopen(page, link);
  assert.equal(await again.inputValue('#smooth'), '3');
  await again.close();
});

test('"within … cells" bounds the decimation: a tighter bound keeps more triangles, EMC\'s max distance within it', async () => {
  const { page } = await openDemo();
  const res = Number(await page.inputValue('#res'));
  const b = (await page.inputValue('#bounds')).split(' ').map(Number);
  const cell = Math.max(b[3] - b[0], b[4] - b[1], b[5] - b[2]) / res;
  const decimated = async (cells) => {
    const before = await stat(page, LEFT, 'triangles');
    await page.fill('#decimate', '1');
    await page.fill('#decimate-error', String(cells));
    await page.click('#run');
    await statsChanged(page, LEFT, ['triangles'], [before]);
    await settled(page);
    assert.equal(await stat(page, LEFT, 'closed manifold'), 'yes', `within ${cells} cells`);
    assert.equal(await count(page, LEFT, 'crossing pairs'), 0, `within ${cells} cells`);
    const distance = await count(page, LEFT, 'max distance');
    // 1 % over for the f32 rounding of the mesh the numbers are taken from.
    assert.ok(distance <= 1.01 * cells * cell, `within ${cells} cells: max distance ${distance}, cell ${cell}`);
    return count(page, LEFT, 'triangles');
  };
  // EMC's own faces reach 0.11 cells from the surface at 48 cells (the teeth of docs/emc.md), and
  // decimation leaves a face alone rather than move it: the bounds here lie above that.
  const tight = await decimated(0.25);
  const loose = await decimated(1);
  assert.ok(loose < tight, `${loose} triangles within 1 cell, ${tight} within 0.25`);
  const again = await reopen(page, page.url());
  assert.equal(await again.inputValue('#decimate-error'), '1');
  await again.close();
});

test('"Decimate to" shrinks both sides to the target, closed, with the frame\'s topology, and is kept in the link', async () => {
  // 3 000 is within reach of both sides at 48 cells (EMC's corners and curved rims keep about
  // 1 800 vertices' worth of triangles; below that it stops short of the target).
  const { page } = await openDemo();
  const before = await count(page, LEFT, 'triangles');
  await page.fill('#decimate', '3000');
  await page.click('#run');
  await settled(page);
  for (const side of [LEFT, RIGHT]) {
    assert.ok(await count(page, side, 'triangles') <= 3000, side);
    assert.equal(await stat(page, side, 'closed manifold'), 'yes', side);
    assert.equal(await stat(page, side, 'Euler characteristic'), '-8', side);
    assert.equal(await count(page, side, 'crossing pairs'), 0, side);
  }
  assert.ok(before > 3 * 3000, `EMC had ${before} triangles before`);
  assert.ok(await count(page, LEFT, 'feature edges') > 0, 'EMC keeps its feature lines');
  const link = page.url();
  const again = await reopen(page, link);
  assert.equal(await again.inputValue('#decimate'), '3000');
  await again.close();
});

// The demo in a real browser: headless Chromium (Debian's) driven by playwright-core against the
// page served on localhost. Run by scripts/test.sh after the wasm package is built.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

const PORT = 8000 + Math.floor(Math.random() * 1000);
const URL = `http://127.0.0.1:${PORT}/`;
let server;
let browser;

before(async () => {
  server = spawn(process.execPath, ['scripts/serve.mjs', 'www', String(PORT)], { stdio: ['ignore', 'pipe', 'inherit'] });
  await new Promise((resolve, reject) => {
    server.stdout.once('data', resolve);
    server.once('exit', (code) => reject(new Error(`server exited with ${code}`)));
  });
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
});

after(async () => {
  await browser?.close();
  server?.kill();
});

async function openDemo() {
  const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(URL);
  await page.waitForSelector('#status[data-state="done"]', { timeout: 60_000 });
  return { page, errors };
}

const stat = (page, key) => page.$eval(`#stats tr[data-key="${key}"] td:last-child`, (td) => td.textContent);

test('the demo meshes the default scene and reports a closed manifold', async () => {
  const { page, errors } = await openDemo();
  assert.ok(Number((await stat(page, 'triangles')).replace(/,/g, '')) > 0);
  assert.equal(await stat(page, 'closed manifold'), 'yes');
  // The cube minus a ball that pokes through all six faces is a frame of genus 5.
  assert.equal(await stat(page, 'Euler characteristic'), '-8');
  assert.deepEqual(errors, []);
  await page.close();
});

test('choosing another scene re-meshes it with its own topology', async () => {
  const { page } = await openDemo();
  await page.evaluate(() => { document.querySelector('#status').dataset.state = 'pending'; });
  await page.selectOption('#scene', 'torus');
  await page.waitForSelector('#status[data-state="done"]');
  assert.equal(await stat(page, 'Euler characteristic'), '0');
  assert.equal(await stat(page, 'closed manifold'), 'yes');
  await page.close();
});

test('the viewport draws the mesh (not a blank canvas)', async () => {
  const { page } = await openDemo();
  await page.waitForTimeout(300);
  const colours = await page.evaluate(() => {
    const src = document.querySelector('#viewport canvas');
    const c = document.createElement('canvas');
    c.width = 64; c.height = 64;
    const ctx = c.getContext('2d');
    ctx.drawImage(src, 0, 0, 64, 64);
    const data = ctx.getImageData(0, 0, 64, 64).data;
    const seen = new Set();
    for (let i = 0; i < data.length; i += 4) seen.add((data[i] >> 4) << 8 | (data[i + 1] >> 4) << 4 | (data[i + 2] >> 4));
    return seen.size;
  });
  assert.ok(colours > 8, `only ${colours} distinct colours: the mesh was not drawn`);
  await page.screenshot({ path: 'target/demo-screenshot.png' });
  await page.close();
});

test('a bad request shows a clear error instead of freezing the tab', async () => {
  const { page } = await openDemo();
  await page.fill('#res', '2048');
  await page.click('#run');
  await page.waitForSelector('#status[data-state="error"]');
  const message = await page.textContent('#status');
  assert.match(message, /larger than the limit/);
  await page.close();
});

test('the editor shows the scene program, and an edited program is meshed instead', async () => {
  const { page, errors } = await openDemo();
  assert.match(await page.inputValue('#source'), /subtract\(box\(0\.6, 0\.6, 0\.6\), sphere\(0\.75\)\)/);
  await page.evaluate(() => { document.querySelector('#status').dataset.state = 'pending'; });
  await page.selectOption('#scene', 'rocket');
  await page.waitForSelector('#status[data-state="done"]');
  assert.match(await page.inputValue('#source'), /rotate\(fin, 0, 0, 1, 82\)/);
  await page.fill('#source', '// a ring\ntorus(0.5, 0.2)');
  await page.evaluate(() => { document.querySelector('#status').dataset.state = 'pending'; });
  await page.click('#run');
  await page.waitForSelector('#status[data-state="done"]');
  assert.equal(await stat(page, 'Euler characteristic'), '0');
  await page.fill('#source', 'union(sphere(0.5),\n  bx(1, 1, 1))');
  await page.click('#run');
  await page.waitForSelector('#status[data-state="error"]');
  assert.match(await page.textContent('#status'), /^2:3: unknown function 'bx'/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('EMC draws feature lines', async () => {
  const { page } = await openDemo();
  await page.evaluate(() => { document.querySelector('#status').dataset.state = 'pending'; });
  await page.selectOption('#method', 'emc');
  await page.click('#run');
  await page.waitForSelector('#status[data-state="done"]');
  assert.ok(Number((await stat(page, 'feature edges')).replace(/,/g, '')) > 0);
  assert.equal(await stat(page, 'closed manifold'), 'yes');
  await page.close();
});

// The evaluator's speed in the browser (the wasm build in headless Chromium timing itself with
// measureEvaluator), the counterpart of `cargo bench --bench expr`, and the demo's click-to-shown
// time: from a click on "mesh" to the first frame drawn after the left pane's mesh arrived, with the
// warm worker, on the gear at res 64 (EMC left, MC right); and how long a download's bytes take
// (exportMesh per format on the same mesh); and MC's extraction on a sampled sphere, the
// counterpart of `cargo bench --bench marching_cubes`. Needs the package built
// (scripts/build-wasm.sh). Usage: node scripts/bench-browser.mjs [minMs] [repeats]
import { serve, launch, packagePage, inPage } from './browser.mjs';

const BLOB = `r = 0.3; s = translate(sphere(r), 0.5, 0, 0);
body = smooth_union(union(s, rotate(s, 0, 0, 1, 120), rotate(s, 0, 0, 1, 240)), torus(0.6, 0.1), 0.1);
subtract(body, rotate(cylinder(0.15, 2), 1, 0, 0, 90))`;
const minMs = Number(process.argv[2] ?? 300);
const repeats = Number(process.argv[3] ?? 7);

const server = await serve('www');
const browser = await launch();
try {
  const page = await packagePage(browser, server.url);
  const rows = await inPage(page, (m, [blob, minMs]) => {
    const programs = { blob, rocket: m.sceneSource('rocket') };
    return Object.entries(programs).map(([name, text]) => ({ name, ...m.measureEvaluator(text, 4096, minMs) }));
  }, [BLOB, minMs]);
  console.log(`Chromium ${browser.version()}, ns per point (per box for interval); x = speed-up over the tree walk`);
  console.log('| program | instructions | tree walk | value | value+gradient | batch of 64 | gradients, batch of 64 | interval |');
  console.log('|---|---|---|---|---|---|---|---|');
  for (const r of rows) {
    const cell = (v) => `${v.toFixed(1)} (${(r.treeWalk / v).toFixed(1)}x)`;
    console.log(`| ${r.name} | ${r.instructions} | ${r.treeWalk.toFixed(1)} | ${cell(r.value)} | ${cell(r.valueGradient)} | ${cell(r.batch)} | ${cell(r.gradientBatch)} | ${cell(r.interval)} |`);
  }
  const exports = await inPage(page, (m) => {
    const gear = m.meshScene('gear', { method: 'emc', res: 64 });
    const row = { triangles: gear.stats.triangles };
    for (const format of ['obj', 'stl', 'ply', 'glb']) {
      const t = performance.now();
      const bytes = m.exportMesh(gear, format);
      row[format] = [performance.now() - t, bytes.length];
    }
    return row;
  });
  const grids = await inPage(page, (m) => [128, 256].map((n) => {
    // The sampled sphere of `cargo bench --bench marching_cubes` (radius 0.8 in [-1, 1]³, n cells).
    const values = new Float32Array((n + 1) ** 3);
    let at = 0;
    for (let k = 0; k <= n; k++) for (let j = 0; j <= n; j++) for (let i = 0; i <= n; i++) {
      const [x, y, z] = [i, j, k].map((v) => -1 + (2 * v) / n);
      values[at++] = Math.hypot(x, y, z) - 0.8;
    }
    const extract = [];
    for (let r = 0; r < 5; r++) {
      extract.push(m.meshGrid(values, [n + 1, n + 1, n + 1], [-1, -1, -1, 1, 1, 1], { method: 'mc' }).stats.phases_ms.extract);
    }
    return { n, extract: extract.sort((a, b) => a - b)[2] };
  }));
  await page.close();
  console.log('\nMC extraction on a sampled sphere (meshGrid, median of 5):');
  for (const g of grids) console.log(`  ${g.n}³: ${g.extract.toFixed(1)} ms`);
  console.log(`\nexportMesh on the gear (EMC res 64, ${exports.triangles} triangles), ms and bytes, on the main thread:`);
  for (const format of ['obj', 'stl', 'ply', 'glb']) console.log(`  ${format}: ${exports[format][0].toFixed(0)} ms, ${exports[format][1]} bytes`);
  console.log();
  await clickToShown(browser, server.url);
} finally {
  await browser.close();
  server.close();
}

/** Median click-to-shown and meshing times of the demo's left pane over `repeats` re-meshes. */
async function clickToShown(browser, url) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 800 } });
  const idle = () => page.waitForFunction(() => [...document.querySelectorAll('.pane')]
    .every((p) => p.dataset.state === 'done' || p.dataset.state === 'error'), null, { timeout: 120_000 });
  await page.goto(url);
  await idle();
  await page.selectOption('.pane[data-side="right"] .method', 'mc');
  await page.fill('#res', '64');
  await page.click('#gallery button[data-scene="gear"]');
  await idle();
  const rows = [];
  for (let i = 0; i < repeats; i++) {
    rows.push(await page.evaluate(() => new Promise((resolve) => {
      const pane = document.querySelector('.pane[data-side="left"]');
      const started = performance.now();
      const seen = new MutationObserver(() => {
        if (pane.dataset.state === 'busy') return;
        seen.disconnect();
        requestAnimationFrame(() => {
          const ms = pane.querySelector('.stats tr[data-key="meshing (ms)"] td:last-child')?.textContent;
          resolve({ shown: performance.now() - started, meshing: Number(ms?.replace(/,/g, '')), state: pane.dataset.state });
        });
      });
      seen.observe(pane, { attributes: true, attributeFilter: ['data-state'] });
      document.querySelector('#run').click();
    })));
  }
  await page.close();
  const median = (xs) => xs.sort((a, b) => a - b)[xs.length >> 1];
  const failed = rows.filter((r) => r.state !== 'done');
  if (failed.length) throw new Error(`the demo failed to mesh the gear: ${JSON.stringify(failed)}`);
  console.log(`demo, gear, EMC res 64, ${repeats} re-meshes: click to shown ${median(rows.map((r) => r.shown)).toFixed(0)} ms (median), of which meshing ${median(rows.map((r) => r.meshing)).toFixed(0)} ms`);
}

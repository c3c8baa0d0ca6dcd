// The evaluator's speed in the browser (the wasm build in headless Chromium timing itself with
// measureEvaluator), the counterpart of `cargo bench --bench expr`. Needs the package built
// (scripts/build-wasm.sh). Usage: node scripts/bench-browser.mjs [minMs]
import { serve, launch, packagePage, inPage } from './browser.mjs';

const BLOB = `r = 0.3; s = translate(sphere(r), 0.5, 0, 0);
body = smooth_union(union(s, rotate(s, 0, 0, 1, 120), rotate(s, 0, 0, 1, 240)), torus(0.6, 0.1), 0.1);
subtract(body, rotate(cylinder(0.15, 2), 1, 0, 0, 90))`;
const minMs = Number(process.argv[2] ?? 300);

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
} finally {
  await browser.close();
  server.close();
}

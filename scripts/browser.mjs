// Shared by the browser tests and the browser benchmark: serve www/ on a free localhost port and
// launch Debian's Chromium headless through playwright-core (see ../shared/TOOLCHAIN.md).
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

/**
 * Serves `dir` on 127.0.0.1 at a random port, cross-origin isolated unless `isolated` is false;
 * resolves to { url, close }.
 */
export async function serve(dir = 'www', { isolated = true } = {}) {
  const port = 8000 + Math.floor(Math.random() * 2000);
  const args = ['scripts/serve.mjs', dir, String(port), ...(isolated ? [] : ['--not-isolated'])];
  const server = spawn(process.execPath, args, { stdio: ['ignore', 'pipe', 'inherit'] });
  await new Promise((resolve, reject) => {
    server.stdout.once('data', resolve);
    server.once('exit', (code) => reject(new Error(`server exited with ${code}`)));
  });
  return { url: `http://127.0.0.1:${port}/`, close: () => server.kill() };
}

/** Headless Chromium ($CHROMIUM or /usr/bin/chromium). */
export function launch() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

/** A page of `url`'s origin with the wasm package imported and initialised. */
export async function packagePage(browser, url) {
  const page = await browser.newPage();
  // Any page of the origin will do; scripts import the package themselves.
  await page.goto(`${url}style.css`);
  await page.evaluate(async () => {
    const m = await import('./pkg/isoforge.js');
    await m.default();
  });
  return page;
}

/**
 * Runs `body(m, arg)` in `page` with the package module `m`; resolves to what it returns
 * (JSON-able). `body` is sent as source text, so it must not close over Node variables.
 */
export const inPage = (page, body, arg) => page.evaluate(async ([src, arg]) => {
  const m = await import('./pkg/isoforge.js');
  // eslint-disable-next-line no-new-func
  return new Function('m', 'arg', `return (${src})(m, arg);`)(m, arg);
}, [body.toString(), arg]);

/**
 * For a node:test file whose tests all run in one package page: registers `before`/`after` hooks
 * that serve www/, launch Chromium and open the page, and returns `inPage(body, arg)` for it.
 */
export function sharedPackagePage({ before, after }) {
  let server;
  let browser;
  let page;
  before(async () => {
    server = await serve('www');
    browser = await launch();
    page = await packagePage(browser, server.url);
  });
  after(async () => {
    await browser?.close();
    server?.close();
  });
  return (body, arg) => inPage(page, body, arg);
}

/**
 * What the canvas at `selector` shows, downscaled to `width`×`height`: the number of distinct
 * colours (12-bit) and the share of pixels that are not near-white. A blank canvas has one colour.
 */
export function canvasColours(page, selector, width = 64, height = 48) {
  return page.$eval(selector, (src, [w, h]) => {
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const ctx = c.getContext('2d');
    ctx.drawImage(src, 0, 0, w, h);
    const data = ctx.getImageData(0, 0, w, h).data;
    const seen = new Set();
    let nonWhite = 0;
    for (let i = 0; i < data.length; i += 4) {
      seen.add((data[i] >> 4) << 8 | (data[i + 1] >> 4) << 4 | (data[i + 2] >> 4));
      if (data[i] + data[i + 1] + data[i + 2] < 3 * 250) nonWhite++;
    }
    return { colours: seen.size, covered: nonWhite / (w * h) };
  }, [width, height]);
}

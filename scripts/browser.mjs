// Shared by the browser tests and the browser benchmark: serve www/ on a free localhost port and
// launch Debian's Chromium headless through playwright-core (see ../shared/TOOLCHAIN.md).
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

/** Serves `dir` on 127.0.0.1 at a random port; resolves to { url, close }. */
export async function serve(dir = 'www') {
  const port = 8000 + Math.floor(Math.random() * 2000);
  const server = spawn(process.execPath, ['scripts/serve.mjs', dir, String(port)], { stdio: ['ignore', 'pipe', 'inherit'] });
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

// What the demo's browser tests share: the server and browser for a test file, a fresh page per
// test (closed after it, so a failed test does not leave work running), and readers of the panes.
import assert from 'node:assert/strict';
import { serve, launch } from '../../scripts/browser.mjs';

export const LEFT = '.pane[data-side="left"]';
export const RIGHT = '.pane[data-side="right"]';

/**
 * Waits until neither pane is meshing, nor measuring a mesh it shows; fails on a pane error
 * unless `allowErrors`.
 */
export async function settled(page, { allowErrors = false } = {}) {
  await page.waitForFunction(() => {
    const panes = [...document.querySelectorAll('.pane')];
    const idle = (p) => ['error', 'stopped'].includes(p.dataset.state) || (p.dataset.state === 'done' && p.dataset.measured !== 'pending');
    return panes.length === 2 && panes.every(idle);
  }, null, { timeout: 120_000 });
  if (!allowErrors) {
    for (const side of [LEFT, RIGHT]) {
      const state = await page.$eval(side, (p) => [p.dataset.state, p.querySelector('.state').textContent]);
      assert.equal(state[0], 'done', `${side}: ${state[1]}`);
      assert.equal(await page.$eval(side, (p) => p.dataset.measured), 'yes', `${side}: measured`);
    }
  }
}

/**
 * Opens `link` in a new page of `page`'s context and waits until it has meshed: the page's module
 * awaits its wasm before it reads the link into the fields, so a field read as soon as `goto`
 * returns can still be empty.
 */
export async function reopen(page, link) {
  const again = await page.context().newPage();
  await again.goto(link);
  await settled(again);
  return again;
}

export const stat = (page, side, key) => page.$eval(`${side} .stats tr[data-key="${key}"] td:last-child`, (td) => td.textContent);
export const count = async (page, side, key) => Number((await stat(page, side, key)).replace(/,/g, ''));

/**
 * Waits until one of the numbers `keys` of a pane differs from `old` (theirs, read before a new
 * run was asked for): the panes may still read as settled from the last mesh when the new request
 * starts, so `settled` alone could read the old numbers.
 */
export async function statsChanged(page, side, keys, old) {
  await page.waitForFunction(([side, keys, old]) => keys.some((key, i) =>
    document.querySelector(`${side} .stats tr[data-key="${key}"] td:last-child`)?.textContent !== old[i]),
  [side, keys, old], { timeout: 60_000 });
}

/**
 * Registers the hooks of a test file and returns `{ openDemo, server }`: `openDemo(options)` opens
 * the demo in a new page (of a new browser context unless `context` is given) and waits for
 * its first meshes; `url` overrides the address (a shared link, say).
 */
export function demoSuite({ before, after, afterEach }) {
  const env = {};
  const open = new Set();
  before(async () => {
    env.server = await serve('www');
    env.browser = await launch();
  });
  after(async () => {
    await env.browser?.close();
    env.server?.close();
  });
  afterEach(async () => {
    for (const page of open) await page.close();
    open.clear();
  });
  async function openDemo({ viewport = { width: 1400, height: 800 }, context = null, url = null } = {}) {
    const ctx = context ?? await env.browser.newContext({ viewport });
    const page = await ctx.newPage();
    open.add(page);
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(url ?? env.server.url);
    await settled(page);
    return { page, errors, context: ctx };
  }
  return { openDemo, env };
}

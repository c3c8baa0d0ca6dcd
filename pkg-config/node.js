// The package under Node (≥ 20): the same module as isoforge.js, with an init() that reads
// isoforge_bg.wasm from the package's folder where the browser build would fetch it (Node's fetch
// has no file: URLs). Package.json's "node" condition picks this file for `import 'isoforge'`.
import { readFile } from 'node:fs/promises';
import init from './isoforge.js';

export * from './isoforge.js';

/** Loads the module; with no argument, from the file beside this one. */
export default async function initNode(input) {
  return init(input ?? { module_or_path: await readFile(new URL('./isoforge_bg.wasm', import.meta.url)) });
}

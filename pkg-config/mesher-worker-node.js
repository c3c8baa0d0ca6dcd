// The mesher's worker under Node: gives mesher-worker.js the `self` of a Web Worker over
// worker_threads' parentPort, and the wasm bytes read from disk for its init().
import { parentPort } from 'node:worker_threads';
import { readFileSync } from 'node:fs';

// `self` is the global object, as in a worker (js-sys looks things such as `performance` up on it).
globalThis.self = globalThis;
globalThis.postMessage = (message, transfer) => parentPort.postMessage(message, transfer);
Object.defineProperty(globalThis, 'onmessage', {
  set(handler) {
    parentPort.on('message', (data) => handler({ data }));
  },
});
globalThis.ISOFORGE_WASM = { module_or_path: readFileSync(new URL('./isoforge_bg.wasm', import.meta.url)) };
await import('./mesher-worker.js');

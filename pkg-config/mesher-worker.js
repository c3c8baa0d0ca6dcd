// The worker behind createMesher() (mesher.js): runs the package's meshing functions off the main
// thread, one call at a time, and sends the results back with their typed arrays transferred,
// not copied. It stays alive between calls, keeping its compiled module.
//
// Where the page is cross-origin isolated and the package has its threaded build beside this
// script (threads/isoforge.js, shared memory), that build is loaded instead and starts a pool of
// Web Workers for the meshers' parallel sections; elsewhere, or if it fails to start, the plain
// build runs on this worker's one thread. The meshes are the same either way.
import init, * as plain from './isoforge.js';

// What a page may ask for: the meshing, analysis and export functions, nothing else of the module.
const CALLS = new Set(['meshScene', 'meshExpr', 'meshCsg', 'meshGrid', 'analyzeMesh', 'exportMesh', 'threadCount']);
// Progress events at most this often (ms).
const PROGRESS_EVERY = 100;
// The most pool threads started: sampling and slabs stop scaling well before this on the machines
// browsers run on, and each thread costs a copy of the module's instance.
const MAX_THREADS = 8;

/** Shared with the page where it can be (see mesher.js): job ids up to flag[0] are cancelled. */
let cancelFlag = null;
let current = 0;
let lastProgress = 0;
/** The module in use, once loaded. */
let isoforge = null;
let ready = null;

/**
 * Loads and initialises the module: `threads` 1 asks for the plain build, 0 for as many threads as
 * the machine has cores (at most MAX_THREADS), more for that many.
 */
async function load(threads) {
  // `ISOFORGE_WASM` is set only by the Node wrapper (mesher-worker-node.js); browsers fetch the file.
  // A bundler renames this script (Vite: assets/mesher-worker-<hash>.js) and puts no threads/
  // beside it, so there the threaded build is asked for only when a thread count was given (the
  // app copied threads/ next to the emitted script): otherwise one failed request less.
  const bundled = !new URL(import.meta.url).pathname.endsWith('/mesher-worker.js');
  if (threads !== 1 && self.crossOriginIsolated && !globalThis.ISOFORGE_WASM && (!bundled || threads > 1)) {
    try {
      // Not a literal: a bundler that emits `new URL('<literal>', import.meta.url)` as an asset
      // would copy the threaded glue without the worker helpers it imports.
      const url = new URL(['.', 'threads', 'isoforge.js'].join('/'), import.meta.url).href;
      const threaded = await import(/* @vite-ignore */ url);
      await threaded.default();
      await threaded.startThreads(threads || Math.min(MAX_THREADS, navigator.hardwareConcurrency || 1));
      return threaded;
    } catch {
      // No threaded build here, or no workers to be had: one thread.
    }
  }
  await init(globalThis.ISOFORGE_WASM);
  return plain;
}

function start(threads) {
  ready = load(threads).then((module) => {
    isoforge = module;
    isoforge.setProgressHook((phase, fraction) => {
      const now = performance.now();
      if (now - lastProgress >= PROGRESS_EVERY) {
        lastProgress = now;
        self.postMessage({ id: current, progress: { phase, fraction } });
      }
      return cancelFlag !== null && Atomics.load(cancelFlag, 0) >= current;
    });
  });
}

self.onmessage = async ({ data }) => {
  // The first message from mesher.js, before any call.
  if (data.setup) {
    if (data.setup.cancelFlag) cancelFlag = new Int32Array(data.setup.cancelFlag);
    start(data.setup.threads ?? 0);
    return;
  }
  const { id, call, args } = data;
  try {
    if (!ready) start(0);
    await ready;
    if (!CALLS.has(call) || typeof isoforge[call] !== 'function') throw new Error(`unknown call '${call}'`);
    current = id;
    lastProgress = performance.now();
    const result = isoforge[call](...args);
    const buffers = ArrayBuffer.isView(result)
      ? [result.buffer]
      : Object.values(result).filter(ArrayBuffer.isView).map((a) => a.buffer);
    self.postMessage({ id, result }, buffers);
  } catch (e) {
    self.postMessage({ id, error: String(e?.message ?? e) });
  }
};

// The worker behind createMesher() (mesher.js): runs the package's meshing functions off the main
// thread, one call at a time, and sends the results back with their typed arrays transferred,
// not copied. It stays alive between calls, keeping its compiled module.
import init, * as isoforge from './isoforge.js';

// What a page may ask for: the meshing, analysis and export functions, nothing else of the module.
const CALLS = new Set(['meshScene', 'meshExpr', 'meshCsg', 'meshGrid', 'analyzeMesh', 'exportMesh']);
// Progress events at most this often (ms).
const PROGRESS_EVERY = 100;

/** Shared with the page where it can be (see mesher.js): job ids up to flag[0] are cancelled. */
let cancelFlag = null;
let current = 0;
let lastProgress = 0;

// `ISOFORGE_WASM` is set only by the Node wrapper (mesher-worker-node.js); browsers fetch the file.
const ready = init(globalThis.ISOFORGE_WASM).then(() => {
  isoforge.setProgressHook((phase, fraction) => {
    const now = performance.now();
    if (now - lastProgress >= PROGRESS_EVERY) {
      lastProgress = now;
      self.postMessage({ id: current, progress: { phase, fraction } });
    }
    return cancelFlag !== null && Atomics.load(cancelFlag, 0) >= current;
  });
});

self.onmessage = async ({ data }) => {
  if (data.cancelFlag) {
    cancelFlag = new Int32Array(data.cancelFlag);
    return;
  }
  const { id, call, args } = data;
  try {
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

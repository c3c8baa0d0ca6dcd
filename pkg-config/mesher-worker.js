// The worker behind createMesher() (mesher.js): runs the package's meshing functions off the main
// thread and sends the results back with their typed arrays transferred, not copied.
import init, * as isoforge from './isoforge.js';

// What a page may ask for: the meshing and export functions, nothing else of the module.
const CALLS = new Set(['meshScene', 'meshExpr', 'meshCsg', 'meshGrid', 'exportMesh']);
const ready = init();

self.onmessage = async ({ data: { id, call, args } }) => {
  try {
    await ready;
    if (!CALLS.has(call) || typeof isoforge[call] !== 'function') throw new Error(`unknown call '${call}'`);
    const result = isoforge[call](...args);
    const buffers = ArrayBuffer.isView(result)
      ? [result.buffer]
      : Object.values(result).filter(ArrayBuffer.isView).map((a) => a.buffer);
    self.postMessage({ id, result }, buffers);
  } catch (e) {
    self.postMessage({ id, error: String(e?.message ?? e) });
  }
};

// createMesher(): the package's meshing functions in a Web Worker, so a page never freezes while a
// mesh is computed, and a newer request can cancel one in flight.
//
// Meshing is one synchronous WebAssembly call, which cannot be interrupted from outside; so
// cancelling terminates the worker (and with it the call) and the next request starts a fresh
// one. That costs a module instantiation (a few milliseconds), far less than waiting.

/** Thrown (as the rejection of a pending call) when `cancel()` or an AbortSignal stopped it. */
export class MeshingCancelled extends Error {
  constructor() {
    super('meshing cancelled');
    this.name = 'AbortError';
  }
}

export function createMesher({ workerUrl } = {}) {
  let worker = null;
  let nextId = 1;
  const pending = new Map();

  const failAll = (error) => {
    for (const { reject } of pending.values()) reject(error);
    pending.clear();
  };

  const start = () => {
    // Bundlers (Vite, webpack, Parcel) find and emit the worker script only from this literal form.
    worker = workerUrl
      ? new Worker(workerUrl, { type: 'module' })
      : new Worker(new URL('./mesher-worker.js', import.meta.url), { type: 'module' });
    worker.onmessage = ({ data: { id, result, error } }) => {
      const job = pending.get(id);
      if (!job) return;
      pending.delete(id);
      if (error !== undefined) job.reject(new Error(error));
      else job.resolve(result);
    };
    // A crash (out of memory, say) loses the worker and every call in it.
    worker.onerror = (event) => {
      event.preventDefault();
      worker.terminate();
      worker = null;
      failAll(new Error(`the meshing worker failed: ${event.message || 'out of memory?'}`));
    };
  };

  const cancel = () => {
    if (worker) worker.terminate();
    worker = null;
    failAll(new MeshingCancelled());
  };

  const call = (name, args, { signal } = {}) => new Promise((resolve, reject) => {
    if (signal?.aborted) return reject(new MeshingCancelled());
    if (!worker) start();
    const id = nextId++;
    pending.set(id, { resolve, reject });
    signal?.addEventListener('abort', () => { if (pending.has(id)) cancel(); }, { once: true });
    worker.postMessage({ id, call: name, args });
  });

  return {
    meshScene: (name, options, control) => call('meshScene', [name, options], control),
    meshExpr: (text, options, control) => call('meshExpr', [text, options], control),
    meshCsg: (tree, options, control) => call('meshCsg', [typeof tree === 'string' ? tree : JSON.stringify(tree), options], control),
    meshGrid: (values, dims, bounds, options, control) => call('meshGrid', [values, dims, bounds, options], control),
    exportMesh: (result, format, control) => call('exportMesh', [result, format], control),
    /** Calls in flight. */
    get busy() { return pending.size; },
    cancel,
    terminate: cancel,
  };
}

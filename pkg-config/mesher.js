// createMesher(): the package's meshing functions in a Web Worker, so a page never freezes while a
// mesh is computed, and a newer request can cancel one in flight.
//
// The worker stays warm: it keeps its compiled module between calls, so a call pays only for
// meshing. Calls run one at a time, in order; `cancel()` rejects the calls still waiting at once
// (they never reach the worker) and stops the one running:
// - where the page can share memory with the worker (`crossOriginIsolated`, so SharedArrayBuffer
//   exists), through a flag the meshers read at their checkpoints between slabs and octree
//   levels: the call stops within a few milliseconds and the worker stays;
// - elsewhere the running call cannot be told, so it is left to finish (its result is dropped).
// Either way, a call still running `staleMs` after its cancel (default 250 ms) has its worker
// terminated, and a fresh one takes what comes next: short calls never pay for a restart, long
// ones never hold up their successor by more than `staleMs`.

/** Thrown (as the rejection of a pending call) when `cancel()` or an AbortSignal stopped it. */
export class MeshingCancelled extends Error {
  constructor() {
    super('meshing cancelled');
    this.name = 'AbortError';
  }
}

const CANCELLED = 'meshing cancelled';

/** The arrays of a result the worker reads: the rest (stats, feature lines) is not copied there. */
const meshArrays = ({ positions, normals, indices }) => ({ positions, normals, indices });

export function createMesher({ workerUrl, staleMs, threads } = {}) {
  // Bundlers (Vite, webpack, Parcel) find and emit the worker script only from this literal form.
  const spawn = () => (workerUrl
    ? new Worker(workerUrl, { type: 'module' })
    : new Worker(new URL('./mesher-worker.js', import.meta.url), { type: 'module' }));
  const shared = globalThis.crossOriginIsolated === true && typeof SharedArrayBuffer === 'function';
  return createMesherWith(spawn, { staleMs, shared, threads });
}

/**
 * The mesher over workers made by `spawn()` (anything with `onmessage`, `onerror`, `postMessage`
 * and `terminate`, as a Web Worker has); `shared` says whether it may share a SharedArrayBuffer
 * with them. For the Node entry (mesher-node.js); pages use createMesher.
 */
export function createMesherWith(spawn, { staleMs = 250, shared = false, threads = 0 } = {}) {
  let worker = null;
  let nextId = 1;
  /** Calls not yet sent, oldest first: { id, name, args, resolve, reject, onProgress }. */
  const queue = [];
  /** The call the worker is running, or null. */
  let running = null;
  let staleTimer = null;
  // Job ids up to cancelFlag[0] are cancelled; the worker's progress hook reads it.
  const cancelFlag = shared ? new Int32Array(new SharedArrayBuffer(4)) : null;

  const start = () => {
    worker = spawn();
    worker.postMessage({ setup: { cancelFlag: cancelFlag?.buffer, threads } });
    worker.onmessage = ({ data: { id, result, error, progress } }) => {
      const job = running;
      if (!job || job.id !== id) return;
      if (progress) {
        job.onProgress?.(progress);
        return;
      }
      finish();
      if (job.abandoned) return;
      if (error === CANCELLED) job.reject(new MeshingCancelled());
      else if (error !== undefined) job.reject(new Error(error));
      else job.resolve(result);
    };
    // A crash (out of memory, say) loses the worker and the call it was running.
    worker.onerror = (event) => {
      event.preventDefault();
      const job = running;
      stop();
      if (job && !job.abandoned) job.reject(new Error(`the meshing worker failed: ${event.message || 'out of memory?'}`));
      pump();
    };
  };

  /** The running call is over: send the next one. */
  const finish = () => {
    running = null;
    clearTimeout(staleTimer);
    staleTimer = null;
    pump();
  };

  const stop = () => {
    worker?.terminate();
    worker = null;
    running = null;
    clearTimeout(staleTimer);
    staleTimer = null;
  };

  const pump = () => {
    if (running || queue.length === 0) return;
    if (!worker) start();
    running = queue.shift();
    const { id, name, args } = running;
    worker.postMessage({ id, call: name, args });
  };

  const cancel = () => {
    for (const job of queue.splice(0)) job.reject(new MeshingCancelled());
    if (!running || running.abandoned) return;
    running.abandoned = true;
    running.reject(new MeshingCancelled());
    if (cancelFlag) Atomics.store(cancelFlag, 0, running.id);
    // Without shared memory, or in a stretch without checkpoints, a call may not stop: past
    // `staleMs` the worker goes, and a fresh one takes the next call.
    const stale = running;
    staleTimer = setTimeout(() => {
      if (running !== stale) return;
      stop();
      pump();
    }, staleMs);
  };

  const call = (name, args, { signal, onProgress } = {}) => new Promise((resolve, reject) => {
    if (signal?.aborted) return reject(new MeshingCancelled());
    const job = { id: nextId++, name, args, resolve, reject, onProgress, abandoned: false };
    signal?.addEventListener('abort', () => {
      const waiting = queue.indexOf(job);
      if (waiting >= 0) {
        queue.splice(waiting, 1);
        reject(new MeshingCancelled());
      } else if (running === job) {
        cancel();
      }
    }, { once: true });
    queue.push(job);
    pump();
  });

  return {
    meshScene: (name, options, control) => call('meshScene', [name, options], control),
    meshExpr: (text, options, control) => call('meshExpr', [text, options], control),
    meshCsg: (tree, options, control) => call('meshCsg', [typeof tree === 'string' ? tree : JSON.stringify(tree), options], control),
    meshGrid: (values, dims, bounds, options, control) => call('meshGrid', [values, dims, bounds, options], control),
    analyzeMesh: (result, options, control) => call('analyzeMesh', [meshArrays(result), options], control),
    exportMesh: (result, format, control) => call('exportMesh', [meshArrays(result), format], control),
    threadCount: (control) => call('threadCount', [], control),
    /** Calls in flight: the running one and those waiting. */
    get busy() { return queue.length + (running && !running.abandoned ? 1 : 0); },
    /** Whether a running call can be stopped at once (shared memory), rather than left to finish. */
    get stopsAtOnce() { return cancelFlag !== null; },
    cancel,
    terminate: () => {
      cancel();
      stop();
    },
  };
}

// isoforge/mesher under Node (≥ 20): the same createMesher as in a browser, its worker a
// worker_threads Worker behind the small part of the Web Worker interface the mesher uses. Node
// always has SharedArrayBuffer, so cancel() stops a running call at its next checkpoint.
// A worker does not keep the process alive while no call is running.
import { Worker } from 'node:worker_threads';
import { createMesherWith } from './mesher.js';

export { MeshingCancelled } from './mesher.js';

/** worker_threads' Worker seen through `onmessage`, `onerror`, `postMessage` and `terminate`. */
class NodeWorker {
  constructor(url) {
    this.worker = new Worker(url);
    this.worker.unref();
    this.onmessage = null;
    this.onerror = null;
    this.worker.on('message', (data) => {
      // A result or error ends the call: idle again, the process may exit.
      if (!data.progress) this.worker.unref();
      this.onmessage?.({ data });
    });
    this.worker.on('error', (e) => this.onerror?.({ message: e.message, preventDefault() {} }));
  }

  postMessage(message, transfer) {
    if (message.call) this.worker.ref();
    this.worker.postMessage(message, transfer);
  }

  terminate() {
    this.worker.terminate();
  }
}

export function createMesher({ staleMs } = {}) {
  return createMesherWith(() => new NodeWorker(new URL('./mesher-worker-node.js', import.meta.url)), { staleMs, shared: true });
}

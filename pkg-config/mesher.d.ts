// Non-blocking meshing in a Web Worker:
//
//   import { createMesher } from "isoforge/mesher";
//   const mesher = createMesher();
//   const result = await mesher.meshExpr("sphere(0.8)", { method: "emc", res: 64 });
//
// Each call resolves to the same MeshResult as the synchronous function of the same name, its
// typed arrays transferred from the worker. The worker stays warm between calls (its compiled
// module kept), and calls run one at a time in order. `cancel()` (or aborting a call's signal)
// rejects the pending calls with a MeshingCancelled (name "AbortError") at once; the running call
// stops at its next checkpoint where the page is cross-origin isolated (SharedArrayBuffer), and is
// otherwise left to finish unseen, its worker replaced if it runs `staleMs` longer.

import type { AnalyzeOptions, CsgNode, GridOptions, MeshAnalysis, MeshOptions, MeshResult } from "./isoforge.js";

/** Optional control of one call. */
export interface CallControl {
  /** Aborting it cancels this call (and, if it is running, stops it like cancel()). */
  signal?: AbortSignal;
  /**
   * Called while the call runs, at most every 100 ms, with the phase (a key of
   * `stats.phases_ms`, or "analysis") and how far it got (0 to 1).
   */
  onProgress?: (progress: { phase: string; fraction: number }) => void;
}

/** The rejection of calls stopped by cancel() or an AbortSignal. */
export class MeshingCancelled extends Error {
  readonly name: "AbortError";
}

/** File formats of exportMesh. */
export type ExportFormat = "obj" | "stl" | "ply" | "glb";

export interface Mesher {
  meshScene(name: string, options?: MeshOptions, control?: CallControl): Promise<MeshResult>;
  meshExpr(text: string, options?: MeshOptions, control?: CallControl): Promise<MeshResult>;
  meshCsg(tree: string | CsgNode | { toJSON(): CsgNode }, options?: MeshOptions, control?: CallControl): Promise<MeshResult>;
  meshGrid(
    values: Float32Array | Uint8Array | Uint16Array | ArrayBuffer,
    dims: [number, number, number],
    bounds: [number, number, number, number, number, number],
    options?: GridOptions,
    control?: CallControl,
  ): Promise<MeshResult>;
  /**
   * analyzeMesh in the worker: the mesh's error against `options.expr` / `options.csg` and its
   * crossing triangles, for a result already shown (its arrays are copied, not transferred).
   */
  analyzeMesh(result: MeshResult, options?: AnalyzeOptions, control?: CallControl): Promise<MeshAnalysis>;
  /** The mesh as file bytes (the arrays of `result` are copied to the worker, not transferred). */
  exportMesh(result: MeshResult, format: ExportFormat, control?: CallControl): Promise<Uint8Array<ArrayBuffer>>;
  /**
   * Threads the worker meshes on: more than 1 where the page is cross-origin isolated and the
   * package's threaded build (threads/) loaded beside the worker script, else 1.
   */
  threadCount(control?: CallControl): Promise<number>;
  /** Calls in flight: the running one and those waiting. */
  readonly busy: number;
  /** Whether cancel() stops a running call at its next checkpoint (the page is cross-origin isolated). */
  readonly stopsAtOnce: boolean;
  /** Rejects every pending call with MeshingCancelled and stops the running one; the worker stays warm. */
  cancel(): void;
  /** cancel(), then ends the worker and frees its memory; it is started again if the mesher is used again. */
  terminate(): void;
}

/**
 * A mesher with its own worker. `workerUrl` overrides where the worker script is loaded from;
 * `staleMs` (default 250) is how long a cancelled call may keep running before its worker is
 * replaced; `threads` (default 0: one per core, at most 8) is how many threads the worker may
 * mesh on where the page is cross-origin isolated (1: never more than one). The mesh is the same
 * for every count.
 */
export function createMesher(options?: { workerUrl?: string | URL; staleMs?: number; threads?: number }): Mesher;

/**
 * The mesher over workers made by `spawn()` (anything with `onmessage`, `onerror`, `postMessage`
 * and `terminate`, as a Web Worker has); `shared` lets it cancel through a SharedArrayBuffer.
 * The Node entry is built on it; pages use createMesher.
 */
export function createMesherWith(
  spawn: () => Pick<Worker, "postMessage" | "terminate" | "onmessage" | "onerror">,
  options?: { staleMs?: number; shared?: boolean; threads?: number },
): Mesher;

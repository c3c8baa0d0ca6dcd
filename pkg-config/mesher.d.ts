// Non-blocking meshing in a Web Worker:
//
//   import { createMesher } from "isoforge/mesher";
//   const mesher = createMesher();
//   const result = await mesher.meshExpr("sphere(0.8)", { method: "emc", res: 64 });
//
// Each call resolves to the same MeshResult as the synchronous function of the same name, its
// typed arrays transferred from the worker. `cancel()` (or aborting a call's signal) stops the
// work in flight at once: pending calls reject with a MeshingCancelled (name "AbortError").

import type { CsgNode, GridOptions, MeshOptions, MeshResult } from "./isoforge.js";

/** Optional control of one call. */
export interface CallControl {
  /** Aborting it cancels the mesher's work in flight (this call and any other). */
  signal?: AbortSignal;
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
  /** The mesh as file bytes (the arrays of `result` are copied to the worker, not transferred). */
  exportMesh(result: MeshResult, format: ExportFormat, control?: CallControl): Promise<Uint8Array>;
  /** Calls in flight. */
  readonly busy: number;
  /** Stops the work in flight now; pending calls reject with MeshingCancelled. The mesher stays usable. */
  cancel(): void;
  /** Same as cancel(): the worker is started again only if the mesher is used again. */
  terminate(): void;
}

/** A mesher with its own worker. `workerUrl` overrides where the worker script is loaded from. */
export function createMesher(options?: { workerUrl?: string | URL }): Mesher;

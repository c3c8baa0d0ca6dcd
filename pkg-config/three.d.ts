// three.js views of a MeshResult, without copying its arrays (three is a peer dependency):
//
//   import { toBufferGeometry, featureLines } from "isoforge/three";
//   const geometry = toBufferGeometry(result);
//   scene.add(new THREE.Mesh(geometry, material));
//   const lines = featureLines(result, geometry); if (lines) scene.add(lines);

import type { BufferGeometry, LineBasicMaterial, LineSegments } from "three";
import type { MeshResult } from "./isoforge.js";

/** A BufferGeometry whose position, normal and index attributes wrap the result's arrays. */
export function toBufferGeometry(result: MeshResult): BufferGeometry;
/** EMC's sharp feature lines over `geometry`'s positions; null when there are none. */
export function featureLines(result: MeshResult, geometry: BufferGeometry, material?: LineBasicMaterial): LineSegments | null;
/** A segment of length `length` along each vertex normal. */
export function normalLines(result: MeshResult, length: number, material?: LineBasicMaterial): LineSegments;

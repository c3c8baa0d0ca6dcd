// three.js views of a MeshResult (import from "isoforge/three"; three is a peer dependency). The
// geometry's attributes wrap the result's typed arrays: nothing is copied.
import { BufferAttribute, BufferGeometry, LineSegments, LineBasicMaterial } from 'three';

/** A BufferGeometry over the result's positions, normals and indices. */
export function toBufferGeometry(result) {
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(result.positions, 3));
  geometry.setAttribute('normal', new BufferAttribute(result.normals, 3));
  geometry.setIndex(new BufferAttribute(result.indices, 1));
  geometry.computeBoundingSphere();
  return geometry;
}

/**
 * The sharp feature lines (EMC's featureEdges) as LineSegments sharing `geometry`'s positions, or
 * null when there are none.
 */
export function featureLines(result, geometry, material = new LineBasicMaterial({ color: 0xd9480f })) {
  if (!result.featureEdges || result.featureEdges.length === 0) return null;
  const lines = new BufferGeometry();
  lines.setAttribute('position', geometry.getAttribute('position'));
  lines.setIndex(new BufferAttribute(result.featureEdges, 1));
  return new LineSegments(lines, material);
}

/** Short line segments along each vertex normal (length `length`), for checking shading. */
export function normalLines(result, length, material = new LineBasicMaterial({ color: 0x2b8a3e })) {
  const p = result.positions;
  const n = result.normals;
  const ends = new Float32Array(p.length * 2);
  for (let i = 0; i < p.length; i += 3) {
    for (let k = 0; k < 3; k++) {
      ends[2 * i + k] = p[i + k];
      ends[2 * i + 3 + k] = p[i + k] + length * n[i + k];
    }
  }
  const lines = new BufferGeometry();
  lines.setAttribute('position', new BufferAttribute(ends, 3));
  return new LineSegments(lines, material);
}

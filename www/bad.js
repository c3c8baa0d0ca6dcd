// "Show bad triangles": the faces a modeller should look at. Slivers (a corner under
// `minAngleDeg`) and edges that break the manifold (used by one face: a hole; by three or more: a
// fin or a pinch) are found here from the mesh alone; triangles that cross another come from the
// library's analysis (analyzeMesh), which the pane asks for after showing the mesh.

/** The smallest corner angle of the triangle (a, b, c) of `p` (xyz triples), in degrees. */
function smallestAngle(p, a, b, c) {
  const corner = (o, u, v) => {
    const ux = p[3 * u] - p[3 * o], uy = p[3 * u + 1] - p[3 * o + 1], uz = p[3 * u + 2] - p[3 * o + 2];
    const vx = p[3 * v] - p[3 * o], vy = p[3 * v + 1] - p[3 * o + 1], vz = p[3 * v + 2] - p[3 * o + 2];
    const cross = Math.hypot(uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx);
    return Math.atan2(cross, ux * vx + uy * vy + uz * vz);
  };
  return (Math.min(corner(a, b, c), corner(b, c, a), corner(c, a, b)) * 180) / Math.PI;
}

/**
 * `{ slivers, crossing, openEdges, nonManifoldEdges }` of a MeshResult: slivers and the triangles
 * of `crossingPairs` (triangle index pairs from analyzeMesh, or null) as Uint32Arrays of triangle
 * corners (three per triangle, like `indices`), the edges as vertex pairs.
 */
export function badTriangles({ positions, indices }, crossingPairs = null, minAngleDeg = 10) {
  const slivers = [];
  const uses = new Map();
  const n = positions.length / 3;
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = [indices[t], indices[t + 1], indices[t + 2]];
    if (smallestAngle(positions, a, b, c) < minAngleDeg) slivers.push(a, b, c);
    for (const [u, v] of [[a, b], [b, c], [c, a]]) {
      const key = Math.min(u, v) * n + Math.max(u, v);
      uses.set(key, (uses.get(key) ?? 0) + 1);
    }
  }
  const openEdges = [];
  const nonManifoldEdges = [];
  for (const [key, count] of uses) {
    if (count === 2) continue;
    const pair = [Math.floor(key / n), key % n];
    (count === 1 ? openEdges : nonManifoldEdges).push(...pair);
  }
  const crossing = [...new Set(crossingPairs ?? [])].flatMap((t) => [indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]]);
  return { slivers: Uint32Array.from(slivers), crossing: Uint32Array.from(crossing), openEdges: Uint32Array.from(openEdges), nonManifoldEdges: Uint32Array.from(nonManifoldEdges) };
}

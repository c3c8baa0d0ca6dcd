//! The TypeScript declarations of the package's options, results and shape trees, emitted into
//! the generated `.d.ts` next to wasm-bindgen's own: the contract a TypeScript user compiles
//! against. Keep them in step with [`super::options`] and [`crate::stats::Stats`].

use wasm_bindgen::prelude::*;

#[wasm_bindgen(typescript_custom_section)]
const TS_TYPES: &'static str = r#"
/**
 * Meshing method: Marching Cubes, Extended Marching Cubes (keeps sharp edges and corners), Dual
 * Marching Cubes (adaptive octree: sharp features and thin walls with few triangles), Marching
 * Cubes with per-cell triangle-quality rules and vertex snapping (better angles), or a
 * semi-regular quad mesh (result also carries `quads`).
 */
export type Method = "mc" | "emc" | "dmc" | "mcq" | "quad";
/** How ambiguous cell faces are resolved: a fixed rule (fastest) or the trilinear interpolant's. */
export type Topology = "fixed" | "trilinear";
/** Sample type of a volume given to meshGrid as raw little-endian bytes. */
export type Dtype = "f32" | "u8" | "u16";

/** Options shared by every mesh function. Unknown keys are an error, so typos do not pass silently. */
export interface MeshOptions {
  /** Meshing method (default "mc"). */
  method?: Method;
  /** Cells along the longest side of the bounds (default 64). Ignored by meshGrid. */
  res?: number;
  /** Iso-level (default 0): points with value < iso are inside. */
  iso?: number;
  /** Ambiguity rule (default "fixed"). */
  topology?: Topology;
  /** Refuse grids with more cells than this (default 72 000 000). */
  maxCells?: number;
  /**
   * [x0, y0, z0, x1, y1, z1]: mesh this box instead of the input's own bounds (a scene's,
   * [-1, 1]³ for shapes, expressions and CSG trees, and for meshTriangles / meshPoints the
   * input's bounding box padded by two cells, `res` cells along its longest side). Ignored by
   * meshGrid.
   */
  bounds?: [number, number, number, number, number, number];
  /** Run the pairwise self-intersection check (default false: it is the costliest check). */
  checkIntersections?: boolean;
  /**
   * Measure distance and normal deviation against the true surface (default false: on a
   * 50-primitive part it costs more than EMC's meshing; the stats then hold null).
   */
  surfaceError?: boolean;
  /** EMC: a cell is sharp when the smallest dot product of its normals is below this cosine (default 0.9). */
  thetaSharp?: number;
  /** EMC: a sharp cell holds a corner when max |n·n*| exceeds this cosine (default 0.7). */
  phiCorner?: number;
  /** EMC: exact edge crossings by root finding (default true) rather than linear interpolation. */
  directed?: boolean;
  /**
   * EMC: triangulate cells without a sharp feature by MCQ's per-cell polygon rules instead of
   * Marching Cubes' table (default false); feature fans are unchanged. See docs/emc.md's measurements.
   */
  betterTriangles?: boolean;
  /**
   * EMC: move feature points onto curved creases by sampling each sheet again next to the crease
   * (default true; expressions and CSG only). false keeps the paper's tangent-plane points.
   */
  resampleCreases?: boolean;
  /**
   * EMC: collapse, into each feature point, one neighbouring crossing whose triangles lie in one
   * plane (default true): gives back the fans' extra triangles without moving the surface.
   */
  mergeFlat?: boolean;
  /** DMC: error tolerance as a fraction of the bounds' longest side (default 0.001). */
  tolerance?: number;
  /** DMC: deepest octree level (default: the depth whose finest cells match res). */
  maxDepth?: number;
  /** DMC: QEF samples per cell along each axis, 2 to 16 (default 4). */
  samplesPerCell?: number;
  /** MCQ: merge vertices closer than this many cells to a grid point onto it (default 0.3; 0 turns snapping off). */
  snap?: number;
  /** MCQ: project inserted and merged vertices onto the surface (default true; the paper does not). */
  project?: boolean;
  /**
   * After meshing, decimate to at most this many triangles (not for method "quad"): feature lines
   * stay where they are, the mesh stays closed, manifold and free of crossings.
   */
  decimate?: number;
  /** With decimate: never move the surface farther than this many cells from the true one. */
  decimateError?: number;
  /** After meshing (and decimating), this many passes of smoothing that leaves feature lines put (0 to 100, default 0). */
  smooth?: number;
}

/** Options of meshGrid: the shared ones plus the sample type. */
export interface GridOptions extends MeshOptions {
  /**
   * Sample type. Inferred from a Float32Array, Uint8Array or Uint16Array; with a Uint8Array or an
   * ArrayBuffer of raw little-endian bytes (a .raw file), "f32" and "u16" reinterpret the bytes.
   */
  dtype?: Dtype;
  /**
   * The volume's gradient, used for the normals of the surface-error statistics (default
   * "central"): central differences at the samples interpolated (continuous across cells) or
   * the trilinear interpolant's own (consistent with it, but it jumps at every cell face).
   */
  gradient?: SampleGradientName;
}

/** Which gradient a sampled volume reports: see GridOptions.gradient. */
export type SampleGradientName = "trilinear" | "central";

/**
 * A field given as a JavaScript function for meshFunction: called with a batch of points as xyz
 * triples (one z-slab of the grid per call, never one point at a time), it returns one value per
 * point, negative inside.
 */
export type BatchFieldFunction = (points: Float32Array) => Float32Array | number[];

/** Nanoseconds per point (per box for `interval`) of each evaluation mode: see measureEvaluator. */
export interface EvaluatorSpeed {
  treeWalk: number; value: number; valueGradient: number; batch: number; gradientBatch: number;
  interval: number;
  instructions: number;
}

/** Numbers describing one run; the same keys as the CLI's `--stats` JSON. */
export interface MeshStats {
  method: string; res: number; vertices: number; triangles: number;
  closed_manifold: boolean; euler: number; genus: number | null; components: number;
  boundary_edges: number; non_manifold_edges: number; non_manifold_vertices: number;
  misoriented_edges: number; degenerate_triangles: number; self_intersections: number | null;
  /** Pairs of triangles lying on each other across an edge (a fold, not a crossing). */
  folded_pairs: number;
  min_angle_deg: number; max_angle_deg: number; angle_histogram_5deg: number[];
  aspect_ratio_mean: number; aspect_ratio_max: number; area: number; volume: number;
  dist_max: number | null; dist_rms: number | null;
  normal_dev_deg_p50: number | null; normal_dev_deg_p95: number | null; normal_dev_deg_max: number | null;
  /** Faces at a sharp edge (true normals at their corners over 30° apart), and their normal
   * deviation p95: where "crinkly" edges show. */
  crease_faces: number | null; crease_normal_dev_deg_p95: number | null;
  /** Per face against the nearest true normal at its corners, centroid and the points between:
   * a face lying flat beside a crease reads 0 (the centroid's gradient can be the other side's,
   * which normal_dev_deg_* then count); spikes and faces turned over stay large. */
  face_normal_dev_deg_p95: number | null; face_normal_dev_deg_max: number | null;
  /** Milliseconds of meshing (analysis excluded). */
  ms_total: number;
  /** Milliseconds per phase, in the order the phases ran. */
  phases_ms: Record<string, number>;
  ms_analysis: number;
  /** EMC: mesh edges on feature lines, cells with an edge / corner feature point, cells fanned
   * around a point near (not on) their feature, edges flipped, crossings collapsed into feature
   * points on flat faces (0 for MC). */
  feature_edges: number; edge_features: number; corner_features: number; approximate_features: number;
  flips: number; flat_merges: number;
  /** EMC: grid points evaluated and the grid's points (null for other methods). */
  points_evaluated: number | null; grid_points: number | null;
  /** DMC: leaves of the final octree and dual cells traversed (null for other methods). */
  octree_leaves: number | null; dual_cells: number | null;
  /** Quad method: quad count and, per stage, valence-four share, aspect ratios and vertex distance. */
  quads: number;
  quad_stages: {
    stage: string; vertices: number; quads: number; euler: number; valence4_share: number;
    irregular: number; operations: number; aspect_mean: number; aspect_max: number;
    dist_max: number; dist_rms: number;
    /** Vertices left where the stage found them (1 for a stage undone whole) so nothing crosses. */
    held_back: number;
  }[];
}

/**
 * Inputs that are not fields (EMC's remeshing and reconstruction applications), as typed arrays:
 * - meshTriangles(positions: Float32Array, indices: Uint32Array, options?: MeshOptions): remesh a
 *   triangle mesh (xyz triples; vertex-index triples, counter-clockwise from outside); holes are
 *   spanned by the generalised winding number, a sheet that encloses nothing is refused;
 * - meshPoints(positions: Float32Array, normals: Float32Array, options?: MeshOptions): reconstruct
 *   the surface sampled by points with outward normals (xyz triples each); normals that disagree
 *   with their neighbours are turned back first, a cloud whose normals are not oriented is refused.
 * Use method "emc" for sharp edges and corners; "mc" (default) is plain Marching Cubes on the same
 * grid. iso must be 0. Stats measure against the input (distance to the mesh, or to the nearest
 * sample's tangent plane).
 */
export type InputFunctions = "meshTriangles" | "meshPoints";

/** A mesh ready for WebGL / three.js: `positions` and `normals` are xyz triples, `indices` triangles (CCW = outward). */
export interface MeshResult {
  positions: Float32Array;
  normals: Float32Array;
  indices: Uint32Array;
  /**
   * Sharp feature lines found by EMC as pairs of vertex indices (empty for MC): draw with gl.LINES.
   * Gaps where a crease skims a cell are bridged through the approximate fan centre beside it.
   */
  featureEdges: Uint32Array;
  /** Quad method: 4 vertex indices per quad (CCW = outward); `indices` triangulates them. Empty otherwise. */
  quads: Uint32Array;
  stats: MeshStats;
}

/**
 * A shape tree for meshCsg / compileCsg. Each node means the language function of the same name;
 * see docs/language.md. Unknown fields are an error.
 */
export type CsgNode =
  | { op: "sphere"; radius: number }
  | { op: "box"; half: [number, number, number] }
  | { op: "rounded_box"; half: [number, number, number]; radius: number }
  | { op: "cylinder"; radius: number; half_height: number }
  | { op: "cone"; radius: number; height: number }
  | { op: "torus"; major: number; minor: number }
  | { op: "capsule"; a: [number, number, number]; b: [number, number, number]; radius: number }
  | { op: "plane"; normal: [number, number, number]; distance: number }
  | { op: "union" | "intersect"; args: CsgNode[] }
  | { op: "subtract"; args: [CsgNode, CsgNode] }
  | { op: "smooth_union" | "smooth_intersect" | "smooth_subtract"; args: [CsgNode, CsgNode]; k: number }
  | { op: "shell"; shape: CsgNode; thickness: number }
  | { op: "offset"; shape: CsgNode; distance: number }
  | { op: "translate"; shape: CsgNode; offset: [number, number, number] }
  | { op: "rotate"; shape: CsgNode; axis: [number, number, number]; degrees: number }
  | { op: "scale"; shape: CsgNode; factor: number }
  | { op: "mirror_x" | "mirror_y" | "mirror_z"; shape: CsgNode };
"#;

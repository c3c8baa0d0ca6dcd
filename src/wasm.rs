//! The JavaScript face of the library: a thin layer that parses options, calls [`crate::pipeline`],
//! and copies results out as typed arrays in one go (no per-vertex calls across the boundary).
//! Every failure becomes a JavaScript `Error` carrying the library's message.

use crate::error::Error;
use crate::expr::{self, Program};
use crate::field::{BatchFn, SampleGradient};
use crate::grid::{self, Dtype, Grid, DEFAULT_MAX_CELLS};
use crate::mc::Topology;
use crate::pipeline::{self, Method, Output, Request};
use crate::scenes;
use crate::stats::AnalysisOptions;
use glam::Vec3;
use js_sys::{ArrayBuffer, Float32Array, Object, Reflect, Uint16Array, Uint32Array, Uint8Array};
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

mod export;
mod inputs;
pub use export::export_mesh;
pub use inputs::{mesh_points, mesh_triangles};

#[wasm_bindgen(start)]
fn start() {
    console_error_panic_hook::set_once();
}

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
  /** Measure distance and normal deviation against the true surface (default true). */
  surfaceError?: boolean;
  /** EMC: a cell is sharp when the smallest dot product of its normals is below this cosine (default 0.9). */
  thetaSharp?: number;
  /** EMC: a sharp cell holds a corner when max |n·n*| exceeds this cosine (default 0.7). */
  phiCorner?: number;
  /** EMC: exact edge crossings by root finding (default true) rather than linear interpolation. */
  directed?: boolean;
  /**
   * EMC: triangulate cells without a sharp feature by MCQ's per-cell polygon rules instead of
   * Marching Cubes' table (default false); feature fans are unchanged. See the README's measurements.
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
  /**
   * DMC: how far, as a fraction of its leaf's side (0 to 1, default 0), a leaf's vertex may follow
   * its QEF minimiser out of the leaf; 0.25 with tolerance 0.01 meshes the thin-walled room in
   * under 1 000 triangles within 1 % (see the README).
   */
  vertexReach?: number;
  /** DMC: the paper's refinement only, the QEF residual split (default false; see the README). */
  paperOnly?: boolean;
  /** DMC: refinement rule 3, the triangles' distance to the surface (default true). */
  accuracyRule?: boolean;
  /** MCQ: merge vertices closer than this many cells to a grid point onto it (default 0.3; 0 turns snapping off). */
  snap?: number;
  /** MCQ: project inserted and merged vertices onto the surface (default true; the paper does not). */
  project?: boolean;
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
  treeWalk: number; value: number; valueGradient: number; batch: number; interval: number;
  instructions: number;
}

/** Numbers describing one run; the same keys as the CLI's `--stats` JSON. */
export interface MeshStats {
  method: string; res: number; vertices: number; triangles: number;
  closed_manifold: boolean; euler: number; genus: number | null; components: number;
  boundary_edges: number; non_manifold_edges: number; non_manifold_vertices: number;
  misoriented_edges: number; degenerate_triangles: number; self_intersections: number | null;
  min_angle_deg: number; max_angle_deg: number; angle_histogram_5deg: number[];
  aspect_ratio_mean: number; aspect_ratio_max: number; area: number; volume: number;
  dist_max: number | null; dist_rms: number | null;
  normal_dev_deg_p50: number | null; normal_dev_deg_p95: number | null; normal_dev_deg_max: number | null;
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
  }[];
}

/**
 * Inputs that are not fields (EMC's remeshing and reconstruction applications), as typed arrays:
 * - meshTriangles(positions: Float32Array, indices: Uint32Array, options?: MeshOptions): remesh a
 *   closed triangle mesh (xyz triples; vertex-index triples, counter-clockwise from outside);
 * - meshPoints(positions: Float32Array, normals: Float32Array, options?: MeshOptions): reconstruct
 *   the surface sampled by points with outward normals (xyz triples each).
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
 * see the README's "Language" section. Unknown fields are an error.
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

#[derive(Deserialize, Default)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
struct JsOptions {
    method: Option<String>,
    res: Option<f64>,
    iso: Option<f32>,
    topology: Option<String>,
    max_cells: Option<f64>,
    bounds: Option<Vec<f32>>,
    check_intersections: Option<bool>,
    surface_error: Option<bool>,
    theta_sharp: Option<f32>,
    phi_corner: Option<f32>,
    directed: Option<bool>,
    better_triangles: Option<bool>,
    resample_creases: Option<bool>,
    merge_flat: Option<bool>,
    tolerance: Option<f32>,
    max_depth: Option<f64>,
    samples_per_cell: Option<f64>,
    vertex_reach: Option<f32>,
    paper_only: Option<bool>,
    accuracy_rule: Option<bool>,
    snap: Option<f32>,
    project: Option<bool>,
    dtype: Option<String>,
    gradient: Option<String>,
}

fn js_error(e: impl std::fmt::Display) -> JsValue {
    js_sys::Error::new(&e.to_string()).into()
}

/// Options of every function but meshGrid, which alone takes a `dtype`.
fn parse_options(options: JsValue) -> Result<Request, JsValue> {
    let (request, dtype, gradient_given) = parse_grid_options(options)?;
    if dtype.is_some() {
        return Err(js_error(Error::InvalidOption("dtype is an option of meshGrid only".into())));
    }
    if gradient_given {
        return Err(js_error(Error::InvalidOption("gradient is an option of meshGrid only".into())));
    }
    Ok(request)
}

/// The request, the dtype, and whether a `gradient` was given.
fn parse_grid_options(options: JsValue) -> Result<(Request, Option<Dtype>, bool), JsValue> {
    let o: JsOptions = if options.is_undefined() || options.is_null() {
        JsOptions::default()
    } else {
        check_keys(&options)?;
        serde_wasm_bindgen::from_value(options).map_err(|e| js_error(format!("invalid options: {e}")))?
    };
    let mut r = Request::default();
    if let Some(m) = &o.method {
        r.method = Method::parse(m).map_err(js_error)?;
    }
    if let Some(res) = o.res {
        if !(res.is_finite() && res >= 1.0 && res.fract() == 0.0 && res <= 1e6) {
            return Err(js_error(Error::InvalidOption(format!("res must be a whole number ≥ 1, got {res}"))));
        }
        r.res = res as usize;
    }
    if let Some(iso) = o.iso {
        if !iso.is_finite() {
            return Err(js_error(Error::InvalidOption(format!("iso must be finite, got {iso}"))));
        }
        r.iso = iso;
    }
    r.topology = match o.topology.as_deref() {
        None | Some("fixed") => Topology::Fixed,
        Some("trilinear") => Topology::Trilinear,
        Some(t) => {
            return Err(js_error(Error::InvalidOption(format!(
                "topology must be \"fixed\" or \"trilinear\", got \"{t}\""
            ))))
        }
    };
    r.max_cells = match o.max_cells {
        None => DEFAULT_MAX_CELLS,
        Some(m) if m.is_finite() && m >= 1.0 => m as u64,
        Some(m) => return Err(js_error(Error::InvalidOption(format!("maxCells must be ≥ 1, got {m}")))),
    };
    if let Some(b) = &o.bounds {
        r.bounds = Some(parse_bounds(b)?);
    }
    r.analysis = AnalysisOptions {
        self_intersections: o.check_intersections.unwrap_or(false),
        surface_error: o.surface_error.unwrap_or(true),
    };
    // Ranges are checked by the method itself, with the same names.
    r.theta_sharp = o.theta_sharp.unwrap_or(r.theta_sharp);
    r.phi_corner = o.phi_corner.unwrap_or(r.phi_corner);
    r.directed = o.directed.unwrap_or(r.directed);
    r.better_triangles = o.better_triangles.unwrap_or(r.better_triangles);
    r.resample_creases = o.resample_creases.unwrap_or(r.resample_creases);
    r.merge_flat = o.merge_flat.unwrap_or(r.merge_flat);
    r.tolerance = o.tolerance.unwrap_or(r.tolerance);
    r.vertex_reach = o.vertex_reach.unwrap_or(r.vertex_reach);
    r.paper_only = o.paper_only.unwrap_or(r.paper_only);
    r.accuracy_rule = o.accuracy_rule.unwrap_or(r.accuracy_rule);
    let whole = |name: &str, v: f64, max: f64| {
        if v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= max {
            Ok(v)
        } else {
            Err(js_error(Error::InvalidOption(format!(
                "{name} must be a whole number in 0..={max}, got {v}"
            ))))
        }
    };
    if let Some(d) = o.max_depth {
        r.max_depth = Some(whole("maxDepth", d, 255.0)? as u8);
    }
    if let Some(n) = o.samples_per_cell {
        r.samples_per_cell = whole("samplesPerCell", n, 1e6)? as usize;
    }
    // 0 turns snapping off; other values are range-checked by the method, like the CLI's --snap.
    if let Some(a) = o.snap {
        r.mcq_snap = (a != 0.0).then_some(a);
    }
    r.mcq_project = o.project.unwrap_or(r.mcq_project);
    if let Some(g) = &o.gradient {
        r.gradient = SampleGradient::parse(g).map_err(js_error)?;
    }
    let dtype = o.dtype.as_deref().map(Dtype::parse).transpose().map_err(js_error)?;
    Ok((r, dtype, o.gradient.is_some()))
}

/// Refuses keys `JsOptions` does not have. serde-wasm-bindgen reads a struct by looking up its
/// fields by name, so `deny_unknown_fields` never sees the others; here serde itself checks the
/// object's keys (each paired with `()`, which every `Option` field accepts as `None`), so the
/// message lists the known options.
fn check_keys(options: &JsValue) -> Result<(), JsValue> {
    if !options.is_object() {
        return Err(js_error(Error::InvalidOption("options must be an object".into())));
    }
    let names: Vec<String> =
        Object::keys(options.unchecked_ref::<Object>()).iter().filter_map(|k| k.as_string()).collect();
    let keys = serde::de::value::MapDeserializer::<_, serde::de::value::Error>::new(
        names.into_iter().map(|k| (k, ())),
    );
    JsOptions::deserialize(keys).map(|_| ()).map_err(|e| js_error(format!("invalid options: {e}")))
}

fn parse_bounds(b: &[f32]) -> Result<(Vec3, Vec3), JsValue> {
    if b.len() != 6 {
        return Err(js_error(Error::InvalidOption(format!(
            "bounds must be [x0, y0, z0, x1, y1, z1], got {} numbers",
            b.len()
        ))));
    }
    Ok((Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5])))
}

fn to_js(out: &Output) -> Result<JsValue, JsValue> {
    let result = Object::new();
    let set = |k: &str, v: &JsValue| Reflect::set(&result, &JsValue::from_str(k), v).map(|_| ());
    set("positions", &Float32Array::from(&out.mesh.flat_positions()[..]).into())?;
    set("normals", &Float32Array::from(&out.mesh.flat_normals()[..]).into())?;
    set("indices", &Uint32Array::from(&out.mesh.flat_indices()[..]).into())?;
    let features: Vec<u32> = out.feature_edges.iter().flatten().copied().collect();
    set("featureEdges", &Uint32Array::from(&features[..]).into())?;
    let quads: Vec<u32> = out.quads.iter().flatten().copied().collect();
    set("quads", &Uint32Array::from(&quads[..]).into())?;
    let serializer = serde_wasm_bindgen::Serializer::json_compatible();
    set("stats", &out.stats.serialize(&serializer).map_err(js_error)?)?;
    Ok(result.into())
}

/// Names of the built-in scenes.
#[wasm_bindgen(js_name = sceneNames, unchecked_return_type = "string[]")]
pub fn scene_names() -> JsValue {
    let arr = js_sys::Array::new();
    for n in scenes::SCENE_NAMES {
        arr.push(&JsValue::from_str(n));
    }
    arr.into()
}

/// A built-in scene's program in the expression language (for an editor: change it, then
/// `meshExpr` it with `{ bounds: sceneBounds(name) }`). Throws on unknown names.
#[wasm_bindgen(js_name = sceneSource)]
pub fn scene_source(name: &str) -> Result<String, JsValue> {
    scenes::source(name).map(str::to_string).map_err(js_error)
}

/// The box a built-in scene is meshed in, `[x0, y0, z0, x1, y1, z1]`. Throws on unknown names.
#[wasm_bindgen(js_name = sceneBounds, unchecked_return_type = "[number, number, number, number, number, number]")]
pub fn scene_bounds(name: &str) -> Result<JsValue, JsValue> {
    let scene = scenes::scene(name).map_err(js_error)?;
    let arr = js_sys::Array::new();
    for v in scene.min.to_array().into_iter().chain(scene.max.to_array()) {
        arr.push(&JsValue::from_f64(v as f64));
    }
    Ok(arr.into())
}

/// Meshes a built-in scene. Throws an `Error` naming the problem on bad options or unknown names.
#[wasm_bindgen(js_name = meshScene, unchecked_return_type = "MeshResult")]
pub fn mesh_scene(
    name: &str,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&pipeline::mesh_scene(name, &request).map_err(js_error)?)
}

/// A compiled program in the expression language, reusable across meshing calls: compile once,
/// then mesh it at several resolutions or with several methods. Free it with `free()` when done.
#[wasm_bindgen]
pub struct Shape {
    program: Program,
}

#[wasm_bindgen]
impl Shape {
    /// The value at (x, y, z): negative inside, positive outside.
    pub fn value(&self, x: f32, y: f32, z: f32) -> f32 {
        self.program.eval(Vec3::new(x, y, z))
    }

    /// `[value, dx, dy, dz]` at (x, y, z): the value and its exact gradient.
    #[wasm_bindgen(js_name = valueAndGradient)]
    pub fn value_and_gradient(&self, x: f32, y: f32, z: f32) -> Vec<f32> {
        let (v, g) = self.program.eval_grad(Vec3::new(x, y, z));
        vec![v, g.x, g.y, g.z]
    }

    /// Values at many points at once (`points` = xyz triples): far cheaper per point than
    /// `value`, which crosses the JavaScript boundary once per call.
    pub fn values(&self, points: &[f32]) -> Result<Vec<f32>, JsValue> {
        let points = triples(points)?;
        let mut out = vec![0.0; points.len()];
        self.program.eval_many(&points, &mut out);
        Ok(out)
    }

    /// `[value, dx, dy, dz]` for each point of `points` (xyz triples), gradients exact.
    #[wasm_bindgen(js_name = valuesAndGradients)]
    pub fn values_and_gradients(&self, points: &[f32]) -> Result<Vec<f32>, JsValue> {
        let points = triples(points)?;
        let mut out = Vec::with_capacity(points.len() * 4);
        for p in points {
            let (v, g) = self.program.eval_grad(p);
            out.extend_from_slice(&[v, g.x, g.y, g.z]);
        }
        Ok(out)
    }

    /// `[lo, hi]`: conservative bounds of the value over the box between the corners (x0, y0, z0)
    /// and (x1, y1, z1); the surface cannot be in the box if they do not straddle 0.
    pub fn bounds(&self, x0: f32, y0: f32, z0: f32, x1: f32, y1: f32, z1: f32) -> Vec<f32> {
        let (lo, hi) = self.program.eval_interval(Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1));
        vec![lo, hi]
    }

    /// Instructions on the compiled tape (after constant folding and sharing repeated parts).
    #[wasm_bindgen(getter, js_name = instructionCount)]
    pub fn instruction_count(&self) -> usize {
        self.program.instruction_count()
    }
}

/// Points given as a flat array of xyz triples.
fn triples(points: &[f32]) -> Result<Vec<Vec3>, JsValue> {
    if points.len() % 3 != 0 {
        return Err(js_error(Error::InvalidOption(format!(
            "points must be xyz triples, got {} numbers",
            points.len()
        ))));
    }
    Ok(points.chunks_exact(3).map(Vec3::from_slice).collect())
}

/// Times the evaluator on this machine: nanoseconds per point of the reference tree walk, of
/// `value`, `value + gradient`, 64-point batches, and per box of interval bounds, for `text` over
/// `count` points, each mode run for at least `minMs` milliseconds (performance.now()). For
/// benchmarks (`scripts/bench-browser.mjs`); it blocks for about five times `minMs`.
#[wasm_bindgen(js_name = measureEvaluator, unchecked_return_type = "EvaluatorSpeed")]
pub fn measure_evaluator(text: &str, count: usize, min_ms: f64) -> Result<JsValue, JsValue> {
    let performance = js_sys::Reflect::get(&js_sys::global(), &"performance".into())?;
    let now_fn: js_sys::Function = js_sys::Reflect::get(&performance, &"now".into())?.dyn_into()?;
    let now = || now_fn.call0(&performance).ok().and_then(|v| v.as_f64()).unwrap_or(0.0);
    let speed = expr::speed::measure(text, count, min_ms, &now).map_err(js_error)?;
    serde_wasm_bindgen::to_value(&speed).map_err(|e| js_error(e.to_string()))
}

/// Compiles a program in the expression language. A malformed program throws an `Error` whose
/// message reads `line:column: what`, then the line, then a caret under the spot.
#[wasm_bindgen]
pub fn compile(text: &str) -> Result<Shape, JsValue> {
    Ok(Shape { program: expr::compile(text).map_err(js_error)? })
}

/// The JSON text of a CSG tree given as a string or as an object (pretty-printed, so that errors
/// point at a line of it).
fn csg_text(json: &JsValue) -> Result<String, JsValue> {
    if let Some(text) = json.as_string() {
        return Ok(text);
    }
    if !json.is_object() {
        return Err(js_error(Error::InvalidOption("a CSG tree must be a JSON string or an object".into())));
    }
    let text = js_sys::JSON::stringify_with_replacer_and_space(json, &JsValue::NULL, &JsValue::from(1))?;
    Ok(text.as_string().unwrap_or_default())
}

/// Compiles a CSG tree (a JSON string or a `CsgNode` object) into a reusable shape. Throws an
/// `Error` pointing into the JSON on unknown ops, misspelt or missing fields.
#[wasm_bindgen(js_name = compileCsg)]
pub fn compile_csg(
    #[wasm_bindgen(unchecked_param_type = "string | CsgNode")] json: JsValue,
) -> Result<Shape, JsValue> {
    Ok(Shape { program: Program::from_csg_json(&csg_text(&json)?).map_err(js_error)? })
}

/// Meshes a compiled shape in `options.bounds`, or [-1, 1]³.
#[wasm_bindgen(js_name = meshShape, unchecked_return_type = "MeshResult")]
pub fn mesh_shape(
    shape: &Shape,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&pipeline::mesh_program(&shape.program, &request).map_err(js_error)?)
}

/// Compiles and meshes a program in the expression language, in `options.bounds` or [-1, 1]³.
/// Parse errors throw like `compile`'s.
#[wasm_bindgen(js_name = meshExpr, unchecked_return_type = "MeshResult")]
pub fn mesh_expr(
    text: &str,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&pipeline::mesh_expr(text, &request).map_err(js_error)?)
}

/// Compiles and meshes a CSG tree (a JSON string or a `CsgNode` object), in `options.bounds` or
/// [-1, 1]³.
#[wasm_bindgen(js_name = meshCsg, unchecked_return_type = "MeshResult")]
pub fn mesh_csg(
    #[wasm_bindgen(unchecked_param_type = "string | CsgNode")] json: JsValue,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&pipeline::mesh_csg_json(&csg_text(&json)?, &request).map_err(js_error)?)
}

/// The samples of a meshGrid call as `f32`, whatever array type they came in.
fn grid_samples(values: &JsValue, dtype: Option<Dtype>, grid: &Grid) -> Result<Vec<f32>, JsValue> {
    let mismatch = |given: &str, d: Dtype| {
        js_error(Error::InvalidOption(format!(
            "dtype \"{}\" does not match a {given}; pass a Uint8Array or ArrayBuffer of raw bytes to reinterpret them",
            d.name()
        )))
    };
    if let Some(a) = values.dyn_ref::<Float32Array>() {
        match dtype {
            None | Some(Dtype::F32) => Ok(a.to_vec()),
            Some(d) => Err(mismatch("Float32Array", d)),
        }
    } else if let Some(a) = values.dyn_ref::<Uint16Array>() {
        match dtype {
            None | Some(Dtype::U16) => Ok(grid::samples_from_u16(&a.to_vec())),
            Some(d) => Err(mismatch("Uint16Array", d)),
        }
    } else if let Some(a) = values.dyn_ref::<Uint8Array>() {
        match dtype {
            None | Some(Dtype::U8) => Ok(grid::samples_from_u8(&a.to_vec())),
            Some(d) => grid::samples_from_bytes(&a.to_vec(), d, grid).map_err(js_error),
        }
    } else if let Some(b) = values.dyn_ref::<ArrayBuffer>() {
        let d = dtype.ok_or_else(|| {
            js_error(Error::InvalidOption("an ArrayBuffer of samples needs a dtype option".into()))
        })?;
        grid::samples_from_bytes(&Uint8Array::new(b).to_vec(), d, grid).map_err(js_error)
    } else if js_sys::Array::is_array(values) {
        match dtype {
            None | Some(Dtype::F32) => Ok(Float32Array::new(values).to_vec()),
            Some(d) => Err(mismatch("plain Array", d)),
        }
    } else {
        Err(js_error(Error::InvalidGrid(
            "values must be a Float32Array, Uint8Array, Uint16Array, an array of numbers, or an ArrayBuffer with a dtype"
                .into(),
        )))
    }
}

/// Meshes a sampled volume. `values` holds `dims[0] * dims[1] * dims[2]` samples, x fastest, at the
/// points of a lattice spanning `bounds` = [x0, y0, z0, x1, y1, z1] (`dims` counts points, not
/// cells). Integer samples keep their values (give `iso` in 0..255 for bytes); `options.dtype`
/// reinterprets raw little-endian bytes.
#[wasm_bindgen(js_name = meshGrid, unchecked_return_type = "MeshResult")]
pub fn mesh_grid(
    #[wasm_bindgen(
        unchecked_param_type = "Float32Array | Uint8Array | Uint16Array | number[] | ArrayBuffer"
    )]
    values: JsValue,
    #[wasm_bindgen(unchecked_param_type = "[number, number, number] | Uint32Array")] dims: Vec<u32>,
    #[wasm_bindgen(unchecked_param_type = "[number, number, number, number, number, number] | Float32Array")]
    bounds: Vec<f32>,
    #[wasm_bindgen(unchecked_param_type = "GridOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let (request, dtype, _) = parse_grid_options(options)?;
    if dims.len() != 3 || dims.iter().any(|&d| d < 2) {
        return Err(js_error(Error::InvalidGrid(format!(
            "dims must be three point counts, each at least 2, got {dims:?}"
        ))));
    }
    let (min, max) = parse_bounds(&bounds)?;
    let cells = [dims[0] as usize - 1, dims[1] as usize - 1, dims[2] as usize - 1];
    let grid = Grid::new(min, max, cells).map_err(js_error)?;
    grid.check_size(request.max_cells).map_err(js_error)?;
    let samples = grid_samples(&values, dtype, &grid)?;
    to_js(&pipeline::mesh_samples(&samples, &grid, &request).map_err(js_error)?)
}

/// The message of whatever a JavaScript function threw.
fn thrown_message(e: &JsValue) -> String {
    if let Some(err) = e.dyn_ref::<js_sys::Error>() {
        return String::from(err.message());
    }
    if let Some(s) = e.as_string() {
        return s;
    }
    js_sys::JSON::stringify(e).ok().and_then(|s| s.as_string()).unwrap_or_else(|| format!("{e:?}"))
}

/// Meshes a field given as a JavaScript function, the slow path for shapes the language cannot
/// express. `fn(points)` gets a Float32Array of xyz triples (one z-slab of the grid per call) and
/// returns a Float32Array (or array) with one value per point, negative inside. The grid spans
/// `bounds` = [x0, y0, z0, x1, y1, z1] with `options.res` cells along its longest side; gradients
/// are central differences of the samples. Throws an `Error` if `fn` throws, returns the wrong
/// number of values or a non-finite one.
#[wasm_bindgen(js_name = meshFunction, unchecked_return_type = "MeshResult")]
pub fn mesh_function(
    #[wasm_bindgen(unchecked_param_type = "BatchFieldFunction")] f: js_sys::Function,
    #[wasm_bindgen(unchecked_param_type = "[number, number, number, number, number, number] | Float32Array")]
    bounds: Vec<f32>,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    let bounds = parse_bounds(&bounds)?;
    let batch = BatchFn::new(
        |points: &[Vec3], out: &mut [f32]| {
            let flat: Vec<f32> = points.iter().flat_map(|p| p.to_array()).collect();
            let arg = Float32Array::from(&flat[..]);
            let result =
                f.call1(&JsValue::NULL, &arg).map_err(|e| format!("it threw: {}", thrown_message(&e)))?;
            let values = if let Some(a) = result.dyn_ref::<Float32Array>() {
                a.to_vec()
            } else if js_sys::Array::is_array(&result) {
                Float32Array::new(&result).to_vec()
            } else {
                return Err("it must return a Float32Array or an array of numbers".into());
            };
            if values.len() != out.len() {
                return Err(format!(
                    "it returned {} values for {} points (one value per xyz triple)",
                    values.len(),
                    out.len()
                ));
            }
            out.copy_from_slice(&values);
            Ok(())
        },
        1e-3,
    );
    to_js(&pipeline::mesh_function(&batch, bounds, &request).map_err(js_error)?)
}

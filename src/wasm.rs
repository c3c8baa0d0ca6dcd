//! The JavaScript face of the library: a thin layer that parses options, calls [`crate::pipeline`],
//! and copies results out as typed arrays in one go (no per-vertex calls across the boundary).
//! Every failure becomes a JavaScript `Error` carrying the library's message.

use crate::error::Error;
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::Topology;
use crate::mesh::Mesh;
use crate::pipeline::{self, Method, Request};
use crate::scenes;
use crate::stats::{AnalysisOptions, Stats};
use glam::Vec3;
use js_sys::{Float32Array, Object, Reflect, Uint32Array};
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

#[wasm_bindgen(start)]
fn start() {
    console_error_panic_hook::set_once();
}

#[wasm_bindgen(typescript_custom_section)]
const TS_TYPES: &'static str = r#"
/** Meshing method. */
export type Method = "mc";
/** How ambiguous cell faces are resolved: a fixed rule (fastest) or the trilinear interpolant's. */
export type Topology = "fixed" | "trilinear";

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
  /** [x0, y0, z0, x1, y1, z1]: mesh this box instead of the input's own bounds. Ignored by meshGrid. */
  bounds?: [number, number, number, number, number, number];
  /** Run the pairwise self-intersection check (default false: it is the costliest check). */
  checkIntersections?: boolean;
  /** Measure distance and normal deviation against the true surface (default true). */
  surfaceError?: boolean;
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
}

/** A mesh ready for WebGL / three.js: `positions` and `normals` are xyz triples, `indices` triangles (CCW = outward). */
export interface MeshResult {
  positions: Float32Array;
  normals: Float32Array;
  indices: Uint32Array;
  stats: MeshStats;
}
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
}

fn js_error(e: impl std::fmt::Display) -> JsValue {
    js_sys::Error::new(&e.to_string()).into()
}

fn parse_options(options: JsValue) -> Result<Request, JsValue> {
    let o: JsOptions = if options.is_undefined() || options.is_null() {
        JsOptions::default()
    } else {
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
    Ok(r)
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

fn to_js(mesh: &Mesh, stats: &Stats) -> Result<JsValue, JsValue> {
    let out = Object::new();
    let set = |k: &str, v: &JsValue| Reflect::set(&out, &JsValue::from_str(k), v).map(|_| ());
    set("positions", &Float32Array::from(&mesh.flat_positions()[..]).into())?;
    set("normals", &Float32Array::from(&mesh.flat_normals()[..]).into())?;
    set("indices", &Uint32Array::from(&mesh.flat_indices()[..]).into())?;
    let serializer = serde_wasm_bindgen::Serializer::json_compatible();
    set("stats", &stats.serialize(&serializer).map_err(js_error)?)?;
    Ok(out.into())
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

/// Meshes a built-in scene. Throws an `Error` naming the problem on bad options or unknown names.
#[wasm_bindgen(js_name = meshScene, unchecked_return_type = "MeshResult")]
pub fn mesh_scene(
    name: &str,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    let scene = scenes::scene(name).map_err(js_error)?;
    let (mesh, stats) =
        pipeline::mesh_field(scene.field.as_ref(), (scene.min, scene.max), &request).map_err(js_error)?;
    to_js(&mesh, &stats)
}

/// Meshes a sampled volume. `values` holds `dims[0] * dims[1] * dims[2]` samples, x fastest, at the
/// points of a lattice spanning `bounds` = [x0, y0, z0, x1, y1, z1] (`dims` counts points, not cells).
#[wasm_bindgen(js_name = meshGrid, unchecked_return_type = "MeshResult")]
pub fn mesh_grid(
    values: &[f32],
    #[wasm_bindgen(unchecked_param_type = "[number, number, number] | Uint32Array")] dims: Vec<u32>,
    #[wasm_bindgen(unchecked_param_type = "[number, number, number, number, number, number] | Float32Array")]
    bounds: Vec<f32>,
    #[wasm_bindgen(unchecked_param_type = "MeshOptions | undefined")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    if dims.len() != 3 || dims.iter().any(|&d| d < 2) {
        return Err(js_error(Error::InvalidGrid(format!(
            "dims must be three point counts, each at least 2, got {dims:?}"
        ))));
    }
    let (min, max) = parse_bounds(&bounds)?;
    let cells = [dims[0] as usize - 1, dims[1] as usize - 1, dims[2] as usize - 1];
    let grid = Grid::new(min, max, cells).map_err(js_error)?;
    grid.check_size(request.max_cells).map_err(js_error)?;
    let (mesh, stats) = pipeline::mesh_samples(values, &grid, &request).map_err(js_error)?;
    to_js(&mesh, &stats)
}

//! `analyzeMesh`: the costly measurements of a mesh (distance and normal error against the shape,
//! crossing triangles) as a call of their own, so that a page shows a mesh first and its numbers
//! after, and can highlight the triangles that cross.

use super::export::mesh_from_arrays;
use super::{csg_text, js_error, with_progress};
use crate::error::Error;
use crate::expr::regions::RegionalProgram;
use crate::expr::Program;
use crate::mesh::analysis;
use glam::Vec3;
use js_sys::{Object, Reflect, Uint32Array};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_time::Instant;

#[wasm_bindgen(typescript_custom_section)]
const TS_ANALYSIS: &'static str = r#"
/** What analyzeMesh measures: `expr` or `csg` is the shape the mesh approximates. */
export interface AnalyzeOptions {
  /** The program (expression language) the mesh was made from: measures the surface error. */
  expr?: string;
  /** Or the CSG tree it was made from. */
  csg?: string | CsgNode | { toJSON(): CsgNode };
  /** Find the pairs of triangles that cross (default false). */
  checkIntersections?: boolean;
}

/**
 * The numbers of analyzeMesh, under the keys MeshStats uses for them (null where not asked for),
 * so `Object.assign(result.stats, analysis)` fills a result meshed without them.
 */
export interface MeshAnalysis {
  dist_max: number | null; dist_rms: number | null;
  normal_dev_deg_p50: number | null; normal_dev_deg_p95: number | null; normal_dev_deg_max: number | null;
  crease_faces: number | null; crease_normal_dev_deg_p95: number | null;
  face_normal_dev_deg_p95: number | null; face_normal_dev_deg_max: number | null;
  self_intersections: number | null;
  /** The crossing pairs as triangle indices, two per pair (empty where not asked for). */
  self_intersecting_pairs: Uint32Array;
  ms_analysis: number;
}
"#;

/// Tape bricks for the distance queries: about as fine as a 64-cell mesh's (the analysis runs on
/// meshes of every size; finer bricks pay off only on long programs, coarser ones lose little).
const ANALYSIS_BRICK_DEPTH: u8 = 4;

/// Measures a mesh result (the arrays of `MeshArrays`): its distance and normal error against
/// `options.expr` or `options.csg`, and its crossing triangles where `options.checkIntersections`.
/// Stops at a checkpoint like the meshing calls (a cancelled worker call). Throws on mangled
/// arrays, unknown options, both `expr` and `csg`, or a program that does not compile.
#[wasm_bindgen(js_name = analyzeMesh, unchecked_return_type = "MeshAnalysis")]
pub fn analyze_mesh(
    #[wasm_bindgen(unchecked_param_type = "MeshArrays")] result: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "AnalyzeOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let started = Instant::now();
    let mesh = mesh_from_arrays(&result)?;
    let invalid = |message: String| js_error(Error::InvalidOption(message));
    if let Some(message) = mesh.index_error() {
        return Err(invalid(message));
    }
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(invalid(format!("vertex {v} is not finite: {:?}", mesh.positions[v].to_array())));
    }
    let (program, check_intersections) = parse(options)?;
    // Both checks look for a cancel every few thousand box pairs or faces: the page runs them
    // after every mesh, and the next request must not wait for them.
    let (pairs, error) = with_progress(|| -> Result<_, Error> {
        crate::progress::checkpoint("analysis", 0.0)?;
        let pairs =
            check_intersections.then(|| analysis::self_intersecting_pairs_cancellable(&mesh)).transpose()?;
        let error = match &program {
            Some(program) if mesh.triangle_count() > 0 => {
                let (lo, hi) = mesh
                    .positions
                    .iter()
                    .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
                let regional = RegionalProgram::new(program, lo, hi, ANALYSIS_BRICK_DEPTH);
                Some(analysis::surface_error_cancellable(&mesh, &regional)?)
            }
            Some(_) => Some(analysis::SurfaceError::default()),
            None => None,
        };
        Ok((pairs, error))
    })
    .map_err(js_error)?;

    let out = Object::new();
    let set = |k: &str, v: JsValue| Reflect::set(&out, &JsValue::from_str(k), &v).map(|_| ());
    let number =
        |pick: fn(&analysis::SurfaceError) -> f64| error.as_ref().map_or(JsValue::NULL, |e| pick(e).into());
    set("dist_max", number(|e| e.dist_max))?;
    set("dist_rms", number(|e| e.dist_rms))?;
    set("normal_dev_deg_p50", number(|e| e.normal_dev_deg_p50))?;
    set("normal_dev_deg_p95", number(|e| e.normal_dev_deg_p95))?;
    set("normal_dev_deg_max", number(|e| e.normal_dev_deg_max))?;
    set("crease_faces", number(|e| e.crease_faces as f64))?;
    set("crease_normal_dev_deg_p95", number(|e| e.crease_normal_dev_deg_p95))?;
    set("face_normal_dev_deg_p95", number(|e| e.face_normal_dev_deg_p95))?;
    set("face_normal_dev_deg_max", number(|e| e.face_normal_dev_deg_max))?;
    set("self_intersections", pairs.as_ref().map_or(JsValue::NULL, |p| (p.len() as f64).into()))?;
    let flat: Vec<u32> = pairs.iter().flatten().flatten().copied().collect();
    set("self_intersecting_pairs", Uint32Array::from(&flat[..]).into())?;
    set("ms_analysis", crate::mc::ms_since(started).into())?;
    Ok(out.into())
}

/// Keys analyzeMesh reads; any other is an error naming them (a misspelt key would otherwise
/// measure nothing without a word).
const KEYS: [&str; 3] = ["expr", "csg", "checkIntersections"];

/// The shape (if any) and whether to find crossings.
fn parse(options: Option<JsValue>) -> Result<(Option<Program>, bool), JsValue> {
    let Some(options) = options else { return Ok((None, false)) };
    let invalid = |message: String| js_error(Error::InvalidOption(message));
    if !options.is_object() {
        return Err(invalid("analyzeMesh options must be an object".into()));
    }
    for key in Object::keys(options.unchecked_ref::<Object>()).iter().filter_map(|k| k.as_string()) {
        if !KEYS.contains(&key.as_str()) {
            return Err(invalid(format!("unknown analyzeMesh option `{key}`, expected one of {KEYS:?}")));
        }
    }
    let get = |key: &str| {
        Reflect::get(&options, &JsValue::from_str(key))
            .map(|v| (!v.is_undefined() && !v.is_null()).then_some(v))
    };
    let program = match (get("expr")?, get("csg")?) {
        (Some(_), Some(_)) => return Err(invalid("analyzeMesh takes expr or csg, not both".into())),
        (Some(text), None) => {
            let text = text.as_string().ok_or_else(|| invalid("expr must be a string".into()))?;
            Some(crate::expr::compile(&text).map_err(js_error)?)
        }
        (None, Some(csg)) => Some(Program::from_csg_json(&csg_text(&csg)?).map_err(js_error)?),
        (None, None) => None,
    };
    let check_intersections = match get("checkIntersections")? {
        None => false,
        Some(v) => v.as_bool().ok_or_else(|| invalid("checkIntersections must be a boolean".into()))?,
    };
    Ok((program, check_intersections))
}

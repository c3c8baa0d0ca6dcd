//! Options objects from JavaScript into a [`Request`]: every key checked (unknown ones named with
//! the list of known ones), numbers range-checked, and every failure a JavaScript `Error` with
//! the library's message.

use super::js_error;
use crate::error::Error;
use crate::field::SampleGradient;
use crate::grid::{Dtype, DEFAULT_MAX_CELLS};
use crate::mc::Topology;
use crate::pipeline::{Method, Request};
use crate::stats::AnalysisOptions;
use glam::Vec3;
use js_sys::Object;
use serde::Deserialize;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

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
    snap: Option<f32>,
    project: Option<bool>,
    dtype: Option<String>,
    gradient: Option<String>,
    decimate: Option<f64>,
    decimate_error: Option<f32>,
    smooth: Option<f64>,
}

/// Options of every function but meshGrid, which alone takes a `dtype`.
pub(super) fn parse_options(options: Option<JsValue>) -> Result<Request, JsValue> {
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
pub(super) fn parse_grid_options(
    options: Option<JsValue>,
) -> Result<(Request, Option<Dtype>, bool), JsValue> {
    // wasm-bindgen passes `undefined` and `null` as None.
    let o: JsOptions = match options {
        None => JsOptions::default(),
        Some(options) => {
            check_keys(&options)?;
            serde_wasm_bindgen::from_value(options).map_err(|e| js_error(format!("invalid options: {e}")))?
        }
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
        surface_error: o.surface_error.unwrap_or(false),
    };
    // Ranges are checked by the method itself, with the same names.
    r.theta_sharp = o.theta_sharp.unwrap_or(r.theta_sharp);
    r.phi_corner = o.phi_corner.unwrap_or(r.phi_corner);
    r.directed = o.directed.unwrap_or(r.directed);
    r.better_triangles = o.better_triangles.unwrap_or(r.better_triangles);
    r.resample_creases = o.resample_creases.unwrap_or(r.resample_creases);
    r.merge_flat = o.merge_flat.unwrap_or(r.merge_flat);
    r.tolerance = o.tolerance.unwrap_or(r.tolerance);
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
    // A target of 0 is refused by the request's validation, with the same words as the CLI's.
    if let Some(n) = o.decimate {
        r.decimate = Some(whole("decimate", n, 1e9)? as usize);
    }
    r.decimate_error = o.decimate_error;
    if let Some(n) = o.smooth {
        r.smooth = whole("smooth", n, 1e6)? as usize;
    }
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

pub(super) fn parse_bounds(b: &[f32]) -> Result<(Vec3, Vec3), JsValue> {
    if b.len() != 6 {
        return Err(js_error(Error::InvalidOption(format!(
            "bounds must be [x0, y0, z0, x1, y1, z1], got {} numbers",
            b.len()
        ))));
    }
    Ok((Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5])))
}

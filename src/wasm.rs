//! The JavaScript face of the library: a thin layer that parses options, calls [`crate::pipeline`],
//! and copies results out as typed arrays in one go (no per-vertex calls across the boundary).
//! Every failure becomes a JavaScript `Error` carrying the library's message.

use crate::error::Error;
use crate::expr::{self, Program};
use crate::field::BatchFn;
use crate::grid::{self, Dtype, Grid};
use crate::pipeline::{self, Output};
use crate::scenes;
use glam::Vec3;
use js_sys::{ArrayBuffer, Float32Array, Object, Reflect, Uint16Array, Uint32Array, Uint8Array};
use serde::Serialize;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

mod analysis;
mod export;
mod inputs;
mod options;
mod types;
pub use export::export_mesh;
pub use inputs::{mesh_points, mesh_triangles};
use options::{parse_bounds, parse_grid_options, parse_options};

#[wasm_bindgen(start)]
fn start() {
    console_error_panic_hook::set_once();
}

/// Threads the meshing functions run on: 1 in the plain build; in the threaded one (`threads/`,
/// shared memory) the size of the pool [`start_threads`] started, or 1 before that.
#[wasm_bindgen(js_name = threadCount)]
pub fn thread_count() -> usize {
    crate::par::threads()
}

/// Starts `threads` Web Workers that the meshing functions' parallel sections (sampling, slabs,
/// batches) then share; resolves once they run. Only in the threaded build, and only where the
/// page is cross-origin isolated (`SharedArrayBuffer`); the meshes are the same as on one thread.
/// `createMesher` calls it in its worker where it can.
#[cfg(feature = "threads")]
#[wasm_bindgen(js_name = startThreads)]
pub fn start_threads(threads: usize) -> js_sys::Promise {
    let started = Closure::once(|_: JsValue| crate::par::pool_started());
    let promise = wasm_bindgen_rayon::init_thread_pool(threads.max(1)).then(&started);
    started.forget();
    promise
}

thread_local! {
    static PROGRESS_HOOK: std::cell::RefCell<Option<js_sys::Function>> = const { std::cell::RefCell::new(None) };
}

/// Installs `hook(phase, fraction)` for every later meshing call (in this worker or page): the
/// meshers call it between slabs, octree levels and passes with the phase's name (the keys of
/// `stats.phases_ms`, and `"analysis"`) and how far it got, 0 to 1. Returning `true` stops the
/// call, which then throws an `Error` "meshing cancelled"; that is how `createMesher` abandons a
/// superseded request without restarting its worker. `undefined` removes the hook.
#[wasm_bindgen(js_name = setProgressHook)]
pub fn set_progress_hook(
    #[wasm_bindgen(
        unchecked_param_type = "((phase: string, fraction: number) => boolean | void) | undefined"
    )]
    hook: JsValue,
) -> Result<(), JsValue> {
    let hook = if hook.is_undefined() || hook.is_null() {
        None
    } else {
        Some(
            hook.dyn_into::<js_sys::Function>()
                .map_err(|_| js_error("the progress hook must be a function"))?,
        )
    };
    PROGRESS_HOOK.with(|h| *h.borrow_mut() = hook);
    Ok(())
}

/// Runs a meshing job under the installed progress hook, if any. A hook that throws is ignored
/// (the job goes on): a bug in a listener should not lose the mesh.
fn with_progress<R>(job: impl FnOnce() -> R) -> R {
    match PROGRESS_HOOK.with(|h| h.borrow().clone()) {
        None => job(),
        Some(hook) => crate::progress::with_hook(
            move |phase, fraction| {
                hook.call2(&JsValue::NULL, &JsValue::from_str(phase), &JsValue::from_f64(fraction as f64))
                    .is_ok_and(|stop| stop.is_truthy())
            },
            job,
        ),
    }
}

fn js_error(e: impl std::fmt::Display) -> JsValue {
    js_sys::Error::new(&e.to_string()).into()
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

/// The functions of the expression language, in the order of the docs: `{ name, signature,
/// group, summary }` each, `group` one of "math", "shapes", "combinators", "transforms".
#[wasm_bindgen(
    js_name = languageReference,
    unchecked_return_type = "{ name: string, signature: string, group: string, summary: string }[]"
)]
pub fn language_reference() -> Result<JsValue, JsValue> {
    let arr = js_sys::Array::new();
    for b in expr::Builtin::all() {
        let entry = js_sys::Object::new();
        for (key, value) in
            [("name", b.name()), ("signature", b.signature()), ("group", b.group()), ("summary", b.summary())]
        {
            js_sys::Reflect::set(&entry, &key.into(), &value.into())?;
        }
        arr.push(&entry);
    }
    Ok(arr.into())
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
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&with_progress(|| pipeline::mesh_scene(name, &request)).map_err(js_error)?)
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

    /// `[x0, y0, z0, x1, y1, z1]`: bounds to mesh the shape in, found from interval bounds alone:
    /// the box its inside fits in (conservative, tight to about 1 % of its size) grown on every
    /// side by `margin` (default 0.05) times its longest side. Throws when the inside is empty or
    /// unbounded (a half-space, an unclipped gyroid), naming the open directions.
    #[wasm_bindgen(js_name = autoBounds, unchecked_return_type = "[number, number, number, number, number, number]")]
    pub fn auto_bounds(&self, margin: Option<f32>) -> Result<Vec<f32>, JsValue> {
        let (lo, hi) = expr::extent::auto_bounds(&self.program, margin.unwrap_or(0.05)).map_err(js_error)?;
        Ok(vec![lo.x, lo.y, lo.z, hi.x, hi.y, hi.z])
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
    #[wasm_bindgen(unchecked_param_type = "string | CsgNode | { toJSON(): CsgNode }")] json: JsValue,
) -> Result<Shape, JsValue> {
    Ok(Shape { program: Program::from_csg_json(&csg_text(&json)?).map_err(js_error)? })
}

/// Meshes a compiled shape in `options.bounds`, or [-1, 1]³.
#[wasm_bindgen(js_name = meshShape, unchecked_return_type = "MeshResult")]
pub fn mesh_shape(
    shape: &Shape,
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&with_progress(|| pipeline::mesh_program(&shape.program, &request)).map_err(js_error)?)
}

/// Compiles and meshes a program in the expression language, in `options.bounds` or [-1, 1]³.
/// Parse errors throw like `compile`'s.
#[wasm_bindgen(js_name = meshExpr, unchecked_return_type = "MeshResult")]
pub fn mesh_expr(
    text: &str,
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    to_js(&with_progress(|| pipeline::mesh_expr(text, &request)).map_err(js_error)?)
}

/// Compiles and meshes a CSG tree (a JSON string or a `CsgNode` object), in `options.bounds` or
/// [-1, 1]³.
#[wasm_bindgen(js_name = meshCsg, unchecked_return_type = "MeshResult")]
pub fn mesh_csg(
    #[wasm_bindgen(unchecked_param_type = "string | CsgNode | { toJSON(): CsgNode }")] json: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    let text = csg_text(&json)?;
    to_js(&with_progress(|| pipeline::mesh_csg_json(&text, &request)).map_err(js_error)?)
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
    #[wasm_bindgen(unchecked_optional_param_type = "GridOptions")] options: Option<JsValue>,
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
    to_js(&with_progress(|| pipeline::mesh_samples(&samples, &grid, &request)).map_err(js_error)?)
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
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
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
    to_js(&with_progress(|| pipeline::mesh_function(&batch, bounds, &request)).map_err(js_error)?)
}

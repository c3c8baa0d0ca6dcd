//! `exportMesh`: a meshing result encoded as OBJ, STL, PLY or GLB bytes in the page, for downloads
//! and uploads without a server round trip. The arrays are checked before anything is written, so
//! a mangled result gives a message naming the array at fault rather than a corrupt file.

use super::js_error;
use crate::error::Error;
use crate::mesh::export::{self, Format};
use crate::mesh::Mesh;
use glam::Vec3;
use js_sys::{Float32Array, Reflect, Uint32Array};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

#[wasm_bindgen(typescript_custom_section)]
const TS_EXPORT: &'static str = r#"
/** A file format of exportMesh: Wavefront OBJ (text), binary STL, binary PLY, binary glTF 2.0. */
export type ExportFormat = "obj" | "stl" | "ply" | "glb";

/** The arrays of a MeshResult exportMesh reads (a whole MeshResult will do). */
export type MeshArrays = Pick<MeshResult, "positions" | "normals" | "indices">;
"#;

/// The mesh file of a result (`positions`, `normals`, `indices` as returned by the mesh functions;
/// `normals` may be empty) in `format`: `"obj"`, `"stl"`, `"ply"` or `"glb"`. Throws an `Error` on
/// an unknown format or arrays that do not fit together (lengths not multiples of 3, a normal
/// count other than zero or one per vertex, indices past the vertices).
#[wasm_bindgen(js_name = exportMesh, unchecked_return_type = "Uint8Array<ArrayBuffer>")]
pub fn export_mesh(
    #[wasm_bindgen(unchecked_param_type = "MeshArrays")] result: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ExportFormat")] format: &str,
) -> Result<Vec<u8>, JsValue> {
    let format = Format::parse(format).map_err(js_error)?;
    let mesh = mesh_from_arrays(&result)?;
    export::to_bytes(&mesh, format).map_err(js_error)
}

/// The mesh of a result's arrays, checked as far as `exportMesh` needs (see [`export_mesh`]).
pub(super) fn mesh_from_arrays(result: &JsValue) -> Result<Mesh, JsValue> {
    if !result.is_object() {
        return Err(invalid("exportMesh needs a mesh result: { positions, normals, indices }".into()));
    }
    let get = |name: &str| Reflect::get(result, &JsValue::from_str(name));
    let positions = get("positions")?
        .dyn_into::<Float32Array>()
        .map_err(|_| invalid("positions must be a Float32Array".into()))?
        .to_vec();
    let normals = get("normals")?;
    let normals = if normals.is_undefined() {
        Vec::new()
    } else {
        normals
            .dyn_into::<Float32Array>()
            .map_err(|_| invalid("normals must be a Float32Array".into()))?
            .to_vec()
    };
    let indices = get("indices")?
        .dyn_into::<Uint32Array>()
        .map_err(|_| invalid("indices must be a Uint32Array".into()))?
        .to_vec();
    for (name, len) in
        [("positions", positions.len()), ("normals", normals.len()), ("indices", indices.len())]
    {
        if len % 3 != 0 {
            return Err(invalid(format!("{name} holds {len} numbers, not a multiple of 3")));
        }
    }
    let triples = |v: &[f32]| v.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
    // The writers check normal counts and index ranges with messages naming the numbers.
    Ok(Mesh {
        positions: triples(&positions),
        normals: triples(&normals),
        triangles: indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    })
}

fn invalid(message: String) -> JsValue {
    js_error(Error::InvalidOption(message))
}

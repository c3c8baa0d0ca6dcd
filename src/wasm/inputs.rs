//! Triangle meshes and oriented point clouds from JavaScript typed arrays: `meshTriangles` remeshes
//! a closed mesh, `meshPoints` reconstructs a surface from points with normals (see
//! [`crate::pipeline::mesh_triangles`], [`crate::pipeline::mesh_points`]). With no `bounds` the grid
//! covers the input's bounding box padded by two cells, `res` cells along its longest side.

use super::{js_error, parse_options, to_js};
use crate::error::Error;
use crate::input::PointCloud;
use crate::mesh::Mesh;
use crate::pipeline;
use glam::Vec3;
use wasm_bindgen::prelude::*;

/// xyz triples as points; `what` names the array in the error.
fn triples(values: &[f32], what: &str) -> Result<Vec<Vec3>, JsValue> {
    if values.len() % 3 != 0 {
        return Err(js_error(Error::InvalidOption(format!(
            "{what} must hold xyz triples, got {} numbers",
            values.len()
        ))));
    }
    Ok(values.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
}

/// Remeshes a closed triangle mesh with EMC (`method: "emc"`) or plain MC on its signed distances
/// (`"mc"`, the default, the baseline): `positions` are xyz triples, `indices` vertex triples,
/// counter-clockwise seen from outside (a mesh wound the other way throughout is turned around).
/// Sharp edges and corners of the input come back as `featureEdges`; the stats measure against the
/// input. `iso` must be 0. Throws on indices past the vertices, non-finite positions or a mesh
/// without area.
#[wasm_bindgen(js_name = meshTriangles, unchecked_return_type = "MeshResult")]
pub fn mesh_triangles(
    positions: &[f32],
    indices: &[u32],
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    if indices.len() % 3 != 0 {
        return Err(js_error(Error::InvalidOption(format!(
            "indices must hold vertex triples, got {} numbers",
            indices.len()
        ))));
    }
    let mesh = Mesh {
        positions: triples(positions, "positions")?,
        normals: Vec::new(),
        triangles: indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    };
    to_js(&super::with_progress(|| pipeline::mesh_triangles(&mesh, &request)).map_err(js_error)?)
}

/// Reconstructs the surface an oriented point cloud samples, with EMC (`method: "emc"`, tangent
/// planes of the nearest samples) or plain MC on the same signed distances (`"mc"`, the default):
/// `positions` and `normals` are xyz triples, one normal per point pointing out of the solid (scaled
/// to unit length here). The cloud should be dense compared with the grid's cells. `iso` must be 0.
#[wasm_bindgen(js_name = meshPoints, unchecked_return_type = "MeshResult")]
pub fn mesh_points(
    positions: &[f32],
    normals: &[f32],
    #[wasm_bindgen(unchecked_optional_param_type = "MeshOptions")] options: Option<JsValue>,
) -> Result<JsValue, JsValue> {
    let request = parse_options(options)?;
    let cloud =
        PointCloud { positions: triples(positions, "positions")?, normals: triples(normals, "normals")? };
    to_js(&super::with_progress(|| pipeline::mesh_points(&cloud, &request)).map_err(js_error)?)
}

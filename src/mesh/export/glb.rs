//! Binary glTF 2.0 (`.glb`), the web's own mesh format: three.js, Babylon.js, Blender and model
//! viewers load it directly, and it keeps shared vertices, normals and 32-bit indices in one file.
//!
//! Layout (glTF 2.0 specification, "GLB File Format Specification"): a 12-byte header (`glTF`,
//! version 2, total length), a JSON chunk padded with spaces and a binary chunk padded with zeros,
//! each chunk's length a multiple of 4. The binary chunk holds positions, then normals, then
//! indices, all little-endian and naturally 4-byte aligned. The JSON describes one scene with one
//! node holding one mesh of one triangle primitive; POSITION carries the `min`/`max` the
//! specification requires of it.

use super::check;
use crate::mesh::Mesh;
use glam::Vec3;
use serde_json::{json, Value};
use std::io::{self, Write};

/// `glTF` read as a little-endian `u32`.
pub const MAGIC: u32 = 0x4654_6C67;
/// Chunk type of the JSON chunk (`JSON`).
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary buffer chunk (`BIN\0`).
pub const CHUNK_BIN: u32 = 0x004E_4942;

// glTF enumerations (the specification's accessor component types, buffer view targets, modes).
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const TRIANGLES: u32 = 4;

/// Writes `mesh` as binary glTF 2.0. Normals are written when the mesh has them (renormalised,
/// since glTF requires unit normals; a zero normal at a degenerate spot takes the average of its
/// faces' normals). An empty mesh gives a valid file with an empty scene: glTF forbids accessors
/// and buffers of length zero, so there is then no mesh at all.
pub fn write_glb(mesh: &Mesh, w: &mut dyn Write) -> io::Result<()> {
    let has_normals = check(mesh)?;
    let (json, bin) = if mesh.triangles.is_empty() {
        (document_header(), Vec::new())
    } else {
        mesh_document(mesh, has_normals)?
    };
    let mut json = serde_json::to_vec(&json).map_err(io::Error::other)?;
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut chunks = vec![(CHUNK_JSON, json)];
    if !bin.is_empty() {
        chunks.push((CHUNK_BIN, bin));
    }
    let total: usize = 12 + chunks.iter().map(|(_, data)| 8 + data.len()).sum::<usize>();
    let total = u32::try_from(total).map_err(|_| super::invalid("a GLB file is limited to 4 GiB"))?;
    let mut out = io::BufWriter::new(w);
    for word in [MAGIC, 2, total] {
        out.write_all(&word.to_le_bytes())?;
    }
    for (kind, data) in &chunks {
        out.write_all(&(data.len() as u32).to_le_bytes())?;
        out.write_all(&kind.to_le_bytes())?;
        out.write_all(data)?;
    }
    out.flush()
}

/// What every file has: the asset version and a default scene.
fn document_header() -> Value {
    json!({
        "asset": { "version": "2.0", "generator": concat!("isoforge ", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{}],
    })
}

/// The JSON document and the binary buffer of a non-empty mesh.
fn mesh_document(mesh: &Mesh, has_normals: bool) -> io::Result<(Value, Vec<u8>)> {
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push_view = |bin: &mut Vec<u8>, data: &[u8], target: u32| {
        views.push(
            json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": data.len(), "target": target }),
        );
        bin.extend_from_slice(data);
        views.len() - 1
    };

    let (min, max) = bounds(&mesh.positions);
    let view = push_view(&mut bin, &vec3_bytes(&mesh.positions), ARRAY_BUFFER);
    accessors.push(json!({
        "bufferView": view, "componentType": FLOAT, "count": mesh.positions.len(), "type": "VEC3",
        "min": min.to_array(), "max": max.to_array(),
    }));
    let mut attributes = json!({ "POSITION": 0 });
    if has_normals {
        let view = push_view(&mut bin, &vec3_bytes(&unit_normals(mesh)), ARRAY_BUFFER);
        accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": mesh.positions.len(), "type": "VEC3",
        }));
        attributes["NORMAL"] = json!(accessors.len() - 1);
    }
    let indices: Vec<u8> = mesh.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    let view = push_view(&mut bin, &indices, ELEMENT_ARRAY_BUFFER);
    accessors.push(json!({
        "bufferView": view, "componentType": UNSIGNED_INT, "count": 3 * mesh.triangles.len(), "type": "SCALAR",
    }));
    let index_accessor = accessors.len() - 1;
    // Every part is a whole number of 4-byte words already; the chunk itself must be too.
    debug_assert_eq!(bin.len() % 4, 0);
    let byte_length =
        u32::try_from(bin.len()).map_err(|_| super::invalid("a GLB file is limited to 4 GiB"))?;

    let mut doc = document_header();
    doc["scenes"] = json!([{ "nodes": [0] }]);
    doc["nodes"] = json!([{ "mesh": 0 }]);
    doc["meshes"] = json!([{
        "primitives": [{ "attributes": attributes, "indices": index_accessor, "mode": TRIANGLES }],
    }]);
    doc["accessors"] = Value::Array(accessors);
    doc["bufferViews"] = Value::Array(views);
    doc["buffers"] = json!([{ "byteLength": byte_length }]);
    Ok((doc, bin))
}

/// Component-wise minimum and maximum of the positions (at least one).
fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
}

fn vec3_bytes(points: &[Vec3]) -> Vec<u8> {
    points.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect()
}

/// The mesh's normals at unit length; zero ones (degenerate spots) replaced by the area-weighted
/// normal of the incident faces, and +z where even that vanishes, since glTF readers may reject
/// non-unit normals.
fn unit_normals(mesh: &Mesh) -> Vec<Vec3> {
    let mut normals: Vec<Vec3> = mesh.normals.iter().map(|n| n.normalize_or_zero()).collect();
    if normals.contains(&Vec3::ZERO) {
        let mut from_faces = mesh.clone();
        from_faces.compute_normals_from_faces();
        for (n, f) in normals.iter_mut().zip(from_faces.normals) {
            if *n == Vec3::ZERO {
                *n = if f == Vec3::ZERO { Vec3::Z } else { f };
            }
        }
    }
    normals
}

#[cfg(test)]
#[path = "glb_tests.rs"]
mod tests;

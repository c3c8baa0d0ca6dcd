//! GLB output parsed back by an independent reader written from the specification: header,
//! chunks, JSON, buffer views and accessors must agree with each other and with the mesh.

use super::*;
use crate::mesh::analysis::fixtures::{cube, mc_sphere, octahedron};

/// A GLB file taken apart: the JSON document and the binary chunk (empty when absent). Panics on
/// any violation of the container rules.
fn parse(bytes: &[u8]) -> (Value, Vec<u8>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(word(0), MAGIC);
    assert_eq!(word(4), 2, "version");
    assert_eq!(word(8) as usize, bytes.len(), "header length is the file length");
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < bytes.len() {
        let (len, kind) = (word(at) as usize, word(at + 4));
        assert_eq!(len % 4, 0, "chunk length {len} is not a multiple of 4");
        assert!(at + 8 + len <= bytes.len(), "chunk runs past the end");
        chunks.push((kind, &bytes[at + 8..at + 8 + len]));
        at += 8 + len;
    }
    assert_eq!(at, bytes.len());
    assert_eq!(chunks[0].0, CHUNK_JSON, "the JSON chunk comes first");
    let text = std::str::from_utf8(chunks[0].1).unwrap();
    assert!(text[text.trim_end().len()..].bytes().all(|b| b == b' '), "JSON padding is spaces");
    let json: Value = serde_json::from_str(text).unwrap();
    assert!(chunks.len() <= 2);
    let bin = match chunks.get(1) {
        Some((kind, data)) => {
            assert_eq!(*kind, CHUNK_BIN);
            data.to_vec()
        }
        None => Vec::new(),
    };
    (json, bin)
}

fn glb(mesh: &Mesh) -> Vec<u8> {
    let mut bytes = Vec::new();
    write_glb(mesh, &mut bytes).unwrap();
    bytes
}

/// The bytes accessor `index` covers, after checking its view lies inside the buffer and is
/// aligned to the 4-byte components every accessor here uses.
fn accessor_bytes<'a>(json: &'a Value, bin: &'a [u8], index: usize) -> (&'a [u8], &'a Value) {
    let accessor = &json["accessors"][index];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    assert_eq!(view["buffer"], 0);
    let offset = view["byteOffset"].as_u64().unwrap() as usize;
    let length = view["byteLength"].as_u64().unwrap() as usize;
    assert_eq!(offset % 4, 0, "view offset {offset} unaligned");
    assert!(offset + length <= bin.len(), "view past the buffer");
    let components = match accessor["type"].as_str().unwrap() {
        "VEC3" => 3,
        "SCALAR" => 1,
        t => panic!("unexpected accessor type {t}"),
    };
    let count = accessor["count"].as_u64().unwrap() as usize;
    assert_eq!(length, 4 * components * count, "view length matches the accessor");
    (&bin[offset..offset + length], accessor)
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
}

#[test]
fn sphere_round_trips_through_an_independent_reader() {
    let (m, _) = mc_sphere(12);
    let (json, bin) = parse(&glb(&m));
    assert_eq!(json["asset"]["version"], "2.0");
    let scene = json["scene"].as_u64().unwrap() as usize;
    let node = json["scenes"][scene]["nodes"][0].as_u64().unwrap() as usize;
    let mesh = json["nodes"][node]["mesh"].as_u64().unwrap() as usize;
    let primitives = json["meshes"][mesh]["primitives"].as_array().unwrap();
    assert_eq!(primitives.len(), 1);
    let primitive = &primitives[0];
    assert_eq!(primitive["mode"], 4, "triangles");
    assert_eq!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize, bin.len());

    let at = |name: &str| primitive["attributes"][name].as_u64().unwrap() as usize;
    let (bytes, positions) = accessor_bytes(&json, &bin, at("POSITION"));
    assert_eq!(positions["componentType"], 5126);
    assert_eq!(positions["count"].as_u64().unwrap() as usize, m.vertex_count());
    let read: Vec<f32> = floats(bytes);
    assert_eq!(read, m.flat_positions());
    // min/max computed here per component, compared exactly (the JSON numbers are f32 values).
    for axis in 0..3 {
        let column = read.iter().skip(axis).step_by(3);
        let lo = column.clone().copied().fold(f32::INFINITY, f32::min);
        let hi = column.copied().fold(f32::NEG_INFINITY, f32::max);
        assert_eq!(positions["min"][axis].as_f64().unwrap() as f32, lo);
        assert_eq!(positions["max"][axis].as_f64().unwrap() as f32, hi);
    }

    let (bytes, normals) = accessor_bytes(&json, &bin, at("NORMAL"));
    assert_eq!(normals["count"], positions["count"]);
    let read = floats(bytes);
    for (n, want) in read.chunks_exact(3).zip(&m.normals) {
        let n = Vec3::from_slice(n);
        assert!((n.length() - 1.0).abs() < 1e-5, "non-unit normal {n}");
        assert!(n.dot(*want) > 0.9999, "{n} vs {want}");
    }

    let (bytes, indices) = accessor_bytes(&json, &bin, primitive["indices"].as_u64().unwrap() as usize);
    assert_eq!(indices["componentType"], 5125);
    assert_eq!(indices["count"].as_u64().unwrap() as usize, 3 * m.triangle_count());
    let read: Vec<u32> = bytes.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(read, m.flat_indices());
}

#[test]
fn mesh_without_normals_has_positions_and_indices_only() {
    let m = cube();
    let (json, bin) = parse(&glb(&m));
    let primitive = &json["meshes"][0]["primitives"][0];
    assert!(primitive["attributes"].get("NORMAL").is_none());
    assert_eq!(json["accessors"].as_array().unwrap().len(), 2);
    // 8 positions and 36 indices, 4 bytes each.
    assert_eq!(bin.len(), 4 * (3 * 8 + 36));
    let (_, positions) = accessor_bytes(&json, &bin, 0);
    assert_eq!(positions["min"], json!([0.0, 0.0, 0.0]));
    assert_eq!(positions["max"], json!([1.0, 1.0, 1.0]));
}

#[test]
fn empty_mesh_gives_an_empty_scene_without_buffers() {
    let bytes = glb(&Mesh::default());
    let (json, bin) = parse(&bytes);
    assert!(bin.is_empty());
    assert!(json.get("meshes").is_none() && json.get("buffers").is_none() && json.get("accessors").is_none());
    assert_eq!(json["scenes"][0], json!({}));
}

#[test]
fn zero_and_unnormalised_normals_become_unit_normals() {
    let mut m = octahedron();
    m.normals = m.positions.iter().map(|p| 3.0 * *p).collect();
    m.normals[4] = Vec3::ZERO;
    let (json, bin) = parse(&glb(&m));
    let (bytes, _) = accessor_bytes(&json, &bin, 1);
    let normals: Vec<Vec3> = floats(bytes).chunks_exact(3).map(Vec3::from_slice).collect();
    for (n, p) in normals.iter().zip(&m.positions) {
        // The octahedron's vertex normal (from faces or given) points along the vertex itself.
        assert!(n.dot(*p) > 0.9999, "{n} at {p}");
    }
}

#[test]
fn inconsistent_meshes_are_refused() {
    let mut m = octahedron();
    m.triangles.push([0, 1, 9]);
    let err = write_glb(&m, &mut Vec::new()).unwrap_err();
    assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
}

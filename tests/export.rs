//! Every export format on a real scene, natively and as wasm in Chromium (where the browser's
//! downloads come from): the bytes of each file agree with the mesh they came from.

use isoforge::mesh::export::{self, Format};
use isoforge::pipeline::{self, Method, Request};
use isoforge::Mesh;

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

/// The EMC rocket (sharp fins, normals at every vertex) at a resolution that meshes quickly.
fn rocket() -> Mesh {
    let request = Request { method: Method::Emc, res: 32, ..Request::default() };
    let mesh = pipeline::mesh_scene("rocket", &request).unwrap().mesh;
    assert!(mesh.triangle_count() > 1000 && mesh.normals.len() == mesh.vertex_count());
    mesh
}

fn u32_at(bytes: &[u8], at: usize) -> usize {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize
}

#[test]
fn each_format_describes_the_scene_mesh() {
    let m = rocket();
    let (v, t) = (m.vertex_count(), m.triangle_count());

    let obj = String::from_utf8(export::to_bytes(&m, Format::Obj).unwrap()).unwrap();
    let lines = |prefix: &str| obj.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!([lines("v "), lines("vn "), lines("f ")], [v, v, t]);

    let stl = export::to_bytes(&m, Format::Stl).unwrap();
    assert_eq!((stl.len(), u32_at(&stl, 80)), (84 + 50 * t, t));

    let ply = export::to_bytes(&m, Format::Ply).unwrap();
    let text = String::from_utf8_lossy(&ply);
    let header = text.find("end_header\n").unwrap() + "end_header\n".len();
    assert!(text[..header].contains(&format!("element vertex {v}\nproperty float x")));
    assert_eq!(ply.len(), header + 24 * v + 13 * t);

    let glb = export::to_bytes(&m, Format::Glb).unwrap();
    assert_eq!((&glb[..4], u32_at(&glb, 4), u32_at(&glb, 8)), (&b"glTF"[..], 2, glb.len()));
    let json_len = u32_at(&glb, 12);
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin_len = u32_at(&glb, 20 + json_len);
    assert_eq!(glb.len(), 28 + json_len + bin_len);
    assert_eq!(bin_len, 4 * (6 * v + 3 * t));
    let primitive = &json["meshes"][0]["primitives"][0];
    let count = |accessor: &serde_json::Value| {
        json["accessors"][accessor.as_u64().unwrap() as usize]["count"].as_u64().unwrap() as usize
    };
    assert_eq!(count(&primitive["attributes"]["POSITION"]), v);
    assert_eq!(count(&primitive["attributes"]["NORMAL"]), v);
    assert_eq!(count(&primitive["indices"]), 3 * t);
    // The rocket stands in its scene box: the POSITION bounds lie inside it and span most of it.
    let scene = isoforge::scenes::scene("rocket").unwrap();
    let position = &json["accessors"][primitive["attributes"]["POSITION"].as_u64().unwrap() as usize];
    for axis in 0..3 {
        let lo = position["min"][axis].as_f64().unwrap() as f32;
        let hi = position["max"][axis].as_f64().unwrap() as f32;
        assert!(scene.min[axis] <= lo && lo < hi && hi <= scene.max[axis], "axis {axis}: {lo}..{hi}");
        assert!(hi - lo > 0.5 * (scene.max[axis] - scene.min[axis]), "axis {axis}: {lo}..{hi}");
    }
}

//! The quad method (seed paper 003) on a sphere, a torus and a CSG part: the quad mesh must be a
//! closed 2-manifold with the Euler characteristic of the true surface (and of plain Marching Cubes
//! on the same grid), its vertices must sit on the surface after projection, and the collapses must
//! strictly reduce the number of irregular (non-valence-four) vertices.

use isoforge::mc::{self, McOptions};
use isoforge::mesh::analysis;
use isoforge::pipeline::{self, Method, Output, Request};
use isoforge::quad::QuadMesh;
use isoforge::scenes;
use isoforge::stats::AnalysisOptions;
use isoforge::{Grid, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

fn request(res: usize) -> Request {
    Request {
        method: Method::Quad,
        res,
        analysis: AnalysisOptions { self_intersections: false, surface_error: true },
        ..Request::default()
    }
}

/// Meshes a scene with the quad method and checks what every quad output must satisfy; returns
/// the output and the Euler characteristic of plain MC on the same grid.
fn quad_scene(name: &str, res: usize) -> (Output, i64) {
    let out = pipeline::mesh_scene(name, &request(res)).unwrap();
    let quads = QuadMesh::new(out.mesh.positions.clone(), out.quads.clone());
    assert!(quads.is_closed_manifold(), "{name}: quad mesh not a closed 2-manifold");
    assert_eq!(out.mesh.triangle_count(), 2 * quads.quad_count(), "{name}: two triangles per quad");
    // The independent triangle-mesh checker must agree on the triangulation.
    let topo = analysis::topology(&out.mesh);
    assert!(topo.is_closed_manifold(), "{name}: triangulation not closed/manifold: {topo:?}");
    assert_eq!(topo.euler, quads.euler(), "{name}: triangulating keeps the Euler characteristic");
    assert!(analysis::signed_volume(&out.mesh) > 0.0, "{name}: quads must face outward");
    let scene = scenes::scene(name).unwrap();
    let grid = Grid::with_resolution(scene.min, scene.max, res).unwrap();
    let (mc_mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
    (out, analysis::topology(&mc_mesh).euler)
}

fn stage<'a>(out: &'a Output, name: &str) -> &'a isoforge::quad::QuadStage {
    out.stats.quad_stages.iter().find(|s| s.stage == name).unwrap_or_else(|| panic!("no stage {name}"))
}

#[test]
fn sphere_is_a_closed_quad_sphere_and_collapses_remove_irregular_vertices() {
    let res = 24;
    let (out, mc_euler) = quad_scene("sphere", res);
    assert_eq!(out.stats.euler, 2);
    assert_eq!(mc_euler, 2);
    assert!(out.stats.quad_stages.iter().all(|s| s.euler == 2), "every stage keeps χ = 2");
    let h = 2.0 / res as f64;
    let projected = stage(&out, "projected");
    assert!(projected.dist_max < 1e-3 * h, "vertices on the sphere after projection: {}", projected.dist_max);
    let collapsed = stage(&out, "local");
    assert!(
        collapsed.irregular < projected.irregular,
        "collapses must remove irregular vertices: {} -> {}",
        projected.irregular,
        collapsed.irregular
    );
    assert!(collapsed.valence4_share > projected.valence4_share);
    // Subdivided and projected, the result is still on the sphere: every vertex (exact SDF).
    for p in &out.mesh.positions {
        assert!((p.length() - 0.8).abs() < 1e-3 * h as f32, "vertex {p} off the sphere");
    }
    // Each collapse stage did something.
    assert!(stage(&out, "semilocal1").operations + stage(&out, "ring1").operations > 0);
}

#[test]
fn torus_keeps_genus_one() {
    let (out, mc_euler) = quad_scene("torus", 32);
    assert_eq!(out.stats.euler, 0);
    assert_eq!(mc_euler, 0);
    let last = out.stats.quad_stages.last().unwrap();
    assert!(last.dist_max < 0.01, "torus vertices on the surface: {}", last.dist_max);
    assert!(stage(&out, "local").irregular <= stage(&out, "projected").irregular);
}

#[test]
fn csg_part_with_five_tunnels_keeps_its_topology() {
    // Cube minus a ball poking through all six faces: genus 5, χ = -8.
    let (out, mc_euler) = quad_scene("cube_minus_sphere", 32);
    assert_eq!(mc_euler, -8);
    assert_eq!(out.stats.euler, -8);
    assert!(out.stats.quad_stages.iter().all(|s| s.euler == -8));
}

#[test]
fn each_stage_is_measured_and_stats_count_the_quads() {
    let out = pipeline::mesh_expr("sphere(0.7)", &request(16)).unwrap();
    assert_eq!(out.stats.method, "quad");
    assert_eq!(out.stats.quads, out.quads.len());
    let names: Vec<&str> = out.stats.quad_stages.iter().map(|s| s.stage.as_str()).collect();
    assert_eq!(names[..2], ["extracted", "projected"]);
    assert!(names.contains(&"local") && names.last().unwrap().starts_with("subdivided"));
    let extracted = &out.stats.quad_stages[0];
    // Unprojected, vertices are centroids of MC polygons, inside the cells the surface cuts: within
    // a cell diagonal of the surface, and not on it.
    assert!(extracted.dist_max < 2.0 * 3f64.sqrt() / 16.0 && extracted.dist_max > 1e-4);
    assert_eq!(extracted.held_back, 0, "the extraction is valid as it comes");
    assert!(out.stats.quad_stages.iter().all(|s| s.aspect_mean >= 1.0 && s.aspect_max.is_finite()));
    assert!(out.mesh.positions.iter().all(|p| p.is_finite() && p.abs().max_element() <= 1.0));
    let _ = Vec3::ZERO;
}

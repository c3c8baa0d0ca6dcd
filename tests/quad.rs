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

/// Quad and MC on the same grid: (Euler characteristic, components, closed) of each, after the
/// checks every quad output must pass wherever it ends (manifold, finite, no crossings or folds).
fn quad_and_mc(program: &str, res: usize) -> ((i64, usize, bool), (i64, usize, bool)) {
    let out = pipeline::mesh_expr(program, &request(res)).unwrap();
    let quads = QuadMesh::new(out.mesh.positions.clone(), out.quads.clone());
    assert!(quads.is_manifold(), "{program}: not a 2-manifold");
    assert!(out.mesh.positions.iter().all(|p| p.is_finite()), "{program}");
    assert_eq!(analysis::self_intersections(&out.mesh), 0, "{program}: self-intersections");
    assert!(analysis::folded_pairs(&out.mesh).is_empty(), "{program}: folds");
    let mc_out = pipeline::mesh_expr(program, &Request { method: Method::Mc, ..request(res) }).unwrap();
    let summary = |m: &isoforge::Mesh| {
        let t = analysis::topology(m);
        (t.euler, t.components, t.boundary_edges == 0)
    };
    (summary(&out.mesh), summary(&mc_out.mesh))
}

/// Issue 15: `--expr x` panicked (index out of bounds in the extraction). The plane reaches the
/// bounds on four sides; like MC's, the quad mesh is a disc cut open there (χ = 1).
#[test]
fn a_plane_through_the_bounds_is_a_disc_cut_open_as_mc_cuts_it() {
    let (quad, mc) = quad_and_mc("x", 16);
    assert_eq!(quad, mc);
    assert_eq!(quad, (1, 1, false));
}

/// Issue 15: `sphere(1.2)` (larger than the bounds' inscribed ball) panicked too. In [-1, 1]³ it is
/// the sphere with its six caps beyond the cube's faces cut off: one piece, χ = 2 − 6 = −4.
#[test]
fn a_sphere_past_the_bounds_has_mcs_topology() {
    let (quad, mc) = quad_and_mc("sphere(1.2)", 24);
    assert_eq!(quad, mc);
    assert!(!quad.2, "cut open by the bounds");
}

/// Issue 15: eight disjoint balls close together became one genus-5 surface (the old extraction
/// joined cells touching along an edge). Gaps of 0.02 at res 20 (cells of 0.1) are below a cell.
#[test]
fn eight_disjoint_balls_close_together_stay_eight_spheres() {
    let balls: Vec<String> = (0..8)
        .map(|k| {
            let c = [k & 1, (k >> 1) & 1, k >> 2].map(|b| if b == 1 { 0.26 } else { -0.26 });
            format!("translate(sphere(0.25), {}, {}, {})", c[0], c[1], c[2])
        })
        .collect();
    let (quad, mc) = quad_and_mc(&format!("union({})", balls.join(", ")), 20);
    assert_eq!(mc, (16, 8, true));
    assert_eq!(quad, mc);
}

/// Issue 15: a thin cavity meshed to nothing. A slot 0.04 thick in a box at res 16 (cells of
/// 0.125) holds one layer of grid points; MC sees it as a second sphere inside, and so must quad.
#[test]
fn a_thin_cavity_is_kept_as_a_second_sphere() {
    let (quad, mc) = quad_and_mc("subtract(box(0.8, 0.8, 0.8), box(0.6, 0.6, 0.02))", 16);
    assert_eq!(mc, (4, 2, true));
    assert_eq!(quad, mc);
    let (quad, mc) = quad_and_mc("subtract(sphere(0.5), sphere(0.3))", 32);
    assert_eq!((quad, mc), ((4, 2, true), (4, 2, true)), "the hollow ball");
}

/// Issue 15: quad ignored `max_cells` (`--res 1000` grew past 3.5 GB). Now it is refused before
/// anything is sampled, and a cell count that does not fit a u64 cannot wrap past the check.
#[test]
fn quad_refuses_grids_past_max_cells_before_allocating() {
    let err = pipeline::mesh_expr("x", &request(1000)).unwrap_err();
    assert!(matches!(err, isoforge::Error::GridTooLarge { cells: 1_000_000_000, .. }), "{err}");
    // The grid constructors refuse such a grid themselves; one built field by field still cannot
    // get past the quad method's own check.
    assert!(Grid::from_points([1 << 22; 3], Vec3::ZERO, Vec3::ONE).is_err());
    let huge = Grid { origin: Vec3::ZERO, spacing: Vec3::ONE, cells: [1 << 22; 3] };
    let err = isoforge::quad::check_size(&huge, u64::MAX).unwrap_err();
    assert!(matches!(err, isoforge::Error::GridTooLarge { cells: u64::MAX, .. }), "{err}");
}

//! Feature-sensitive decimation and smoothing (issue 18, the EMC paper's §5) on EMC's meshes of
//! the scenes and of seeded random CSG trees: what `--decimate` and `--smooth` promise.
//!
//! - the mesh keeps its topology: a manifold with the input's border, Euler characteristic and
//!   components, no degenerate triangles, no crossings;
//! - every feature edge of the input (sampled along its length) stays within 1 % of a cell of the
//!   output's feature lines;
//! - with an error bound of twice undecimated EMC's largest distance, the triangle count drops by
//!   10× or more (fandisk and the cube minus a ball at 128; the cube minus a ball at 256 too,
//!   ignored for its time).
//!
//! Heavy cases are `#[ignore]`d: `cargo test --release --test decimate -- --ignored --nocapture`.

mod common;

use common::csg::random_tree;
use common::{case_seeds, Rng};
use isoforge::expr;
use isoforge::field::Field;
use isoforge::mesh::analysis::{self, Topology};
use isoforge::pipeline::{self, Method, Output, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::{scenes, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

fn request(res: usize) -> Request {
    common::bare_request(Method::Emc, res)
}

/// The cell side of `res` cells along the longest side of a scene's bounds.
fn scene_cell(name: &str, res: usize) -> f32 {
    let scene = scenes::scene(name).unwrap();
    (scene.max - scene.min).max_element() / res as f32
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let d = b - a;
    let t =
        if d.length_squared() > 0.0 { ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + t * d)).length()
}

/// The largest distance from points along the input's feature edges (ends, quarters, middle) to
/// the nearest feature edge of the output.
fn feature_drift(input: &Output, output: &Output) -> f32 {
    let segments: Vec<(Vec3, Vec3)> = output
        .feature_edges
        .iter()
        .map(|&[a, b]| (output.mesh.positions[a as usize], output.mesh.positions[b as usize]))
        .collect();
    let mut worst = 0.0f32;
    for &[a, b] in &input.feature_edges {
        let (pa, pb) = (input.mesh.positions[a as usize], input.mesh.positions[b as usize]);
        for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let p = pa.lerp(pb, t);
            let nearest =
                segments.iter().map(|&(s, e)| segment_distance(p, s, e)).fold(f32::INFINITY, f32::min);
            worst = worst.max(nearest);
        }
    }
    worst
}

/// What decimation and smoothing promise of `output` made from `input` (see the module doc).
fn assert_kept(input: &Output, output: &Output, cell: f32, what: &str) -> Topology {
    let (before, after) = (analysis::topology(&input.mesh), analysis::topology(&output.mesh));
    assert_eq!(
        (
            after.non_manifold_edges,
            after.misoriented_edges,
            after.non_manifold_vertices,
            after.degenerate_triangles
        ),
        (0, 0, 0, 0),
        "{what}: not an oriented manifold: {after:?}"
    );
    assert_eq!(after.boundary_edges, before.boundary_edges, "{what}: border changed");
    assert_eq!(
        (after.euler, after.components),
        (before.euler, before.components),
        "{what}: topology changed"
    );
    assert_eq!(analysis::self_intersections(&output.mesh), 0, "{what}: crossings");
    let drift = feature_drift(input, output);
    assert!(drift <= 0.01 * cell, "{what}: a feature edge moved {} cells", drift / cell);
    after
}

#[test]
fn scenes_decimated_towards_a_tenth_keep_topology_creases_and_no_crossings() {
    for name in ["cube_minus_sphere", "fandisk", "rotated_box", "gear", "sphere", "torus"] {
        let res = 40;
        let input = pipeline::mesh_scene(name, &request(res)).unwrap();
        let target = input.mesh.triangle_count() / 10;
        let output = pipeline::mesh_scene(name, &Request { decimate: Some(target), ..request(res) }).unwrap();
        let topo = assert_kept(&input, &output, scene_cell(name, res), name);
        assert!(topo.is_closed_manifold(), "{name}: {topo:?}");
        // The gear's many short curved creases keep the most vertices: 3.4× fewer at this size.
        assert!(
            output.mesh.triangle_count() * 3 <= input.mesh.triangle_count(),
            "{name}: {} of {} triangles left, target {target}",
            output.mesh.triangle_count(),
            input.mesh.triangle_count()
        );
    }
}

/// Triangles and largest distance of EMC at `res` on `name`, and of EMC decimated with an error
/// bound of twice that distance.
fn ratio_at_twice_the_error(name: &str, res: usize) -> (usize, f64, usize, f64) {
    let scene = scenes::scene(name).unwrap();
    let field = scene.field.as_ref();
    let cell = scene_cell(name, res);
    let input = pipeline::mesh_scene(name, &request(res)).unwrap();
    let before = analysis::surface_error(&input.mesh, field).dist_max;
    let bounded =
        Request { decimate: Some(1), decimate_error: Some(2.0 * before as f32 / cell), ..request(res) };
    let output = pipeline::mesh_scene(name, &bounded).unwrap();
    let after = analysis::surface_error(&output.mesh, field).dist_max;
    let topo = assert_kept(&input, &output, cell, name);
    assert!(topo.is_closed_manifold());
    eprintln!(
        "{name} {res}: {} -> {} triangles, max distance {before:.6} -> {after:.6}",
        input.mesh.triangle_count(),
        output.mesh.triangle_count()
    );
    (input.mesh.triangle_count(), before, output.mesh.triangle_count(), after)
}

#[test]
// Seconds natively, a minute in the browser: the ratio does not depend on the target.
#[cfg_attr(target_arch = "wasm32", ignore)]
fn fandisk_at_128_loses_ninety_percent_of_its_triangles_within_twice_emcs_error() {
    let (before, error_before, after, error_after) = ratio_at_twice_the_error("fandisk", 128);
    assert!(after * 10 <= before, "{before} -> {after} triangles");
    // 1 % over for the f32 rounding of the written mesh.
    assert!(error_after <= 2.0 * error_before * 1.01, "{error_before} -> {error_after}");
}

/// At 128 the ball's curvature bounds the triangles' size: with every vertex on the ball, faces
/// within 0.0002 of it need about 7 000 triangles on the ball alone; the vertices placed off it
/// against their faces' sag (and evened out between rounds) bring the whole part to about 7 300.
#[test]
// Seconds natively, a minute in the browser: the ratio does not depend on the target.
#[cfg_attr(target_arch = "wasm32", ignore)]
fn cube_minus_sphere_at_128_loses_ninety_percent_of_its_triangles_within_twice_emcs_error() {
    let (before, error_before, after, error_after) = ratio_at_twice_the_error("cube_minus_sphere", 128);
    assert!(after * 10 <= before, "{before} -> {after} triangles");
    assert!(error_after <= 2.0 * error_before * 1.01, "{error_before} -> {error_after}");
}

/// EMC's 300 000 triangles at 256³ (about 20 s in a release build).
#[test]
#[ignore]
fn cube_minus_sphere_at_256_loses_ninety_percent_of_its_triangles_within_twice_emcs_error() {
    let (before, error_before, after, error_after) = ratio_at_twice_the_error("cube_minus_sphere", 256);
    assert!(after * 10 <= before, "{before} -> {after} triangles");
    assert!(error_after <= 2.0 * error_before * 1.01, "{error_before} -> {error_after}");
}

#[test]
fn smoothing_leaves_features_and_distance_and_evens_out_normals() {
    let name = "fandisk";
    let res = 48;
    let with_error = |r: Request| Request {
        analysis: AnalysisOptions { self_intersections: false, surface_error: true },
        ..r
    };
    let input = pipeline::mesh_scene(name, &with_error(request(res))).unwrap();
    let output = pipeline::mesh_scene(name, &with_error(Request { smooth: 5, ..request(res) })).unwrap();
    let topo = assert_kept(&input, &output, scene_cell(name, res), name);
    assert!(topo.is_closed_manifold());
    for &[a, b] in &input.feature_edges {
        for v in [a, b] {
            assert_eq!(
                input.mesh.positions[v as usize], output.mesh.positions[v as usize],
                "feature vertex {v} moved"
            );
        }
    }
    let (before, after) = (input.stats.dist_max.unwrap(), output.stats.dist_max.unwrap());
    assert!(after <= before * 1.01, "max distance {before} -> {after}");
    let (p50_before, p50_after) =
        (input.stats.normal_dev_deg_p50.unwrap(), output.stats.normal_dev_deg_p50.unwrap());
    assert!(p50_after <= p50_before + 0.01, "normal deviation p50 {p50_before} -> {p50_after}");
    let moved = input.mesh.positions.iter().zip(&output.mesh.positions).filter(|(a, b)| a != b).count();
    assert!(moved * 2 > input.mesh.vertex_count(), "only {moved} vertices moved: smoothing did nothing");
}

/// The random CSG tree of `seed` (see `props_csg.rs`) compiled, a resolution of 16–32 cells for
/// it, and both named for messages.
fn random_case(seed: u64) -> (expr::Program, usize, String) {
    let mut rng = Rng::new(seed);
    let tree = random_tree(&mut rng);
    let program = expr::compile(&tree.text).unwrap();
    let res = 16 + rng.below(17) as usize;
    (program, res, format!("seed {seed}, res {res}: {}", tree.text))
}

/// Seeded random CSG trees (see `props_csg.rs`), EMC at 16–32 cells, decimated to a quarter:
/// still an oriented manifold with the input's border, topology and creases, no crossings.
#[test]
fn prop_decimated_emc_of_random_trees_keeps_its_promises() {
    for seed in case_seeds(0xDEC1_0000, 12) {
        let (program, res, what) = random_case(seed);
        let input = pipeline::mesh_program(&program, &request(res)).unwrap();
        let target = input.mesh.triangle_count() / 4;
        let output =
            pipeline::mesh_program(&program, &Request { decimate: Some(target.max(1)), ..request(res) })
                .unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_kept(&input, &output, 2.0 / res as f32, &what);
    }
}

/// Seeded random CSG trees, EMC at 16–32 cells smoothed, alone and after decimation to a quarter:
/// feature vertices where they were, and the decimation's promises, crossings included (a
/// relaxed vertex pulled back onto the surface can land where its faces cross a neighbour's).
#[test]
fn prop_smoothed_emc_of_random_trees_keeps_its_promises() {
    for seed in case_seeds(0x5300_0000, 10) {
        let (program, res, what) = random_case(seed);
        let input = pipeline::mesh_program(&program, &request(res)).unwrap();
        let target = (input.mesh.triangle_count() / 4).max(1);
        for decimate in [None, Some(target)] {
            let asked = Request { smooth: 5, decimate, ..request(res) };
            let output = pipeline::mesh_program(&program, &asked).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_kept(&input, &output, 2.0 / res as f32, &format!("{what}, decimate {decimate:?}"));
        }
    }
}

/// Shrunk from `prop_smoothed_emc_of_random_trees_keeps_its_promises` (seed 1392508933): where
/// a cone's tip meets a ball, five smoothing passes without a crossing check left 11 pairs of
/// faces crossing (vertices relaxed and pulled back onto the surface across their neighbours').
#[test]
fn smoothing_where_a_cone_meets_a_ball_crosses_nothing() {
    let text = "union(mirror_x(translate(sphere(0.412), 0.517, -0.038, -0.431)), \
        rotate(offset(translate(cone(0.203, 0.371), 0.273, -0.358, 0.408), -0.016), -0.501, 0.153, 0.259, -121.832))";
    let program = expr::compile(text).unwrap();
    let input = pipeline::mesh_program(&program, &request(28)).unwrap();
    let output = pipeline::mesh_program(&program, &Request { smooth: 5, ..request(28) }).unwrap();
    assert_kept(&input, &output, 2.0 / 28.0, "cone meets ball");
}

/// The largest `|f| / |∇f|` (the decimation guard's distance estimate) over the vertices, the
/// face centroids and the points halfway from each centroid to its corners.
fn largest_estimated_distance(mesh: &isoforge::Mesh, field: &dyn Field) -> f64 {
    let estimate = |p: Vec3| {
        let (value, gradient) = field.value_and_gradient(p);
        let g = gradient.expect("programs have exact gradients").length();
        if g > 1e-12 {
            (value / g).abs() as f64
        } else {
            f64::INFINITY
        }
    };
    let mut worst = mesh.positions.iter().map(|&p| estimate(p)).fold(0.0, f64::max);
    for t in 0..mesh.triangle_count() {
        let c = mesh.corners(t);
        let centre = (c[0] + c[1] + c[2]) / 3.0;
        worst = c.iter().map(|&x| estimate(0.5 * (centre + x))).fold(worst.max(estimate(centre)), f64::max);
    }
    worst
}

/// Seeded random CSG trees, EMC at 16–32 cells decimated as far as twice EMC's own largest
/// distance estimate allows: the vertices placed off the surface, the alternative placements and
/// the relaxing rounds keep every vertex and face sample within the bound, and the mesh keeps its
/// promises. Fails if a move skips the distance check or an offset overshoots.
#[test]
fn prop_decimated_emc_of_random_trees_stays_within_its_error_bound() {
    for seed in case_seeds(0xDEC2_0000, 10) {
        let (program, res, what) = random_case(seed);
        let cell = 2.0 / res as f32;
        let input = pipeline::mesh_program(&program, &request(res)).unwrap();
        if input.mesh.triangle_count() == 0 {
            continue;
        }
        let before = largest_estimated_distance(&input.mesh, &program);
        let bound = 2.0 * before;
        let bounded =
            Request { decimate: Some(1), decimate_error: Some(bound as f32 / cell), ..request(res) };
        let output = pipeline::mesh_program(&program, &bounded).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_kept(&input, &output, cell, &what);
        let after = largest_estimated_distance(&output.mesh, &program);
        // 1 % and a hair over for the f32 rounding of the written mesh.
        assert!(after <= bound * 1.01 + 1e-6, "{what}: {before} -> {after}, bound {bound}");
        assert!(output.mesh.triangle_count() < input.mesh.triangle_count(), "{what}: nothing collapsed");
    }
}

#[test]
fn bad_decimate_and_smooth_values_are_refused_by_name() {
    let err = |r: Request| pipeline::mesh_scene("sphere", &r).unwrap_err().to_string();
    assert!(err(Request { decimate: Some(0), ..request(8) }).contains("decimate"));
    assert!(err(Request { decimate: Some(10), decimate_error: Some(-1.0), ..request(8) })
        .contains("decimateError"));
    assert!(err(Request { smooth: 1000, ..request(8) }).contains("smooth"));
    assert!(err(Request { method: Method::Quad, decimate: Some(10), ..request(8) }).contains("quad"));
}

/// The share of triangles with a corner under 10°.
fn sliver_share(mesh: &isoforge::Mesh) -> f64 {
    let slivers = (0..mesh.triangle_count())
        .filter(|&t| {
            let c = mesh.corners(t);
            (0..3).any(|i| {
                let (a, b) = (c[(i + 1) % 3] - c[i], c[(i + 2) % 3] - c[i]);
                a.angle_between(b).to_degrees() < 10.0
            })
        })
        .count();
    slivers as f64 / mesh.triangle_count().max(1) as f64
}

/// The goal, fewer than 2 % of the triangles under 10° without moving a feature point,
/// where EMC at 64 cells has 6.0 % (cube minus a ball, decimated: 0 %), 15.8 % (rotated box:
/// 0.2 %), 0.9 % (fandisk: 0.5 %), 4.3 % (cube with cut-outs: 0.8 %), 12.4 % (rocket: 0.5 %) and
/// 5.3 % (gear). Before the sliver passes moved free vertices, the fandisk kept 1.8 % and the
/// cube with cut-outs 2.4 %; before they split sliver edges (Steiner points), the gear kept
/// 3.4 %, between the vertices of its feature lines.
#[test]
#[cfg_attr(target_arch = "wasm32", ignore)]
fn decimation_to_a_tenth_leaves_few_slivers() {
    for name in ["cube_minus_sphere", "rotated_box", "fandisk", "cube_with_cutouts", "rocket", "gear"] {
        let res = 64;
        let input = pipeline::mesh_scene(name, &request(res)).unwrap();
        let target = input.mesh.triangle_count() / 10;
        let output = pipeline::mesh_scene(name, &Request { decimate: Some(target), ..request(res) }).unwrap();
        let (before, after) = (sliver_share(&input.mesh), sliver_share(&output.mesh));
        eprintln!("{name}: {:.1} % -> {:.1} % under 10°", 100.0 * before, 100.0 * after);
        assert!(after < 0.02, "{name}: {:.1} % of the triangles under 10°", 100.0 * after);
        assert_kept(&input, &output, scene_cell(name, res), name);
    }
}

/// The gear at 64 cells, whose teeth's short creases leave EMC with 5.3 % of its triangles under
/// 10° (6.1 % when this was written): decimation's sliver passes alone (a target above its count:
/// sliver edges collapsed, free vertices moved, flat pairs flipped; no feature point moves) take
/// it under 2 % (0.02 % today; 0.9 % before free vertices moved), no sample of it farther from the
/// surface than EMC's. (Decimated towards a tenth: the test above.)
#[test]
#[cfg_attr(target_arch = "wasm32", ignore)]
fn the_gears_slivers_go_with_decimations_sliver_passes() {
    let res = 64;
    let field = scenes::scene("gear").unwrap().field;
    let input = pipeline::mesh_scene("gear", &request(res)).unwrap();
    let everything = input.mesh.triangle_count() + 1;
    let output =
        pipeline::mesh_scene("gear", &Request { decimate: Some(everything), ..request(res) }).unwrap();
    let (before, after) = (sliver_share(&input.mesh), sliver_share(&output.mesh));
    eprintln!("gear: {:.1} % -> {:.1} % under 10°", 100.0 * before, 100.0 * after);
    assert!(before > 0.05, "the gear's slivers are still there to remove: {before}");
    assert!(after < 0.02, "{:.1} % of the triangles under 10°", 100.0 * after);
    let (far_before, far_after) = (
        largest_estimated_distance(&input.mesh, field.as_ref()),
        largest_estimated_distance(&output.mesh, field.as_ref()),
    );
    assert!(far_after <= far_before * 1.01 + 1e-6, "{far_before} -> {far_after}");
    assert_kept(&input, &output, scene_cell("gear", res), "gear");
}

/// Every triangle method's mesh can be decimated (no feature lines: only the quadrics and the
/// checks protect the creases): the topology and the absence of crossings hold for all.
#[test]
fn every_triangle_method_decimates_to_a_closed_manifold_without_crossings() {
    for method in [Method::Mc, Method::Mcq, Method::Dmc, Method::Emc] {
        let res = 32;
        let input = pipeline::mesh_scene("cube_minus_sphere", &Request { method, ..request(res) }).unwrap();
        let target = input.mesh.triangle_count() / 4;
        let output = pipeline::mesh_scene(
            "cube_minus_sphere",
            &Request { method, decimate: Some(target), ..request(res) },
        )
        .unwrap();
        let topo = assert_kept(&input, &output, scene_cell("cube_minus_sphere", res), method.name());
        assert!(topo.is_closed_manifold(), "{method:?}: {topo:?}");
        assert!(output.mesh.triangle_count() * 3 <= input.mesh.triangle_count(), "{method:?}");
    }
}

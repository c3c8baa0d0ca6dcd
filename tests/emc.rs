//! Extended Marching Cubes against plain Marching Cubes on the same grid, in the same test: same
//! topology, no self-intersections, sharper normals, smaller error, feature points on the true
//! creases, and feature lines that form the expected chains.

mod common;

use common::assert_watertight;
use isoforge::emc::directed::{self, DirectedGrid};
use isoforge::emc::{self, EmcMesh, EmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::mesh::analysis;
use isoforge::{expr, Field, Grid, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

const CUBE_MINUS_SPHERE: &str = "max(box(.6, .6, .6), .75 - length(x, y, z))";
const ROTATED_BOX: &str = "rotate(rotate(box(.5, .35, .25), 1, 0, 0, 23), 0, 1, 1, 31)";

struct Comparison {
    emc: EmcMesh,
    mc_triangles: usize,
    mc_error: analysis::SurfaceError,
    emc_error: analysis::SurfaceError,
    h: f32,
}

fn compare(field: &dyn Field, res: usize) -> Comparison {
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
    let (mc_mesh, _) = mc::mesh_field(field, &grid, &McOptions::default()).unwrap();
    let (emc, _) = emc::mesh_field(field, &grid, &EmcOptions::default()).unwrap();
    let mc_topo = assert_watertight(&mc_mesh, "mc");
    let emc_topo = assert_watertight(&emc.mesh, "emc");
    assert_eq!(emc_topo.euler, mc_topo.euler, "EMC keeps MC's topology");
    Comparison {
        mc_triangles: mc_mesh.triangle_count(),
        mc_error: analysis::surface_error(&mc_mesh, field),
        emc_error: analysis::surface_error(&emc.mesh, field),
        emc,
        h: grid.cell_size(),
    }
}

/// Connected components of the graph formed by the feature edges.
fn feature_line_components(emc: &EmcMesh) -> usize {
    components(emc.mesh.vertex_count(), &emc.feature_edges)
}

/// Connected components of the graph of `edges` over `n` vertices (vertices on no edge ignored).
fn components(n: usize, edges: &[[u32; 2]]) -> usize {
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], v: usize) -> usize {
        let mut r = v;
        while p[r] != r {
            r = p[r];
        }
        p[v] = r;
        r
    }
    for &[a, b] in edges {
        let (ra, rb) = (find(&mut parent, a as usize), find(&mut parent, b as usize));
        parent[ra] = rb;
    }
    let used: std::collections::BTreeSet<usize> =
        edges.iter().flatten().map(|&v| find(&mut parent, v as usize)).collect();
    used.len()
}

#[test]
fn cube_minus_sphere_is_sharper_and_closer_than_mc() {
    let field = expr::compile(CUBE_MINUS_SPHERE).unwrap();
    for res in [32, 64] {
        let c = compare(&field, res);
        let what = format!("cube_minus_sphere res {res}");
        // Measured: 1.08x and 1.02x MC's triangles at 32 and 64 (1.30x and 1.12x with every fan's
        // two extra triangles kept: this part is mostly crease at 32 cells); the floor is
        // +20 %.
        let tris = c.emc.mesh.triangle_count() as f64 / c.mc_triangles as f64;
        assert!(tris < 1.2, "{what}: {tris:.2}x MC's triangles");
        let p95 = c.mc_error.normal_dev_deg_p95 / c.emc_error.normal_dev_deg_p95;
        let dist = c.mc_error.dist_max / c.emc_error.dist_max;
        eprintln!(
            "{what}: triangles {tris:.3}x MC's, normal p95 {:.3}° vs MC {:.2}° ({p95:.1}x), distance max {:.2e} vs {:.2e} ({dist:.2}x)",
            c.emc_error.normal_dev_deg_p95, c.mc_error.normal_dev_deg_p95, c.emc_error.dist_max, c.mc_error.dist_max
        );
        // Measured: 43.2x and 36.0x (p95), 15.8x and 14.5x (max distance) at res 32 and 64; the
        // issue's floors are 5x and 3x.
        assert!(p95 > 5.0, "{what}: normal deviation p95 only {p95:.2}x better");
        assert!(dist > 3.0, "{what}: max distance only {dist:.2}x better");
        // Eight cube corners are found as corners.
        assert_eq!(c.emc.corner_features, 8, "{what}");
        // Every feature point lies on a crease, on two of the solid's surfaces at once, within 1 %
        // of a cell: the cube's straight edges and the circles where the ball cuts the faces
        // (curved creases, where intersecting tangent planes alone errs by O(h²): 0.4 and 0.16
        // cells before creases were resampled). Measured: at most 0.0093 cells, on the circles at
        // 64.
        for (v, p) in c.emc.mesh.positions.iter().enumerate().filter(|(v, _)| c.emc.feature_vertex[*v]) {
            let planes = [(p.x.abs() - 0.6).abs(), (p.y.abs() - 0.6).abs(), (p.z.abs() - 0.6).abs()];
            let mut d = [planes[0], planes[1], planes[2], (p.length() - 0.75).abs()];
            d.sort_by(f32::total_cmp);
            assert!(
                d[1] < 0.01 * c.h,
                "{what}: feature vertex {v} at {p} is {} cells from a crease",
                d[1] / c.h
            );
        }
        // Feature lines: the cube's 12 edges joined at its corners, and the six circles where the
        // ball cuts the faces.
        assert_eq!(feature_line_components(&c.emc), 7, "{what}");
    }
}

#[test]
fn fandisk_is_sharper_and_closer_than_mc() {
    let scene = isoforge::scenes::scene("fandisk").unwrap();
    for res in [32, 64] {
        let c = compare(scene.field.as_ref(), res);
        let what = format!("fandisk res {res}");
        let tris = c.emc.mesh.triangle_count() as f64 / c.mc_triangles as f64;
        let p95 = c.mc_error.normal_dev_deg_p95 / c.emc_error.normal_dev_deg_p95;
        let dist = c.mc_error.dist_max / c.emc_error.dist_max;
        eprintln!(
            "{what}: triangles {tris:.3}x MC's, normal p95 {:.3}° vs MC {:.2}° ({p95:.1}x), distance max {:.2e} vs {:.2e} ({dist:.2}x), {} corners",
            c.emc_error.normal_dev_deg_p95, c.mc_error.normal_dev_deg_p95, c.emc_error.dist_max, c.mc_error.dist_max, c.emc.corner_features
        );
        // Measured at res 32 and 64: 1.04x and 1.02x the triangles (1.19x and 1.10x without flat
        // merges); 9.7x and 16.2x (p95; 10.6x at 32 without merges: the p95 is over faces, and the
        // merges remove flat faces at 0°); 7.6x and 4.0x (max distance; 2.30x and 1.15x before
        // blunt corners that pass the φ test as edges were solved as corners, the lattice search
        // for a valid fan on the groove's rim, where the top face lies within 1 % of a cell of a
        // grid plane, and resampled creases).
        assert!(tris < 1.2, "{what}: {tris:.2}x MC's triangles");
        assert!(p95 > 5.0, "{what}: normal deviation p95 only {p95:.2}x better");
        assert!(dist > 3.0, "{what}: max distance only {dist:.2}x better");
        // Every feature point on the part's creases: on two of its primitive surfaces at once and
        // on the part, within 1 % of a cell. Measured: all 258 and 512, worst 0.005 and 0.009
        // cells. Two centres at 64 lie 0.07 cells off, where the chamfer/side edge ends in a
        // corner under the top (an edge component that sees two of the three sheets; its line
        // runs past the corner): the field says they are off the surface, so they are reported as
        // approximate centres, not feature points.
        let (off, worst) = fandisk_feature_offsets(&c);
        // The part's creases form one connected graph of feature edges. At 64 cells the edges
        // between feature vertices alone fall into 10 pieces, most of the gaps where the top/side
        // crease runs 1 % of a cell above a grid plane (z = 41): cells below it see a sliver of
        // the top, and their centres are approximate. Those bridge the gaps (see `emc::lines`).
        let lines = feature_line_components(&c.emc);
        eprintln!("{what}: feature lines in {lines} pieces");
        assert_eq!(lines, 1, "{what}: the creases' graph is one piece");
        eprintln!("{what}: {} feature points, worst {worst:.4} cells off a crease", off.len());
        assert!(off.len() > 250, "{what}: only {} feature points", off.len());
        assert!(worst < 0.01, "{what}: a feature point {worst:.4} cells off the creases");
    }
}

/// How far (in cells) each feature vertex of the fandisk is from lying on two of its primitive
/// surfaces and on the part's surface; and the largest.
fn fandisk_feature_offsets(c: &Comparison) -> (Vec<f32>, f32) {
    let primitives: Vec<_> = [
        "abs(x) - 0.7",
        "abs(y) - 0.4",
        "abs(z) - 0.35",
        "translate(rotate(cylinder(1.2, 1), 0, 1, 0, 90), 0, 0, -0.85)",
        "plane(1, 0, 1, 0.6)",
        "x + 0.3",
        "abs(y) - 0.5",
        "z - 0.1",
        "translate(rotate(cylinder(0.15, 1), 1, 0, 0, 90), 0.05, 0, 0.3)",
    ]
    .iter()
    .map(|s| expr::compile(s).unwrap())
    .collect();
    let part = isoforge::scenes::scene("fandisk").unwrap().field;
    let off: Vec<f32> = (0..c.emc.mesh.vertex_count())
        .filter(|&v| c.emc.feature_vertex[v])
        .map(|v| {
            let p = c.emc.mesh.positions[v];
            let mut d: Vec<f32> = primitives.iter().map(|f| f.value(p).abs()).collect();
            d.sort_by(f32::total_cmp);
            d[1].max(part.value(p).abs()) / c.h
        })
        .collect();
    let worst = off.iter().copied().fold(0.0, f32::max);
    (off, worst)
}

#[test]
fn rotated_box_is_sharper_and_its_edges_become_feature_lines() {
    let field = expr::compile(ROTATED_BOX).unwrap();
    for res in [32, 64] {
        let c = compare(&field, res);
        let what = format!("rotated box res {res}");
        let tris = c.emc.mesh.triangle_count() as f64 / c.mc_triangles as f64;
        assert!(tris < 1.2, "{what}: {tris:.2}x MC's triangles");
        let p95 = c.mc_error.normal_dev_deg_p95 / c.emc_error.normal_dev_deg_p95;
        let dist = c.mc_error.dist_max / c.emc_error.dist_max;
        eprintln!(
            "{what}: triangles {tris:.3}x MC's, normal p95 {:.3}° vs MC {:.2}° ({p95:.1}x), distance max {:.2e} vs {:.2e} ({dist:.2}x)",
            c.emc_error.normal_dev_deg_p95, c.mc_error.normal_dev_deg_p95, c.emc_error.dist_max, c.mc_error.dist_max
        );
        // Measured: 0.000° against 43.7° and 27.5° (p95); 4.35x and 9.3x (max distance) at res 32
        // and 64. The floors are 5x and 3x.
        assert!(p95 > 5.0, "{what}: normal deviation p95 only {p95:.2}x better");
        assert!(dist > 3.0, "{what}: max distance only {dist:.2}x better");
        assert_eq!(c.emc.corner_features, 8, "{what}: the box's eight corners");
        // Every feature point lies on an edge of the box (on two faces at once) within 1 % of a
        // cell; crossings lie on its surface, which checks the frame.
        let to_box = rotated_box_frame();
        let faces = |p: Vec3| {
            let q = to_box * p;
            let mut d = [(q.x.abs() - 0.5).abs(), (q.y.abs() - 0.35).abs(), (q.z.abs() - 0.25).abs()];
            d.sort_by(f32::total_cmp);
            d
        };
        for (v, &p) in c.emc.mesh.positions.iter().enumerate() {
            let d = faces(p);
            if c.emc.feature_vertex[v] {
                assert!(d[1] < 0.01 * c.h, "{what}: feature vertex {v} at {p} is {} from an edge", d[1]);
            } else {
                assert!(d[0] < 0.2 * c.h, "{what}: vertex {v} at {p} is {} from the box", d[0]);
            }
        }
        // The 12 edges (4 × (1 + .7 + .5) = 8.8 long) come out as feature lines joined at the
        // corners: one connected graph, about as long as the edges (a little longer: next to the
        // corners feature points of two edges are joined too).
        let length: f32 = c
            .emc
            .feature_edges
            .iter()
            .map(|&[a, b]| c.emc.mesh.positions[a as usize].distance(c.emc.mesh.positions[b as usize]))
            .sum();
        let lines = feature_line_components(&c.emc);
        eprintln!(
            "{what}: feature lines {length} long in {lines} pieces ({} approximate centres)",
            c.emc.approximate_features
        );
        // Measured: 9.24 and 9.04 long at res 32 and 64 (9.17 and 8.98 between feature vertices
        // alone, in 2 and 5 pieces: every gap one approximate centre next to a corner, where the
        // crease skims a cell's corner, which bridges it).
        assert!(length > 0.95 * 8.8 && length < 1.06 * 8.8, "{what}: feature lines {length} long");
        assert_eq!(lines, 1, "{what}: feature lines in {lines} pieces");
    }
}

/// The rotation taking world coordinates into the frame of ROTATED_BOX's box.
fn rotated_box_frame() -> glam::Quat {
    let about = |axis: Vec3, deg: f32| glam::Quat::from_axis_angle(axis.normalize(), deg.to_radians());
    (about(Vec3::new(0.0, 1.0, 1.0), 31.0) * about(Vec3::X, 23.0)).inverse()
}

#[test]
fn linear_crossings_are_the_baseline_directed_distances_improve_on() {
    let field = expr::compile(CUBE_MINUS_SPHERE).unwrap();
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 48).unwrap();
    let directed = emc::mesh_field(&field, &grid, &EmcOptions::default()).unwrap().0;
    let linear =
        emc::mesh_field(&field, &grid, &EmcOptions { directed: false, ..EmcOptions::default() }).unwrap().0;
    let exact = analysis::surface_error(&directed.mesh, &field);
    let interpolated = analysis::surface_error(&linear.mesh, &field);
    assert!(exact.dist_rms < interpolated.dist_rms, "{} vs {}", exact.dist_rms, interpolated.dist_rms);
    assert_watertight(&linear.mesh, "linear");
}

#[test]
fn options_out_of_range_are_refused() {
    let field = expr::compile("length(x, y, z) - .5").unwrap();
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 8).unwrap();
    let bad = EmcOptions { theta_sharp: 1.5, ..EmcOptions::default() };
    let err = emc::mesh_field(&field, &grid, &bad).unwrap_err();
    assert!(err.to_string().contains("thetaSharp"), "{err}");
}

#[test]
fn the_crust_traversal_gives_the_uniform_grid_result_from_far_fewer_evaluations() {
    for text in [CUBE_MINUS_SPHERE, ROTATED_BOX, "length(length(x, y) - .6, z) - .25"] {
        let field = expr::compile(text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 64).unwrap();
        let (crust, _) = emc::mesh_field(&field, &grid, &EmcOptions::default()).unwrap();
        let uniform_options = EmcOptions { crust: false, ..EmcOptions::default() };
        let (uniform, _) = emc::mesh_field(&field, &grid, &uniform_options).unwrap();
        assert_eq!(crust.mesh, uniform.mesh, "{text}");
        assert_eq!(uniform.points_evaluated, grid.point_count());
        assert!(crust.points_evaluated * 3 < grid.point_count(), "{text}: {}", crust.points_evaluated);
    }
}

/// EMC keeps MC's topology without crossings or folds (two triangles across an edge lying on
/// each other). MC had one fold: on the thin room at 40 cells (walls a third of a cell thick) it
/// folded the door jamb's two sheets onto each other within 0.2°, until samples on the level
/// were given a side by rule rather than by rounding (`field::snap_to_level`). The rocket at 40
/// cells had 9 folded pairs on its bottom rim (crossings and resampled crease points all on the
/// rim circle, which lies in a grid plane) until fans and flips refused triangles folding onto
/// their neighbours.
#[test]
fn every_scene_keeps_mc_topology_without_self_intersections() {
    for name in isoforge::scenes::SCENE_NAMES {
        let scene = isoforge::scenes::scene(name).unwrap();
        for res in [24, 40] {
            let grid = Grid::with_resolution(scene.min, scene.max, res).unwrap();
            let (mc_mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
            let (emc, _) = emc::mesh_field(scene.field.as_ref(), &grid, &EmcOptions::default()).unwrap();
            let what = format!("{name} at {res}");
            let mc_topo = analysis::topology(&mc_mesh);
            let emc_topo = assert_watertight(&emc.mesh, &what);
            let folds = (analysis::folded_pairs(&mc_mesh).len(), analysis::folded_pairs(&emc.mesh).len());
            assert_eq!(folds, (0, 0), "{what}: MC and EMC folded pairs");
            assert_eq!(emc_topo.euler, mc_topo.euler, "{what}");
            assert_eq!(emc_topo.components, mc_topo.components, "{what}");
        }
    }
}

/// The gyroid at 72 cells (sheets a few cells apart, spurious "features" where they curve
/// tightly, several sheets in one cell): fan centres outside their cell cut a neighbour's
/// triangles there (27 crossing pairs before any check), and flips made for a centre's old place
/// cut other sheets (12). Now a centre in a cell of several sheets stays inside it, every flip is
/// refused that would cross a triangle near it, and a fan outside its cell that cuts one is pulled
/// back in: a closed manifold with MC's Euler characteristic and no self-intersections.
#[test]
fn the_gyroid_at_72_cells_does_not_cross_itself() {
    let scene = isoforge::scenes::scene("gyroid").unwrap();
    let grid = Grid::with_resolution(scene.min, scene.max, 72).unwrap();
    let (emc, _) = emc::mesh_field(scene.field.as_ref(), &grid, &EmcOptions::default()).unwrap();
    let (mc_mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
    assert!(emc.flips > 1000, "{} flips: the feature lines are still made", emc.flips);
    let topo = assert_watertight(&emc.mesh, "gyroid at 72");
    assert_eq!(topo.euler, analysis::topology(&mc_mesh).euler);
}

/// A directed distance field stored on the grid meshes exactly as its field does: same crossings,
/// same normals, same mesh.
#[test]
fn a_stored_directed_field_meshes_exactly_as_its_field() {
    let field = expr::compile(ROTATED_BOX).unwrap();
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 24).unwrap();
    let stored = DirectedGrid::from_field(&field, &grid, 0.0).unwrap();
    let (from_stored, _) = directed::mesh_directed(&stored, &EmcOptions::default()).unwrap();
    // Stored records know the grid edges only: the function's mesh without resampled creases.
    let options = EmcOptions { crust: false, resample_creases: false, ..EmcOptions::default() };
    let (direct, _) = emc::mesh_field(&field, &grid, &options).unwrap();
    assert_eq!(from_stored.mesh.triangles, direct.mesh.triangles);
    assert_eq!(from_stored.mesh.positions, direct.mesh.positions);
    assert_eq!(from_stored.corner_features, 8);
}

/// Booleans on stored directed fields, edge by edge from the two records alone, give the mesh EMC
/// makes of the CSG of the two fields (min/max), whose crossings are found by root finding on the
/// combined function: the same cases, crossings within 1e-4 of a cell, the same feature points.
#[test]
fn booleans_of_directed_fields_mesh_like_the_csg_of_their_fields() {
    let a_src = "rotate(box(.55, .5, .45), 1, 1, 0, 20)";
    let b_src = "translate(sphere(.5), .4, .3, .35)";
    let a = expr::compile(a_src).unwrap();
    let b = expr::compile(b_src).unwrap();
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 32).unwrap();
    let (da, db) = (
        DirectedGrid::from_field(&a, &grid, 0.0).unwrap(),
        DirectedGrid::from_field(&b, &grid, 0.0).unwrap(),
    );
    let options = EmcOptions { crust: false, resample_creases: false, ..EmcOptions::default() };
    for (op, combined) in [
        ("union", da.union(&db).unwrap()),
        ("intersect", da.intersect(&db).unwrap()),
        ("subtract", da.subtract(&db).unwrap()),
    ] {
        let csg = expr::compile(&format!("{op}({a_src}, {b_src})")).unwrap();
        let (stored, _) = directed::mesh_directed(&combined, &options).unwrap();
        let (direct, _) = emc::mesh_field(&csg, &grid, &options).unwrap();
        let what = format!("{op} of a box and a ball");
        let topo = assert_watertight(&stored.mesh, &what);
        assert_eq!(topo.euler, 2, "{what}");
        assert_eq!(stored.mesh.triangles.len(), direct.mesh.triangles.len(), "{what}");
        assert_eq!(stored.mesh.positions.len(), direct.mesh.positions.len(), "{what}");
        let off = stored
            .mesh
            .positions
            .iter()
            .zip(&direct.mesh.positions)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0f32, f32::max);
        assert!(off < 1e-4 * grid.cell_size(), "{what}: a vertex moved {off}");
        assert_eq!(stored.feature_vertex, direct.feature_vertex, "{what}");
        // The crease where the box and the ball meet is found like any other: feature points
        // on both surfaces at once.
        let on_both = stored
            .mesh
            .positions
            .iter()
            .zip(&stored.feature_vertex)
            .filter(|&(&p, &f)| f && a.value(p).abs() < 1e-3 && b.value(p).abs() < 1e-3)
            .count();
        eprintln!("{what}: {on_both} feature points on the box-ball crease");
        assert!(on_both >= 10, "{what}: {on_both} feature points on the box-ball crease");
    }
    let other = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 16).unwrap();
    let coarse = DirectedGrid::from_field(&b, &other, 0.0).unwrap();
    assert!(da.union(&coarse).is_err(), "fields on different grids cannot be combined");
}

/// Random gears whose flat top and bottom lie in grid planes (a disc and rotated box teeth of the
/// same height, the way people model a gear; half of them with teeth along the axes): the samples
/// there are zero, crossings crowd the grid points, and the teeth's edges run through cells whose
/// polygons lie flat in the plane. Closed, with no crossings (folds are not promised: seed 18305
/// has one). The gear scene at 64 cells crossed itself in its top face (see
/// `the_gear_at_64_cells_does_not_cross_itself`); none of 100 seeds here did, before or after
/// that fix, so the scene stays as its own regression.
#[test]
fn gears_with_faces_in_grid_planes_do_not_cross_themselves() {
    for seed in common::case_seeds(18_300, 12) {
        let mut rng = common::Rng::new(seed);
        let res = 24 + 2 * rng.below(21) as usize;
        let h = 2.0 / res as f32;
        // Top and bottom on grid planes: the grid has an even number of cells, so z = 0 is one of
        // its planes, and so is every whole number of cells from it.
        let half_height = (2 + rng.below(res as u64 / 8)) as f32 * h;
        let radius = rng.range(0.3, 0.6);
        // Half of them with teeth along the axes (their sides in grid planes too, near enough).
        let axial = rng.below(2) == 0;
        let teeth = if axial { 4 * (2 + rng.below(8) as usize) } else { 6 + rng.below(20) as usize };
        let start = if axial { 0.0 } else { rng.range(0.0, 360.0) };
        let tooth = format!(
            "translate(box({}, {}, {half_height}), {}, 0, 0)",
            rng.range(0.05, 0.1),
            rng.range(0.015, 0.04),
            radius + 0.02
        );
        let all: Vec<String> = (0..teeth)
            .map(|t| format!("rotate({tooth}, 0, 0, 1, {})", start + 360.0 * t as f32 / teeth as f32))
            .collect();
        let text = format!("union(cylinder({radius}, {half_height}), {})", all.join(", "));
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let (out, _) = emc::mesh_field(&field, &grid, &EmcOptions::default()).unwrap();
        let what = format!("seed {seed}: {teeth} teeth, radius {radius}, res {res}");
        assert_watertight(&out.mesh, &what);
    }
}

/// The gear scene at 64 cells, whose top face lies in a grid plane: a flip folded two triangles in
/// it 1.5° apart (the flip's fold test allowed 1°), and merging a flat crossing next to them made
/// them cross (three pairs).
#[test]
fn the_gear_at_64_cells_does_not_cross_itself() {
    let scene = isoforge::scenes::scene("gear").unwrap();
    let grid = Grid::with_resolution(scene.min, scene.max, 64).unwrap();
    let (out, _) = emc::mesh_field(scene.field.as_ref(), &grid, &EmcOptions::default()).unwrap();
    assert_eq!(analysis::self_intersecting_pairs(&out.mesh), Vec::<[u32; 2]>::new());
}

//! Issue 7's triangle-quality method (`mcq`) measured the seed paper's way (angles in 5° bins) on
//! its own setups, against plain Marching Cubes on the same grid: the sphere on a 10³-point grid,
//! the hyperboloid and the "grid with holes" on 40³ cells, plus random fields for robustness.

mod common;

use common::{assert_watertight, Rng};
use isoforge::field::{sample_grid, Field};
use isoforge::mc::{self, McOptions};
use isoforge::mcq::{self, McqOptions};
use isoforge::mesh::analysis;
use isoforge::{expr, Grid, Mesh, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

/// The paper's hyperboloid and "grid" (constants not given in the paper; see the README).
const HYPERBOLOID: &str = "x*x + y*y - z*z - 0.25";
const GRID_WITH_HOLES: &str = "cos(6.2832*x) + cos(6.2832*y) + cos(6.2832*z)";

fn cube_grid(cells: usize) -> Grid {
    Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), cells).unwrap()
}

fn both(field: &dyn Field, grid: &Grid, options: &McqOptions) -> (Mesh, Mesh) {
    let (plain, _) = mc::mesh_field(field, grid, &McOptions::default()).unwrap();
    let (better, _) = mcq::mesh_field(field, grid, options).unwrap();
    (plain, better)
}

/// Fraction of all angles below `deg` (the paper's histograms, read at one bin edge).
fn share_below(mesh: &Mesh, deg: usize) -> f64 {
    let h = analysis::angle_stats(mesh).histogram_5deg;
    h[..deg / 5].iter().sum::<u32>() as f64 / h.iter().sum::<u32>() as f64
}

#[test]
fn sphere_on_ten_points_per_axis_reaches_the_papers_angle_bounds() {
    let sphere = expr::compile("sphere(0.8)").unwrap();
    let grid = cube_grid(9);
    assert_eq!(grid.points(), [10, 10, 10]);
    let (plain, better) = both(&sphere, &grid, &McqOptions::default());
    assert_eq!(plain.triangle_count(), 524, "the paper's Marching Cubes sphere has 524 triangles");
    let before = analysis::angle_stats(&plain);
    assert!(before.min_deg < 20.0 && before.max_deg > 130.0, "MC alone is outside the bounds");
    let topo = assert_watertight(&better, "mcq sphere");
    assert_eq!(topo.euler, assert_watertight(&plain, "mc sphere").euler);
    let after = analysis::angle_stats(&better);
    assert!(after.min_deg >= 20.0, "smallest angle {:.2}°", after.min_deg);
    assert!(after.max_deg <= 130.0, "largest angle {:.2}°", after.max_deg);
    let (e_mc, e_q) = (analysis::surface_error(&plain, &sphere), analysis::surface_error(&better, &sphere));
    assert!(e_q.dist_max <= 1.5 * e_mc.dist_max, "distance {} vs MC {}", e_q.dist_max, e_mc.dist_max);
}

#[test]
fn each_step_keeps_the_sphere_closed_and_snapping_is_what_reaches_the_bounds() {
    let sphere = expr::compile("sphere(0.8)").unwrap();
    let grid = cube_grid(9);
    let per_cell = McqOptions { snap: None, ..McqOptions::default() };
    let paper = McqOptions { project: false, ..per_cell };
    for (what, options) in [("per-cell", per_cell), ("per-cell, unprojected", paper)] {
        let (plain, better) = both(&sphere, &grid, &options);
        let topo = assert_watertight(&better, what);
        assert_eq!(topo.euler, 2, "{what}");
        assert!(better.triangle_count() > plain.triangle_count(), "{what}: inner vertices add triangles");
        // Tiny edges next to grid points survive any per-cell rule: the bound needs snapping.
        assert!(analysis::angle_stats(&better).min_deg < 20.0, "{what}");
    }
}

#[test]
fn hyperboloid_and_grid_with_holes_lose_most_bad_angles_and_keep_their_topology() {
    let grid = cube_grid(40);
    for source in [HYPERBOLOID, GRID_WITH_HOLES] {
        let field = expr::compile(source).unwrap();
        let (plain, better) = both(&field, &grid, &McqOptions::default());
        let (t_mc, t_q) = (analysis::topology(&plain), analysis::topology(&better));
        assert_eq!(t_q.non_manifold_edges + t_q.non_manifold_vertices + t_q.misoriented_edges, 0, "{source}");
        assert_eq!(t_q.degenerate_triangles, 0, "{source}");
        assert_eq!(t_q.euler, t_mc.euler, "{source}");
        assert!(
            t_q.boundary_edges > 0 && t_q.boundary_edges <= t_mc.boundary_edges,
            "{source}: clipped border"
        );
        assert_eq!(analysis::self_intersections(&better), 0, "{source}");
        let (s_mc, s_q) = (share_below(&plain, 20), share_below(&better, 20));
        assert!(s_q < 0.25 * s_mc, "{source}: angles below 20°: {s_q:.3} vs MC {s_mc:.3}");
        let (e_mc, e_q) = (analysis::surface_error(&plain, &field), analysis::surface_error(&better, &field));
        assert!(
            e_q.dist_max <= 2.0 * e_mc.dist_max,
            "{source}: distance {} vs MC {}",
            e_q.dist_max,
            e_mc.dist_max
        );
    }
    // Once border vertices may merge too, the grid with holes reaches the sphere's bounds.
    let (_, better) = both(&expr::compile(GRID_WITH_HOLES).unwrap(), &grid, &McqOptions::default());
    let angles = analysis::angle_stats(&better);
    assert!(
        angles.min_deg >= 20.0 && angles.max_deg <= 130.0,
        "{:.1}°–{:.1}°",
        angles.min_deg,
        angles.max_deg
    );
}

#[test]
fn random_fields_stay_manifold_with_the_euler_characteristic_of_mc() {
    let mut rng = Rng::new(7);
    for round in 0..24 {
        let cells = [6 + rng.below(10) as usize, 6 + rng.below(10) as usize, 6 + rng.below(10) as usize];
        let grid = Grid::new(Vec3::ZERO, Vec3::ONE, cells).unwrap();
        // A union of balls: kept off the border (closed outputs) in even rounds, clipped by it
        // (open outputs, whose border vertices snap too) in odd ones.
        let clipped = round % 2 == 1;
        let (lo, hi, r_max) = if clipped { (0.0, 1.0, 0.4) } else { (0.25, 0.75, 0.25) };
        let blobs: Vec<(Vec3, f32)> = (0..4)
            .map(|_| {
                (Vec3::new(rng.range(lo, hi), rng.range(lo, hi), rng.range(lo, hi)), rng.range(0.08, r_max))
            })
            .collect();
        let f = |p: Vec3| blobs.iter().map(|&(c, r)| p.distance(c) - r).fold(f32::MAX, f32::min);
        let values: Vec<f32> = (0..grid.point_count())
            .map(|i| {
                let [nx, ny, _] = grid.points();
                f(grid.position(i % nx, (i / nx) % ny, i / (nx * ny)))
            })
            .collect();
        let (plain, _) = mc::mesh_samples(&values, &grid, &McOptions::default()).unwrap();
        for snap in [None, Some(0.2), Some(0.3), Some(0.45)] {
            let options = McqOptions { snap, ..McqOptions::default() };
            let (better, _) = mcq::mesh_samples(&values, &grid, &options).unwrap();
            let what = format!("round {round}, cells {cells:?}, snap {snap:?}");
            let topo = if clipped {
                let t = analysis::topology(&better);
                assert_eq!(t.non_manifold_edges + t.non_manifold_vertices + t.misoriented_edges, 0, "{what}");
                assert_eq!(t.degenerate_triangles, 0, "{what}");
                assert_eq!(analysis::self_intersections(&better), 0, "{what}");
                t
            } else {
                assert_watertight(&better, &what)
            };
            assert_eq!(topo.euler, analysis::topology(&plain).euler, "{what}");
        }
    }
}

#[test]
fn snapping_distance_is_checked() {
    let grid = cube_grid(4);
    let values = sample_grid(&expr::compile("sphere(0.5)").unwrap(), &grid).unwrap();
    for bad in [0.5, -0.1, f32::NAN] {
        let options = McqOptions { snap: Some(bad), ..McqOptions::default() };
        assert!(mcq::mesh_samples(&values, &grid, &options).is_err(), "snap {bad}");
    }
}

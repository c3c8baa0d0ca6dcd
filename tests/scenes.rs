//! Every named scene is a program in the expression language that meshes to a closed manifold with
//! its known topology and stays clear of its bounds.

mod common;

use common::assert_watertight;
use isoforge::expr::{self, Program};
use isoforge::mc::{self, McOptions};
use isoforge::mesh::analysis;
use isoforge::{scenes, Field, Grid, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

/// Scenes whose features are thinner than a cell at the resolutions tested here: Marching Cubes
/// is not expected to find their topology (that is what they are for), only to stay closed.
const SUB_CELL: [&str; 1] = ["thin_room"];

#[test]
fn every_scene_meshes_to_a_closed_manifold_with_its_euler_characteristic() {
    for name in scenes::SCENE_NAMES {
        let scene = scenes::scene(name).unwrap();
        let grid = Grid::with_resolution(scene.min, scene.max, 48).unwrap();
        let (mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
        // Closed, manifold, oriented outward, no degenerate triangles, no self-intersections.
        let topo = assert_watertight(&mesh, name);
        // Every point of the mesh walks to the surface within a cell, along exact gradients.
        let error = analysis::surface_error(&mesh, scene.field.as_ref());
        assert_eq!(error.unconverged, 0, "{name}: projections onto the surface did not settle");
        assert!(error.dist_max < grid.cell_size() as f64, "{name}: {} off the surface", error.dist_max);
        if SUB_CELL.contains(&name) {
            continue;
        }
        assert!(mesh.triangle_count() > 500, "{name}: only {} triangles", mesh.triangle_count());
        if let Some(euler) = scene.euler {
            assert_eq!(topo.euler, euler, "{name}: {} components", topo.components);
        }
    }
}

#[test]
fn the_new_scenes_have_the_intended_topology() {
    let euler = |name: &str| scenes::scene(name).unwrap().euler;
    for name in ["rotated_box", "fandisk", "rocket", "milling", "thin_room"] {
        assert_eq!(euler(name), Some(2), "{name} is one solid without handles");
    }
    assert_eq!(euler("cube_with_cutouts"), Some(0), "one hole goes through");
    assert_eq!(euler("cube_minus_sphere"), Some(-8));
}

/// Whether `program` is positive everywhere in the box: interval bounds, splitting the box along
/// its longest side until they decide.
fn positive_in(program: &Program, lo: Vec3, hi: Vec3, depth: u32) -> Result<(), (Vec3, Vec3)> {
    if program.eval_interval(lo, hi).0 > 0.0 {
        return Ok(());
    }
    if depth == 0 {
        return Err((lo, hi));
    }
    let axis = (hi - lo).max_position();
    let mid = (lo[axis] + hi[axis]) * 0.5;
    let (mut hi_a, mut lo_b) = (hi, lo);
    hi_a[axis] = mid;
    lo_b[axis] = mid;
    positive_in(program, lo, hi_a, depth - 1)?;
    positive_in(program, lo_b, hi, depth - 1)
}

#[test]
fn every_scene_keeps_two_cells_at_resolution_32_from_its_bounds() {
    for name in scenes::SCENE_NAMES {
        let scene = scenes::scene(name).unwrap();
        let program = expr::compile(scene.source).unwrap();
        let margin = 2.0 * (scene.max - scene.min).max_element() / 32.0;
        // The six slabs of that thickness along the faces of the bounds are all outside.
        for axis in 0..3 {
            for side in [0, 1] {
                let (mut lo, mut hi) = (scene.min, scene.max);
                if side == 0 {
                    hi[axis] = lo[axis] + margin;
                } else {
                    lo[axis] = hi[axis] - margin;
                }
                if let Err((a, b)) = positive_in(&program, lo, hi, 24) {
                    panic!("{name}: the surface may come within two cells of its bounds in {a} .. {b}");
                }
            }
        }
    }
}

#[test]
fn every_scene_is_its_source_text() {
    for name in scenes::SCENE_NAMES {
        let scene = scenes::scene(name).unwrap();
        assert_eq!(scenes::source(name).unwrap(), scene.source);
        let program = expr::compile(scene.source).unwrap();
        for p in [Vec3::ZERO, Vec3::new(0.3, -0.2, 0.1), Vec3::new(-0.7, 0.5, 0.45), scene.max * 0.9] {
            assert_eq!(program.eval(p), scene.field.value(p), "{name} at {p}");
        }
        // The corners of the bounds are outside.
        assert!(scene.field.value(scene.min) > 0.0 && scene.field.value(scene.max) > 0.0, "{name}");
    }
}

#[test]
fn thin_room_walls_are_a_fraction_of_a_cell() {
    let scene = scenes::scene("thin_room").unwrap();
    let cell = (scene.max - scene.min).max_element() / 32.0;
    // Across the +x wall: inside only within the wall's thickness.
    let inside: Vec<f32> = (0..2000)
        .map(|i| 0.7 + 0.2 * i as f32 / 2000.0)
        .filter(|&x| scene.field.value(Vec3::new(x, 0.0, 0.0)) < 0.0)
        .collect();
    let thickness = inside.last().unwrap() - inside.first().unwrap();
    assert!((thickness - 0.016).abs() < 0.001, "wall {thickness} thick");
    assert!(thickness < cell / 3.0, "wall {thickness} vs cell {cell}");
    // The door opens the -y wall.
    assert!(scene.field.value(Vec3::new(0.0, -0.8, 0.0)) > 0.0);
    assert!(scene.field.value(Vec3::new(0.5, -0.8, 0.0)) < 0.0);
}

//! EMC's flat merges (`EmcOptions::merge_flat`): one crossing next to each feature point collapsed
//! into it where all its triangles lie in one plane. They must give back triangles and nothing
//! else: the same surface (area, volume, distance to the true surface), the same topology, the
//! same feature lines.

mod common;

use common::assert_watertight;
use isoforge::emc::{self, EmcMesh, EmcOptions};
use isoforge::mesh::analysis;
use isoforge::{expr, Field, Grid, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

fn with_and_without(field: &dyn Field, res: usize) -> (EmcMesh, EmcMesh) {
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
    let mesh =
        |merge_flat| emc::mesh_field(field, &grid, &EmcOptions { merge_flat, ..EmcOptions::default() });
    (mesh(true).unwrap().0, mesh(false).unwrap().0)
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn flat_merges_give_back_triangles_without_moving_the_surface() {
    let cube_minus_sphere = expr::compile("max(box(.6, .6, .6), .75 - length(x, y, z))").unwrap();
    let fandisk = isoforge::scenes::scene("fandisk").unwrap();
    let cases: [(&str, &dyn Field, usize); 4] = [
        ("cube minus sphere", &cube_minus_sphere, 32),
        ("cube minus sphere", &cube_minus_sphere, 64),
        ("fandisk", fandisk.field.as_ref(), 32),
        ("fandisk", fandisk.field.as_ref(), 64),
    ];
    for (name, field, res) in cases {
        let what = format!("{name} at {res}");
        let (merged, kept) = with_and_without(field, res);
        let fans = kept.edge_features + kept.corner_features + kept.approximate_features;
        eprintln!(
            "{what}: {} merges for {fans} fans, {} -> {} triangles",
            merged.flat_merges,
            kept.mesh.triangle_count(),
            merged.mesh.triangle_count()
        );
        // Each merge removes one vertex and two triangles. Measured: 425 of 584 fans and 1016 of
        // 1160 on the cube minus sphere, 206 of 258 and 431 of 522 on the fandisk.
        assert_eq!(kept.flat_merges, 0);
        assert!(merged.flat_merges * 2 > fans, "{what}: only {} merges for {fans} fans", merged.flat_merges);
        assert_eq!(merged.mesh.vertex_count() + merged.flat_merges, kept.mesh.vertex_count(), "{what}");
        assert_eq!(
            merged.mesh.triangle_count() + 2 * merged.flat_merges,
            kept.mesh.triangle_count(),
            "{what}"
        );
        let (topo_merged, topo_kept) =
            (assert_watertight(&merged.mesh, &what), assert_watertight(&kept.mesh, &what));
        assert_eq!(topo_merged.euler, topo_kept.euler, "{what}");
        // The same surface: the fans cover the same planar polygons.
        let area = relative(analysis::surface_area(&merged.mesh), analysis::surface_area(&kept.mesh));
        let volume = relative(analysis::signed_volume(&merged.mesh), analysis::signed_volume(&kept.mesh));
        assert!(area < 1e-5 && volume < 1e-5, "{what}: area {area:.1e}, volume {volume:.1e} apart");
        let (e_merged, e_kept) =
            (analysis::surface_error(&merged.mesh, field), analysis::surface_error(&kept.mesh, field));
        assert!(e_merged.dist_max <= e_kept.dist_max * 1.0001, "{what}: {e_merged:?} vs {e_kept:?}");
        // The same feature lines: the same feature points, joined by as many edges.
        let points = |m: &EmcMesh| {
            let mut p: Vec<[u32; 3]> = (m.mesh.positions.iter().zip(&m.feature_vertex))
                .filter(|(_, &f)| f)
                .map(|(p, _)| p.to_array().map(f32::to_bits))
                .collect();
            p.sort_unstable();
            p
        };
        assert_eq!(points(&merged), points(&kept), "{what}");
        assert_eq!(merged.feature_edges.len(), kept.feature_edges.len(), "{what}");
    }
}

/// A smooth surface has no fans, so nothing to merge: the option changes nothing there.
#[test]
fn flat_merges_leave_smooth_surfaces_alone() {
    let torus = expr::compile("torus(.6, .25)").unwrap();
    let (merged, kept) = with_and_without(&torus, 32);
    assert_eq!(merged.flat_merges, 0);
    assert_eq!(merged.mesh, kept.mesh);
}

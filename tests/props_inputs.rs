//! Seeded random triangle meshes and oriented point clouds, remeshed by EMC and by MC on the
//! same grid: closed inputs (several overlapping shells, turned inside out), and damaged ones
//! (duplicated triangles, zero-area triangles, a hole). The source shapes are random CSG trees
//! (`common::csg`) meshed by MC; the inputs are what a stranger's exporter would hand over.
//!
//! `ISOFORGE_SEED=S` reruns one case, `ISOFORGE_SOAK=N` runs N per property.

mod common;

use common::csg::random_tree;
use common::{bare_request, boundary_edges, case_seeds, Rng};
use isoforge::emc::mesh_source::padded_grid;
use isoforge::expr;
use isoforge::input::PointCloud;
use isoforge::mesh::analysis;
use isoforge::pipeline::{self, Method, Output};
use isoforge::{Field, Grid, Mesh, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

const CI_CASES: usize = 16;

/// A closed mesh of a random tree at least 0.05 across (trees whose parts all fall outside the
/// bounds are skipped by drawing again) at `coarsest` to `coarsest + 9` cells, and its
/// program's text.
fn source_mesh(rng: &mut Rng, coarsest: usize) -> (Mesh, String) {
    loop {
        let tree = random_tree(rng);
        let program = expr::compile(&tree.text).unwrap();
        let res = coarsest + rng.below(10) as usize;
        let out = pipeline::mesh_program(&program, &bare_request(Method::Mc, res)).unwrap();
        // A speck (a part grazing the bounds can leave one) is too small for f32 to grid at the
        // coordinates it sits at, which the pipeline refuses as it should: draw again.
        let (lo, hi) = isoforge::emc::mesh_source::mesh_bounds(&out.mesh);
        if out.stats.closed_manifold && out.mesh.triangle_count() > 0 && (hi - lo).max_element() > 0.05 {
            return (out.mesh, tree.text);
        }
    }
}

/// How a case damages or rearranges its source mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Damage {
    /// As exported: closed and outward.
    None,
    /// Every triangle wound the other way (an inside-out export).
    Inverted,
    /// A second closed shell overlapping the first (a union the exporter did not compute).
    Overlapping,
    /// Some triangles listed twice.
    Duplicated,
    /// Zero-area triangles (a corner repeated) added.
    Degenerate,
}

const DAMAGES: [Damage; 5] =
    [Damage::None, Damage::Inverted, Damage::Overlapping, Damage::Duplicated, Damage::Degenerate];

fn damaged(rng: &mut Rng, mesh: &Mesh, damage: Damage) -> Mesh {
    let mut out = mesh.clone();
    let n = mesh.triangles.len();
    match damage {
        Damage::None => {}
        Damage::Inverted => out.triangles.iter_mut().for_each(|t| t.swap(1, 2)),
        Damage::Overlapping => {
            let shift = Vec3::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), rng.range(-0.3, 0.3));
            let base = out.positions.len() as u32;
            out.positions.extend(mesh.positions.iter().map(|&p| p + shift));
            out.triangles.extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
        }
        Damage::Duplicated => {
            for _ in 0..1 + n / 20 {
                out.triangles.push(mesh.triangles[rng.below(n as u64) as usize]);
            }
        }
        Damage::Degenerate => {
            for _ in 0..1 + n / 20 {
                let t = mesh.triangles[rng.below(n as u64) as usize];
                out.triangles.push([t[0], t[0], t[1]]);
                out.triangles.push([t[2], t[1], t[2]]);
            }
        }
    }
    out.normals.clear();
    out
}

/// Finite, closed, manifold, outward (the grid is padded around the input, so nothing reaches
/// its bounds).
fn assert_closed(out: &Output, what: &str) -> analysis::Topology {
    assert!(out.mesh.positions.iter().all(|p| p.is_finite()), "{what}: non-finite vertex");
    let topo = analysis::topology(&out.mesh);
    assert!(topo.is_closed_manifold(), "{what}: not a closed manifold: {topo:?}");
    assert_eq!(topo.degenerate_triangles, 0, "{what}: degenerate triangles");
    if out.mesh.triangle_count() > 0 {
        assert!(analysis::signed_volume(&out.mesh) > 0.0, "{what}: not outward");
    }
    topo
}

/// Finite, an oriented manifold, every vertex inside the grid, and every border edge on one of
/// the grid's faces.
fn assert_open_only_on_the_grid(out: &Output, grid: &Grid, what: &str) -> analysis::Topology {
    let mesh = &out.mesh;
    assert!(mesh.positions.iter().all(|p| p.is_finite()), "{what}: non-finite vertex");
    let topo = analysis::topology(mesh);
    let manifold = (topo.non_manifold_edges, topo.non_manifold_vertices, topo.misoriented_edges);
    assert_eq!(manifold, (0, 0, 0), "{what}: {topo:?}");
    assert_eq!(topo.degenerate_triangles, 0, "{what}: degenerate triangles");
    let (lo, hi) = (grid.origin, grid.max());
    let slack = grid.cell_size() * 1e-4;
    for &p in &mesh.positions {
        assert!(
            p.cmpge(lo - slack).all() && p.cmple(hi + slack).all(),
            "{what}: vertex {p} outside the grid"
        );
    }
    let on_face = |p: Vec3| (0..3).any(|a| (p[a] - lo[a]).abs() < slack || (p[a] - hi[a]).abs() < slack);
    for [a, b] in boundary_edges(mesh) {
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        assert!(on_face(pa) && on_face(pb), "{what}: border edge {pa} {pb} inside the grid");
    }
    topo
}

/// Closed inputs and damaged ones alike: MC and EMC accept them and mesh a closed, outward
/// manifold; EMC has MC's Euler characteristic and components on the same grid; a duplicated or
/// zero-area triangle changes nothing but the input's face count; an inside-out mesh meshes like
/// the right way round.
#[test]
fn prop_meshes_remesh_closed_with_mcs_topology() {
    for seed in case_seeds(5_500_000, CI_CASES) {
        let mut rng = Rng::new(seed);
        let (source, text) = source_mesh(&mut rng, 12);
        let res = 16 + rng.below(12) as usize;
        let clean_mc = pipeline::mesh_triangles(&source, &bare_request(Method::Mc, res)).unwrap();
        for damage in DAMAGES {
            let input = damaged(&mut rng, &source, damage);
            let what = format!("seed {seed}, res {res}, {damage:?} mesh of {text}");
            let mc = pipeline::mesh_triangles(&input, &bare_request(Method::Mc, res))
                .unwrap_or_else(|e| panic!("{what}: mc refused it: {e}"));
            let emc = pipeline::mesh_triangles(&input, &bare_request(Method::Emc, res))
                .unwrap_or_else(|e| panic!("{what}: emc refused it: {e}"));
            let mc_topo = assert_closed(&mc, &format!("mc, {what}"));
            let emc_topo = assert_closed(&emc, &format!("emc, {what}"));
            assert_eq!(
                (emc_topo.euler, emc_topo.components),
                (mc_topo.euler, mc_topo.components),
                "emc vs mc, {what}"
            );
            if matches!(damage, Damage::Inverted | Damage::Duplicated | Damage::Degenerate) {
                assert_eq!(
                    mc.mesh.positions, clean_mc.mesh.positions,
                    "mc, {what}: differs from the clean mesh's"
                );
            }
        }
    }
}

/// Oriented point clouds sampled densely from a random tree's surface (the vertices of its MC mesh
/// at 40–49 cells, with the program's exact normals), reconstructed at 12–23 cells by MC and EMC:
/// an oriented manifold, open only on the grid's faces, EMC with MC's topology. Not closed in
/// general: where a part is thinner than the samples' spacing, the nearest sample to a grid point
/// outside may lie on the far sheet and face away from it, so the point counts as inside, even
/// on the grid's border (the README says so).
#[test]
fn prop_point_clouds_reconstruct_closed_with_mcs_topology() {
    for seed in case_seeds(6_500_000, CI_CASES) {
        let mut rng = Rng::new(seed);
        let (source, text) = source_mesh(&mut rng, 40);
        let program = expr::compile(&text).unwrap();
        let normals: Vec<Vec3> = source
            .positions
            .iter()
            .map(|&p| program.gradient(p).unwrap_or(Vec3::Z).normalize_or(Vec3::Z))
            .collect();
        let cloud = PointCloud { positions: source.positions.clone(), normals };
        let res = 12 + rng.below(12) as usize;
        let what = format!("seed {seed}, res {res}, {} points of {text}", cloud.positions.len());
        let mc = pipeline::mesh_points(&cloud, &bare_request(Method::Mc, res))
            .unwrap_or_else(|e| panic!("{what}: mc refused it: {e}"));
        let emc = pipeline::mesh_points(&cloud, &bare_request(Method::Emc, res))
            .unwrap_or_else(|e| panic!("{what}: emc refused it: {e}"));
        let (lo, hi) = cloud.bounds();
        let grid = padded_grid(lo, hi, res).unwrap();
        let mc_topo = assert_open_only_on_the_grid(&mc, &grid, &format!("mc, {what}"));
        let emc_topo = assert_open_only_on_the_grid(&emc, &grid, &format!("emc, {what}"));
        assert_eq!(
            (emc_topo.euler, emc_topo.components),
            (mc_topo.euler, mc_topo.components),
            "emc vs mc, {what}"
        );
    }
}

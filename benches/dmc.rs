//! Dual Marching Cubes against plain Marching Cubes at the same finest resolution, in the same run,
//! and DMC's phases one by one:
//!
//! - `dmc/<scene>/{mc_64,dmc_depth6,dmc_depth6_unpruned}`: whole runs from the field (refinement
//!   rounds included), with and without interval pruning (the meshes are identical, tested).
//! - `dmc_phases/<scene>/{octree,octree_unpruned,feature_isolation,topology,contouring}`: the
//!   first round of the pipeline, each phase timed alone on the output of the ones before it:
//!   building the octree, placing the leaves' vertices, listing the dual cells (with the vertex of
//!   each corner), and contouring the dual cells the surface crosses.
//!
//! Run: `cargo bench --bench dmc -- --quick`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use isoforge::dmc::dual::{self, CellRef};
use isoforge::dmc::features::{self, DualVertices};
use isoforge::dmc::memo::Memo;
use isoforge::dmc::octree::Octree;
use isoforge::dmc::{self, contour, DmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::{scenes, Field, Grid};
use std::time::Duration;

const SCENES: [&str; 3] = ["cube_minus_sphere", "fandisk", "rocket"];
const DEPTH: u8 = 6;

fn options(prune: bool) -> DmcOptions {
    DmcOptions { max_depth: DEPTH, prune, ..DmcOptions::default() }
}

fn whole_runs(c: &mut Criterion) {
    for name in SCENES {
        let scene = scenes::scene(name).expect("a scene");
        let field = scene.field.as_ref();
        let mut group = c.benchmark_group(format!("dmc/{name}"));
        group.sample_size(10).measurement_time(Duration::from_secs(5));
        let grid = Grid::with_resolution(scene.min, scene.max, 1 << DEPTH).unwrap();
        group.bench_function("mc_64", |b| {
            b.iter(|| mc::mesh_field(field, &grid, &McOptions::default()).unwrap())
        });
        for (label, prune) in [("dmc_depth6", true), ("dmc_depth6_unpruned", false)] {
            group.bench_function(label, |b| {
                b.iter(|| dmc::mesh_field(field, scene.min, scene.max, &options(prune)).unwrap())
            });
        }
        group.finish();
    }
}

/// The dual cells of `tree` the surface crosses, as vertex ids.
fn mixed_cells(tree: &Octree, field: &dyn Field) -> (DualVertices, Vec<[u32; 8]>) {
    let mut vertices = DualVertices::new(tree);
    let mut ids = Vec::new();
    dual::for_each_dual_cell(tree, |cell: &[CellRef; 8]| {
        let cell_ids = cell.map(|r| vertices.id(tree, field, r));
        let first = vertices.values[cell_ids[0] as usize] < 0.0;
        if cell_ids.iter().any(|&v| (vertices.values[v as usize] < 0.0) != first) {
            ids.push(cell_ids);
        }
    });
    (vertices, ids)
}

fn phases(c: &mut Criterion) {
    for name in SCENES {
        let scene = scenes::scene(name).expect("a scene");
        let field = scene.field.as_ref();
        let mut group = c.benchmark_group(format!("dmc_phases/{name}"));
        group.sample_size(10).measurement_time(Duration::from_secs(3));
        let build = |prune: bool| {
            let (min, size, params) = dmc::octree_root(scene.min, scene.max, &options(prune));
            Octree::build(field, min, size, params).unwrap()
        };
        group.bench_function("octree", |b| b.iter(|| build(true)));
        group.bench_function("octree_unpruned", |b| b.iter(|| build(false)));
        group.bench_function("feature_isolation", |b| {
            b.iter_batched(
                || build(true),
                |mut tree| features::isolate(&mut tree, field, true),
                BatchSize::LargeInput,
            )
        });
        let mut tree = build(true);
        features::isolate(&mut tree, field, true);
        group.bench_function("topology", |b| b.iter(|| mixed_cells(&tree, field)));
        let (vertices, ids) = mixed_cells(&tree, field);
        eprintln!(
            "{name}: {} leaves, {} dual cells crossed in the first round",
            tree.leaf_count(),
            ids.len()
        );
        group.bench_function("contouring", |b| {
            b.iter(|| contour::contour(&ids, &vertices, field, 0.0, &mut Memo::default()))
        });
        group.finish();
    }
}

criterion_group!(benches, whole_runs, phases);
criterion_main!(benches);

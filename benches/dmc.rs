//! Dual Marching Cubes against Extended and plain Marching Cubes at the same finest resolution, in
//! the same run, on every scene (the 50-primitive gear included), and DMC's phases:
//!
//! - `dmc/<scene>/{mc,emc,dmc}`: whole runs from the field at 64 finest cells along the longest
//!   side (DMC at depth 6).
//! - The phases of one DMC run per scene (crust, sampling, simplification, contouring,
//!   untangling) are printed from its stats, with the merges the safety and distance tests
//!   refused.
//!
//! Run: `cargo bench --bench dmc -- --quick`.

use criterion::{criterion_group, criterion_main, Criterion};
use isoforge::dmc::{self, DmcOptions};
use isoforge::emc::{self, EmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::{scenes, Grid};
use std::time::Duration;

const DEPTH: u8 = 6;

fn whole_runs(c: &mut Criterion) {
    let options = DmcOptions { max_depth: DEPTH, ..DmcOptions::default() };
    for name in scenes::SCENE_NAMES {
        let scene = scenes::scene(name).expect("a scene");
        let field = scene.field.as_ref();
        let (_, stats) = dmc::mesh_field(field, scene.min, scene.max, &options).unwrap();
        eprintln!("{name}: {stats:?}");
        let mut group = c.benchmark_group(format!("dmc/{name}"));
        group.sample_size(10).measurement_time(Duration::from_secs(4));
        let grid = Grid::with_resolution(scene.min, scene.max, 1 << DEPTH).unwrap();
        group.bench_function("mc", |b| {
            b.iter(|| mc::mesh_field(field, &grid, &McOptions::default()).unwrap())
        });
        group.bench_function("emc", |b| {
            b.iter(|| emc::mesh_field(field, &grid, &EmcOptions::default()).unwrap())
        });
        group.bench_function("dmc", |b| {
            b.iter(|| dmc::mesh_field(field, scene.min, scene.max, &options).unwrap())
        });
        group.finish();
    }
}

criterion_group!(benches, whole_runs);
criterion_main!(benches);

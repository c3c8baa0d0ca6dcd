//! One thread against every core, in the same run (`isoforge::par`): the meshes are identical
//! (`prop_mc_is_the_same_mesh_on_one_thread_or_three`, `mc::slab_tests`), so only time differs.
//!
//! - `threads/<case>/1` and `threads/<case>/all`: the same call inside a pool of one thread and
//!   of `available_parallelism` threads;
//! - cases: MC's extraction on a pre-sampled 256³ sphere (`extract_sphere_256`), and end to end
//!   from the gear's program (analysis off): MC 256³, EMC 128³, DMC at depth 7.
//!
//! Run: `cargo bench --bench threads -- --quick`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use isoforge::field::sample_grid;
use isoforge::mc::{extract, McOptions};
use isoforge::par::with_threads;
use isoforge::pipeline::{self, Method, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::{scenes, Grid};
use std::time::Duration;

fn threads(c: &mut Criterion) {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut group = c.benchmark_group("threads");
    group.sample_size(10).measurement_time(Duration::from_secs(4));
    let mut compare = |name: &str, job: &(dyn Fn() + Sync)| {
        for (label, n) in [("1", 1), ("all", all)] {
            group.bench_function(BenchmarkId::new(name, label), |b| b.iter(|| with_threads(n, job)));
        }
    };

    let sphere = scenes::scene("sphere").expect("a scene");
    let grid = Grid::with_resolution(sphere.min, sphere.max, 256).expect("a grid");
    let values = sample_grid(sphere.field.as_ref(), &grid).expect("samples");
    compare("extract_sphere_256", &|| {
        extract(&values, &grid, &McOptions::default()).unwrap();
    });

    let no_analysis = AnalysisOptions { self_intersections: false, surface_error: false };
    for (method, res, depth) in
        [(Method::Mc, 256, None), (Method::Emc, 128, None), (Method::Dmc, 128, Some(7))]
    {
        let request = Request { method, res, max_depth: depth, analysis: no_analysis, ..Request::default() };
        compare(&format!("gear_{}_{res}", method.name()), &|| {
            pipeline::mesh_scene("gear", &request).unwrap();
        });
    }
    group.finish();
}

criterion_group!(benches, threads);
criterion_main!(benches);

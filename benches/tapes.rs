//! Tape specialisation per brick (`expr::regions`) against the full tape, in the same run, end to
//! end from the compiled program (analysis off):
//!
//! - `tapes/<scene>/<method>_<res>/full`: `pipeline::mesh_field` on the bare program, every query
//!   running the whole tape;
//! - `tapes/<scene>/<method>_<res>/specialised`: `pipeline::mesh_program`, every query running the
//!   tape of the brick it falls in (`pipeline::mesh_program_in`). The meshes are identical (`prop_specialised_tapes_give_the_same_meshes`).
//!
//! The tape lengths reached are printed once per case. Run: `cargo bench --bench tapes -- --quick`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use isoforge::pipeline::{self, Method, Request};
use isoforge::scenes;
use isoforge::stats::AnalysisOptions;
use std::time::Duration;

fn tapes(c: &mut Criterion) {
    for name in ["gear", "rocket", "cube_minus_sphere"] {
        let scene = scenes::scene(name).expect("a scene");
        let bounds = (scene.min, scene.max);
        let mut group = c.benchmark_group(format!("tapes/{name}"));
        group.sample_size(10).measurement_time(Duration::from_secs(3));
        for (method, res) in [(Method::Mc, 128), (Method::Emc, 64), (Method::Emc, 128), (Method::Dmc, 64)] {
            let request = Request {
                method,
                res,
                analysis: AnalysisOptions { self_intersections: false, surface_error: false },
                ..Request::default()
            };
            let out = pipeline::mesh_scene(name, &request).expect("meshes");
            eprintln!(
                "{name} {} {res}: tape lengths {:?}",
                method.name(),
                out.stats.tape.expect("a program")
            );
            let id = format!("{}_{res}", method.name());
            group.bench_function(BenchmarkId::new(&id, "full"), |b| {
                b.iter(|| pipeline::mesh_field(scene.field.as_ref(), bounds, &request).unwrap())
            });
            group.bench_function(BenchmarkId::new(&id, "specialised"), |b| {
                b.iter(|| pipeline::mesh_program_in(&scene.field, bounds, &request).unwrap())
            });
        }
        group.finish();
    }
}

criterion_group!(benches, tapes);
criterion_main!(benches);

//! Extended Marching Cubes against plain Marching Cubes on the same grid, in the same run:
//!
//! - `emc_vs_mc/<scene>/<res>/{mc,emc}`: whole runs from the field (sampling included), the ratio
//!   the paper reports as 1.4–2.1×. EMC here uses the crust traversal; `emc_uniform` samples every
//!   grid point, so the two EMC rows show what the crust saves; `emc_tangent_planes` keeps the
//!   paper's tangent-plane feature points (no resampled creases), so it shows what those cost.
//! - `edges/<scene>/<res>/{directed,interpolated}`: EMC with exact edge crossings by root finding
//!   against linear interpolation of the samples (the cost of directed distances).
//!
//! Run: `cargo bench --bench emc -- --quick`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use isoforge::emc::{self, EmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::{expr, Field, Grid, Vec3};
use std::time::Duration;

const SCENES: [(&str, &str); 3] = [
    ("cube_minus_sphere", "max(box(.6, .6, .6), .75 - length(x, y, z))"),
    ("rotated_box", "rotate(rotate(box(.5, .35, .25), 1, 0, 0, 23), 0, 1, 1, 31)"),
    ("fandisk", ""),
];

fn emc_vs_mc(c: &mut Criterion) {
    for (name, text) in SCENES {
        let field: Box<dyn Field + Send + Sync> = match text {
            "" => isoforge::scenes::scene(name).expect("a scene").field,
            _ => Box::new(expr::compile(text).expect("scene compiles")),
        };
        let field = field.as_ref();
        let mut group = c.benchmark_group(format!("emc_vs_mc/{name}"));
        group.sample_size(10).measurement_time(Duration::from_secs(3));
        for res in [64usize, 128] {
            let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
            let uniform = EmcOptions { crust: false, ..EmcOptions::default() };
            let tangent_planes = EmcOptions { resample_creases: false, ..EmcOptions::default() };
            let (crust, _) = emc::mesh_field(field, &grid, &EmcOptions::default()).unwrap();
            eprintln!(
                "{name} {res}: crust evaluates {} of {} points",
                crust.points_evaluated,
                grid.point_count()
            );
            group.bench_function(BenchmarkId::new("mc", res), |b| {
                b.iter(|| mc::mesh_field(field, &grid, &McOptions::default()).unwrap())
            });
            group.bench_function(BenchmarkId::new("emc", res), |b| {
                b.iter(|| emc::mesh_field(field, &grid, &EmcOptions::default()).unwrap())
            });
            group.bench_function(BenchmarkId::new("emc_uniform", res), |b| {
                b.iter(|| emc::mesh_field(field, &grid, &uniform).unwrap())
            });
            group.bench_function(BenchmarkId::new("emc_tangent_planes", res), |b| {
                b.iter(|| emc::mesh_field(field, &grid, &tangent_planes).unwrap())
            });
        }
        group.finish();
    }
}

fn directed_vs_interpolated(c: &mut Criterion) {
    let (name, text) = SCENES[0];
    let field = expr::compile(text).expect("scene compiles");
    let mut group = c.benchmark_group(format!("edges/{name}"));
    group.sample_size(10).measurement_time(Duration::from_secs(3));
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 96).unwrap();
    let interpolated = EmcOptions { directed: false, ..EmcOptions::default() };
    group.bench_function("directed", |b| {
        b.iter(|| emc::mesh_field(&field, &grid, &EmcOptions::default()).unwrap())
    });
    group.bench_function("interpolated", |b| {
        b.iter(|| emc::mesh_field(&field, &grid, &interpolated).unwrap())
    });
    group.finish();
}

criterion_group!(benches, emc_vs_mc, directed_vs_interpolated);
criterion_main!(benches);

//! The compiled evaluator against the reference tree walk on the same points, in the same run:
//! `expr/<program>/{tree_walk,value,value_gradient,batch64,gradient_batch64,interval}`, throughput in points (boxes
//! for `interval`) per second. The programs are the README's rocket scene and a formula-heavy
//! sample with shared bindings, where the tape's common-subexpression sharing matters.
//!
//! Run: `cargo bench --bench expr -- --quick`. The browser's numbers for the same programs come from
//! `node scripts/bench-browser.mjs` (the wasm build timing itself with `measureEvaluator`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use isoforge::expr::{self, naive::eval_tree};
use isoforge::{scenes, Vec3};
use std::time::Duration;

/// A blob with shared bindings: three placed copies of one sphere, blended, with a hole.
const BLOB: &str = "r = 0.3; s = translate(sphere(r), 0.5, 0, 0);\n\
    body = smooth_union(union(s, rotate(s, 0, 0, 1, 120), rotate(s, 0, 0, 1, 240)), torus(0.6, 0.1), 0.1);\n\
    subtract(body, rotate(cylinder(0.15, 2), 1, 0, 0, 90))";

fn evaluator(c: &mut Criterion) {
    let rocket = scenes::source("rocket").expect("rocket scene");
    let pts = expr::speed::points(4096);
    for (name, text) in [("blob", BLOB), ("rocket", rocket)] {
        let program = expr::compile(text).expect("compiles");
        let script = expr::parse(text).expect("parses");
        let mut group = c.benchmark_group(format!("expr/{name}"));
        group.sample_size(20).measurement_time(Duration::from_secs(2));
        group.throughput(Throughput::Elements(pts.len() as u64));
        group.bench_function(BenchmarkId::from_parameter("tree_walk"), |b| {
            b.iter(|| pts.iter().map(|&p| eval_tree(&script, p)).sum::<f32>())
        });
        group.bench_function(BenchmarkId::from_parameter("value"), |b| {
            b.iter(|| pts.iter().map(|&p| program.eval(p)).sum::<f32>())
        });
        group.bench_function(BenchmarkId::from_parameter("value_gradient"), |b| {
            b.iter(|| pts.iter().map(|&p| program.eval_grad(p).1.x).sum::<f32>())
        });
        let mut out = vec![0.0; pts.len()];
        group.bench_function(BenchmarkId::from_parameter("batch64"), |b| {
            b.iter(|| {
                program.eval_many(&pts, &mut out);
                out[0]
            })
        });
        let mut gradients = vec![Vec3::ZERO; pts.len()];
        group.bench_function(BenchmarkId::from_parameter("gradient_batch64"), |b| {
            b.iter(|| {
                program.eval_grad_many(&pts, &mut gradients);
                gradients[0].x
            })
        });
        let half = Vec3::splat(1.0 / 32.0);
        group.bench_function(BenchmarkId::from_parameter("interval"), |b| {
            b.iter(|| pts.iter().map(|&p| program.eval_interval(p - half, p + half).1).sum::<f32>())
        });
        group.finish();
    }
}

criterion_group!(benches, evaluator);
criterion_main!(benches);

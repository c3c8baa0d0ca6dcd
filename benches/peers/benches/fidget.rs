//! Our meshers against fidget's (Manifold Dual Contouring on an octree, its bytecode VM
//! evaluator: the same kind of evaluator as our tape interpreter), in the same run, end to end
//! from the formula, one thread each:
//!
//! - `peers/<scene>/<res>/fidget_vm`: the program handed to fidget as a `Tree` (node for node,
//!   see `to_tree`), then `VmShape`, `Octree::build` at depth log2(res), `walk_dual`;
//! - `peers/<scene>/<res>/{mc,emc,dmc}`: `isoforge::expr::compile` of the scene's text, then
//!   `pipeline::mesh_program_in` in the same cubic bounds (analysis off; DMC at the same depth).
//!
//! Both mesh the same cube: fidget's model space [-1, 1]³ is mapped onto the cube of side the
//! scene's longest extent around its centre. Triangle counts are printed once per case.
//! Run from benches/peers: `cargo bench --bench fidget -- --quick`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fidget::context::Tree;
use fidget::mesh::{Octree, Settings};
use fidget::shape::BoundShape;
use fidget::vm::VmShape;
use isoforge::expr::{compile, BinaryOp, Node, Program, UnaryOp};
use isoforge::pipeline::{self, Method, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::{scenes, Vec3};
use std::time::Duration;

/// `program` as a fidget tree over fidget's axes, with our coordinates `centre + half * axis`.
fn to_tree(program: &Program, centre: Vec3, half: f32) -> Tree {
    let (nodes, root) = program.nodes();
    let axes = [Tree::x(), Tree::y(), Tree::z()];
    let mut trees: Vec<Tree> = Vec::with_capacity(nodes.len());
    for node in nodes {
        let tree = match *node {
            Node::Const(bits) => Tree::constant(f32::from_bits(bits)),
            Node::Input(axis) => {
                let a = axis.index();
                axes[a].clone() * half + centre[a]
            }
            Node::Unary(op, a) => {
                let a = &trees[a as usize];
                match op {
                    UnaryOp::Neg => a.neg(),
                    UnaryOp::Abs => a.abs(),
                    UnaryOp::Sqrt => a.sqrt(),
                    UnaryOp::Sin => a.sin(),
                    UnaryOp::Cos => a.cos(),
                    UnaryOp::Tan => a.tan(),
                    UnaryOp::Asin => a.asin(),
                    UnaryOp::Acos => a.acos(),
                    UnaryOp::Atan => a.atan(),
                    UnaryOp::Exp => a.exp(),
                    UnaryOp::Ln => a.ln(),
                    UnaryOp::Floor => a.floor(),
                    UnaryOp::Sign => a.compare(Tree::constant(0.0)),
                    UnaryOp::Powi(2) => a.square(),
                    UnaryOp::Powi(n) => a.pow(n as i64),
                }
            }
            Node::Binary(op, a, b) => {
                let (a, b) = (trees[a as usize].clone(), trees[b as usize].clone());
                match op {
                    BinaryOp::Add => a + b,
                    BinaryOp::Sub => a - b,
                    BinaryOp::Mul => a * b,
                    BinaryOp::Div => a / b,
                    BinaryOp::Min => a.min(b),
                    BinaryOp::Max => a.max(b),
                    BinaryOp::Pow => (a.ln() * b).exp(),
                    BinaryOp::Atan2 => a.atan2(b),
                }
            }
        };
        trees.push(tree);
    }
    trees[root as usize].clone()
}

fn peers(c: &mut Criterion) {
    let no_analysis = AnalysisOptions { self_intersections: false, surface_error: false };
    for name in ["gear", "cube_minus_sphere", "rotated_box", "cube_with_cutouts"] {
        let scene = scenes::scene(name).expect("a scene");
        let centre = (scene.min + scene.max) * 0.5;
        let half = (scene.max - scene.min).max_element() * 0.5;
        let bounds = (centre - Vec3::splat(half), centre + Vec3::splat(half));
        let mut group = c.benchmark_group(format!("peers/{name}"));
        group.sample_size(10).measurement_time(Duration::from_secs(3));
        for depth in [6u8, 7, 8] {
            let res = 1usize << depth;
            let fidget = || {
                let shape = VmShape::from(to_tree(&compile(scene.source).unwrap(), centre, half));
                let shape: BoundShape<_, f32> = shape.try_into().expect("no variables but x, y, z");
                let settings = Settings { depth, threads: None, ..Default::default() };
                Octree::build(&shape, &settings).expect("not cancelled").walk_dual()
            };
            let ours = |method: Method| {
                let request = Request {
                    method,
                    res,
                    max_depth: Some(depth),
                    bounds: Some(bounds),
                    analysis: no_analysis,
                    ..Request::default()
                };
                move || {
                    let program = compile(scene.source).unwrap();
                    isoforge::par::with_threads(1, || {
                        pipeline::mesh_program_in(&program, bounds, &request).unwrap()
                    })
                }
            };
            let counts: Vec<String> = [Method::Mc, Method::Emc, Method::Dmc]
                .into_iter()
                .filter(|&m| depth < 8 || m == Method::Mc)
                .map(|m| format!("{} {}", m.name(), ours(m)().mesh.triangle_count()))
                .collect();
            eprintln!("{name} {res}³: fidget {} triangles; {}", fidget().triangles.len(), counts.join(", "));
            let id = res.to_string();
            group.bench_function(BenchmarkId::new(&id, "fidget_vm"), |b| b.iter(fidget));
            for method in [Method::Mc, Method::Emc, Method::Dmc] {
                // EMC and DMC at 256³ take seconds a call: left to a full run of their own.
                if depth == 8 && method != Method::Mc {
                    continue;
                }
                let run = ours(method);
                group.bench_function(BenchmarkId::new(&id, method.name()), |b| b.iter(&run));
            }
        }
        group.finish();
    }
}

criterion_group!(benches, peers);
criterion_main!(benches);

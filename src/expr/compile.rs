//! Syntax tree → expression graph → [`Program`].
//!
//! Lowering is written once, generically over [`Backend`]: the graph backend builds hash-consed,
//! folded nodes (the real compiler); the reference tree walk in [`super::naive`] plugs in plain
//! numbers. Both share every formula in [`super::shapes`].
//!
//! Transforms are substitutions: `translate(a, dx, dy, dz)` lowers `a` with the coordinate
//! expressions `(x - dx, y - dy, z - dz)` standing in for `x, y, z`, so the tape stays flat and
//! exact derivatives of the moved shape come for free. A binding is lowered once in the untouched
//! coordinates; used under a transform, its subgraph is copied with the coordinates replaced. That
//! is the same meaning as re-reading its text there, without re-walking bindings of bindings.

use super::ast::{ChainOp, Expr, ExprKind, Script};
use super::builtins::Builtin;
use super::diag::{Diag, Span};
use super::graph::{Graph, NodeId, MAX_NODES};
use super::ops::{BinaryOp, UnaryOp};
use super::params;
use super::parser::MAX_NESTING;
use super::program::Program;
use super::shapes::{self, Emit};
use std::collections::HashMap;

/// What lowering needs beyond arithmetic: the value of a binding at given coordinates.
pub trait Backend: Emit {
    /// `depth` is the tree depth of the reference, for backends that walk the binding's tree.
    fn binding(
        &mut self,
        script: &Script,
        index: usize,
        at: [Self::V; 3],
        depth: usize,
    ) -> Result<Self::V, Diag>;

    /// The value of `v` where it is known when the program is built (a constant), so shape
    /// parameters can be range-checked at the call; backends that only compute numbers at one
    /// point know nothing ahead of evaluation.
    fn known(&self, _v: Self::V) -> Option<f32> {
        None
    }

    /// Called after each call is lowered, so a runaway expansion stops early.
    fn check(&self, _span: Span) -> Result<(), Diag> {
        Ok(())
    }
}

/// Deepest tree lowering accepts. Parsed trees stay far below (see [`MAX_NESTING`]); this
/// guards the stack against trees built by hand.
pub const MAX_TREE_DEPTH: usize = 4 * MAX_NESTING;

/// The value of `expr` with `p` standing in for the coordinates.
pub fn lower<B: Backend>(
    b: &mut B,
    script: &Script,
    expr: &Expr,
    p: [B::V; 3],
    depth: usize,
) -> Result<B::V, Diag> {
    if depth > MAX_TREE_DEPTH {
        return Err(Diag::new(expr.span, format!("expression nests deeper than {MAX_TREE_DEPTH} levels")));
    }
    let lower = |b: &mut B, e: &Expr, p: [B::V; 3]| lower(b, script, e, p, depth + 1);
    Ok(match &expr.kind {
        ExprKind::Number(v) => b.constant(*v as f32),
        ExprKind::Coord(axis) => p[axis.index()],
        ExprKind::Binding(i) => b.binding(script, *i, p, depth)?,
        ExprKind::Neg(inner) => {
            let v = lower(b, inner, p)?;
            b.neg(v)
        }
        ExprKind::Chain { first, rest } => {
            let mut acc = lower(b, first, p)?;
            for (op, e) in rest {
                let v = lower(b, e, p)?;
                let op = match op {
                    ChainOp::Add => BinaryOp::Add,
                    ChainOp::Sub => BinaryOp::Sub,
                    ChainOp::Mul => BinaryOp::Mul,
                    ChainOp::Div => BinaryOp::Div,
                };
                acc = b.binary(op, acc, v);
            }
            acc
        }
        ExprKind::Power(base, exponent) => {
            let x = lower(b, base, p)?;
            let e = lower(b, exponent, p)?;
            b.pow(x, e)
        }
        ExprKind::Call(f, args) => {
            // The parser checked this already; a tree built by hand may not have been.
            if !f.arity().accepts(args.len()) {
                let message = format!("'{}' takes {}, but was given {}", f.name(), f.arity(), args.len());
                return Err(Diag::new(expr.span, message));
            }
            let v = if f.is_transform() {
                transform(b, script, *f, args, p, expr.span, depth + 1)?
            } else {
                let mut vals = Vec::with_capacity(args.len());
                for a in args {
                    vals.push(lower(b, a, p)?);
                }
                let known: Vec<Option<f64>> = vals.iter().map(|&v| b.known(v).map(f64::from)).collect();
                if let Some(message) = params::check(*f, &known) {
                    return Err(Diag::new(expr.span, message));
                }
                apply(b, *f, &vals, p, expr.span)?
            };
            b.check(expr.span)?;
            v
        }
    })
}

fn transform<B: Backend>(
    b: &mut B,
    script: &Script,
    f: Builtin,
    args: &[Expr],
    p: [B::V; 3],
    span: Span,
    depth: usize,
) -> Result<B::V, Diag> {
    let mut params = Vec::with_capacity(args.len().saturating_sub(1));
    for a in args.iter().skip(1) {
        params.push(lower(b, script, a, p, depth)?);
    }
    let known: Vec<Option<f64>> =
        std::iter::once(None).chain(params.iter().map(|&v| b.known(v).map(f64::from))).collect();
    if let Some(message) = params::check(f, &known) {
        return Err(Diag::new(span, message));
    }
    let at = match f {
        Builtin::Translate => shapes::translate(b, p, [params[0], params[1], params[2]]),
        Builtin::Rotate => shapes::rotate(b, p, [params[0], params[1], params[2]], params[3])
            .ok_or_else(|| Diag::new(span, "rotate: the axis (0, 0, 0) has no direction"))?,
        Builtin::Scale => shapes::scale(b, p, params[0]),
        Builtin::MirrorX => shapes::mirror(b, p, 0),
        Builtin::MirrorY => shapes::mirror(b, p, 1),
        _ => shapes::mirror(b, p, 2),
    };
    let shape = lower(b, script, &args[0], at, depth)?;
    Ok(if f == Builtin::Scale { b.mul(params[0], shape) } else { shape })
}

/// Non-transform builtins, on already lowered arguments (whose count the parser checked).
fn apply<B: Emit>(b: &mut B, f: Builtin, v: &[B::V], p: [B::V; 3], span: Span) -> Result<B::V, Diag> {
    let unary = |b: &mut B, op| b.unary(op, v[0]);
    let fold = |b: &mut B, op| v[1..].iter().fold(v[0], |acc, &x| b.binary(op, acc, x));
    Ok(match f {
        Builtin::Sin => unary(b, UnaryOp::Sin),
        Builtin::Cos => unary(b, UnaryOp::Cos),
        Builtin::Tan => unary(b, UnaryOp::Tan),
        Builtin::Asin => unary(b, UnaryOp::Asin),
        Builtin::Acos => unary(b, UnaryOp::Acos),
        Builtin::Atan => unary(b, UnaryOp::Atan),
        Builtin::Exp => unary(b, UnaryOp::Exp),
        Builtin::Log => unary(b, UnaryOp::Ln),
        Builtin::Sqrt => unary(b, UnaryOp::Sqrt),
        Builtin::Abs => unary(b, UnaryOp::Abs),
        Builtin::Floor => unary(b, UnaryOp::Floor),
        Builtin::Atan2 => b.binary(BinaryOp::Atan2, v[0], v[1]),
        Builtin::Min | Builtin::Union => fold(b, BinaryOp::Min),
        Builtin::Max | Builtin::Intersect => fold(b, BinaryOp::Max),
        Builtin::Pow => b.pow(v[0], v[1]),
        Builtin::Clamp => b.clamp(v[0], v[1], v[2]),
        Builtin::Mix => b.mix(v[0], v[1], v[2]),
        Builtin::Length => b.length(v),
        Builtin::Sphere => shapes::sphere(b, p, v[0]),
        Builtin::Box => shapes::cuboid(b, p, [v[0], v[1], v[2]]),
        Builtin::RoundedBox => shapes::rounded_box(b, p, [v[0], v[1], v[2]], v[3]),
        Builtin::Cylinder => shapes::cylinder(b, p, v[0], v[1]),
        Builtin::Cone => shapes::cone(b, p, v[0], v[1]),
        Builtin::Torus => shapes::torus(b, p, v[0], v[1]),
        Builtin::Capsule => shapes::capsule(b, p, [v[0], v[1], v[2]], [v[3], v[4], v[5]], v[6]),
        Builtin::Plane => shapes::plane(b, p, [v[0], v[1], v[2]], v[3])
            .ok_or_else(|| Diag::new(span, "plane: the normal (0, 0, 0) has no direction"))?,
        Builtin::Subtract => {
            let nb = b.neg(v[1]);
            b.max(v[0], nb)
        }
        Builtin::SmoothUnion => shapes::smooth_min(b, v[0], v[1], v[2]),
        Builtin::SmoothIntersect => shapes::smooth_max(b, v[0], v[1], v[2]),
        Builtin::SmoothSubtract => {
            let nb = b.neg(v[1]);
            shapes::smooth_max(b, v[0], nb, v[2])
        }
        Builtin::Shell => {
            let a = b.abs(v[0]);
            b.sub(a, v[1])
        }
        Builtin::Offset => b.sub(v[0], v[1]),
        Builtin::Translate
        | Builtin::Rotate
        | Builtin::Scale
        | Builtin::MirrorX
        | Builtin::MirrorY
        | Builtin::MirrorZ => {
            return Err(Diag::new(span, format!("internal: transform '{}' reached apply", f.name())));
        }
    })
}

/// The graph backend: bindings are built once, and copied with new coordinates when a transform
/// reads them (memoised, so a binding used twice under the same transform is copied once).
struct GraphBackend {
    graph: Graph,
    base: [NodeId; 3],
    bindings: Vec<NodeId>,
    moved: HashMap<(usize, [NodeId; 3]), NodeId>,
}

impl Emit for GraphBackend {
    type V = NodeId;
    fn constant(&mut self, c: f32) -> NodeId {
        self.graph.constant(c)
    }
    fn unary(&mut self, op: UnaryOp, a: NodeId) -> NodeId {
        self.graph.unary(op, a)
    }
    fn binary(&mut self, op: BinaryOp, a: NodeId, b: NodeId) -> NodeId {
        self.graph.binary(op, a, b)
    }
    fn as_constant(&self, v: NodeId) -> Option<f32> {
        self.graph.as_constant(v)
    }
}

impl Backend for GraphBackend {
    fn binding(
        &mut self,
        script: &Script,
        index: usize,
        at: [NodeId; 3],
        _depth: usize,
    ) -> Result<NodeId, Diag> {
        let Some(&built) = self.bindings.get(index) else {
            let name = script.bindings.get(index).map_or("?", |b| b.name.as_str());
            return Err(Diag::new(Span::default(), format!("binding '{name}' is used before it is defined")));
        };
        if at == self.base {
            return Ok(built);
        }
        if let Some(&id) = self.moved.get(&(index, at)) {
            return Ok(id);
        }
        let id = self.graph.substitute(built, at);
        self.moved.insert((index, at), id);
        Ok(id)
    }

    fn known(&self, v: NodeId) -> Option<f32> {
        self.graph.as_constant(v)
    }

    fn check(&self, span: Span) -> Result<(), Diag> {
        if self.graph.overflowed() {
            return Err(Diag::new(
                span,
                format!("the program expands to more than {MAX_NODES} operations (transforms copy what they move)"),
            ));
        }
        Ok(())
    }
}

/// Compiles a checked tree. Fails only on a constant zero rotation axis or plane normal, or on
/// runaway size.
pub fn compile_script(script: &Script) -> Result<Program, Diag> {
    let mut graph = Graph::new();
    let base = graph.inputs();
    let mut b = GraphBackend {
        graph,
        base,
        bindings: Vec::with_capacity(script.bindings.len()),
        moved: HashMap::new(),
    };
    for binding in &script.bindings {
        let v = lower(&mut b, script, &binding.value, base, 0)?;
        b.check(binding.span)?;
        b.bindings.push(v);
    }
    let root = lower(&mut b, script, &script.body, base, 0)?;
    b.check(script.body.span)?;
    Ok(Program::from_graph(&b.graph, root))
}

#[cfg(test)]
mod tests {
    use super::super::naive::eval_tree;
    use super::super::tape::Instr;
    use super::super::testutil::{Rng, CASES};
    use super::super::{compile, parse};
    use glam::Vec3;

    const CONSTANT_HEAVY: &[&str] = &[
        "(1 + 2) * x + sin(0.5) * y - 2^3 * z + translate(sphere(1 + 1), 0, 0, 0)",
        "k = 2 * 3 - 4; a = k * x; b = a / k + 0 * y; b - x + exp(log(2)) * -(-z)",
        "rotate(rotate(box(0.3, 0.2, 0.1), 0, 0, 1, 45 + 45), 1, 0, 0, 360 - 90)",
        "scale(scale(sphere(0.5), 2), 0.5) + clamp(1, 2, 3) * mix(x, y, 0.25 + 0.25)",
        "length(3, 4) * x + min(1, 2, 3) + max(x, 1 - 1) + abs(-2) * floor(1.5) * y",
    ];

    #[test]
    fn folded_tape_matches_the_naive_tree_walk() {
        let mut rng = Rng::new(20);
        for case in CASES.iter().chain(CONSTANT_HEAVY) {
            let program = compile(case).unwrap();
            let script = parse(case).unwrap();
            for _ in 0..100 {
                let p = rng.vec3(-1.5, 1.5);
                let (fast, slow) = (program.eval(p), eval_tree(&script, p));
                // Equal up to pow's exponent-kind choice (powi vs powf), which may differ in an ulp.
                let close = (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs());
                assert!(close || (fast.is_nan() && slow.is_nan()), "{case} at {p}: tape {fast}, tree {slow}");
            }
        }
    }

    #[test]
    fn folding_leaves_no_instruction_on_constants_alone() {
        for case in CASES.iter().chain(CONSTANT_HEAVY) {
            let program = compile(case).unwrap();
            let tape = program.tape();
            let consts = tape.consts.len() as u32;
            for instr in &tape.instrs {
                let all_const = match *instr {
                    Instr::Unary { a, .. } => a < consts,
                    Instr::Binary { a, b, .. } => a < consts && b < consts,
                };
                assert!(!all_const, "{case}: {instr:?} could have been folded\n{program}");
            }
        }
        let p = compile("sin(1)^2 + cos(1)^2 + 0 * 5").unwrap();
        assert_eq!(p.instruction_count(), 0);
        assert!((p.eval(Vec3::ZERO) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn repeated_subexpressions_are_computed_once() {
        let one = compile("sphere(1)").unwrap().instruction_count();
        let two = compile("sphere(1) + sphere(1)").unwrap().instruction_count();
        assert!(two < 2 * one, "sphere(1) + sphere(1): {two} instructions, one sphere: {one}");
        assert_eq!(two, one + 1, "only the addition is new");
        // The same shape spelt through a binding, or with operands swapped, is shared too.
        let bound = compile("s = sphere(1); s * 2 + 2 * sphere(1)").unwrap().instruction_count();
        assert_eq!(bound, one + 2);
    }

    #[test]
    fn unused_bindings_cost_nothing() {
        let plain = compile("sphere(1)").unwrap();
        let padded = compile("a = sin(x) * cos(y); b = a^2; sphere(1)").unwrap();
        assert_eq!(plain, padded);
    }

    #[test]
    fn bindings_mean_their_expression_wherever_used() {
        let p = compile("k = x; translate(k, 1, 0, 0)").unwrap();
        assert_eq!(p.eval(Vec3::new(3.0, 0.0, 0.0)), 2.0);
        let p = compile("s = sphere(0.5); translate(s, 1, 0, 0) + translate(s, 1, 0, 0)").unwrap();
        assert_eq!(p.eval(Vec3::new(1.0, 0.0, 0.0)), -1.0);
        let q = compile("translate(sphere(0.5), 1, 0, 0) * 2").unwrap();
        assert_eq!(p.instruction_count(), q.instruction_count(), "both copies are one subgraph");
        let p = compile("a = 1; a = a + 1; a * x").unwrap();
        assert_eq!(p.eval(Vec3::ONE), 2.0, "a later binding shadows an earlier one");
    }

    #[test]
    fn zero_axes_and_normals_are_refused_at_compile_time() {
        let err = compile("rotate(sphere(1),\n  0, 0, 0, 45)").unwrap_err().to_string();
        assert!(err.starts_with("1:1: rotate: the axis (0, 0, 0)"), "{err}");
        let err = compile("x + plane(0, 0, 0, 1)").unwrap_err().to_string();
        assert!(err.starts_with("1:5: plane: the normal"), "{err}");
    }

    #[test]
    fn runaway_expansion_is_an_error_not_a_hang() {
        // Each line doubles the number of distinct placements: translate and scale do not commute.
        let mut src = String::from("b0 = sphere(1);\n");
        for k in 0..40 {
            src += &format!("b{} = union(translate(b{k}, 0.1, 0, 0), scale(b{k}, 1.1));\n", k + 1);
        }
        src += "b40";
        let err = compile(&src).unwrap_err().to_string();
        assert!(err.contains("expands to more than"), "{err}");
    }

    #[test]
    fn deep_nesting_is_refused_and_long_flat_programs_are_fine() {
        let nested = |n: usize| format!("{}x{}", "(".repeat(n), ")".repeat(n));
        let p = compile(&nested(90)).unwrap();
        assert_eq!(p.eval(Vec3::X), 1.0);
        let err = compile(&nested(5000)).unwrap_err().to_string();
        assert!(err.contains("nests deeper than"), "{err}");
        let err = compile(&format!("{}x", "-".repeat(100_000))).unwrap_err().to_string();
        assert!(err.contains("nests deeper than"), "{err}");
        let err = compile(&format!("x{}", "^x".repeat(100_000))).unwrap_err().to_string();
        assert!(err.contains("nests deeper than"), "{err}");
        let calls = format!("{}x{}", "sin(".repeat(5000), ")".repeat(5000));
        assert!(compile(&calls).unwrap_err().to_string().contains("nests deeper than"));
        // A machine-generated sum of many terms is flat, however long.
        let sum = (0..20_000).map(|i| format!("{i} * x")).collect::<Vec<_>>().join(" + ");
        let p = compile(&sum).unwrap();
        assert_eq!(p.eval(Vec3::X), (0..20_000).map(|i| i as f32).sum::<f32>());
    }

    #[test]
    fn hand_built_trees_get_errors_not_panics() {
        use super::super::ast::{Binding, Expr, ExprKind, Script};
        use super::super::{Builtin, Program};
        let e = |kind| Expr::synthetic(kind);
        let wrong_arity = Script { bindings: vec![], body: e(ExprKind::Call(Builtin::Sphere, vec![])) };
        assert!(Program::from_script(&wrong_arity)
            .unwrap_err()
            .to_string()
            .contains("'sphere' takes 1 argument"));
        let forward = Script {
            bindings: vec![Binding {
                name: "a".into(),
                span: Default::default(),
                value: e(ExprKind::Binding(0)),
            }],
            body: e(ExprKind::Binding(0)),
        };
        assert!(Program::from_script(&forward).unwrap_err().to_string().contains("before it is defined"));
        assert!(eval_tree(&forward, Vec3::ZERO).is_nan(), "the tree walk stops too");
        let mut deep = e(ExprKind::Coord(super::super::ast::Axis::X));
        for _ in 0..1000 {
            deep = e(ExprKind::Neg(Box::new(deep)));
        }
        let deep = Script { bindings: vec![], body: deep };
        assert!(Program::from_script(&deep).unwrap_err().to_string().contains("nests deeper"));
    }
}

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
use super::program::Program;
use super::shapes::{self, Emit};
use std::collections::HashMap;

/// What lowering needs beyond arithmetic: the value of a binding at given coordinates.
pub trait Backend: Emit {
    fn binding(&mut self, script: &Script, index: usize, at: [Self::V; 3]) -> Result<Self::V, Diag>;

    /// Called after each call is lowered, so a runaway expansion stops early.
    fn check(&self, _span: Span) -> Result<(), Diag> {
        Ok(())
    }
}

/// The value of `expr` with `p` standing in for the coordinates.
pub fn lower<B: Backend>(b: &mut B, script: &Script, expr: &Expr, p: [B::V; 3]) -> Result<B::V, Diag> {
    Ok(match &expr.kind {
        ExprKind::Number(v) => b.constant(*v as f32),
        ExprKind::Coord(axis) => p[axis.index()],
        ExprKind::Binding(i) => b.binding(script, *i, p)?,
        ExprKind::Neg(inner) => {
            let v = lower(b, script, inner, p)?;
            b.neg(v)
        }
        ExprKind::Chain { first, rest } => {
            let mut acc = lower(b, script, first, p)?;
            for (op, e) in rest {
                let v = lower(b, script, e, p)?;
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
            let x = lower(b, script, base, p)?;
            let e = lower(b, script, exponent, p)?;
            b.pow(x, e)
        }
        ExprKind::Call(f, args) => {
            let v = if f.is_transform() {
                transform(b, script, *f, args, p, expr.span)?
            } else {
                let mut vals = Vec::with_capacity(args.len());
                for a in args {
                    vals.push(lower(b, script, a, p)?);
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
) -> Result<B::V, Diag> {
    let mut params = Vec::with_capacity(args.len().saturating_sub(1));
    for a in args.iter().skip(1) {
        params.push(lower(b, script, a, p)?);
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
    let shape = lower(b, script, &args[0], at)?;
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
        Builtin::Translate | Builtin::Rotate | Builtin::Scale | Builtin::MirrorX | Builtin::MirrorY | Builtin::MirrorZ => {
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
    fn binding(&mut self, _script: &Script, index: usize, at: [NodeId; 3]) -> Result<NodeId, Diag> {
        let built = self.bindings[index];
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
    let mut b = GraphBackend { graph, base, bindings: Vec::with_capacity(script.bindings.len()), moved: HashMap::new() };
    for binding in &script.bindings {
        let v = lower(&mut b, script, &binding.value, base)?;
        b.check(binding.span)?;
        b.bindings.push(v);
    }
    let root = lower(&mut b, script, &script.body, base)?;
    b.check(script.body.span)?;
    Ok(Program::from_graph(&b.graph, root))
}

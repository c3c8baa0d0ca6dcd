//! CSG trees as JSON, for programs that build shapes rather than type them (a UI's scene tree).
//!
//! Each node is an object whose `"op"` names it; parameters are named fields, children are
//! `"shape"` (one) or `"args"` (several). The whole vocabulary:
//!
//! ```json
//! {"op": "sphere", "radius": 1}
//! {"op": "box", "half": [hx, hy, hz]}
//! {"op": "rounded_box", "half": [hx, hy, hz], "radius": r}
//! {"op": "cylinder", "radius": r, "half_height": h}
//! {"op": "cone", "radius": r, "height": h}
//! {"op": "torus", "major": R, "minor": r}
//! {"op": "capsule", "a": [x, y, z], "b": [x, y, z], "radius": r}
//! {"op": "plane", "normal": [nx, ny, nz], "offset": d}
//! {"op": "union", "args": [node, …]}            (at least one)
//! {"op": "intersect", "args": [node, …]}        (at least one)
//! {"op": "subtract", "args": [node, node]}      (first minus second)
//! {"op": "smooth_union", "args": [node, node], "k": k}   (also smooth_intersect, smooth_subtract)
//! {"op": "shell", "shape": node, "thickness": t}
//! {"op": "offset", "shape": node, "distance": d}
//! {"op": "translate", "shape": node, "offset": [dx, dy, dz]}
//! {"op": "rotate", "shape": node, "axis": [ax, ay, az], "degrees": deg}
//! {"op": "scale", "shape": node, "factor": s}
//! {"op": "mirror", "shape": node, "axis": "x"}   ("x", "y" or "z")
//! ```
//!
//! Each node means exactly the language function of the same name, and is converted into the
//! same syntax tree, so a JSON tree and its text spelling ([`CsgNode::to_text`]) compile to the
//! identical tape. Unknown fields are errors, so a misspelt parameter is not silently dropped.

use super::ast::{Expr, ExprKind, Script};
use super::builtins::Builtin;
use super::diag::locate;
use super::parser::MAX_NESTING;
use crate::error::Error;
use serde::{Deserialize, Deserializer, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum CsgNode {
    Sphere { radius: f64 },
    Box { half: [f64; 3] },
    RoundedBox { half: [f64; 3], radius: f64 },
    Cylinder { radius: f64, half_height: f64 },
    Cone { radius: f64, height: f64 },
    Torus { major: f64, minor: f64 },
    Capsule { a: [f64; 3], b: [f64; 3], radius: f64 },
    Plane { normal: [f64; 3], offset: f64 },
    Union {
        #[serde(deserialize_with = "at_least_one")]
        args: Vec<CsgNode>,
    },
    Intersect {
        #[serde(deserialize_with = "at_least_one")]
        args: Vec<CsgNode>,
    },
    Subtract { args: Box<[CsgNode; 2]> },
    SmoothUnion { args: Box<[CsgNode; 2]>, k: f64 },
    SmoothIntersect { args: Box<[CsgNode; 2]>, k: f64 },
    SmoothSubtract { args: Box<[CsgNode; 2]>, k: f64 },
    Shell { shape: Box<CsgNode>, thickness: f64 },
    Offset { shape: Box<CsgNode>, distance: f64 },
    Translate { shape: Box<CsgNode>, offset: [f64; 3] },
    Rotate { shape: Box<CsgNode>, axis: [f64; 3], degrees: f64 },
    Scale { shape: Box<CsgNode>, factor: f64 },
    Mirror { shape: Box<CsgNode>, axis: MirrorAxis },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MirrorAxis {
    X,
    Y,
    Z,
}

fn at_least_one<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<CsgNode>, D::Error> {
    let v = Vec::<CsgNode>::deserialize(d)?;
    if v.is_empty() {
        return Err(serde::de::Error::invalid_length(0, &"at least one shape"));
    }
    Ok(v)
}

/// The function, numeric parameters and child shapes of a node, in the function's argument order
/// (a transform's shape comes first, every other function's shapes before its numbers).
fn parts(node: &CsgNode) -> (Builtin, Vec<&CsgNode>, Vec<f64>) {
    fn pair(a: &[CsgNode; 2]) -> Vec<&CsgNode> {
        vec![&a[0], &a[1]]
    }
    use CsgNode as N;
    match node {
        N::Sphere { radius } => (Builtin::Sphere, vec![], vec![*radius]),
        N::Box { half } => (Builtin::Box, vec![], half.to_vec()),
        N::RoundedBox { half, radius } => (Builtin::RoundedBox, vec![], vec![half[0], half[1], half[2], *radius]),
        N::Cylinder { radius, half_height } => (Builtin::Cylinder, vec![], vec![*radius, *half_height]),
        N::Cone { radius, height } => (Builtin::Cone, vec![], vec![*radius, *height]),
        N::Torus { major, minor } => (Builtin::Torus, vec![], vec![*major, *minor]),
        N::Capsule { a, b, radius } => (Builtin::Capsule, vec![], vec![a[0], a[1], a[2], b[0], b[1], b[2], *radius]),
        N::Plane { normal, offset } => (Builtin::Plane, vec![], vec![normal[0], normal[1], normal[2], *offset]),
        N::Union { args } => (Builtin::Union, args.iter().collect(), vec![]),
        N::Intersect { args } => (Builtin::Intersect, args.iter().collect(), vec![]),
        N::Subtract { args } => (Builtin::Subtract, pair(args), vec![]),
        N::SmoothUnion { args, k } => (Builtin::SmoothUnion, pair(args), vec![*k]),
        N::SmoothIntersect { args, k } => (Builtin::SmoothIntersect, pair(args), vec![*k]),
        N::SmoothSubtract { args, k } => (Builtin::SmoothSubtract, pair(args), vec![*k]),
        N::Shell { shape, thickness } => (Builtin::Shell, vec![shape], vec![*thickness]),
        N::Offset { shape, distance } => (Builtin::Offset, vec![shape], vec![*distance]),
        N::Translate { shape, offset } => (Builtin::Translate, vec![shape], offset.to_vec()),
        N::Rotate { shape, axis, degrees } => (Builtin::Rotate, vec![shape], vec![axis[0], axis[1], axis[2], *degrees]),
        N::Scale { shape, factor } => (Builtin::Scale, vec![shape], vec![*factor]),
        N::Mirror { shape, axis } => {
            let f = match axis {
                MirrorAxis::X => Builtin::MirrorX,
                MirrorAxis::Y => Builtin::MirrorY,
                MirrorAxis::Z => Builtin::MirrorZ,
            };
            (f, vec![shape], vec![])
        }
    }
}

impl CsgNode {
    /// Parses the JSON form; errors point at the offending line and column of the JSON.
    pub fn from_json(json: &str) -> Result<CsgNode, Error> {
        serde_json::from_str(json).map_err(|e| {
            // serde_json counts columns in bytes from 1 (0 at a line's very start); convert.
            let offset = byte_offset(json, e.line(), e.column());
            let (line, column, snippet) = locate(json, offset);
            let message = e.to_string();
            let message = message.split(" at line ").next().unwrap_or(&message).to_string();
            Error::Parse { message, line, column, snippet }
        })
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// The same tree as a syntax tree, ready for [`super::Program::from_script`].
    pub fn to_script(&self) -> Result<Script, Error> {
        Ok(Script { bindings: Vec::new(), body: to_expr(self, 0)? })
    }

    /// The same shape in the expression language, e.g. `subtract(sphere(1.0), box(0.5, …))`.
    /// Non-finite numbers have no spelling in the language and make the text fail to parse.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        write_text(self, &mut out);
        out
    }
}

fn to_expr(node: &CsgNode, depth: usize) -> Result<Expr, Error> {
    if depth >= MAX_NESTING {
        return Err(Error::InvalidOption(format!("shape tree: nested deeper than {MAX_NESTING} levels")));
    }
    let (f, shapes, numbers) = parts(node);
    if shapes.is_empty() && matches!(f, Builtin::Union | Builtin::Intersect) {
        return Err(Error::InvalidOption(format!("shape tree: '{}' needs at least one shape", f.name())));
    }
    let mut args = Vec::with_capacity(shapes.len() + numbers.len());
    for s in shapes {
        args.push(to_expr(s, depth + 1)?);
    }
    args.extend(numbers.into_iter().map(|v| Expr::synthetic(ExprKind::Number(v))));
    Ok(Expr::synthetic(ExprKind::Call(f, args)))
}

fn write_text(node: &CsgNode, out: &mut String) {
    let (f, shapes, numbers) = parts(node);
    out.push_str(f.name());
    out.push('(');
    let mut first = true;
    for s in shapes {
        if !first {
            out.push_str(", ");
        }
        first = false;
        write_text(s, out);
    }
    for v in numbers {
        if !first {
            out.push_str(", ");
        }
        first = false;
        // `{:?}` is the shortest text that reads back as the same f64.
        out.push_str(&format!("{v:?}"));
    }
    out.push(')');
}

fn byte_offset(text: &str, line: usize, column: usize) -> usize {
    let start: usize = text.split_inclusive('\n').take(line.saturating_sub(1)).map(str::len).sum();
    (start + column.saturating_sub(1)).min(text.len())
}

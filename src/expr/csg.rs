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
//! {"op": "plane", "normal": [nx, ny, nz], "distance": d}
//! {"op": "union", "args": [node, …]}            (at least one)
//! {"op": "intersect", "args": [node, …]}        (at least one)
//! {"op": "subtract", "args": [node, node]}      (first minus second)
//! {"op": "smooth_union", "args": [node, node], "k": k}   (also smooth_intersect, smooth_subtract)
//! {"op": "shell", "shape": node, "thickness": t}
//! {"op": "offset", "shape": node, "distance": d}
//! {"op": "translate", "shape": node, "offset": [dx, dy, dz]}
//! {"op": "rotate", "shape": node, "axis": [ax, ay, az], "degrees": deg}
//! {"op": "scale", "shape": node, "factor": s}
//! {"op": "mirror_x", "shape": node}             (also mirror_y, mirror_z)
//! ```
//!
//! Each node means exactly the language function of the same name, and is converted into the
//! same syntax tree, so a JSON tree and its text spelling ([`CsgNode::to_text`]) compile to the
//! identical tape. A field name has one type whatever the op. Unknown or misplaced fields are
//! errors, so a misspelt parameter is not silently dropped; errors point into the JSON text at
//! the offending node (reading is in `csg_json.rs`).

use super::ast::{Expr, ExprKind, Script};
use super::builtins::Builtin;
use super::diag::locate;
use super::parser::MAX_NESTING;
use crate::error::Error;
use serde::Serialize;

/// One node of a shape tree; the variants mirror the language's shape functions (see the module
/// docs for the JSON spelling). `Union` and `Intersect` need at least one shape.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "op", rename_all = "snake_case")]
pub enum CsgNode {
    Sphere { radius: f64 },
    Box { half: [f64; 3] },
    RoundedBox { half: [f64; 3], radius: f64 },
    Cylinder { radius: f64, half_height: f64 },
    Cone { radius: f64, height: f64 },
    Torus { major: f64, minor: f64 },
    Capsule { a: [f64; 3], b: [f64; 3], radius: f64 },
    Plane { normal: [f64; 3], distance: f64 },
    Union { args: Vec<CsgNode> },
    Intersect { args: Vec<CsgNode> },
    Subtract { args: Box<[CsgNode; 2]> },
    SmoothUnion { args: Box<[CsgNode; 2]>, k: f64 },
    SmoothIntersect { args: Box<[CsgNode; 2]>, k: f64 },
    SmoothSubtract { args: Box<[CsgNode; 2]>, k: f64 },
    Shell { shape: Box<CsgNode>, thickness: f64 },
    Offset { shape: Box<CsgNode>, distance: f64 },
    Translate { shape: Box<CsgNode>, offset: [f64; 3] },
    Rotate { shape: Box<CsgNode>, axis: [f64; 3], degrees: f64 },
    Scale { shape: Box<CsgNode>, factor: f64 },
    MirrorX { shape: Box<CsgNode> },
    MirrorY { shape: Box<CsgNode> },
    MirrorZ { shape: Box<CsgNode> },
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
        N::RoundedBox { half, radius } => {
            (Builtin::RoundedBox, vec![], vec![half[0], half[1], half[2], *radius])
        }
        N::Cylinder { radius, half_height } => (Builtin::Cylinder, vec![], vec![*radius, *half_height]),
        N::Cone { radius, height } => (Builtin::Cone, vec![], vec![*radius, *height]),
        N::Torus { major, minor } => (Builtin::Torus, vec![], vec![*major, *minor]),
        N::Capsule { a, b, radius } => {
            (Builtin::Capsule, vec![], vec![a[0], a[1], a[2], b[0], b[1], b[2], *radius])
        }
        N::Plane { normal, distance } => {
            (Builtin::Plane, vec![], vec![normal[0], normal[1], normal[2], *distance])
        }
        N::Union { args } => (Builtin::Union, args.iter().collect(), vec![]),
        N::Intersect { args } => (Builtin::Intersect, args.iter().collect(), vec![]),
        N::Subtract { args } => (Builtin::Subtract, pair(args), vec![]),
        N::SmoothUnion { args, k } => (Builtin::SmoothUnion, pair(args), vec![*k]),
        N::SmoothIntersect { args, k } => (Builtin::SmoothIntersect, pair(args), vec![*k]),
        N::SmoothSubtract { args, k } => (Builtin::SmoothSubtract, pair(args), vec![*k]),
        N::Shell { shape, thickness } => (Builtin::Shell, vec![shape], vec![*thickness]),
        N::Offset { shape, distance } => (Builtin::Offset, vec![shape], vec![*distance]),
        N::Translate { shape, offset } => (Builtin::Translate, vec![shape], offset.to_vec()),
        N::Rotate { shape, axis, degrees } => {
            (Builtin::Rotate, vec![shape], vec![axis[0], axis[1], axis[2], *degrees])
        }
        N::Scale { shape, factor } => (Builtin::Scale, vec![shape], vec![*factor]),
        N::MirrorX { shape } => (Builtin::MirrorX, vec![shape], vec![]),
        N::MirrorY { shape } => (Builtin::MirrorY, vec![shape], vec![]),
        N::MirrorZ { shape } => (Builtin::MirrorZ, vec![shape], vec![]),
    }
}

impl CsgNode {
    /// Parses the JSON form; errors point at the offending line and column of the JSON.
    pub fn from_json(json: &str) -> Result<CsgNode, Error> {
        serde_json::from_str::<CsgNode>(json).map_err(|e| {
            // serde_json counts columns in bytes from 1 (0 at a line's very start); convert.
            let offset = byte_offset(json, e.line(), e.column());
            let (line, column, snippet) = locate(json, offset);
            let message = e.to_string();
            let message = message.split(" at line ").next().unwrap_or(&message).to_string();
            Error::Parse { message, line, column, snippet }
        })
    }

    /// Why this node's own parameters are out of range (see `params::check`), or `None`.
    pub fn parameter_error(&self) -> Option<String> {
        let (f, shapes, numbers) = parts(self);
        let args: Vec<Option<f64>> =
            shapes.iter().map(|_| None).chain(numbers.into_iter().map(Some)).collect();
        super::params::check(f, &args)
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

#[cfg(test)]
mod tests {
    use super::super::{compile, Program};
    use super::*;
    use glam::Vec3;

    const EXAMPLE: &str = r#"{
      "op": "subtract",
      "args": [
        {"op": "rounded_box", "half": [1, 0.6, 0.4], "radius": 0.1},
        {"op": "translate", "shape": {"op": "cylinder", "radius": 0.25, "half_height": 2}, "offset": [0.3, 0, 0]}
      ]
    }"#;

    /// Every node kind once.
    fn everything() -> CsgNode {
        let s = |r: f64| CsgNode::Sphere { radius: r };
        fn b<T>(t: T) -> Box<T> {
            Box::new(t)
        }
        CsgNode::Union {
            args: vec![
                CsgNode::Subtract { args: b([CsgNode::Box { half: [0.5, 0.4, 0.3] }, s(0.45)]) },
                CsgNode::Translate {
                    shape: b(CsgNode::Rotate {
                        shape: b(CsgNode::Cylinder { radius: 0.2, half_height: 0.5 }),
                        axis: [1.0, 0.0, 0.0],
                        degrees: -30.0,
                    }),
                    offset: [0.7, -0.1, 0.0],
                },
                CsgNode::SmoothUnion {
                    args: b([CsgNode::Cone { radius: 0.3, height: 0.6 }, s(0.2)]),
                    k: 0.1,
                },
                CsgNode::SmoothIntersect {
                    args: b([CsgNode::Torus { major: 0.5, minor: 0.1 }, s(0.55)]),
                    k: 0.05,
                },
                CsgNode::SmoothSubtract {
                    args: b([CsgNode::RoundedBox { half: [0.3, 0.3, 0.3], radius: 0.05 }, s(0.3)]),
                    k: 0.02,
                },
                CsgNode::Intersect {
                    args: vec![
                        CsgNode::Capsule { a: [0.0, 0.0, -0.5], b: [0.0, 0.0, 0.5], radius: 0.1 },
                        CsgNode::Plane { normal: [0.0, 0.0, 1.0], distance: 0.1 },
                    ],
                },
                CsgNode::Shell { shape: b(s(0.9)), thickness: 0.02 },
                CsgNode::Offset {
                    shape: b(CsgNode::Scale { shape: b(s(0.1)), factor: 1.5 }),
                    distance: 0.01,
                },
                CsgNode::MirrorZ {
                    shape: b(CsgNode::Translate { shape: b(s(0.1)), offset: [0.0, 0.0, 0.6] }),
                },
                CsgNode::MirrorX { shape: b(s(0.1)) },
                CsgNode::MirrorY { shape: b(s(0.1)) },
            ],
        }
    }

    #[test]
    fn json_and_text_compile_to_the_same_tape() {
        let from_json = Program::from_csg_json(EXAMPLE).unwrap();
        let from_text =
            compile("subtract(rounded_box(1, 0.6, 0.4, 0.1), translate(cylinder(0.25, 2), 0.3, 0, 0))")
                .unwrap();
        assert_eq!(from_json, from_text);
        let tree = everything();
        let text = tree.to_text();
        assert_eq!(Program::from_csg(&tree).unwrap(), compile(&text).unwrap(), "{text}");
        assert!(
            text.starts_with("union(subtract(box(0.5, 0.4, 0.3), sphere(0.45)), translate(rotate("),
            "{text}"
        );
        assert!(text.contains("translate(rotate(cylinder(0.2, 0.5), 1.0, 0.0, 0.0, -30.0), 0.7, -0.1, 0.0)"));
    }

    #[test]
    fn json_round_trips() {
        let tree = everything();
        let json = tree.to_json();
        assert_eq!(CsgNode::from_json(&json).unwrap(), tree);
        assert!(json.contains(r#""op":"smooth_subtract""#) && json.contains(r#""op":"mirror_z""#), "{json}");
        let p = Program::from_csg_json(EXAMPLE).unwrap();
        assert!(p.eval(Vec3::new(-0.6, 0.0, 0.0)) < 0.0);
        assert!(p.eval(Vec3::new(0.3, 0.0, 0.0)) > 0.0);
    }

    fn json_error(json: &str) -> (usize, usize, String) {
        match CsgNode::from_json(json) {
            Err(Error::Parse { line, column, message, .. }) => (line, column, message),
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    #[test]
    fn json_errors_say_where_and_what() {
        let (line, _, message) = json_error("{\"op\": \"union\", \"args\": [\n  {\"op\": \"sphere\", \"radius\": 1},\n  {\"op\": \"sphear\", \"radius\": 1}\n]}");
        assert_eq!(line, 3);
        assert!(message.contains("unknown op `sphear`; did you mean `sphere`?"), "{message}");
        let (line, _, message) = json_error("{\"op\": \"sphere\",\n \"radiuss\": 1}");
        assert_eq!(line, 2);
        assert!(message.contains("unknown field `radiuss`"), "{message}");
        let (_, _, message) = json_error(r#"{"op": "union", "args": []}"#);
        assert!(message.contains("at least 1 shape for `union`"), "{message}");
        let (line, _, message) = json_error(
            "{\"op\": \"translate\",\n \"shape\": {\"op\": \"sphere\", \"radius\": 1},\n \"radius\": 2}",
        );
        assert_eq!(line, 3, "reported at the end of the node it does not belong to");
        assert!(
            message.contains("field `radius` does not belong to `translate`, which takes `shape`, `offset`"),
            "{message}"
        );
        let (line, _, message) =
            json_error("{\"op\": \"scale\", \"factor\": 2, \"shape\":\n {\"op\": \"torus\", \"major\": 1}}");
        assert_eq!(line, 2);
        assert!(message.contains("missing field `minor`"), "{message}");
        let (_, _, message) = json_error(r#"{"op": "subtract", "args": [{"op": "sphere", "radius": 1}]}"#);
        assert!(message.contains("length 1"), "{message}");
        let (line, column, _) = json_error("{\"op\": \"sphere\", \"radius\": 1,}");
        assert_eq!((line, column), (1, 30), "at the stray closing brace");
        let err = Program::from_csg_json("{\"op\": \"box\", \"half\": [1, 2]}").unwrap_err().to_string();
        assert!(err.starts_with("1:"), "{err}");
    }

    #[test]
    fn trees_built_in_rust_are_checked_too() {
        let empty = CsgNode::Intersect { args: vec![] };
        assert!(Program::from_csg(&empty).unwrap_err().to_string().contains("at least one shape"));
        let flat = CsgNode::Rotate {
            shape: Box::new(CsgNode::Sphere { radius: 1.0 }),
            axis: [0.0; 3],
            degrees: 5.0,
        };
        assert!(Program::from_csg(&flat).unwrap_err().to_string().contains("axis (0, 0, 0)"));
        let mut deep = CsgNode::Sphere { radius: 1.0 };
        for _ in 0..500 {
            deep = CsgNode::Offset { shape: Box::new(deep), distance: 0.0 };
        }
        assert!(Program::from_csg(&deep).unwrap_err().to_string().contains("nested deeper"));
        let nested = "{\"op\":\"offset\",\"distance\":0,\"shape\":".repeat(200)
            + "{\"op\":\"sphere\",\"radius\":1}"
            + &"}".repeat(200);
        assert!(Program::from_csg_json(&nested).is_err(), "serde_json's recursion limit applies");
    }
}

//! Reading [`CsgNode`] from JSON (or any serde format), by hand rather than derived.
//!
//! serde's derived form of an `"op"`-tagged enum buffers each object before it knows the op, so
//! an error deep inside a tree is reported at the end of the outermost object. Here every field
//! name has one type whatever the op, so fields are read as they stream past: an error in a child
//! points into that child, a bad `"op"` points at itself, and a missing or misplaced field points
//! at the end of its own node.

use super::csg::CsgNode;
use super::diag::suggest;
use serde::de::{self, Deserialize, Deserializer, MapAccess, Visitor};
use std::fmt;

/// Each op and the fields it takes (besides `"op"`), in the order its docs list them.
const OPS: &[(&str, &[&str])] = &[
    ("sphere", &["radius"]),
    ("box", &["half"]),
    ("rounded_box", &["half", "radius"]),
    ("cylinder", &["radius", "half_height"]),
    ("cone", &["radius", "height"]),
    ("torus", &["major", "minor"]),
    ("capsule", &["a", "b", "radius"]),
    ("plane", &["normal", "distance"]),
    ("union", &["args"]),
    ("intersect", &["args"]),
    ("subtract", &["args"]),
    ("smooth_union", &["args", "k"]),
    ("smooth_intersect", &["args", "k"]),
    ("smooth_subtract", &["args", "k"]),
    ("shell", &["shape", "thickness"]),
    ("offset", &["shape", "distance"]),
    ("translate", &["shape", "offset"]),
    ("rotate", &["shape", "axis", "degrees"]),
    ("scale", &["shape", "factor"]),
    ("mirror_x", &["shape"]),
    ("mirror_y", &["shape"]),
    ("mirror_z", &["shape"]),
];

const NUMBER_FIELDS: &[&str] =
    &["radius", "half_height", "height", "major", "minor", "distance", "k", "thickness", "degrees", "factor"];
const VECTOR_FIELDS: &[&str] = &["half", "a", "b", "normal", "offset", "axis"];
const ALL_FIELDS: &[&str] = &[
    "op",
    "radius",
    "half_height",
    "height",
    "major",
    "minor",
    "distance",
    "k",
    "thickness",
    "degrees",
    "factor",
    "half",
    "a",
    "b",
    "normal",
    "offset",
    "axis",
    "args",
    "shape",
];

/// Everything one object held, by field name.
#[derive(Default)]
struct Fields {
    op: Option<(&'static str, &'static [&'static str])>,
    numbers: Vec<(&'static str, f64)>,
    vectors: Vec<(&'static str, [f64; 3])>,
    args: Option<Vec<CsgNode>>,
    shape: Option<Box<CsgNode>>,
    seen: Vec<&'static str>,
}

impl Fields {
    fn number<E: de::Error>(&self, name: &'static str) -> Result<f64, E> {
        self.numbers.iter().find(|f| f.0 == name).map(|f| f.1).ok_or_else(|| E::missing_field(name))
    }

    fn vector<E: de::Error>(&self, name: &'static str) -> Result<[f64; 3], E> {
        self.vectors.iter().find(|f| f.0 == name).map(|f| f.1).ok_or_else(|| E::missing_field(name))
    }

    fn shape<E: de::Error>(&mut self) -> Result<Box<CsgNode>, E> {
        self.shape.take().ok_or_else(|| E::missing_field("shape"))
    }

    fn args<E: de::Error>(&mut self, op: &str, at_least: usize, at_most: usize) -> Result<Vec<CsgNode>, E> {
        let args = self.args.take().ok_or_else(|| E::missing_field("args"))?;
        if args.len() < at_least || args.len() > at_most {
            let wanted = if at_least == at_most {
                format!("exactly {at_least} shapes for `{op}`")
            } else {
                format!("at least {at_least} shape for `{op}`")
            };
            return Err(E::invalid_length(args.len(), &wanted.as_str()));
        }
        Ok(args)
    }

    fn pair<E: de::Error>(&mut self, op: &str) -> Result<Box<[CsgNode; 2]>, E> {
        let mut args = self.args(op, 2, 2)?.into_iter();
        match (args.next(), args.next()) {
            (Some(a), Some(b)) => Ok(Box::new([a, b])),
            _ => Err(E::missing_field("args")),
        }
    }
}

struct NodeVisitor;

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = CsgNode;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a shape object with an \"op\" field")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<CsgNode, A::Error> {
        let mut fields = Fields::default();
        while let Some(key) = map.next_key::<String>()? {
            let Some(&name) = ALL_FIELDS.iter().find(|&&f| f == key) else {
                return Err(de::Error::unknown_field(&key, ALL_FIELDS));
            };
            if fields.seen.contains(&name) {
                return Err(de::Error::duplicate_field(name));
            }
            fields.seen.push(name);
            if name == "op" {
                let op: String = map.next_value()?;
                let Some(entry) = OPS.iter().find(|o| o.0 == op) else {
                    let hint = match suggest(&op, OPS.iter().map(|o| o.0)) {
                        Some(near) => format!("did you mean `{near}`?"),
                        None => format!("known: {}", OPS.iter().map(|o| o.0).collect::<Vec<_>>().join(", ")),
                    };
                    return Err(de::Error::custom(format!("unknown op `{op}`; {hint}")));
                };
                fields.op = Some(*entry);
            } else if NUMBER_FIELDS.contains(&name) {
                let v: f64 = map.next_value()?;
                fields.numbers.push((name, v));
            } else if VECTOR_FIELDS.contains(&name) {
                let v: [f64; 3] = map.next_value()?;
                fields.vectors.push((name, v));
            } else if name == "args" {
                fields.args = Some(map.next_value()?);
            } else {
                fields.shape = Some(map.next_value()?);
            }
        }
        let (op, takes) = fields.op.ok_or_else(|| de::Error::missing_field("op"))?;
        if let Some(extra) = fields.seen.iter().find(|&&f| f != "op" && !takes.contains(&f)) {
            return Err(de::Error::custom(format!(
                "field `{extra}` does not belong to `{op}`, which takes {}",
                takes.iter().map(|t| format!("`{t}`")).collect::<Vec<_>>().join(", ")
            )));
        }
        let node = build(op, &mut fields)?;
        match node.parameter_error() {
            Some(message) => Err(de::Error::custom(message)),
            None => Ok(node),
        }
    }
}

fn build<E: de::Error>(op: &str, f: &mut Fields) -> Result<CsgNode, E> {
    use CsgNode as N;
    Ok(match op {
        "sphere" => N::Sphere { radius: f.number("radius")? },
        "box" => N::Box { half: f.vector("half")? },
        "rounded_box" => N::RoundedBox { half: f.vector("half")?, radius: f.number("radius")? },
        "cylinder" => N::Cylinder { radius: f.number("radius")?, half_height: f.number("half_height")? },
        "cone" => N::Cone { radius: f.number("radius")?, height: f.number("height")? },
        "torus" => N::Torus { major: f.number("major")?, minor: f.number("minor")? },
        "capsule" => N::Capsule { a: f.vector("a")?, b: f.vector("b")?, radius: f.number("radius")? },
        "plane" => N::Plane { normal: f.vector("normal")?, distance: f.number("distance")? },
        "union" => N::Union { args: f.args(op, 1, usize::MAX)? },
        "intersect" => N::Intersect { args: f.args(op, 1, usize::MAX)? },
        "subtract" => N::Subtract { args: f.pair(op)? },
        "smooth_union" => N::SmoothUnion { args: f.pair(op)?, k: f.number("k")? },
        "smooth_intersect" => N::SmoothIntersect { args: f.pair(op)?, k: f.number("k")? },
        "smooth_subtract" => N::SmoothSubtract { args: f.pair(op)?, k: f.number("k")? },
        "shell" => N::Shell { shape: f.shape()?, thickness: f.number("thickness")? },
        "offset" => N::Offset { shape: f.shape()?, distance: f.number("distance")? },
        "translate" => N::Translate { shape: f.shape()?, offset: f.vector("offset")? },
        "rotate" => N::Rotate { shape: f.shape()?, axis: f.vector("axis")?, degrees: f.number("degrees")? },
        "scale" => N::Scale { shape: f.shape()?, factor: f.number("factor")? },
        "mirror_x" => N::MirrorX { shape: f.shape()? },
        "mirror_y" => N::MirrorY { shape: f.shape()? },
        "mirror_z" => N::MirrorZ { shape: f.shape()? },
        other => return Err(E::custom(format!("internal: op `{other}` has no constructor"))),
    })
}

impl<'de> Deserialize<'de> for CsgNode {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<CsgNode, D::Error> {
        d.deserialize_map(NodeVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_tables_agree() {
        let mut listed: Vec<&str> = vec!["op"];
        listed.extend(NUMBER_FIELDS);
        listed.extend(VECTOR_FIELDS);
        listed.extend(["args", "shape"]);
        assert_eq!(listed, ALL_FIELDS);
        for (op, takes) in OPS {
            assert!(takes.iter().all(|t| ALL_FIELDS.contains(t)), "{op}");
        }
    }
}

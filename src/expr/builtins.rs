//! The table of named functions: math, shapes, combinators and transforms. The parser checks names
//! and argument counts against it; the compiler gives each its meaning.

use std::fmt;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Builtin {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Exp,
    Log,
    Sqrt,
    Abs,
    Floor,
    Min,
    Max,
    Pow,
    Clamp,
    Mix,
    Length,
    Sphere,
    Box,
    RoundedBox,
    Cylinder,
    Cone,
    Torus,
    Capsule,
    Plane,
    Union,
    Intersect,
    Subtract,
    SmoothUnion,
    SmoothIntersect,
    SmoothSubtract,
    Shell,
    Offset,
    Translate,
    Rotate,
    Scale,
    MirrorX,
    MirrorY,
    MirrorZ,
}

/// How many arguments a function takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Arity {
    Exactly(usize),
    AtLeast(usize),
}

impl Arity {
    pub fn accepts(self, n: usize) -> bool {
        match self {
            Arity::Exactly(k) => n == k,
            Arity::AtLeast(k) => n >= k,
        }
    }
}

impl fmt::Display for Arity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (word, k) = match *self {
            Arity::Exactly(k) => ("", k),
            Arity::AtLeast(k) => ("at least ", k),
        };
        write!(f, "{word}{k} argument{}", if k == 1 { "" } else { "s" })
    }
}

use Builtin as B;

/// Name, signature as shown in errors, builtin, and what it is (for the page's language
/// reference). The order is the order of the docs.
const TABLE: &[(&str, &str, Builtin, &str)] = &[
    ("sin", "sin(a)", B::Sin, "sine (radians)"),
    ("cos", "cos(a)", B::Cos, "cosine (radians)"),
    ("tan", "tan(a)", B::Tan, "tangent (radians)"),
    ("asin", "asin(a)", B::Asin, "arc sine"),
    ("acos", "acos(a)", B::Acos, "arc cosine"),
    ("atan", "atan(a)", B::Atan, "arc tangent"),
    ("atan2", "atan2(y, x)", B::Atan2, "angle of the point (x, y), in radians"),
    ("exp", "exp(a)", B::Exp, "e to the power a"),
    ("log", "log(a)", B::Log, "natural logarithm"),
    ("sqrt", "sqrt(a)", B::Sqrt, "square root"),
    ("abs", "abs(a)", B::Abs, "absolute value"),
    ("floor", "floor(a)", B::Floor, "largest integer ≤ a"),
    ("min", "min(a, …)", B::Min, "smallest argument"),
    ("max", "max(a, …)", B::Max, "largest argument"),
    ("pow", "pow(a, b)", B::Pow, "a to the power b"),
    ("clamp", "clamp(a, lo, hi)", B::Clamp, "a limited to [lo, hi]"),
    ("mix", "mix(a, b, t)", B::Mix, "a + (b − a)·t"),
    ("length", "length(a, …)", B::Length, "√(a² + …): length(x, y, z) is the distance to the origin"),
    ("sphere", "sphere(r)", B::Sphere, "ball of radius r at the origin"),
    ("box", "box(hx, hy, hz)", B::Box, "box with half extents hx, hy, hz"),
    (
        "rounded_box",
        "rounded_box(hx, hy, hz, r)",
        B::RoundedBox,
        "box with half extents h, edges rounded by r",
    ),
    ("cylinder", "cylinder(r, h)", B::Cylinder, "radius r about the z axis, from z = −h to h"),
    ("cone", "cone(r, h)", B::Cone, "base radius r in the plane z = 0, apex at z = h"),
    ("torus", "torus(R, r)", B::Torus, "ring of radius R about the z axis, tube radius r"),
    ("capsule", "capsule(ax, ay, az, bx, by, bz, r)", B::Capsule, "segment from a to b thickened by r"),
    ("plane", "plane(nx, ny, nz, d)", B::Plane, "half-space n·p ≤ d (n normalised)"),
    ("union", "union(a, …)", B::Union, "inside any (min)"),
    ("intersect", "intersect(a, …)", B::Intersect, "inside all (max)"),
    ("subtract", "subtract(a, b)", B::Subtract, "inside a, outside b"),
    ("smooth_union", "smooth_union(a, b, k)", B::SmoothUnion, "union blended over width k"),
    (
        "smooth_intersect",
        "smooth_intersect(a, b, k)",
        B::SmoothIntersect,
        "intersection blended over width k",
    ),
    ("smooth_subtract", "smooth_subtract(a, b, k)", B::SmoothSubtract, "difference blended over width k"),
    ("shell", "shell(a, t)", B::Shell, "hollow wall of thickness 2t around the surface: |a| − t"),
    ("offset", "offset(a, d)", B::Offset, "grown by d: a − d"),
    ("translate", "translate(shape, dx, dy, dz)", B::Translate, "moved by (dx, dy, dz)"),
    (
        "rotate",
        "rotate(shape, ax, ay, az, degrees)",
        B::Rotate,
        "turned by degrees about the axis (ax, ay, az) through the origin (right-hand rule)",
    ),
    ("scale", "scale(shape, s)", B::Scale, "scaled by s about the origin"),
    ("mirror_x", "mirror_x(shape)", B::MirrorX, "mirrored across x = 0: shape at (|x|, y, z)"),
    ("mirror_y", "mirror_y(shape)", B::MirrorY, "mirrored across y = 0"),
    ("mirror_z", "mirror_z(shape)", B::MirrorZ, "mirrored across z = 0"),
];

impl Builtin {
    pub fn lookup(name: &str) -> Option<Builtin> {
        TABLE.iter().find(|e| e.0 == name).map(|e| e.2)
    }

    pub fn names() -> impl Iterator<Item = &'static str> {
        TABLE.iter().map(|e| e.0)
    }

    fn entry(self) -> &'static (&'static str, &'static str, Builtin, &'static str) {
        // A variant missing from the table could never be parsed; the fallback only avoids a panic.
        TABLE.iter().find(|e| e.2 == self).unwrap_or(&TABLE[0])
    }

    pub fn name(self) -> &'static str {
        self.entry().0
    }

    pub fn signature(self) -> &'static str {
        self.entry().1
    }

    /// What the function is, in a few words.
    pub fn summary(self) -> &'static str {
        self.entry().3
    }

    /// Which part of the language reference it belongs to.
    pub fn group(self) -> &'static str {
        match self {
            B::Sphere | B::Box | B::RoundedBox | B::Cylinder | B::Cone | B::Torus | B::Capsule | B::Plane => {
                "shapes"
            }
            B::Union
            | B::Intersect
            | B::Subtract
            | B::SmoothUnion
            | B::SmoothIntersect
            | B::SmoothSubtract
            | B::Shell
            | B::Offset => "combinators",
            _ if self.is_transform() => "transforms",
            _ => "math",
        }
    }

    /// Every builtin, in the order of the docs.
    pub fn all() -> impl Iterator<Item = Builtin> {
        TABLE.iter().map(|e| e.2)
    }

    pub fn arity(self) -> Arity {
        match self {
            B::Min | B::Max | B::Length | B::Union | B::Intersect => Arity::AtLeast(1),
            // Count the commas in the signature: one table, no second list to keep in step.
            _ => Arity::Exactly(self.signature().matches(',').count() + 1),
        }
    }

    /// Transforms evaluate their first argument at moved coordinates; see the compiler.
    pub fn is_transform(self) -> bool {
        matches!(self, B::Translate | B::Rotate | B::Scale | B::MirrorX | B::MirrorY | B::MirrorZ)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_round_trips_through_its_name() {
        for &(name, _, b, summary) in TABLE {
            assert!(!summary.is_empty());
            assert_eq!(Builtin::lookup(name), Some(b));
            assert_eq!(b.name(), name);
        }
        assert_eq!(Builtin::lookup("banana"), None);
    }

    #[test]
    fn arities_follow_the_signatures() {
        assert_eq!(Builtin::Sphere.arity(), Arity::Exactly(1));
        assert_eq!(Builtin::Capsule.arity(), Arity::Exactly(7));
        assert_eq!(Builtin::Rotate.arity(), Arity::Exactly(5));
        assert_eq!(Builtin::Union.arity(), Arity::AtLeast(1));
        assert!(!Builtin::Subtract.arity().accepts(3));
        assert_eq!(Arity::Exactly(1).to_string(), "1 argument");
        assert_eq!(Arity::AtLeast(2).to_string(), "at least 2 arguments");
    }
}

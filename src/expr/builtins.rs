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

/// Name, signature as shown in errors, and builtin. The order is the order of the docs.
const TABLE: &[(&str, &str, Builtin)] = &[
    ("sin", "sin(a)", B::Sin),
    ("cos", "cos(a)", B::Cos),
    ("tan", "tan(a)", B::Tan),
    ("asin", "asin(a)", B::Asin),
    ("acos", "acos(a)", B::Acos),
    ("atan", "atan(a)", B::Atan),
    ("atan2", "atan2(y, x)", B::Atan2),
    ("exp", "exp(a)", B::Exp),
    ("log", "log(a)", B::Log),
    ("sqrt", "sqrt(a)", B::Sqrt),
    ("abs", "abs(a)", B::Abs),
    ("floor", "floor(a)", B::Floor),
    ("min", "min(a, …)", B::Min),
    ("max", "max(a, …)", B::Max),
    ("pow", "pow(a, b)", B::Pow),
    ("clamp", "clamp(a, lo, hi)", B::Clamp),
    ("mix", "mix(a, b, t)", B::Mix),
    ("length", "length(a, …)", B::Length),
    ("sphere", "sphere(r)", B::Sphere),
    ("box", "box(hx, hy, hz)", B::Box),
    ("rounded_box", "rounded_box(hx, hy, hz, r)", B::RoundedBox),
    ("cylinder", "cylinder(r, h)", B::Cylinder),
    ("cone", "cone(r, h)", B::Cone),
    ("torus", "torus(R, r)", B::Torus),
    ("capsule", "capsule(ax, ay, az, bx, by, bz, r)", B::Capsule),
    ("plane", "plane(nx, ny, nz, d)", B::Plane),
    ("union", "union(a, …)", B::Union),
    ("intersect", "intersect(a, …)", B::Intersect),
    ("subtract", "subtract(a, b)", B::Subtract),
    ("smooth_union", "smooth_union(a, b, k)", B::SmoothUnion),
    ("smooth_intersect", "smooth_intersect(a, b, k)", B::SmoothIntersect),
    ("smooth_subtract", "smooth_subtract(a, b, k)", B::SmoothSubtract),
    ("shell", "shell(a, t)", B::Shell),
    ("offset", "offset(a, d)", B::Offset),
    ("translate", "translate(shape, dx, dy, dz)", B::Translate),
    ("rotate", "rotate(shape, ax, ay, az, degrees)", B::Rotate),
    ("scale", "scale(shape, s)", B::Scale),
    ("mirror_x", "mirror_x(shape)", B::MirrorX),
    ("mirror_y", "mirror_y(shape)", B::MirrorY),
    ("mirror_z", "mirror_z(shape)", B::MirrorZ),
];

impl Builtin {
    pub fn lookup(name: &str) -> Option<Builtin> {
        TABLE.iter().find(|e| e.0 == name).map(|e| e.2)
    }

    pub fn names() -> impl Iterator<Item = &'static str> {
        TABLE.iter().map(|e| e.0)
    }

    fn entry(self) -> &'static (&'static str, &'static str, Builtin) {
        // A variant missing from the table could never be parsed; the fallback only avoids a panic.
        TABLE.iter().find(|e| e.2 == self).unwrap_or(&TABLE[0])
    }

    pub fn name(self) -> &'static str {
        self.entry().0
    }

    pub fn signature(self) -> &'static str {
        self.entry().1
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
        for &(name, _, b) in TABLE {
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

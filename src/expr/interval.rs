//! Interval arithmetic over the tape: for a box of points, a range that contains the value at
//! every point in it. Octrees use it to skip boxes that cannot contain the surface.
//!
//! Guarantees and choices:
//! - Bounds are conservative with respect to the `f32` point evaluator itself, not just the real
//!   function: the arithmetic uses the same `f32` operations on the endpoints (round-to-nearest is
//!   monotone), and results of library functions (`sin`, `exp`, …), which are not correctly
//!   rounded, are widened by a few ulps.
//! - Points where an operation is undefined (`sqrt` or `log` of a negative, `asin(2)`) are left
//!   out: the bounds describe the points where the program is defined. `sqrt([-1, 4])` is `[0, 2]`.
//! - Division by an interval containing zero gives `[-inf, inf]`.
//! - An endpoint is never NaN; a NaN from endpoint arithmetic (`inf - inf`) widens to infinity.
//! - Leaving undefined points out is only sound while their NaN reaches the result, and `min` and
//!   `max` stop it: `f32::max(x, NaN)` is `x`. So each interval also records whether the point
//!   evaluator may produce NaN somewhere in the box ([`Interval::partial`]), and a min/max with a
//!   partial operand covers the other operand alone too (`max(x, sqrt(z) + 1)` over `z` in
//!   `[-1, 1]` is `x` where `z < 0`, not at least 1). Choices never drop a partial operand's
//!   partner for the same reason.

use super::eval::{run, Domain};
use super::ops::{self, BinaryOp, UnaryOp};
use super::tape::Tape;
use glam::Vec3;
use std::f64::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f32,
    pub hi: f32,
    /// Whether the point evaluator may give NaN somewhere in the box (an operation undefined
    /// there: `sqrt` of a negative, `0 * inf`, ...), those points being left out of the bounds.
    /// Conservative: `true` may be wrong, `false` never is.
    pub partial: bool,
}

impl Default for Interval {
    fn default() -> Self {
        Interval::EVERYTHING
    }
}

/// Whether one operand of a min/max decides it everywhere in a box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// The left operand is the result throughout the box; the right one is irrelevant.
    Left,
    /// The right operand is the result throughout the box.
    Right,
    /// Either may win somewhere in the box.
    Both,
}

impl Interval {
    pub const EVERYTHING: Interval = Interval { lo: f32::NEG_INFINITY, hi: f32::INFINITY, partial: false };

    pub fn new(lo: f32, hi: f32) -> Interval {
        Interval {
            lo: if lo.is_nan() { f32::NEG_INFINITY } else { lo },
            hi: if hi.is_nan() { f32::INFINITY } else { hi },
            partial: false,
        }
    }

    pub fn point(v: f32) -> Interval {
        Interval::new(v, v)
    }

    #[cfg(test)]
    pub fn contains(self, v: f32) -> bool {
        self.lo <= v && v <= self.hi
    }

    fn contains_zero(self) -> bool {
        self.lo <= 0.0 && self.hi >= 0.0
    }

    fn reaches_infinity(self) -> bool {
        !(self.lo.is_finite() && self.hi.is_finite())
    }

    /// The smallest interval holding both (flags aside).
    fn union(self, o: Interval) -> Interval {
        Interval::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }

    /// Applies a non-decreasing function to both ends.
    fn increasing(self, f: impl Fn(f32) -> f32) -> Interval {
        Interval::new(f(self.lo), f(self.hi))
    }

    /// Moves each end outward by `ulps` units in the last place.
    fn widen(self, ulps: u32) -> Interval {
        Interval::new(step(self.lo, ulps, false), step(self.hi, ulps, true))
    }

    fn hull(values: &[f32]) -> Interval {
        // NaN corners are skipped: they are points where the operation is undefined.
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for &v in values {
            if !v.is_nan() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if lo > hi {
            Interval::EVERYTHING
        } else {
            Interval::new(lo, hi)
        }
    }

    fn mul(self, o: Interval) -> Interval {
        // 0 * inf is NaN, but no finite point value multiplies to NaN there: count it as 0.
        let m = |a: f32, b: f32| {
            let p = a * b;
            if p.is_nan() {
                0.0
            } else {
                p
            }
        };
        Interval::hull(&[m(self.lo, o.lo), m(self.lo, o.hi), m(self.hi, o.lo), m(self.hi, o.hi)])
    }

    fn div(self, o: Interval) -> Interval {
        if o.contains_zero() {
            return Interval::EVERYTHING;
        }
        Interval::hull(&[self.lo / o.lo, self.lo / o.hi, self.hi / o.lo, self.hi / o.hi])
    }

    fn powi(self, n: i32) -> Interval {
        if n == 0 {
            return Interval::point(1.0);
        }
        let m = n.unsigned_abs() as i32;
        let p = |v: f32| ops::powi(v, m);
        let positive = if m % 2 == 1 || self.lo >= 0.0 {
            self.increasing(p)
        } else if self.hi <= 0.0 {
            Interval::new(p(self.hi), p(self.lo))
        } else {
            Interval::new(0.0, p(self.lo).max(p(self.hi)))
        };
        if n > 0 {
            positive
        } else {
            Interval::point(1.0).div(positive)
        }
    }

    /// `sin` or `cos`, whose maxima sit at `max_at + 2kπ` and minima half a period later.
    fn periodic(self, f: impl Fn(f32) -> f32, max_at: f64) -> Interval {
        let (lo, hi) = (self.lo as f64, self.hi as f64);
        // (The width is NaN only for an infinite point, where anything goes too.)
        if (hi - lo).is_nan() || hi - lo >= 2.0 * PI {
            return Interval::new(-1.0, 1.0);
        }
        let has = |peak: f64| {
            // Is there a k with lo <= peak + 2kπ <= hi? A little slack keeps it conservative.
            let k = ((lo - peak) / (2.0 * PI)).ceil();
            peak + 2.0 * PI * k <= hi + 1e-9 * (1.0 + hi.abs())
                || peak + 2.0 * PI * (k - 1.0) >= lo - 1e-9 * (1.0 + lo.abs())
        };
        let ends = Interval::hull(&[f(self.lo), f(self.hi)]).widen(2);
        let top = if has(max_at) { 1.0 } else { ends.hi.min(1.0) };
        let bottom = if has(max_at + PI) { -1.0 } else { ends.lo.max(-1.0) };
        Interval::new(bottom, top)
    }

    fn tan(self) -> Interval {
        let (lo, hi) = (self.lo as f64, self.hi as f64);
        if (hi - lo).is_nan() || hi - lo >= PI {
            return Interval::EVERYTHING;
        }
        // The pole after lo; with slack, because f32 inputs near a pole round unpredictably.
        let k = ((lo - PI / 2.0) / PI).ceil();
        let pole = PI / 2.0 + PI * k;
        if pole <= hi + 1e-6 * (1.0 + hi.abs()) || pole - PI >= lo - 1e-6 * (1.0 + lo.abs()) {
            return Interval::EVERYTHING;
        }
        self.increasing(f32::tan).widen(2)
    }

    fn pow(self, e: Interval) -> Interval {
        let constant_fraction = e.lo == e.hi && e.lo.fract() != 0.0;
        // -0 counts as negative: (-0)^-1 is -inf (found by the expr_parse fuzz target).
        if self.lo.is_sign_negative() && !constant_fraction {
            // A negative base to an integer power is defined, and its sign flips: give up.
            return Interval::EVERYTHING;
        }
        // On a >= 0 the extremes of a^b are at the corners (no interior critical points).
        let a = Interval::new(self.lo.max(0.0), self.hi.max(0.0));
        // Negative bases to a fractional power are NaN, except -inf: (-inf)^(1/3) is +inf and
        // (-inf)^(-1/3) is +0 (found by the expr_parse fuzz target).
        let from_minus_infinity = if self.lo == f32::NEG_INFINITY { self.lo.powf(e.lo) } else { f32::NAN };
        let c = [a.lo.powf(e.lo), a.lo.powf(e.hi), a.hi.powf(e.lo), a.hi.powf(e.hi), from_minus_infinity];
        Interval::hull(&c).widen(2)
    }

    fn atan2(y: Interval, x: Interval) -> Interval {
        // atan2 jumps across the negative x axis (and is undefined at the origin). A box missing
        // both is a region where it is continuous without critical points: the corners bound it.
        if x.lo <= 0.0 && y.contains_zero() {
            return Interval::new(-std::f32::consts::PI, std::f32::consts::PI).widen(2);
        }
        Interval::hull(&[y.lo.atan2(x.lo), y.lo.atan2(x.hi), y.hi.atan2(x.lo), y.hi.atan2(x.hi)]).widen(2)
    }
}

fn step(v: f32, ulps: u32, up: bool) -> f32 {
    if !v.is_finite() {
        return v;
    }
    let mut v = v;
    for _ in 0..ulps {
        v = next(v, up);
    }
    v
}

/// The neighbouring float towards +inf (`up`) or -inf. (`f32::next_up` needs Rust 1.86.)
fn next(v: f32, up: bool) -> f32 {
    if v == 0.0 {
        let tiny = f32::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let bits = v.to_bits();
    let away_from_zero = (v > 0.0) == up;
    f32::from_bits(if away_from_zero { bits + 1 } else { bits - 1 })
}

/// Can `op` give NaN at a point of `a` (itself defined there)?
fn unary_may_be_undefined(op: UnaryOp, a: Interval) -> bool {
    match op {
        UnaryOp::Sqrt | UnaryOp::Ln => a.lo < 0.0,
        UnaryOp::Asin | UnaryOp::Acos => a.lo < -1.0 || a.hi > 1.0,
        UnaryOp::Sin | UnaryOp::Cos | UnaryOp::Tan => a.reaches_infinity(),
        UnaryOp::Neg
        | UnaryOp::Abs
        | UnaryOp::Atan
        | UnaryOp::Exp
        | UnaryOp::Floor
        | UnaryOp::Sign
        | UnaryOp::Powi(_) => false,
    }
}

/// Can `op` give NaN at a pair of points of `a` and `b` (both defined there)? Min and max never
/// do unless both operands are NaN (see [`Interval::partial`]).
fn binary_may_be_undefined(op: BinaryOp, a: Interval, b: Interval) -> bool {
    let inf = f32::INFINITY;
    match op {
        BinaryOp::Add => (a.hi == inf && b.lo == -inf) || (a.lo == -inf && b.hi == inf),
        BinaryOp::Sub => (a.hi == inf && b.hi == inf) || (a.lo == -inf && b.lo == -inf),
        BinaryOp::Mul => {
            (a.contains_zero() && b.reaches_infinity()) || (b.contains_zero() && a.reaches_infinity())
        }
        BinaryOp::Div => {
            (a.contains_zero() && b.contains_zero()) || (a.reaches_infinity() && b.reaches_infinity())
        }
        // A negative base to a fractional power.
        BinaryOp::Pow => a.lo < 0.0,
        BinaryOp::Min | BinaryOp::Max | BinaryOp::Atan2 => false,
    }
}

impl Domain for Interval {
    fn constant(c: f32) -> Interval {
        // A NaN constant (`0/0` folded) is undefined everywhere: its bounds are everything, and
        // min/max must still know that they return the other operand there.
        Interval { partial: c.is_nan(), ..Interval::point(c) }
    }

    fn unary(op: UnaryOp, a: Interval) -> Interval {
        let partial = a.partial || unary_may_be_undefined(op, a);
        Interval { partial, ..unary_bounds(op, a) }
    }

    fn binary(op: BinaryOp, a: Interval, b: Interval) -> Interval {
        let bounds = binary_bounds(op, a, b);
        if matches!(op, BinaryOp::Min | BinaryOp::Max) {
            // Where one operand is NaN, f32::min and f32::max return the other one as it is.
            let mut r = bounds;
            if a.partial {
                r = r.union(b);
            }
            if b.partial {
                r = r.union(a);
            }
            return Interval { partial: a.partial && b.partial, ..r };
        }
        let partial = a.partial || b.partial || binary_may_be_undefined(op, a, b);
        Interval { partial, ..bounds }
    }
}

/// The bounds of `op` over `a` at the points where both are defined (flags not set).
fn unary_bounds(op: UnaryOp, a: Interval) -> Interval {
    match op {
        UnaryOp::Neg => Interval::new(-a.hi, -a.lo),
        UnaryOp::Abs => {
            if a.lo >= 0.0 {
                a
            } else if a.hi <= 0.0 {
                Interval::new(-a.hi, -a.lo)
            } else {
                Interval::new(0.0, (-a.lo).max(a.hi))
            }
        }
        UnaryOp::Sqrt => Interval::new(a.lo.max(0.0), a.hi.max(0.0)).increasing(f32::sqrt),
        UnaryOp::Sin => a.periodic(f32::sin, PI / 2.0),
        UnaryOp::Cos => a.periodic(f32::cos, 0.0),
        UnaryOp::Tan => a.tan(),
        UnaryOp::Asin => Interval::new(a.lo.max(-1.0), a.hi.min(1.0)).increasing(f32::asin).widen(2),
        UnaryOp::Acos => {
            let c = Interval::new(a.lo.max(-1.0), a.hi.min(1.0));
            Interval::new(c.hi.acos(), c.lo.acos()).widen(2)
        }
        UnaryOp::Atan => a.increasing(f32::atan).widen(2),
        UnaryOp::Exp => a.increasing(f32::exp).widen(2),
        UnaryOp::Ln => Interval::new(a.lo.max(0.0), a.hi.max(0.0)).increasing(f32::ln).widen(2),
        UnaryOp::Floor => a.increasing(f32::floor),
        UnaryOp::Sign => a.increasing(ops::sign),
        UnaryOp::Powi(n) => a.powi(n),
    }
}

/// The bounds of `op` over `a` and `b` at the points where all are defined (flags not set).
fn binary_bounds(op: BinaryOp, a: Interval, b: Interval) -> Interval {
    match op {
        BinaryOp::Add => Interval::new(a.lo + b.lo, a.hi + b.hi),
        BinaryOp::Sub => Interval::new(a.lo - b.hi, a.hi - b.lo),
        BinaryOp::Mul => a.mul(b),
        BinaryOp::Div => a.div(b),
        BinaryOp::Min => Interval::new(a.lo.min(b.lo), a.hi.min(b.hi)),
        BinaryOp::Max => Interval::new(a.lo.max(b.lo), a.hi.max(b.hi)),
        BinaryOp::Pow => a.pow(b),
        BinaryOp::Atan2 => Interval::atan2(a, b),
    }
}

/// The box with corners `lo` and `hi` (in either order per axis).
fn inputs(lo: Vec3, hi: Vec3) -> [Interval; 3] {
    let (a, b) = (lo.min(hi), lo.max(hi));
    [0, 1, 2].map(|i| Interval::new(a[i], b[i]))
}

pub fn eval_interval(tape: &Tape, lo: Vec3, hi: Vec3) -> Interval {
    run(tape, inputs(lo, hi), |_, _, _| {})
}

/// Bounds, plus one [`Choice`] per min/max instruction in tape order.
pub fn eval_interval_with_choices(tape: &Tape, lo: Vec3, hi: Vec3) -> (Interval, Vec<Choice>) {
    let mut choices = Vec::with_capacity(tape.choice_count());
    let r = run(tape, inputs(lo, hi), |op, a: Interval, b: Interval| {
        let (left_wins, right_wins) = match op {
            BinaryOp::Min => (a.hi < b.lo, b.hi < a.lo),
            BinaryOp::Max => (a.lo > b.hi, b.lo > a.hi),
            _ => return,
        };
        // Where the winner is NaN the min/max returns the loser: a partial winner cannot stand in.
        let (left_wins, right_wins) = (left_wins && !a.partial, right_wins && !b.partial);
        choices.push(if left_wins {
            Choice::Left
        } else if right_wins {
            Choice::Right
        } else {
            Choice::Both
        });
    });
    (r, choices)
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use super::super::testutil::{Rng, CASES};
    use super::*;

    /// A random box: anywhere in the test cube, from tiny to most of the cube.
    fn random_box(rng: &mut Rng) -> (Vec3, Vec3) {
        let c = rng.vec3(-1.5, 1.5);
        let h = Vec3::new(rng.range(-3.0, 0.0), rng.range(-3.0, 0.0), rng.range(-3.0, 0.0))
            .map(|e| 10f32.powf(e));
        (c - h, c + h)
    }

    fn sample(rng: &mut Rng, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * Vec3::new(rng.range(0.0, 1.0), rng.range(0.0, 1.0), rng.range(0.0, 1.0))
    }

    #[test]
    fn bounds_contain_every_sampled_value_for_every_case() {
        let mut rng = Rng::new(10);
        for case in CASES {
            let program = compile(case).unwrap();
            let mut finite = 0;
            for _ in 0..60 {
                let (lo, hi) = random_box(&mut rng);
                let (a, b) = program.eval_interval(lo, hi);
                assert!(a <= b, "{case}: empty bounds [{a}, {b}]");
                finite += usize::from(a.is_finite() && b.is_finite());
                let corners = (0..8)
                    .map(|i| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo));
                let inside: Vec<Vec3> = (0..40).map(|_| sample(&mut rng, lo, hi)).collect();
                for p in corners.chain(inside) {
                    let v = program.eval(p);
                    assert!(
                        v.is_nan() || (a <= v && v <= b),
                        "{case}: {v} at {p} outside [{a}, {b}] for box {lo}..{hi}"
                    );
                }
            }
            assert!(finite > 20, "{case}: bounds were almost always infinite, which proves nothing");
        }
    }

    #[test]
    fn every_operation_bounds_its_values_on_random_intervals() {
        let unary = [
            UnaryOp::Neg,
            UnaryOp::Abs,
            UnaryOp::Sqrt,
            UnaryOp::Sin,
            UnaryOp::Cos,
            UnaryOp::Tan,
            UnaryOp::Asin,
            UnaryOp::Acos,
            UnaryOp::Atan,
            UnaryOp::Exp,
            UnaryOp::Ln,
            UnaryOp::Floor,
            UnaryOp::Sign,
            UnaryOp::Powi(2),
            UnaryOp::Powi(3),
            UnaryOp::Powi(-2),
            UnaryOp::Powi(-3),
        ];
        let binary = [
            BinaryOp::Add,
            BinaryOp::Sub,
            BinaryOp::Mul,
            BinaryOp::Div,
            BinaryOp::Min,
            BinaryOp::Max,
            BinaryOp::Pow,
            BinaryOp::Atan2,
        ];
        let mut rng = Rng::new(11);
        let interval = |rng: &mut Rng| {
            let c = rng.range(-20.0, 20.0) * if rng.below(2) == 0 { 1.0 } else { 0.05 };
            let w = 10f32.powf(rng.range(-4.0, 1.0));
            if rng.below(8) == 0 {
                Interval::point(c)
            } else {
                Interval::new(c - w, c + w)
            }
        };
        let inside = |rng: &mut Rng, i: Interval| i.lo + (i.hi - i.lo) * rng.range(0.0, 1.0);
        for _ in 0..3000 {
            let (a, b) = (interval(&mut rng), interval(&mut rng));
            for op in unary {
                let r = Interval::unary(op, a);
                for _ in 0..20 {
                    let x = inside(&mut rng, a);
                    let v = ops::unary(op, x);
                    assert!(v.is_nan() || r.contains(v), "{op}({x}) = {v} outside {r:?} for {a:?}");
                }
            }
            for op in binary {
                let r = Interval::binary(op, a, b);
                for _ in 0..20 {
                    let (x, y) = (inside(&mut rng, a), inside(&mut rng, b));
                    let v = ops::binary(op, x, y);
                    assert!(
                        v.is_nan() || r.contains(v),
                        "{}({x}, {y}) = {v} outside {r:?} for {a:?}, {b:?}",
                        op.name()
                    );
                }
            }
        }
    }

    #[test]
    fn special_cases_are_tight_where_they_can_be() {
        let i = Interval::new;
        let u = Interval::unary;
        let pi = std::f32::consts::PI;
        let root = u(UnaryOp::Sqrt, i(-1.0, 4.0));
        assert_eq!((root.lo, root.hi), (0.0, 2.0), "the undefined part is dropped");
        assert!(root.partial && !u(UnaryOp::Sqrt, i(0.0, 4.0)).partial, "and flagged");
        assert_eq!(Interval::binary(BinaryOp::Div, i(1.0, 2.0), i(-1.0, 1.0)), Interval::EVERYTHING);
        assert_eq!(u(UnaryOp::Powi(2), i(-3.0, 2.0)), i(0.0, 9.0));
        assert_eq!(u(UnaryOp::Tan, i(1.0, 2.0)), Interval::EVERYTHING, "a pole at π/2");
        let s = u(UnaryOp::Sin, i(0.1, 0.2));
        assert!(s.lo > 0.09 && s.hi < 0.2, "no extremum inside: {s:?}");
        // A maximum of sin far out, at π/2 + 20π.
        let far = 0.5 * pi + 20.0 * pi;
        assert_eq!(u(UnaryOp::Sin, i(far - 0.1, far + 0.1)).hi, 1.0);
        assert!(u(UnaryOp::Sin, i(far - 0.1, far + 0.1)).lo > 0.99);
        assert_eq!(u(UnaryOp::Cos, i(pi - 0.1, pi + 0.1)).lo, -1.0);
        assert!(u(UnaryOp::Cos, i(-0.1, 0.1)).lo > 0.99);
        assert_eq!(u(UnaryOp::Cos, i(0.0, 7.0)), i(-1.0, 1.0));
        assert_eq!(u(UnaryOp::Ln, i(-1.0, 0.0)).hi, f32::NEG_INFINITY);
        assert_eq!(
            Interval::binary(BinaryOp::Sub, i(f32::NEG_INFINITY, 0.0), i(f32::NEG_INFINITY, 0.0)).hi,
            f32::INFINITY
        );
    }

    /// Found by the `expr_parse` fuzz target: `f32::max(x, NaN)` is `x`, so bounds that leave out
    /// the undefined half of `sqrt(z)` must not claim `max(x, sqrt(z) + 1) >= 1` (DMC's octree
    /// culled the whole box and meshed nothing).
    #[test]
    fn min_and_max_cover_the_other_operand_where_one_is_undefined() {
        let (lo, hi) = (Vec3::splat(-1.0), Vec3::ONE);
        let texts = [
            "max(x, sqrt(z) + 1)",
            "min(x, -sqrt(z) - 1)",
            "max(x, z^-0.3)",
            "max(x, 0 * exp(1000 + y))",
            // A NaN constant, through an operation that narrows everything to [0, inf].
            "max(abs(0/-0*y), x)",
            // Not undefined but signed: (-0)^-1 is -inf.
            "(-0)^x",
            // 0^-1 is inf, so the base of the root reaches -inf, whose cube root is +inf.
            "max((z - 0^x)^(1/3), x)",
        ];
        for text in texts {
            let program = compile(text).unwrap();
            let (a, b) = program.eval_interval(lo, hi);
            for p in [Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0)] {
                let v = program.eval(p);
                assert!(!v.is_nan() && a <= v && v <= b, "{text}: {v} at {p} outside [{a}, {b}]");
            }
        }
        // An operand that wins on its bounds but is undefined somewhere is no choice: where
        // sqrt(z) is NaN, max gives x.
        let program = compile("max(sqrt(z) + 2, x)").unwrap();
        let (_, choices) = program.eval_interval_with_choices(lo, hi);
        assert_eq!(choices, vec![Choice::Both]);
        // Both undefined somewhere: the result may be NaN, and is still bounded where it is not.
        let root = Interval::unary(UnaryOp::Sqrt, Interval::new(-1.0, 4.0));
        let log = Interval::unary(UnaryOp::Ln, Interval::new(-1.0, 1.0));
        let both = Interval::binary(BinaryOp::Max, root, log);
        assert!(both.partial && both.lo == f32::NEG_INFINITY && both.hi == 2.0, "{both:?}");
    }

    #[test]
    fn choices_name_the_branch_that_wins_and_simplify_keeps_values() {
        let program =
            compile("union(translate(sphere(0.5), -1, 0, 0), translate(box(0.4, 0.4, 0.4), 1, 0, 0))")
                .unwrap();
        assert_eq!(program.choice_count(), 7, "{program}"); // the union and six in the box
        let near_sphere = (Vec3::new(-1.2, -0.2, -0.2), Vec3::new(-0.8, 0.2, 0.2));
        let (_, choices) = program.eval_interval_with_choices(near_sphere.0, near_sphere.1);
        let union_choice = *choices.last().unwrap();
        assert_eq!(union_choice, Choice::Left);
        let lean = program.simplify(&choices);
        assert!(lean.instruction_count() < program.instruction_count() / 2, "{lean}");
        let (_, choices) = program.eval_interval_with_choices(Vec3::splat(-2.0), Vec3::splat(2.0));
        assert_eq!(*choices.last().unwrap(), Choice::Both);

        let mut rng = Rng::new(12);
        for case in CASES {
            let program = compile(case).unwrap();
            for _ in 0..30 {
                let (lo, hi) = random_box(&mut rng);
                let (_, choices) = program.eval_interval_with_choices(lo, hi);
                assert_eq!(choices.len(), program.choice_count());
                let lean = program.simplify(&choices);
                assert!(lean.instruction_count() <= program.instruction_count());
                for _ in 0..20 {
                    let p = sample(&mut rng, lo, hi);
                    let (a, b) = (program.eval(p), lean.eval(p));
                    assert!(a == b || (a.is_nan() && b.is_nan()), "{case} at {p}: {a} vs simplified {b}");
                }
            }
        }
    }
}

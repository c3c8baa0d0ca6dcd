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

use super::eval::{run, Domain};
use super::ops::{self, BinaryOp, UnaryOp};
use super::tape::Tape;
use glam::Vec3;
use std::f64::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f32,
    pub hi: f32,
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
    pub const EVERYTHING: Interval = Interval { lo: f32::NEG_INFINITY, hi: f32::INFINITY };

    pub fn new(lo: f32, hi: f32) -> Interval {
        Interval { lo: if lo.is_nan() { f32::NEG_INFINITY } else { lo }, hi: if hi.is_nan() { f32::INFINITY } else { hi } }
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
        if !(hi - lo < 2.0 * PI) {
            return Interval::new(-1.0, 1.0);
        }
        let has = |peak: f64| {
            // Is there a k with lo <= peak + 2kπ <= hi? A little slack keeps it conservative.
            let k = ((lo - peak) / (2.0 * PI)).ceil();
            peak + 2.0 * PI * k <= hi + 1e-9 * (1.0 + hi.abs()) || peak + 2.0 * PI * (k - 1.0) >= lo - 1e-9 * (1.0 + lo.abs())
        };
        let ends = Interval::hull(&[f(self.lo), f(self.hi)]).widen(2);
        let top = if has(max_at) { 1.0 } else { ends.hi.min(1.0) };
        let bottom = if has(max_at + PI) { -1.0 } else { ends.lo.max(-1.0) };
        Interval::new(bottom, top)
    }

    fn tan(self) -> Interval {
        let (lo, hi) = (self.lo as f64, self.hi as f64);
        if !(hi - lo < PI) {
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
        if self.lo < 0.0 && !constant_fraction {
            // A negative base to an integer power is defined, and its sign flips: give up.
            return Interval::EVERYTHING;
        }
        // On a >= 0 the extremes of a^b are at the corners (no interior critical points).
        let a = Interval::new(self.lo.max(0.0), self.hi.max(0.0));
        let c = [a.lo.powf(e.lo), a.lo.powf(e.hi), a.hi.powf(e.lo), a.hi.powf(e.hi)];
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

impl Domain for Interval {
    fn constant(c: f32) -> Interval {
        Interval::point(c)
    }

    fn unary(op: UnaryOp, a: Interval) -> Interval {
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

    fn binary(op: BinaryOp, a: Interval, b: Interval) -> Interval {
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
            BinaryOp::Min => (a.hi <= b.lo, b.hi < a.lo),
            BinaryOp::Max => (a.lo >= b.hi, b.lo > a.hi),
            _ => return,
        };
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

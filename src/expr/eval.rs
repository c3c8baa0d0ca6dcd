//! Running a [`Tape`] at single points: one generic interpreter for plain values, values with
//! gradients and intervals (the column interpreters for many points are in
//! [`super::columns`]).
//!
//! Everything is `f32`, like the [`crate::field::Field`] trait: meshing never needs more, and the
//! gradient tests pass against central differences at f32 precision.
//!
//! Derivative conventions where the derivative does not exist (forward mode, exact elsewhere):
//! - `min`/`max` pass on the gradient of the branch whose value was taken; the left one on a tie.
//! - `abs` uses the sign of its argument, taking `+` at zero.
//! - `sqrt` at zero gives a zero derivative (the centre of a sphere has no outward direction),
//!   and so does `atan2` at the origin.
//! - `floor` and the internal `sign` have zero derivative everywhere.

use super::ops::{self, BinaryOp, UnaryOp};
use super::tape::{Instr, Tape};
use glam::{Vec3, Vec3A};

/// A number system the tape can run in.
pub trait Domain: Copy + Default {
    fn constant(c: f32) -> Self;
    fn unary(op: UnaryOp, a: Self) -> Self;
    fn binary(op: BinaryOp, a: Self, b: Self) -> Self;
}

impl Domain for f32 {
    fn constant(c: f32) -> f32 {
        c
    }
    #[inline(always)]
    fn unary(op: UnaryOp, a: f32) -> f32 {
        ops::unary(op, a)
    }
    #[inline(always)]
    fn binary(op: BinaryOp, a: f32, b: f32) -> f32 {
        ops::binary(op, a, b)
    }
}

/// Runs the tape once. `observe` sees the operands of every binary instruction (the interval
/// mode uses it to record min/max choices; elsewhere it compiles away).
pub fn run<D: Domain>(tape: &Tape, inputs: [D; 3], mut observe: impl FnMut(BinaryOp, D, D)) -> D {
    const STACK_SLOTS: usize = 48;
    let mut go = |slots: &mut [D]| {
        for (s, &c) in slots.iter_mut().zip(&tape.consts) {
            *s = D::constant(c);
        }
        for (axis, input) in tape.inputs.iter().enumerate() {
            if let Some(s) = input {
                slots[*s as usize] = inputs[axis];
            }
        }
        for instr in &tape.instrs {
            match *instr {
                Instr::Unary { op, out, a } => slots[out as usize] = unary_by_op(op, slots[a as usize]),
                Instr::Binary { op, out, a, b } => {
                    let (x, y) = (slots[a as usize], slots[b as usize]);
                    observe(op, x, y);
                    slots[out as usize] = binary_by_op(op, x, y);
                }
            }
        }
        slots[tape.output as usize]
    };
    // Small programs (most) need no allocation per point.
    if tape.slot_count <= STACK_SLOTS {
        go(&mut [D::default(); STACK_SLOTS])
    } else {
        go(&mut vec![D::default(); tape.slot_count])
    }
}

/// `D::binary(op, x, y)` with one arm per operation, each calling it with its operation as a
/// constant: with `D::binary` and [`ops::binary`] inlined into every arm, each arm is that
/// operation's code alone, and a point's run takes one jump per instruction instead of one per
/// `match` on the operation it passes through (the value's, then the derivative's).
#[inline(always)]
fn binary_by_op<D: Domain>(op: BinaryOp, x: D, y: D) -> D {
    match op {
        BinaryOp::Add => D::binary(BinaryOp::Add, x, y),
        BinaryOp::Sub => D::binary(BinaryOp::Sub, x, y),
        BinaryOp::Mul => D::binary(BinaryOp::Mul, x, y),
        BinaryOp::Div => D::binary(BinaryOp::Div, x, y),
        BinaryOp::Min => D::binary(BinaryOp::Min, x, y),
        BinaryOp::Max => D::binary(BinaryOp::Max, x, y),
        BinaryOp::Pow => D::binary(BinaryOp::Pow, x, y),
        BinaryOp::Atan2 => D::binary(BinaryOp::Atan2, x, y),
    }
}

/// [`binary_by_op`] for unary operations.
#[inline(always)]
fn unary_by_op<D: Domain>(op: UnaryOp, x: D) -> D {
    match op {
        UnaryOp::Neg => D::unary(UnaryOp::Neg, x),
        UnaryOp::Abs => D::unary(UnaryOp::Abs, x),
        UnaryOp::Sqrt => D::unary(UnaryOp::Sqrt, x),
        UnaryOp::Sin => D::unary(UnaryOp::Sin, x),
        UnaryOp::Cos => D::unary(UnaryOp::Cos, x),
        UnaryOp::Tan => D::unary(UnaryOp::Tan, x),
        UnaryOp::Asin => D::unary(UnaryOp::Asin, x),
        UnaryOp::Acos => D::unary(UnaryOp::Acos, x),
        UnaryOp::Atan => D::unary(UnaryOp::Atan, x),
        UnaryOp::Exp => D::unary(UnaryOp::Exp, x),
        UnaryOp::Ln => D::unary(UnaryOp::Ln, x),
        UnaryOp::Floor => D::unary(UnaryOp::Floor, x),
        UnaryOp::Sign => D::unary(UnaryOp::Sign, x),
        UnaryOp::Powi(n) => D::unary(UnaryOp::Powi(n), x),
    }
}

/// The derivative of unary `op` at `x`, where its value is `v`: every dual evaluator (points and
/// columns) scales the gradient by this one, so they agree bit for bit.
#[inline(always)]
pub(super) fn unary_slope(op: UnaryOp, x: f32, v: f32) -> f32 {
    match op {
        UnaryOp::Neg => -1.0,
        UnaryOp::Abs => {
            if x < 0.0 {
                -1.0
            } else {
                1.0
            }
        }
        UnaryOp::Sqrt => {
            if v > 0.0 {
                0.5 / v
            } else {
                0.0
            }
        }
        UnaryOp::Sin => x.cos(),
        UnaryOp::Cos => -x.sin(),
        UnaryOp::Tan => 1.0 + v * v,
        UnaryOp::Asin => 1.0 / (1.0 - x * x).sqrt(),
        UnaryOp::Acos => -1.0 / (1.0 - x * x).sqrt(),
        UnaryOp::Atan => 1.0 / (1.0 + x * x),
        UnaryOp::Exp => v,
        UnaryOp::Ln => 1.0 / x,
        UnaryOp::Floor | UnaryOp::Sign => 0.0,
        UnaryOp::Powi(0) => 0.0,
        UnaryOp::Powi(n) => n as f32 * ops::powi(x, n - 1),
    }
}

/// A value with its gradient with respect to (x, y, z).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Dual {
    pub v: f32,
    /// Four lanes wide (`Vec3A`), so that the gradient's arithmetic is one vector operation on
    /// SSE2 and wasm's simd128 instead of three scalar ones.
    pub d: Vec3A,
}

impl Dual {
    pub fn input(v: f32, axis: usize) -> Dual {
        let mut d = Vec3A::ZERO;
        d[axis] = 1.0;
        Dual { v, d }
    }
}

impl Domain for Dual {
    fn constant(c: f32) -> Dual {
        Dual { v: c, d: Vec3A::ZERO }
    }

    #[inline(always)]
    fn unary(op: UnaryOp, a: Dual) -> Dual {
        let v = ops::unary(op, a.v);
        Dual { v, d: a.d * unary_slope(op, a.v, v) }
    }

    #[inline(always)]
    fn binary(op: BinaryOp, a: Dual, b: Dual) -> Dual {
        let v = ops::binary(op, a.v, b.v);
        let d = match op {
            BinaryOp::Add => a.d + b.d,
            BinaryOp::Sub => a.d - b.d,
            BinaryOp::Mul => a.d * b.v + b.d * a.v,
            BinaryOp::Div => (a.d - b.d * v) / b.v,
            // The value tells which branch was taken (NaN operands included, as f32::min decides).
            BinaryOp::Min | BinaryOp::Max => {
                if v == a.v {
                    a.d
                } else {
                    b.d
                }
            }
            BinaryOp::Pow => {
                let base = a.d * (b.v * a.v.powf(b.v - 1.0));
                // Skip the ln term for a constant exponent: ln of a negative base is NaN.
                if b.d == Vec3A::ZERO {
                    base
                } else {
                    base + b.d * (v * a.v.ln())
                }
            }
            BinaryOp::Atan2 => {
                let (y, x) = (a, b);
                let r2 = x.v * x.v + y.v * y.v;
                if r2 > 0.0 {
                    (y.d * x.v - x.d * y.v) / r2
                } else {
                    Vec3A::ZERO
                }
            }
        };
        Dual { v, d }
    }
}

pub fn eval_point(tape: &Tape, p: Vec3) -> f32 {
    run(tape, p.to_array(), |_, _, _| {})
}

pub fn eval_gradient(tape: &Tape, p: Vec3) -> (f32, Vec3) {
    let r = run(tape, [0, 1, 2].map(|i| Dual::input(p[i], i)), |_, _, _| {});
    (r.v, r.d.into())
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use super::super::testutil::{central_difference, Rng, CASES};
    use glam::Vec3;

    #[test]
    fn gradients_match_central_differences_for_every_case() {
        let mut rng = Rng::new(1);
        for case in CASES {
            let program = compile(case).unwrap();
            let f = |p: Vec3| program.eval(p);
            let (mut checked, mut total) = (0, 0);
            for _ in 0..200 {
                let p = rng.vec3(-1.2, 1.2);
                total += 1;
                let (coarse, fine) = (central_difference(f, p, 2e-3), central_difference(f, p, 1e-3));
                // Two step sizes disagreeing means a kink or jump within reach: no derivative to compare.
                if !coarse.is_finite() || (coarse - fine).length() > 3e-3 * (1.0 + fine.length()) {
                    continue;
                }
                let (_, g) = program.eval_grad(p);
                assert!(
                    (g - fine).length() <= 5e-3 * (1.0 + fine.length()),
                    "{case} at {p}: exact {g}, finite differences {fine}"
                );
                checked += 1;
            }
            assert!(
                checked * 10 >= total * 7,
                "{case}: only {checked} of {total} points were away from kinks"
            );
        }
    }

    #[test]
    fn gradient_mode_computes_the_same_value() {
        let mut rng = Rng::new(2);
        for case in CASES {
            let program = compile(case).unwrap();
            for _ in 0..50 {
                let p = rng.vec3(-1.5, 1.5);
                let (a, b) = (program.eval(p), program.eval_grad(p).0);
                assert!(a == b || (a.is_nan() && b.is_nan()), "{case} at {p}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn exact_distances_have_unit_gradients() {
        let exact = [
            "sphere(0.8)",
            "box(0.5, 0.4, 0.3)",
            "rounded_box(0.5, 0.4, 0.3, 0.1)",
            "cylinder(0.4, 0.6)",
            "cone(0.5, 0.8)",
            "cone(1.2, 0.3)",
            "torus(0.6, 0.2)",
            "capsule(-0.3, 0, 0.1, 0.3, 0.2, -0.1, 0.2)",
            "plane(1, 2, 3, 0.1)",
            "rotate(translate(cone(0.4, 0.9), 0.1, 0.2, -0.3), 1, 2, 3, 33)",
            "scale(box(0.2, 0.3, 0.4), 2.5)",
            "mirror_y(translate(cylinder(0.2, 0.3), 0, 0.4, 0))",
        ];
        let mut rng = Rng::new(4);
        for case in exact {
            let program = compile(case).unwrap();
            let mut nonzero = 0;
            for _ in 0..300 {
                let (_, g) = program.eval_grad(rng.vec3(-1.5, 1.5));
                if g == Vec3::ZERO {
                    continue; // on a medial axis with a sqrt(0): no direction, by convention
                }
                nonzero += 1;
                assert!((g.length() - 1.0).abs() < 1e-4, "{case}: |gradient| = {}", g.length());
            }
            assert!(nonzero > 290, "{case}: {nonzero}");
        }
    }

    #[test]
    fn kink_conventions_are_as_documented() {
        let at = |src: &str, p: Vec3| compile(src).unwrap().eval_grad(p).1;
        assert_eq!(at("min(x, y)", Vec3::ZERO), Vec3::X, "left branch on a tie");
        assert_eq!(at("max(2 * y, x)", Vec3::ZERO), Vec3::Y * 2.0);
        assert_eq!(at("abs(x)", Vec3::ZERO), Vec3::X, "abs takes + at zero");
        assert_eq!(at("sphere(1)", Vec3::ZERO), Vec3::ZERO, "no direction at the centre");
        assert_eq!(at("atan2(y, x)", Vec3::ZERO), Vec3::ZERO);
        assert_eq!(at("floor(5 * x)", Vec3::new(0.3, 0.0, 0.0)), Vec3::ZERO);
    }
}

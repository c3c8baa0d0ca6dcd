//! Running a [`Tape`] over many points: each instruction runs over a column of 64 points at once,
//! so the per-instruction dispatch is paid once per chunk and simple loops vectorise. Plain values
//! in `f32` columns; values with gradients in columns of [`Dual`], through the very functions the
//! point interpreter uses, so both give the same bits (the meshers' output must not depend on
//! whether a point was evaluated alone or in a batch).

use super::eval::Domain;
use super::eval::Dual;
use super::ops::{self, BinaryOp, UnaryOp};
use super::tape::{Instr, Tape};
use glam::Vec3;

/// Points per column: enough to amortise dispatch, few enough that slots × lanes stays in cache.
pub const LANES: usize = 64;

type Column = [f32; LANES];

/// Values at many points; only the first `min(points.len(), out.len())` are written.
pub fn eval_columns(tape: &Tape, points: &[Vec3], out: &mut [f32]) {
    run_columns(tape, points, out, |v, _| v, run_column, |&v| v);
}

/// Runs `tape` over `points`, 64 at a time, in the number system `D`: inputs made by `input`
/// from a coordinate and its axis, each instruction run over a column by `step`, and `result` of
/// the output written to `out` (the first `min(points.len(), out.len())` entries).
fn run_columns<D: Domain, O>(
    tape: &Tape,
    points: &[Vec3],
    out: &mut [O],
    input: impl Fn(f32, usize) -> D,
    step: impl Fn(&Instr, &mut [[D; LANES]]),
    result: impl Fn(&D) -> O,
) {
    let n = points.len().min(out.len());
    if n == 0 {
        return;
    }
    let mut cols: Vec<[D; LANES]> = vec![[D::default(); LANES]; tape.slot_count];
    for (col, &c) in cols.iter_mut().zip(&tape.consts) {
        col.fill(D::constant(c));
    }
    for start in (0..n).step_by(LANES) {
        let chunk = &points[start..n.min(start + LANES)];
        for (axis, input_slot) in tape.inputs.iter().enumerate() {
            if let Some(s) = input_slot {
                let col = &mut cols[*s as usize];
                for (c, p) in col.iter_mut().zip(chunk) {
                    *c = input(p[axis], axis);
                }
            }
        }
        for instr in &tape.instrs {
            step(instr, &mut cols);
        }
        for (o, v) in out[start..start + chunk.len()].iter_mut().zip(&cols[tape.output as usize]) {
            *o = result(v);
        }
    }
}

/// The output column mutably and the operand columns shared, split out of one slice; the tape
/// guarantees the output is not an operand.
fn split<C>(cols: &mut [C], out: u32, a: u32, b: u32) -> (&mut C, &C, &C) {
    let out = out as usize;
    let (before, rest) = cols.split_at_mut(out);
    let (o, after) = rest.split_first_mut().expect("output slot is in range");
    let pick = |i: u32| -> &C {
        let i = i as usize;
        if i < out {
            &before[i]
        } else {
            &after[i - out - 1]
        }
    };
    (o, pick(a), pick(b))
}

fn run_column(instr: &Instr, cols: &mut [Column]) {
    match *instr {
        Instr::Unary { op, out, a } => {
            let (o, a, _) = split(cols, out, a, a);
            match op {
                UnaryOp::Neg => o.iter_mut().zip(a).for_each(|(o, a)| *o = -a),
                UnaryOp::Abs => o.iter_mut().zip(a).for_each(|(o, a)| *o = a.abs()),
                UnaryOp::Sqrt => o.iter_mut().zip(a).for_each(|(o, a)| *o = a.sqrt()),
                UnaryOp::Powi(2) => o.iter_mut().zip(a).for_each(|(o, a)| *o = a * a),
                op => o.iter_mut().zip(a).for_each(|(o, &a)| *o = ops::unary(op, a)),
            }
        }
        Instr::Binary { op, out, a, b } => {
            let (o, a, b) = split(cols, out, a, b);
            let lanes = o.iter_mut().zip(a.iter().zip(b));
            match op {
                BinaryOp::Add => lanes.for_each(|(o, (a, b))| *o = a + b),
                BinaryOp::Sub => lanes.for_each(|(o, (a, b))| *o = a - b),
                BinaryOp::Mul => lanes.for_each(|(o, (a, b))| *o = a * b),
                BinaryOp::Div => lanes.for_each(|(o, (a, b))| *o = a / b),
                BinaryOp::Min => lanes.for_each(|(o, (&a, &b))| *o = ops::min(a, b)),
                BinaryOp::Max => lanes.for_each(|(o, (&a, &b))| *o = ops::max(a, b)),
                op => lanes.for_each(|(o, (&a, &b))| *o = ops::binary(op, a, b)),
            }
        }
    }
}

type DualColumn = [Dual; LANES];

/// Gradients at many points (see [`super::eval::eval_gradient`] for the conventions at kinks),
/// each passed through `wrap` (callers that want `Option`s need no second buffer); only the
/// first `min(points.len(), out.len())` are written.
pub fn eval_gradient_columns<O>(tape: &Tape, points: &[Vec3], out: &mut [O], wrap: impl Fn(Vec3) -> O) {
    run_columns(tape, points, out, Dual::input, run_dual_column, |d| wrap(d.d));
}

/// One instruction over a column of duals. Each arm names its operation as a constant, so that
/// the match inside [`Dual::unary`] / [`Dual::binary`] folds away in the lane loop.
fn run_dual_column(instr: &Instr, cols: &mut [DualColumn]) {
    fn lanes(o: &mut DualColumn, a: &DualColumn, b: &DualColumn, f: impl Fn(Dual, Dual) -> Dual) {
        for (o, (&a, &b)) in o.iter_mut().zip(a.iter().zip(b)) {
            *o = f(a, b);
        }
    }
    match *instr {
        Instr::Unary { op, out, a } => {
            let (o, a, _) = split(cols, out, a, a);
            match op {
                UnaryOp::Neg => lanes(o, a, a, |a, _| Dual::unary(UnaryOp::Neg, a)),
                UnaryOp::Abs => lanes(o, a, a, |a, _| Dual::unary(UnaryOp::Abs, a)),
                UnaryOp::Sqrt => lanes(o, a, a, |a, _| Dual::unary(UnaryOp::Sqrt, a)),
                UnaryOp::Powi(2) => lanes(o, a, a, |a, _| Dual::unary(UnaryOp::Powi(2), a)),
                op => lanes(o, a, a, |a, _| Dual::unary(op, a)),
            }
        }
        Instr::Binary { op, out, a, b } => {
            let (o, a, b) = split(cols, out, a, b);
            match op {
                BinaryOp::Add => lanes(o, a, b, |a, b| Dual::binary(BinaryOp::Add, a, b)),
                BinaryOp::Sub => lanes(o, a, b, |a, b| Dual::binary(BinaryOp::Sub, a, b)),
                BinaryOp::Mul => lanes(o, a, b, |a, b| Dual::binary(BinaryOp::Mul, a, b)),
                BinaryOp::Div => lanes(o, a, b, |a, b| Dual::binary(BinaryOp::Div, a, b)),
                BinaryOp::Min => lanes(o, a, b, |a, b| Dual::binary(BinaryOp::Min, a, b)),
                BinaryOp::Max => lanes(o, a, b, |a, b| Dual::binary(BinaryOp::Max, a, b)),
                op => lanes(o, a, b, |a, b| Dual::binary(op, a, b)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use super::super::testutil::{Rng, CASES};
    use glam::Vec3;

    /// Not a multiple of the column width, so the last chunk is partial; NaN equals NaN.
    fn points(seed: u64) -> Vec<Vec3> {
        let mut rng = Rng::new(seed);
        (0..150).map(|_| rng.vec3(-1.5, 1.5)).collect()
    }

    fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[test]
    fn eval_many_equals_eval_pointwise() {
        for case in CASES {
            let program = compile(case).unwrap();
            let points = points(3);
            let mut out = vec![f32::NAN; points.len() + 3];
            program.eval_many(&points, &mut out);
            for (p, &v) in points.iter().zip(&out) {
                let e = program.eval(*p);
                assert!(same(e, v), "{case} at {p}: column {v} vs point {e}");
            }
            assert!(out[points.len()..].iter().all(|v| v.is_nan()), "wrote past the points");
        }
    }

    #[test]
    fn gradient_columns_equal_pointwise_gradients_bit_for_bit() {
        for case in CASES {
            let program = compile(case).unwrap();
            let points = points(5);
            let mut out = vec![Vec3::splat(f32::NAN); points.len() + 3];
            program.eval_grad_many(&points, &mut out);
            for (p, g) in points.iter().zip(&out) {
                let e = program.eval_grad(*p).1;
                let equal = (0..3).all(|i| same(e[i], g[i]));
                assert!(equal, "{case} at {p}: column {g} vs point {e}");
            }
            assert!(out[points.len()..].iter().all(|g| g.x.is_nan()), "wrote past the points");
        }
    }
}

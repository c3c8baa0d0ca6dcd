//! Running a [`Tape`] over many points: each instruction runs over a column of 64 points at once,
//! so the per-instruction dispatch is paid once per chunk and simple loops vectorise. Plain values
//! in `f32` columns; values with gradients in columns of [`Dual`], through the very functions the
//! point interpreter uses, so both give the same bits (the meshers' output must not depend on
//! whether a point was evaluated alone or in a batch).

use super::eval::{unary_slope, Domain, Dual};
use super::ops::{self, BinaryOp, UnaryOp};
use super::tape::{Instr, Tape};
use glam::Vec3;
use std::cell::RefCell;

/// Points per column: enough to amortise dispatch, few enough that slots × lanes stays in cache.
pub const LANES: usize = 64;

type Column = [f32; LANES];

/// Batches smaller than this run point by point: a column pass costs all its lanes and the
/// columns' setup (a column per slot, constants filled) however few points it holds, so a handful
/// of points, as a batch split by brick ([`super::RegionalProgram`]) leaves, are cheaper one at a
/// time through the point interpreter, which gives the same bits.
pub const SMALL_BATCH: usize = 8;

/// [`SMALL_BATCH`] for gradients, whose columns are four times the size.
pub const SMALL_GRADIENT_BATCH: usize = 16;

/// Values at many points; only the first `min(points.len(), out.len())` are written.
pub fn eval_columns(tape: &Tape, points: &[Vec3], out: &mut [f32]) {
    if points.len().min(out.len()) < SMALL_BATCH {
        for (o, &p) in out.iter_mut().zip(points) {
            *o = super::eval::eval_point(tape, p);
        }
        return;
    }
    with_columns(&VALUE_COLUMNS, tape.slot_count, |cols| {
        run_columns(
            tape,
            points,
            out,
            cols,
            |c| [c; LANES],
            |col, axis, chunk| col.iter_mut().zip(chunk).for_each(|(c, p)| *c = p[axis]),
            run_column,
            |col, out| out.copy_from_slice(&col[..out.len()]),
        )
    });
}

thread_local! {
    /// Each thread's columns, kept from batch to batch (see [`with_columns`]).
    static VALUE_COLUMNS: RefCell<Vec<Column>> = const { RefCell::new(Vec::new()) };
    static DUAL_COLUMNS: RefCell<Vec<DualColumn>> = const { RefCell::new(Vec::new()) };
}

/// Tapes with more slots than this get columns of their own for each batch rather than growing
/// the thread's kept ones (4 MB of dual columns): a user's program can be that long, the
/// meshers' brick tapes are a few dozen slots.
const KEPT_SLOTS: usize = 4096;

/// Calls `f` with the thread's kept columns of `cache`. A column per slot is 256 bytes (1 KB for
/// duals), and allocating and zeroing them for every batch was most of a small batch's setup:
/// DMC's tests on the gear at 128 cells spent 3 % of their instructions in that `memset`. No slot
/// is read before it is written in a batch (constants and inputs are filled first, every
/// instruction writes its output before a later one reads it), so what a column held before does
/// not matter.
fn with_columns<C, R>(
    cache: &'static std::thread::LocalKey<RefCell<Vec<C>>>,
    slots: usize,
    f: impl FnOnce(&mut Vec<C>) -> R,
) -> R {
    if slots > KEPT_SLOTS {
        return f(&mut Vec::new());
    }
    cache.with(|cell| match cell.try_borrow_mut() {
        Ok(mut kept) => f(&mut kept),
        // A batch inside a batch on this thread (none today): columns of its own.
        Err(_) => f(&mut Vec::new()),
    })
}

/// Runs `tape` over `points`, 64 at a time, in columns of type `C` (`cols`: at least one per
/// slot once grown, their contents unread): constants filled by `constant`, the inputs' columns
/// by `input(column, axis, chunk)`, each instruction run over its columns by `step`, and the
/// output column's first lanes written by `result` (the first `min(points.len(), out.len())`
/// entries of `out` in all).
#[allow(clippy::too_many_arguments)]
fn run_columns<C: Clone, O>(
    tape: &Tape,
    points: &[Vec3],
    out: &mut [O],
    cols: &mut Vec<C>,
    constant: impl Fn(f32) -> C,
    input: impl Fn(&mut C, usize, &[Vec3]),
    step: impl Fn(&Instr, &mut [C]),
    result: impl Fn(&C, &mut [O]),
) {
    let n = points.len().min(out.len());
    if n == 0 {
        return;
    }
    if cols.len() < tape.slot_count {
        cols.resize(tape.slot_count, constant(0.0));
    }
    let cols = &mut cols[..tape.slot_count];
    for (col, &c) in cols.iter_mut().zip(&tape.consts) {
        *col = constant(c);
    }
    for start in (0..n).step_by(LANES) {
        let chunk = &points[start..n.min(start + LANES)];
        for (axis, input_slot) in tape.inputs.iter().enumerate() {
            if let Some(s) = input_slot {
                input(&mut cols[*s as usize], axis, chunk);
            }
        }
        for instr in &tape.instrs {
            step(instr, cols);
        }
        result(&cols[tape.output as usize], &mut out[start..start + chunk.len()]);
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

/// Values and their gradients over a column of points, one array per component: every lane loop
/// then runs over plain `f32` arrays and vectorises, where a column of 16-byte [`Dual`]s did not
/// (in wasm the gradient batches ran at 1.7-1.9x native's time).
#[derive(Clone, Copy)]
struct DualColumn {
    v: Column,
    d: [Column; 3],
}

impl DualColumn {
    fn constant(c: f32) -> Self {
        DualColumn { v: [c; LANES], d: [[0.0; LANES]; 3] }
    }

    fn lane(&self, l: usize) -> Dual {
        Dual { v: self.v[l], d: glam::Vec3A::new(self.d[0][l], self.d[1][l], self.d[2][l]) }
    }

    fn set_lane(&mut self, l: usize, dual: Dual) {
        self.v[l] = dual.v;
        for axis in 0..3 {
            self.d[axis][l] = dual.d[axis];
        }
    }
}

/// Values and gradients at many points (see [`super::eval::eval_gradient`] for the conventions
/// at kinks), each pair passed through `wrap` (callers that want `Option`s need no second
/// buffer); only the first `min(points.len(), out.len())` are written.
pub fn eval_gradient_columns<O>(tape: &Tape, points: &[Vec3], out: &mut [O], wrap: impl Fn(f32, Vec3) -> O) {
    if points.len().min(out.len()) < SMALL_GRADIENT_BATCH {
        for (o, &p) in out.iter_mut().zip(points) {
            let (v, g) = super::eval::eval_gradient(tape, p);
            *o = wrap(v, g);
        }
        return;
    }
    with_columns(&DUAL_COLUMNS, tape.slot_count, |cols| {
        run_columns(
            tape,
            points,
            out,
            cols,
            DualColumn::constant,
            |col, axis, chunk| {
                for (l, p) in chunk.iter().enumerate() {
                    col.set_lane(l, Dual::input(p[axis], axis));
                }
            },
            run_dual_column,
            |col, out| {
                for (l, o) in out.iter_mut().enumerate() {
                    let lane = col.lane(l);
                    *o = wrap(lane.v, lane.d.into());
                }
            },
        )
    });
}

/// One instruction over a column of duals, component by component, with the very formulas of
/// [`Dual`]'s `unary` and `binary` (in the same order of operations, so the bits agree). Each arm
/// names its operation as a constant so that the lane loops compile to straight vector code; the
/// rare operations (`pow`, `atan2`) go lane by lane through [`Dual`] itself.
fn run_dual_column(instr: &Instr, cols: &mut [DualColumn]) {
    /// `o.v = value(a.v)` and `o.d = a.d * slope(a.v, o.v)` on every lane. Inlined into each
    /// arm, so that `op` is a constant there and the lane loops vectorise: for wasm LLVM kept it
    /// a call with `op` a run-time argument, and the value loop went lane by lane through
    /// `ops::unary`'s match (a sphere's gradient batch at 5.6x native's time).
    #[inline(always)]
    fn unary(o: &mut DualColumn, a: &DualColumn, op: UnaryOp) {
        let mut slope = [0.0; LANES];
        for ((ov, s), &av) in o.v.iter_mut().zip(&mut slope).zip(&a.v) {
            *ov = ops::unary(op, av);
            *s = unary_slope(op, av, *ov);
        }
        for (od, ad) in o.d.iter_mut().zip(&a.d) {
            for ((od, ad), s) in od.iter_mut().zip(ad).zip(&slope) {
                *od = ad * s;
            }
        }
    }
    /// `o.v = value(a.v, b.v)` and, per component, `o.d = grad(a.v, a.d, b.v, b.d, o.v)`.
    #[inline(always)]
    fn binary(
        o: &mut DualColumn,
        a: &DualColumn,
        b: &DualColumn,
        value: impl Fn(f32, f32) -> f32,
        grad: impl Fn(f32, f32, f32, f32, f32) -> f32,
    ) {
        for (ov, (&av, &bv)) in o.v.iter_mut().zip(a.v.iter().zip(&b.v)) {
            *ov = value(av, bv);
        }
        for ((od, ad), bd) in o.d.iter_mut().zip(&a.d).zip(&b.d) {
            let lanes = od.iter_mut().zip(ad).zip(bd).zip(a.v.iter().zip(&b.v).zip(&o.v));
            for (((od, &ad), &bd), ((&av, &bv), &v)) in lanes {
                *od = grad(av, ad, bv, bd, v);
            }
        }
    }
    match *instr {
        Instr::Unary { op, out, a } => {
            let (o, a, _) = split(cols, out, a, a);
            match op {
                UnaryOp::Neg => unary(o, a, UnaryOp::Neg),
                UnaryOp::Abs => unary(o, a, UnaryOp::Abs),
                UnaryOp::Sqrt => unary(o, a, UnaryOp::Sqrt),
                UnaryOp::Powi(2) => unary(o, a, UnaryOp::Powi(2)),
                op => unary(o, a, op),
            }
        }
        Instr::Binary { op, out, a, b } => {
            let (o, a, b) = split(cols, out, a, b);
            match op {
                BinaryOp::Add => binary(o, a, b, |a, b| a + b, |_, ad, _, bd, _| ad + bd),
                BinaryOp::Sub => binary(o, a, b, |a, b| a - b, |_, ad, _, bd, _| ad - bd),
                BinaryOp::Mul => binary(o, a, b, |a, b| a * b, |av, ad, bv, bd, _| ad * bv + bd * av),
                BinaryOp::Div => binary(o, a, b, |a, b| a / b, |_, ad, bv, bd, v| (ad - bd * v) / bv),
                // The value tells which branch was taken, as in `Dual::binary`.
                BinaryOp::Min => binary(o, a, b, ops::min, |av, ad, _, bd, v| if v == av { ad } else { bd }),
                BinaryOp::Max => binary(o, a, b, ops::max, |av, ad, _, bd, v| if v == av { ad } else { bd }),
                op => {
                    for l in 0..LANES {
                        o.set_lane(l, Dual::binary(op, a.lane(l), b.lane(l)));
                    }
                }
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

    /// Values and gradients in one pass are the point interpreter's, for batches above and below
    /// the size where batches run point by point.
    #[test]
    fn values_with_gradients_equal_pointwise_values_and_gradients_bit_for_bit() {
        for case in CASES {
            let program = compile(case).unwrap();
            for n in [3, 150] {
                let points = &points(7)[..n];
                let mut out = vec![(f32::NAN, Vec3::splat(f32::NAN)); n];
                program.eval_value_grad_many(points, &mut out);
                for (p, (v, g)) in points.iter().zip(&out) {
                    let (ev, eg) = program.eval_grad(*p);
                    assert!(same(ev, program.eval(*p)) && same(*v, ev), "{case} at {p}: {v} vs {ev}");
                    assert!((0..3).all(|i| same(eg[i], g[i])), "{case} at {p}: {g} vs {eg}");
                }
            }
        }
    }

    /// The thread keeps its columns from batch to batch: whatever a longer program left in them
    /// (NaN and infinities included) must not reach a later program's results. Programs of every
    /// length take turns on one thread, each batch after a poisoning one, in shuffled order.
    #[test]
    fn kept_columns_carry_nothing_from_one_batch_to_the_next() {
        let poison = compile("sqrt(x - 2) / (y * 0) + log(z - 5)").unwrap();
        let mut programs: Vec<_> = CASES.iter().map(|case| (case, compile(case).unwrap())).collect();
        let mut rng = Rng::new(11);
        for round in 0..3 {
            for i in (1..programs.len()).rev() {
                programs.swap(i, rng.below(i + 1));
            }
            for (case, program) in &programs {
                let points = points(13 + round);
                let mut scratch = vec![0.0; points.len()];
                poison.eval_many(&points, &mut scratch);
                let mut scratch_dual = vec![Vec3::ZERO; points.len()];
                poison.eval_grad_many(&points, &mut scratch_dual);
                let mut values = vec![0.0; points.len()];
                program.eval_many(&points, &mut values);
                let mut both = vec![(0.0, Vec3::ZERO); points.len()];
                program.eval_value_grad_many(&points, &mut both);
                for ((p, &v), &(bv, bg)) in points.iter().zip(&values).zip(&both) {
                    let (ev, eg) = program.eval_grad(*p);
                    assert!(same(v, program.eval(*p)), "{case} at {p}: {v} after another batch");
                    assert!(same(bv, ev), "{case} at {p}: {bv} vs {ev} after another batch");
                    assert!((0..3).all(|i| same(eg[i], bg[i])), "{case} at {p}: {bg} vs {eg}");
                }
            }
        }
    }
}

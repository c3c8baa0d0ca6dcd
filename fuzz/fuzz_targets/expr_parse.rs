//! Text → `expr::compile`. Any text may be refused, none may panic, hang or allocate without
//! bound (the parser caps nesting, the graph caps nodes). A program that compiles is then held to
//! what `Program` documents, because a compiled program is what every mesher trusts:
//! - `eval_grad`'s value equals `eval`'s (or both are NaN);
//! - `eval_interval` over a box never has a NaN endpoint and contains `eval` at every point of the
//!   box where that is not NaN;
//! - the program simplified by the box's min/max choices agrees with the original inside the box.
#![no_main]

use isoforge::expr::{self, Program};
use isoforge::Vec3;
use libfuzzer_sys::fuzz_target;

/// Boxes the interval checks run over: the default meshing bounds, a small off-centre one and a
/// degenerate (single point) one.
const BOXES: [(Vec3, Vec3); 3] = [
    (Vec3::splat(-1.0), Vec3::splat(1.0)),
    (Vec3::new(0.1, -0.3, 0.2), Vec3::new(0.35, -0.05, 0.6)),
    (Vec3::new(0.5, 0.5, 0.5), Vec3::new(0.5, 0.5, 0.5)),
];

/// Points of `lo..hi` at fixed fractions: corners, centre and a few inside.
fn points_in(lo: Vec3, hi: Vec3) -> impl Iterator<Item = Vec3> {
    const FRACTIONS: [[f32; 3]; 7] = [
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [0.5, 0.5, 0.5],
        [1.0, 0.0, 0.5],
        [0.25, 0.75, 0.1],
        [0.9, 0.3, 0.0],
        [0.0, 1.0, 0.6],
    ];
    // lo + (hi - lo) * f can round past hi; clamping keeps the point in the box the bounds
    // are promised for.
    FRACTIONS.into_iter().map(move |f| (lo + (hi - lo) * Vec3::from(f)).clamp(lo, hi))
}

/// Bit for bit, or both NaN: what the docs promise of the batch gradients.
fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Equal as numbers (0 and -0 alike), or both NaN: "equal" in the docs of `eval_grad` and
/// `simplify`. A min/max of 0 and -0 may return either, and a decided choice may pick the other
/// zero than `f32::min` does; no sign test can tell them apart.
fn equal(a: f32, b: f32) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

fn check(program: &Program) {
    for (lo, hi) in BOXES {
        let (ilo, ihi) = program.eval_interval(lo, hi);
        assert!(!ilo.is_nan() && !ihi.is_nan(), "NaN interval endpoint over {lo}..{hi}: {ilo}..{ihi}");
        let ((clo, chi), choices) = program.eval_interval_with_choices(lo, hi);
        assert!(
            same(clo, ilo) && same(chi, ihi),
            "intervals differ with choices: {ilo}..{ihi} vs {clo}..{chi}"
        );
        let simple = program.simplify(&choices);
        for p in points_in(lo, hi) {
            let v = program.eval(p);
            let (g, grad) = program.eval_grad(p);
            assert!(equal(v, g), "eval {v} but eval_grad {g} at {p}");
            let _ = grad;
            if !v.is_nan() {
                assert!(
                    ilo <= v && v <= ihi,
                    "eval {v} at {p} outside its interval {ilo}..{ihi} over {lo}..{hi}"
                );
            }
            let s = simple.eval(p);
            // A NaN operand is "left out" of the intervals, so a min/max decided by them may pick
            // the side that is NaN at a point where f32::min would have returned the other.
            if !v.is_nan() && !s.is_nan() {
                assert!(equal(v, s), "simplified program gives {s}, the original {v} at {p}");
            }
        }
    }
    let points: Vec<Vec3> = points_in(Vec3::splat(-2.0), Vec3::splat(2.0)).collect();
    let mut out = vec![0.0; points.len()];
    program.eval_many(&points, &mut out);
    let mut grads = vec![Vec3::ZERO; points.len()];
    program.eval_grad_many(&points, &mut grads);
    for (p, g) in points.iter().zip(&grads) {
        let (_, one) = program.eval_grad(*p);
        assert!(
            one.to_array().iter().zip(g.to_array()).all(|(a, b)| same(*a, b)),
            "eval_grad_many {g} but eval_grad {one} at {p}"
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(program) = expr::compile(text) {
        check(&program);
    }
});

//! How fast each evaluation mode runs on the machine at hand, with the clock passed in so the same
//! measurement runs natively and in a browser (where `std::time::Instant` does not exist). The
//! criterion benchmark (`benches/expr.rs`) is the careful native measurement; this one exists so a
//! browser can report its own numbers (`measureEvaluator` in the wasm API, `scripts/bench-browser.mjs`).

use super::{naive::eval_tree, parse, Program};
use crate::error::Error;
use glam::Vec3;

/// Nanoseconds per point (per box for `interval`) of each evaluation mode on one program.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "camelCase")]
pub struct EvaluatorSpeed {
    /// The reference tree walk ([`super::naive`]): the baseline.
    pub tree_walk: f64,
    /// [`Program::eval`], one point per call.
    pub value: f64,
    /// [`Program::eval_grad`]: value and exact gradient.
    pub value_gradient: f64,
    /// [`Program::eval_many`]: 64-point columns, what grids and octrees use.
    pub batch: f64,
    /// [`Program::eval_grad_many`]: gradients in 64-point columns, what octrees use.
    pub gradient_batch: f64,
    /// [`Program::eval_interval`] over boxes of a 32nd of the domain.
    pub interval: f64,
    /// Tape length after folding and sharing.
    pub instructions: usize,
}

/// Measures every mode of `text` over `count` pseudo-random points in [-1, 1]³, each mode repeated
/// until it has run for at least `min_ms` by `now` (milliseconds, any origin). Fails if the text
/// does not compile, or if the modes disagree on the values (which would make the timing moot).
pub fn measure(
    text: &str,
    count: usize,
    min_ms: f64,
    now: &dyn Fn() -> f64,
) -> Result<EvaluatorSpeed, Error> {
    let program = super::compile(text)?;
    let script = parse(text)?;
    let points = points(count.max(1));
    let per_point = |f: &mut dyn FnMut() -> f32| -> (f64, f32) {
        let start = now();
        let mut runs = 0usize;
        let mut checksum = 0.0;
        while runs == 0 || now() - start < min_ms {
            checksum = f();
            runs += 1;
        }
        ((now() - start) * 1e6 / (runs * points.len()) as f64, checksum)
    };
    let (tree_walk, tree_sum) = per_point(&mut || points.iter().map(|&p| eval_tree(&script, p)).sum());
    let (value, value_sum) = per_point(&mut || points.iter().map(|&p| program.eval(p)).sum());
    let (value_gradient, grad_sum) = per_point(&mut || points.iter().map(|&p| program.eval_grad(p).0).sum());
    let mut out = vec![0.0; points.len()];
    let (batch, batch_sum) = per_point(&mut || {
        program.eval_many(&points, &mut out);
        out.iter().sum()
    });
    let (_, grad_x_sum) = per_point(&mut || points.iter().map(|&p| program.eval_grad(p).1.x).sum());
    let mut gradients = vec![Vec3::ZERO; points.len()];
    let (gradient_batch, gradient_batch_sum) = per_point(&mut || {
        program.eval_grad_many(&points, &mut gradients);
        gradients.iter().map(|g| g.x).sum()
    });
    let half = Vec3::splat(1.0 / 32.0);
    let (interval, _) =
        per_point(&mut || points.iter().map(|&p| program.eval_interval(p - half, p + half).0).sum());
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-3 * a.abs().max(1.0) || (a.is_nan() && b.is_nan());
    let agree = close(tree_sum, value_sum)
        && close(value_sum, grad_sum)
        && close(value_sum, batch_sum)
        && close(grad_x_sum, gradient_batch_sum);
    if !agree {
        return Err(Error::InvalidOption(format!(
            "evaluation modes disagree: tree {tree_sum}, value {value_sum}, gradient {grad_sum}, batch {batch_sum}, \
             gradient x {grad_x_sum} against batched {gradient_batch_sum}"
        )));
    }
    Ok(EvaluatorSpeed {
        tree_walk,
        value,
        value_gradient,
        batch,
        gradient_batch,
        interval,
        instructions: Program::instruction_count(&program),
    })
}

/// Deterministic points in [-1, 1]³ (a fixed xorshift stream), the same natively and in wasm, so
/// the criterion bench and the browser harness time the same points.
pub fn points(count: usize) -> Vec<Vec3> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    (0..count).map(|_| Vec3::new(next(), next(), next())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn every_mode_is_timed_on_agreeing_values() {
        // A fake clock ticking 1 ms per reading: each mode runs once, and the numbers follow.
        let t = Cell::new(0.0);
        let now = || {
            t.set(t.get() + 1.0);
            t.get()
        };
        let s = measure("union(sphere(0.5), box(.2, .3, .4))", 100, 0.5, &now).unwrap();
        for v in [s.tree_walk, s.value, s.value_gradient, s.batch, s.gradient_batch, s.interval] {
            assert!(v > 0.0 && v.is_finite(), "{s:?}");
        }
        assert!(s.instructions > 3);
        assert!(measure("sphere(", 10, 0.0, &now).is_err());
    }

    #[test]
    fn points_fill_the_cube() {
        let p = points(1000);
        assert!(p.iter().all(|p| p.abs().max_element() <= 1.0));
        let mean = p.iter().copied().sum::<Vec3>() / 1000.0;
        assert!(mean.abs().max_element() < 0.1, "{mean}");
        assert!(p.iter().any(|p| p.x > 0.9) && p.iter().any(|p| p.x < -0.9));
    }
}

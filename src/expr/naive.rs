//! The naive tree walk: evaluates a [`Script`] straight from the tree, re-reading a binding's
//! subtree wherever it is used and folding nothing. Slow on purpose; it exists as the reference
//! the compiled tape is tested against, and as the baseline the benchmarks compare with.

use super::ast::Script;
use super::compile::{lower, Backend};
use super::diag::Diag;
use super::ops::{self, BinaryOp, UnaryOp};
use super::shapes::Emit;
use glam::Vec3;

struct Numbers;

impl Emit for Numbers {
    type V = f32;
    fn constant(&mut self, c: f32) -> f32 {
        c
    }
    fn unary(&mut self, op: UnaryOp, a: f32) -> f32 {
        ops::unary(op, a)
    }
    fn binary(&mut self, op: BinaryOp, a: f32, b: f32) -> f32 {
        ops::binary(op, a, b)
    }
    fn as_constant(&self, v: f32) -> Option<f32> {
        Some(v)
    }
}

impl Backend for Numbers {
    fn binding(&mut self, script: &Script, index: usize, at: [f32; 3], depth: usize) -> Result<f32, Diag> {
        // Re-reading the binding's tree counts as going deeper, so a hand-built self-reference
        // ends in an error instead of a stack overflow.
        let binding =
            script.bindings.get(index).ok_or_else(|| Diag::new(Default::default(), "no such binding"))?;
        lower(self, script, &binding.value, at, depth + 1)
    }
}

/// The value of `script` at `p` by walking the tree; NaN where the compiler would have refused the
/// program (a zero rotation axis, say). Exponential in the depth of bindings-of-bindings.
pub fn eval_tree(script: &Script, p: Vec3) -> f32 {
    lower(&mut Numbers, script, &script.body, p.to_array(), 0).unwrap_or(f32::NAN)
}

//! The primitive operations every evaluation mode agrees on, with their scalar `f32` meaning.
//!
//! Constant folding, the point evaluator, the column evaluator and the reference tree walk all
//! call these functions, so a folded constant is bit-for-bit what the tape would have computed.

use std::fmt;

/// One-argument operations. `Powi` carries its (small) integer exponent as an immediate so
/// `x^2` costs one multiply and has exact interval bounds instead of going through `powf`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnaryOp {
    Neg,
    Abs,
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Exp,
    Ln,
    Floor,
    /// -1, 0 or 1 (NaN stays NaN). Internal: shapes use it to pick a side; not in the language.
    Sign,
    Powi(i32),
}

/// Two-argument operations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    /// Ignores a NaN argument (like `f32::min`), so an undefined branch does not poison a union.
    Min,
    Max,
    Pow,
    /// `atan2(y, x)`: the first operand is y.
    Atan2,
}

/// Exponents up to this size become [`UnaryOp::Powi`]; larger ones stay `powf`.
pub const MAX_POWI: i32 = 64;

#[inline(always)]
pub fn unary(op: UnaryOp, a: f32) -> f32 {
    match op {
        UnaryOp::Neg => -a,
        UnaryOp::Abs => a.abs(),
        UnaryOp::Sqrt => a.sqrt(),
        UnaryOp::Sin => a.sin(),
        UnaryOp::Cos => a.cos(),
        UnaryOp::Tan => a.tan(),
        UnaryOp::Asin => a.asin(),
        UnaryOp::Acos => a.acos(),
        UnaryOp::Atan => a.atan(),
        UnaryOp::Exp => a.exp(),
        UnaryOp::Ln => a.ln(),
        UnaryOp::Floor => a.floor(),
        UnaryOp::Sign => sign(a),
        UnaryOp::Powi(n) => powi(a, n),
    }
}

#[inline(always)]
pub fn binary(op: BinaryOp, a: f32, b: f32) -> f32 {
    match op {
        BinaryOp::Add => a + b,
        BinaryOp::Sub => a - b,
        BinaryOp::Mul => a * b,
        BinaryOp::Div => a / b,
        BinaryOp::Min => min(a, b),
        BinaryOp::Max => max(a, b),
        BinaryOp::Pow => a.powf(b),
        BinaryOp::Atan2 => a.atan2(b),
    }
}

/// The smaller of `a` and `b`, ignoring a NaN operand as `f32::min` does (`a` on a tie). Written
/// as two selects: wasm has no instruction with `f32::min`'s NaN rule, so LLVM turns `f32::min`
/// into a branchy sequence per lane there, while selects vectorise (the 64-lane columns of
/// [`super::columns`]). Every evaluator calls this one, so they agree bit for bit.
#[inline]
pub fn min(a: f32, b: f32) -> f32 {
    let smaller = if b < a { b } else { a };
    if a.is_nan() {
        b
    } else {
        smaller
    }
}

/// The larger of `a` and `b`, ignoring a NaN operand as `f32::max` does (`a` on a tie); see
/// [`min`].
#[inline]
pub fn max(a: f32, b: f32) -> f32 {
    let larger = if b > a { b } else { a };
    if a.is_nan() {
        b
    } else {
        larger
    }
}

pub fn sign(a: f32) -> f32 {
    if a > 0.0 {
        1.0
    } else if a < 0.0 {
        -1.0
    } else {
        a
    }
}

/// Integer power by repeated squaring, written out rather than `f32::powi` so that every platform
/// (and the interval code, which relies on it being monotone) sees the same sequence of multiplies.
/// A negative exponent is exactly `1 / a^|n|`.
pub fn powi(a: f32, n: i32) -> f32 {
    let mut e = n.unsigned_abs();
    let mut base = a;
    let mut acc = 1.0f32;
    let mut first = true;
    while e > 0 {
        if e & 1 == 1 {
            acc = if first { base } else { acc * base };
            first = false;
        }
        e >>= 1;
        if e > 0 {
            base *= base;
        }
    }
    if n < 0 {
        1.0 / acc
    } else {
        acc
    }
}

impl UnaryOp {
    pub fn name(self) -> &'static str {
        match self {
            UnaryOp::Neg => "neg",
            UnaryOp::Abs => "abs",
            UnaryOp::Sqrt => "sqrt",
            UnaryOp::Sin => "sin",
            UnaryOp::Cos => "cos",
            UnaryOp::Tan => "tan",
            UnaryOp::Asin => "asin",
            UnaryOp::Acos => "acos",
            UnaryOp::Atan => "atan",
            UnaryOp::Exp => "exp",
            UnaryOp::Ln => "log",
            UnaryOp::Floor => "floor",
            UnaryOp::Sign => "sign",
            UnaryOp::Powi(_) => "powi",
        }
    }
}

impl BinaryOp {
    pub fn name(self) -> &'static str {
        match self {
            BinaryOp::Add => "add",
            BinaryOp::Sub => "sub",
            BinaryOp::Mul => "mul",
            BinaryOp::Div => "div",
            BinaryOp::Min => "min",
            BinaryOp::Max => "max",
            BinaryOp::Pow => "pow",
            BinaryOp::Atan2 => "atan2",
        }
    }

    /// Operand order does not matter, so the graph may sort operands to share more nodes.
    /// Min and max are excluded: at a tie the gradient follows the left operand by convention.
    pub fn is_commutative(self) -> bool {
        matches!(self, BinaryOp::Add | BinaryOp::Mul)
    }
}

impl fmt::Display for UnaryOp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            UnaryOp::Powi(n) => write!(f, "powi{n}"),
            op => f.write_str(op.name()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powi_matches_repeated_multiplication_and_reciprocal() {
        for &a in &[0.0f32, -0.0, 1.5, -2.25, 3.0, 1e-3, -7.5] {
            let mut expect = 1.0f32;
            for n in 0..=9 {
                if n > 0 {
                    expect *= a;
                }
                let got = powi(a, n);
                assert!((got - expect).abs() <= expect.abs() * 1e-6, "{a}^{n}: {got} vs {expect}");
                let inv = powi(a, -n);
                assert_eq!(inv, 1.0 / got, "{a}^-{n}");
            }
        }
        assert_eq!(powi(2.0, 10), 1024.0);
        assert_eq!(powi(-2.0, 3), -8.0);
    }

    #[test]
    fn sign_is_three_valued() {
        assert_eq!(sign(3.0), 1.0);
        assert_eq!(sign(-0.5), -1.0);
        assert_eq!(sign(0.0), 0.0);
        assert!(sign(f32::NAN).is_nan());
    }
}

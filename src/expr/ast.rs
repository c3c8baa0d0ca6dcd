//! The syntax tree both front ends (text and CSG JSON) produce, and the compiler consumes.
//!
//! Names are already resolved when a tree exists: a call holds a [`Builtin`], an identifier is a
//! coordinate or the index of an earlier binding. So every tree is meaningful, and the compiler
//! has no lookup errors left to report.

use super::builtins::Builtin;
use super::diag::Span;

/// A whole program: bindings in order, then the expression whose value is the field.
#[derive(Debug, Clone, PartialEq)]
pub struct Script {
    pub bindings: Vec<Binding>,
    pub body: Expr,
}

/// `name = value;`. The value may refer to earlier bindings only, so there are no cycles.
#[derive(Debug, Clone, PartialEq)]
pub struct Binding {
    pub name: String,
    pub span: Span,
    pub value: Expr,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }
}

/// The four left-associative arithmetic operators of a [`ExprKind::Chain`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainOp {
    Add,
    Sub,
    Mul,
    Div,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    Number(f64),
    Coord(Axis),
    /// Index into [`Script::bindings`].
    Binding(usize),
    Neg(Box<Expr>),
    /// `first op1 e1 op2 e2 …`, evaluated left to right. Kept flat rather than as nested binary
    /// nodes so that a machine-generated sum of ten thousand terms is not ten thousand levels of
    /// recursion (and stack) in every pass over the tree.
    Chain {
        first: Box<Expr>,
        rest: Vec<(ChainOp, Expr)>,
    },
    /// `base ^ exponent`.
    Power(Box<Expr>, Box<Expr>),
    Call(Builtin, Vec<Expr>),
}

impl Expr {
    pub fn new(kind: ExprKind, span: Span) -> Expr {
        Expr { kind, span }
    }

    /// A node with no source position (trees built from CSG).
    pub fn synthetic(kind: ExprKind) -> Expr {
        Expr { kind, span: Span::default() }
    }
}

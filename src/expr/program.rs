//! [`Program`]: a compiled field, and the one public face of every evaluation mode.

use super::columns::{eval_columns, eval_gradient_columns};
use super::compile::compile_script;
use super::csg::CsgNode;
use super::eval::{eval_gradient, eval_point};
use super::graph::{Graph, Node, NodeId};
use super::interval::{self, Choice};
use super::ops::BinaryOp;
use super::tape::Tape;
use super::Script;
use crate::error::Error;
use glam::Vec3;
use std::fmt;

/// A compiled expression: a flat tape of `f32` operations over a handful of slots, with constants
/// folded and repeated subexpressions computed once. Immutable, so `Send + Sync` and cheap to
/// share between threads.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// The folded, compacted graph the tape was allocated from, kept for [`Program::simplify`].
    nodes: Vec<Node>,
    root: NodeId,
    tape: Tape,
}

impl Program {
    pub(crate) fn from_graph(graph: &Graph, root: NodeId) -> Program {
        let (nodes, root) = graph.compact(root);
        let tape = Tape::from_nodes(&nodes, root);
        Program { nodes, root, tape }
    }

    /// Compiles an already parsed (or CSG-built) tree. Errors carry no source position; prefer
    /// [`super::compile`] for text.
    pub fn from_script(script: &Script) -> Result<Program, Error> {
        compile_script(script).map_err(|d| d.into_error_without_source())
    }

    /// Compiles a CSG tree (see [`CsgNode`]).
    pub fn from_csg(node: &CsgNode) -> Result<Program, Error> {
        Program::from_script(&node.to_script()?)
    }

    /// Parses and compiles a CSG tree in JSON; malformed JSON reports its line and column.
    pub fn from_csg_json(json: &str) -> Result<Program, Error> {
        Program::from_csg(&CsgNode::from_json(json)?)
    }

    /// The value at `p`.
    pub fn eval(&self, p: Vec3) -> f32 {
        eval_point(&self.tape, p)
    }

    /// The value and its exact gradient at `p` (forward-mode differentiation). Where there is no
    /// derivative: min/max pass on the taken branch's gradient (the left one on a tie), `abs`
    /// takes `+` at zero, `sqrt(0)` and `atan2(0, 0)` contribute zero, `floor` is flat. The value
    /// equals [`Program::eval`]'s.
    pub fn eval_grad(&self, p: Vec3) -> (f32, Vec3) {
        eval_gradient(&self.tape, p)
    }

    /// Bounds `(lo, hi)` on the value over the box between corners `lo` and `hi`, containing what
    /// [`Program::eval`] returns at every point of the box where it is not NaN (`f32` rounding
    /// included). Points where an operation is undefined are left out (`sqrt([-1, 4])` is
    /// `[0, 2]`); dividing by a range that contains zero gives `(-inf, inf)`; `sin`/`cos` find
    /// their extrema across any number of periods.
    pub fn eval_interval(&self, lo: Vec3, hi: Vec3) -> (f32, f32) {
        let r = interval::eval_interval(&self.tape, lo, hi);
        (r.lo, r.hi)
    }

    /// Like [`Program::eval_interval`], plus for each min/max (in tape order, see
    /// [`Program::choice_count`]) whether one operand alone decides it inside the box.
    pub fn eval_interval_with_choices(&self, lo: Vec3, hi: Vec3) -> ((f32, f32), Vec<Choice>) {
        let (r, c) = interval::eval_interval_with_choices(&self.tape, lo, hi);
        ((r.lo, r.hi), c)
    }

    /// Values at many points, evaluated 64 at a time column by column. Writes
    /// `min(points.len(), out.len())` values, like [`crate::field::Field::values`].
    pub fn eval_many(&self, points: &[Vec3], out: &mut [f32]) {
        eval_columns(&self.tape, points, out);
    }

    /// Gradients at many points, 64 at a time, bit for bit [`Program::eval_grad`]'s. Writes
    /// `min(points.len(), out.len())` gradients.
    pub fn eval_grad_many(&self, points: &[Vec3], out: &mut [Vec3]) {
        eval_gradient_columns(&self.tape, points, out, |_, g| g);
    }

    /// [`Program::eval_grad_many`] with each gradient passed through `wrap`.
    pub(super) fn eval_grad_many_as<O>(&self, points: &[Vec3], out: &mut [O], wrap: impl Fn(Vec3) -> O) {
        eval_gradient_columns(&self.tape, points, out, |_, g| wrap(g));
    }

    /// Values and gradients at many points in one pass, bit for bit [`Program::eval_grad`]'s
    /// (whose value is [`Program::eval`]'s).
    pub fn eval_value_grad_many(&self, points: &[Vec3], out: &mut [(f32, Vec3)]) {
        eval_gradient_columns(&self.tape, points, out, |v, g| (v, g));
    }

    /// A shorter program equal to this one wherever `choices` hold (typically inside the box
    /// they were computed for): each decided min/max is replaced by its winning operand, and
    /// whatever only the loser needed disappears. Missing choices count as [`Choice::Both`].
    /// Values and gradients are bit for bit the full program's wherever the choices hold (a
    /// choice is only made when one side wins strictly, so no tie rule is involved).
    pub fn simplify(&self, choices: &[Choice]) -> Program {
        self.specialize(choices).unwrap_or_else(|| self.clone())
    }

    /// [`Program::simplify`], or `None` when no choice removes anything. One forward and one
    /// backward sweep over the node list, no hashing: cheap enough to run per brick of a grid.
    pub fn specialize(&self, choices: &[Choice]) -> Option<Program> {
        if !choices.iter().any(|c| *c != Choice::Both) {
            return None;
        }
        // Forward: a decided min/max stands for its winner (itself possibly an alias).
        let mut alias: Vec<NodeId> = (0..self.nodes.len() as NodeId).collect();
        let mut k = 0;
        for (i, node) in self.nodes.iter().enumerate() {
            if let Node::Binary(BinaryOp::Min | BinaryOp::Max, a, b) = *node {
                match choices.get(k).copied().unwrap_or(Choice::Both) {
                    Choice::Left => alias[i] = alias[a as usize],
                    Choice::Right => alias[i] = alias[b as usize],
                    Choice::Both => {}
                }
                k += 1;
            }
        }
        // Backward: what the (aliased) root still reads.
        let root = alias[self.root as usize] as usize;
        let mut live = vec![false; self.nodes.len()];
        live[root] = true;
        for i in (0..=root).rev() {
            if live[i] {
                for a in self.nodes[i].operands() {
                    live[alias[a as usize] as usize] = true;
                }
            }
        }
        let mut renumber = vec![0 as NodeId; self.nodes.len()];
        let mut nodes = Vec::with_capacity(self.nodes.len());
        for (i, node) in self.nodes.iter().enumerate() {
            if !live[i] {
                continue;
            }
            let to = |a: NodeId| renumber[alias[a as usize] as usize];
            let renumbered = match *node {
                Node::Unary(op, a) => Node::Unary(op, to(a)),
                Node::Binary(op, a, b) => Node::Binary(op, to(a), to(b)),
                other => other,
            };
            renumber[i] = nodes.len() as NodeId;
            nodes.push(renumbered);
        }
        let root = renumber[root];
        let tape = Tape::from_nodes(&nodes, root);
        Some(Program { nodes, root, tape })
    }

    /// Instructions on the tape (constants and coordinate loads not counted).
    /// The program as a graph: nodes in evaluation order (every operand before its readers),
    /// constants folded and repeated subexpressions shared, and the node that is the result. For
    /// handing a program to another evaluator (the benchmarks against peer meshers do).
    pub fn nodes(&self) -> (&[Node], NodeId) {
        (&self.nodes, self.root)
    }

    pub fn instruction_count(&self) -> usize {
        self.tape.instrs.len()
    }

    /// Registers the tape needs.
    pub fn slot_count(&self) -> usize {
        self.tape.slot_count
    }

    pub fn constant_count(&self) -> usize {
        self.tape.consts.len()
    }

    /// Min/max instructions: the length of the choice vectors.
    pub fn choice_count(&self) -> usize {
        self.tape.choice_count()
    }

    #[cfg(test)]
    pub(crate) fn tape(&self) -> &Tape {
        &self.tape
    }
}

/// The tape as an assembly-like listing.
impl fmt::Display for Program {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.tape.fmt(f)
    }
}

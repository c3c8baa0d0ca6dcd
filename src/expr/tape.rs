//! The flat program the evaluators run: constants preloaded into the first slots, the three
//! coordinates loaded into theirs, then one instruction per operation node.
//!
//! Slots are registers. A slot is handed back as soon as its value's last reader has run, so a
//! long program needs few of them; that keeps the column evaluator's working set (slots × 64
//! lanes) in cache. An instruction never writes a slot it reads, which lets the column evaluator
//! borrow its output and operands as separate slices. Constant slots are never reused, so they are
//! loaded once per call rather than once per chunk.

use super::ast::Axis;
use super::graph::{Node, NodeId};
use super::ops::{BinaryOp, UnaryOp};
use std::fmt;

pub type Slot = u32;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Instr {
    Unary { op: UnaryOp, out: Slot, a: Slot },
    Binary { op: BinaryOp, out: Slot, a: Slot, b: Slot },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Tape {
    /// `consts[i]` lives in slot `i`.
    pub consts: Vec<f32>,
    /// The slot each coordinate is loaded into, if the program reads it.
    pub inputs: [Option<Slot>; 3],
    pub instrs: Vec<Instr>,
    pub slot_count: usize,
    pub output: Slot,
}

impl Tape {
    /// Allocates slots for a compacted graph (see [`super::graph::Graph::compact`]).
    pub fn from_nodes(nodes: &[Node], root: NodeId) -> Tape {
        let n = nodes.len();
        // Index of the last node reading each node; the root is read "after the end".
        let mut last_use = vec![0usize; n];
        for (i, node) in nodes.iter().enumerate() {
            for a in node.operands() {
                last_use[a as usize] = i;
            }
        }
        last_use[root as usize] = usize::MAX;

        let mut slot = vec![0 as Slot; n];
        let mut consts = Vec::with_capacity(n);
        for (i, node) in nodes.iter().enumerate() {
            if let Node::Const(bits) = node {
                slot[i] = consts.len() as Slot;
                consts.push(f32::from_bits(*bits));
            }
        }
        let mut next = consts.len() as Slot;
        let mut inputs = [None; 3];
        for (i, node) in nodes.iter().enumerate() {
            if let Node::Input(axis) = node {
                slot[i] = next;
                inputs[axis.index()] = Some(next);
                next += 1;
            }
        }
        // Sized up front: a brick's tape is built from its parent's nodes (hundreds on a CSG part),
        // and growing these vectors step by step was a quarter of the building's instructions.
        let mut free: Vec<Slot> = Vec::with_capacity(n);
        let mut instrs = Vec::with_capacity(n);
        // Inputs nobody reads (impossible after compaction, but harmless) are simply never freed.
        for (i, node) in nodes.iter().enumerate() {
            let instr = match *node {
                Node::Const(_) | Node::Input(_) => continue,
                Node::Unary(op, a) => {
                    let out = free.pop().unwrap_or_else(|| bump(&mut next));
                    Instr::Unary { op, out, a: slot[a as usize] }
                }
                Node::Binary(op, a, b) => {
                    let out = free.pop().unwrap_or_else(|| bump(&mut next));
                    Instr::Binary { op, out, a: slot[a as usize], b: slot[b as usize] }
                }
            };
            slot[i] = match instr {
                Instr::Unary { out, .. } | Instr::Binary { out, .. } => out,
            };
            instrs.push(instr);
            // Free operands after choosing the output slot, so the output never aliases them.
            let (a, b) = match *node {
                Node::Unary(_, a) => (a, a),
                Node::Binary(_, a, b) => (a, b),
                _ => unreachable!("constants and inputs were skipped"),
            };
            for a in if a == b { [Some(a), None] } else { [Some(a), Some(b)] }.into_iter().flatten() {
                let a = a as usize;
                if last_use[a] == i && !matches!(nodes[a], Node::Const(_)) {
                    free.push(slot[a]);
                }
            }
        }
        Tape { consts, inputs, instrs, slot_count: next as usize, output: slot[root as usize] }
    }

    /// How many min/max instructions there are: the length of a choice vector.
    pub fn choice_count(&self) -> usize {
        self.instrs
            .iter()
            .filter(|i| matches!(i, Instr::Binary { op: BinaryOp::Min | BinaryOp::Max, .. }))
            .count()
    }
}

fn bump(next: &mut Slot) -> Slot {
    *next += 1;
    *next - 1
}

/// An assembly-like listing, one instruction per line, for debugging and for the curious.
impl fmt::Display for Tape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "; {} constants, {} instructions, {} slots",
            self.consts.len(),
            self.instrs.len(),
            self.slot_count
        )?;
        for (i, c) in self.consts.iter().enumerate() {
            writeln!(f, "r{i} = {c:?}")?;
        }
        for axis in Axis::ALL {
            if let Some(s) = self.inputs[axis.index()] {
                writeln!(f, "r{s} = {}", axis.name())?;
            }
        }
        for instr in &self.instrs {
            match instr {
                Instr::Unary { op, out, a } => writeln!(f, "r{out} = {op} r{a}")?,
                Instr::Binary { op, out, a, b } => writeln!(f, "r{out} = {} r{a} r{b}", op.name())?,
            }
        }
        write!(f, "out r{}", self.output)
    }
}

#[cfg(test)]
mod tests {
    use super::super::graph::Graph;
    use super::super::shapes::Emit;
    use super::*;

    #[test]
    fn slots_are_reused_once_their_last_reader_has_run() {
        // ((x + 1) * 2 + 3) * 4 ...: a chain needs only a couple of slots however long it is.
        let mut g = Graph::new();
        let mut v = g.input(Axis::X);
        for k in 2..51 {
            let c = g.constant(k as f32);
            v = if k % 2 == 0 { g.add(v, c) } else { g.mul(v, c) };
        }
        let (nodes, root) = g.compact(v);
        let tape = Tape::from_nodes(&nodes, root);
        assert_eq!(tape.instrs.len(), 49);
        assert_eq!(tape.consts.len(), 49);
        // The constants, then x's slot and one more taking turns (x's is recycled after its read).
        assert_eq!(tape.slot_count, 49 + 2, "{tape}");
        for instr in &tape.instrs {
            if let Instr::Binary { out, a, b, .. } = instr {
                assert!(out != a && out != b, "an instruction must not overwrite its operand");
            }
        }
    }

    #[test]
    fn listing_names_every_instruction() {
        let mut g = Graph::new();
        let [x, y, _] = g.inputs();
        let s = g.add(x, y);
        let r = g.sqrt(s);
        let (nodes, root) = g.compact(r);
        let text = Tape::from_nodes(&nodes, root).to_string();
        assert!(
            text.contains("= x") && text.contains("= y") && text.contains("add") && text.contains("sqrt"),
            "{text}"
        );
        assert!(!text.contains("= z"), "z is not read: {text}");
    }
}

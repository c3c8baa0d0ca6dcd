//! The expression DAG under construction: hash-consed (an identical operation on identical
//! operands is one node, which is all common-subexpression elimination needs) and folded (an
//! operation on constants is its result, computed by the same [`ops`] functions the evaluator uses).
//!
//! Node ids grow in creation order and operands are always created first, so the node list is
//! already topologically sorted; every later pass is a forward or backward sweep, never recursion.

use super::ast::Axis;
use super::ops::{self, BinaryOp, UnaryOp};
use super::shapes::Emit;
use std::collections::HashMap;

pub type NodeId = u32;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Node {
    /// The bits of an `f32`, so the node can be hashed (and `-0.0` stays distinct from `0.0`).
    Const(u32),
    Input(Axis),
    Unary(UnaryOp, NodeId),
    Binary(BinaryOp, NodeId, NodeId),
}

impl Node {
    pub fn operands(&self) -> impl Iterator<Item = NodeId> {
        let (a, b) = match *self {
            Node::Const(_) | Node::Input(_) => (None, None),
            Node::Unary(_, a) => (Some(a), None),
            Node::Binary(_, a, b) => (Some(a), Some(b)),
        };
        a.into_iter().chain(b)
    }
}

/// Upper bound on nodes. Transforms copy their operand's subgraph, so a few lines that keep
/// transforming bindings of bindings can ask for exponentially many nodes; this stops them.
pub const MAX_NODES: usize = 1 << 18;

#[derive(Default)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, NodeId>,
    overflowed: bool,
}

impl Graph {
    pub fn new() -> Graph {
        Graph::default()
    }

    pub fn node(&self, id: NodeId) -> Node {
        self.nodes[id as usize]
    }

    /// True once [`MAX_NODES`] was reached; from then on every request returns a placeholder, and
    /// the caller must report an error instead of using the graph.
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    pub fn input(&mut self, axis: Axis) -> NodeId {
        self.intern(Node::Input(axis))
    }

    pub fn inputs(&mut self) -> [NodeId; 3] {
        Axis::ALL.map(|a| self.input(a))
    }

    fn intern(&mut self, node: Node) -> NodeId {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        if self.nodes.len() >= MAX_NODES {
            self.overflowed = true;
            // Any existing node will do as a placeholder; the result is discarded.
            return 0;
        }
        let id = self.nodes.len() as NodeId;
        self.nodes.push(node);
        self.index.insert(node, id);
        id
    }

    fn constant_value(&self, id: NodeId) -> Option<f32> {
        match self.nodes.get(id as usize) {
            Some(Node::Const(bits)) => Some(f32::from_bits(*bits)),
            _ => None,
        }
    }

    /// Rebuilds the subgraph under `root` with the inputs replaced by `coords`: what a transform
    /// does to a binding that was built in untransformed coordinates. Re-interning folds again and
    /// shares whatever did not depend on the coordinates.
    pub fn substitute(&mut self, root: NodeId, coords: [NodeId; 3]) -> NodeId {
        let mut reachable = vec![root];
        let mut seen = std::collections::HashSet::from([root]);
        let mut i = 0;
        while i < reachable.len() {
            let node = self.node(reachable[i]);
            for a in node.operands() {
                if seen.insert(a) {
                    reachable.push(a);
                }
            }
            i += 1;
        }
        reachable.sort_unstable();
        let mut map: HashMap<NodeId, NodeId> = HashMap::with_capacity(reachable.len());
        for id in reachable {
            let new = match self.node(id) {
                Node::Const(_) => id,
                Node::Input(axis) => coords[axis.index()],
                Node::Unary(op, a) => self.unary(op, map[&a]),
                Node::Binary(op, a, b) => self.binary(op, map[&a], map[&b]),
            };
            map.insert(id, new);
        }
        map[&root]
    }

    /// The nodes reachable from `root`, renumbered densely in the same (topological) order, and
    /// the new id of `root`. Dead nodes (unused bindings, folded-away operands) disappear here.
    pub fn compact(&self, root: NodeId) -> (Vec<Node>, NodeId) {
        let mut live = vec![false; self.nodes.len()];
        live[root as usize] = true;
        for id in (0..=root as usize).rev() {
            if live[id] {
                for a in self.nodes[id].operands() {
                    live[a as usize] = true;
                }
            }
        }
        let mut renumber = vec![0 as NodeId; self.nodes.len()];
        let mut out = Vec::new();
        for (id, node) in self.nodes.iter().enumerate() {
            if !live[id] {
                continue;
            }
            renumber[id] = out.len() as NodeId;
            out.push(match *node {
                Node::Unary(op, a) => Node::Unary(op, renumber[a as usize]),
                Node::Binary(op, a, b) => Node::Binary(op, renumber[a as usize], renumber[b as usize]),
                other => other,
            });
        }
        (out, renumber[root as usize])
    }
}

impl Emit for Graph {
    type V = NodeId;

    fn constant(&mut self, c: f32) -> NodeId {
        self.intern(Node::Const(c.to_bits()))
    }

    fn as_constant(&self, v: NodeId) -> Option<f32> {
        self.constant_value(v)
    }

    fn unary(&mut self, op: UnaryOp, a: NodeId) -> NodeId {
        if let Some(c) = self.constant_value(a) {
            return self.constant(ops::unary(op, c));
        }
        // Identities that hold for every input, NaN and signed zero included.
        match (op, self.node(a)) {
            (UnaryOp::Neg, Node::Unary(UnaryOp::Neg, inner)) => return inner,
            (UnaryOp::Abs, Node::Unary(UnaryOp::Abs | UnaryOp::Neg, inner)) => {
                return self.unary(UnaryOp::Abs, inner)
            }
            (UnaryOp::Powi(1), _) => return a,
            _ => {}
        }
        self.intern(Node::Unary(op, a))
    }

    fn binary(&mut self, op: BinaryOp, a: NodeId, b: NodeId) -> NodeId {
        let (ca, cb) = (self.constant_value(a), self.constant_value(b));
        if let (Some(x), Some(y)) = (ca, cb) {
            return self.constant(ops::binary(op, x, y));
        }
        // Only identities that are exact for every input: `x + 0` is not (it turns -0 into +0),
        // and `x * 0` is not (inf * 0 is NaN).
        match (op, ca, cb) {
            (BinaryOp::Sub, _, Some(z)) if z == 0.0 && z.is_sign_positive() => return a,
            (BinaryOp::Mul, Some(1.0), _) => return b,
            (BinaryOp::Mul | BinaryOp::Div, _, Some(1.0)) => return a,
            _ => {}
        }
        let (a, b) = if op.is_commutative() && b < a { (b, a) } else { (a, b) };
        self.intern(Node::Binary(op, a, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_operations_are_one_node() {
        let mut g = Graph::new();
        let [x, y, _] = g.inputs();
        let a = g.add(x, y);
        let b = g.add(y, x);
        assert_eq!(a, b, "addition is commutative, so operand order must not matter");
        let m1 = g.min(x, y);
        let m2 = g.min(y, x);
        assert_ne!(m1, m2, "min keeps its order: the left operand wins ties");
    }

    #[test]
    fn constants_fold_with_evaluator_semantics() {
        let mut g = Graph::new();
        let two = g.constant(2.0);
        let s = g.sqrt(two);
        assert_eq!(g.as_constant(s), Some(2f32.sqrt()));
        let x = g.input(Axis::X);
        let one = g.constant(1.0);
        assert_eq!(g.mul(one, x), x);
        assert_eq!(g.div(x, one), x);
        let zero = g.constant(0.0);
        assert_eq!(g.sub(x, zero), x);
        assert_ne!(g.add(x, zero), x, "x + 0 is not exact for x = -0");
        let n = g.neg(x);
        assert_eq!(g.neg(n), x);
    }

    #[test]
    fn substitution_rebuilds_only_what_depends_on_coordinates() {
        let mut g = Graph::new();
        let [x, y, z] = g.inputs();
        let c = g.constant(3.0);
        let s = g.sqrt(c);
        let e = g.mul(x, s);
        let moved = g.substitute(e, [y, y, z]);
        let expect = g.mul(y, s);
        assert_eq!(moved, expect);
        let (nodes, root) = g.compact(moved);
        assert_eq!(nodes.len(), 3, "y, the folded constant and the product: {nodes:?}");
        assert_eq!(root, 2);
    }
}

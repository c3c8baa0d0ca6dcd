//! Topology creation (§3): the cells of the dual grid, one per octree vertex, each listing the eight
//! leaves around that vertex (octant `c = x | y << 1 | z << 2` relative to the vertex). Leaves larger
//! than their neighbours appear several times, so adaptive dual cells are degenerate hexahedra.
//!
//! The traversal is Ju et al.'s, extended to vertices: `cell_proc` on a node, `face_proc` on two
//! face-adjacent nodes, `edge_proc` on four nodes around an edge, `vert_proc` on eight nodes around a
//! vertex; each recurses into the children touching the shared face/edge/vertex, passing a leaf on
//! unchanged. A dual cell is emitted when `vert_proc` holds eight leaves. There is one call per
//! octree cell, face, edge and vertex, so the cost is linear in the octree and no neighbour is ever
//! searched for.
//!
//! **The boundary.** The root is treated as the centre of a 3 × 3 × 3 block whose other 26 cells
//! are degenerate: flattened onto the root's faces, edges and corners. Such a cell is a [`CellRef`]
//! with some axes *clamped* to one side; its children are the real node's children on that side, so
//! it mirrors the subdivision of the root's boundary, and its leaves carry vertices on the boundary
//! (found by the leaf's QEF restricted to that face, edge or corner). Calling `face_proc`,
//! `edge_proc` and `vert_proc` between the root and these cells gives the dual cells of the octree
//! vertices on the root's boundary, so the dual grid fills the root cube exactly and the contour is
//! closed wherever the surface stays inside the bounds.

use super::octree::{Kind, Octree};

/// A node, or its degenerate copy flattened onto the root's boundary: for axis `a`, bits `2a..2a+2`
/// of `clamp` are 0 (free), 1 (flattened onto the low side) or 2 (the high side).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CellRef {
    pub node: u32,
    pub clamp: u8,
}

impl CellRef {
    /// 0 (free), 1 (low) or 2 (high) on `axis`.
    pub fn side(self, axis: usize) -> u8 {
        (self.clamp >> (2 * axis)) & 3
    }
}

/// Calls `emit` once per dual cell (octree vertex, boundary included).
pub fn for_each_dual_cell(tree: &Octree, mut emit: impl FnMut(&[CellRef; 8])) {
    let mut walk = Walk { tree, emit: &mut emit };
    let root = CellRef { node: 0, clamp: 0 };
    // The degenerate neighbour at offset o ∈ {-1, 0, 1}³ from the root.
    let around = |o: [i32; 3]| -> CellRef {
        let mut clamp = 0u8;
        for (a, &oa) in o.iter().enumerate() {
            let side = match oa {
                -1 => 1,
                1 => 2,
                _ => 0,
            };
            clamp |= side << (2 * a);
        }
        CellRef { node: 0, clamp }
    };
    walk.cell(root);
    for a in 0..3 {
        let mut e = [0; 3];
        e[a] = -1;
        walk.face([around(e), root], a);
        e[a] = 1;
        walk.face([root, around(e)], a);
    }
    // Offset along an axis of the cell on side `bit` (0 low, 1 high) of a root boundary at `side`.
    let offset = |side: i32, bit: usize| -> i32 {
        match (side, bit) {
            (1, 1) => 1,
            (-1, 0) => -1,
            _ => 0,
        }
    };
    for e in 0..3 {
        let (p1, p2) = ((e + 1) % 3, (e + 2) % 3);
        for s1 in [-1, 1] {
            for s2 in [-1, 1] {
                let cells = std::array::from_fn(|k| {
                    let mut o = [0; 3];
                    o[p1] = offset(s1, k & 1);
                    o[p2] = offset(s2, k >> 1);
                    around(o)
                });
                walk.edge(cells, e);
            }
        }
    }
    for corner in 0..8usize {
        let sides: [i32; 3] = std::array::from_fn(|a| if corner >> a & 1 == 1 { 1 } else { -1 });
        let cells = std::array::from_fn(|i| around(std::array::from_fn(|a| offset(sides[a], i >> a & 1))));
        walk.vert(cells);
    }
}

struct Walk<'a, F: FnMut(&[CellRef; 8])> {
    tree: &'a Octree,
    emit: &'a mut F,
}

impl<F: FnMut(&[CellRef; 8])> Walk<'_, F> {
    fn is_leaf(&self, r: CellRef) -> bool {
        self.tree.nodes[r.node as usize].kind != Kind::Internal
    }

    /// The child of `r` in octant `i` (a leaf stands for all its octants).
    fn child(&self, r: CellRef, i: usize) -> CellRef {
        let node = &self.tree.nodes[r.node as usize];
        if node.kind != Kind::Internal {
            return r;
        }
        let mut j = i;
        for a in 0..3 {
            match r.side(a) {
                1 => j &= !(1 << a),
                2 => j |= 1 << a,
                _ => {}
            }
        }
        CellRef { node: node.children + j as u32, clamp: r.clamp }
    }

    fn cell(&mut self, n: CellRef) {
        if self.is_leaf(n) {
            return;
        }
        let c: [CellRef; 8] = std::array::from_fn(|i| self.child(n, i));
        for &child in &c {
            self.cell(child);
        }
        for a in 0..3 {
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            for k in 0..4 {
                let base = (k & 1) << u | (k >> 1) << v;
                self.face([c[base], c[base | 1 << a]], a);
            }
        }
        for e in 0..3 {
            let (p1, p2) = ((e + 1) % 3, (e + 2) % 3);
            for h in 0..2 {
                self.edge(std::array::from_fn(|k| c[h << e | (k & 1) << p1 | (k >> 1) << p2]), e);
            }
        }
        self.vert(c);
    }

    /// `n[0]` below and `n[1]` above a face perpendicular to `a`.
    fn face(&mut self, n: [CellRef; 2], a: usize) {
        if n.iter().all(|&r| self.is_leaf(r)) {
            return;
        }
        let (u, v) = ((a + 1) % 3, (a + 2) % 3);
        for k in 0..4 {
            let base = (k & 1) << u | (k >> 1) << v;
            self.face([self.child(n[0], base | 1 << a), self.child(n[1], base)], a);
        }
        // The four half-edges through the face centre, along each in-plane axis.
        for (e, o) in [(u, v), (v, u)] {
            let (p1, p2) = ((e + 1) % 3, (e + 2) % 3);
            for h in 0..2 {
                let cells = std::array::from_fn(|k| {
                    let mut side = [0usize; 3];
                    side[p1] = k & 1;
                    side[p2] = k >> 1;
                    let s = side[a];
                    self.child(n[s], (1 - s) << a | side[o] << o | h << e)
                });
                self.edge(cells, e);
            }
        }
        self.vert(std::array::from_fn(|i| self.child(n[i >> a & 1], i ^ (1 << a))));
    }

    /// Four nodes around an edge along `e`: node `k` lies on side `k & 1` of the edge along
    /// `(e + 1) % 3` and on side `k >> 1` along `(e + 2) % 3`.
    fn edge(&mut self, n: [CellRef; 4], e: usize) {
        if n.iter().all(|&r| self.is_leaf(r)) {
            return;
        }
        let (p1, p2) = ((e + 1) % 3, (e + 2) % 3);
        for h in 0..2 {
            let cells = std::array::from_fn(|k| {
                self.child(n[k], h << e | (1 - (k & 1)) << p1 | (1 - (k >> 1)) << p2)
            });
            self.edge(cells, e);
        }
        self.vert(std::array::from_fn(|i| {
            let k = (i >> p1 & 1) | (i >> p2 & 1) << 1;
            self.child(n[k], i ^ (1 << p1 | 1 << p2))
        }));
    }

    /// Eight nodes around a vertex, node `i` in octant `i`.
    fn vert(&mut self, n: [CellRef; 8]) {
        if n.iter().all(|&r| self.is_leaf(r)) {
            (self.emit)(&n);
            return;
        }
        self.vert(std::array::from_fn(|i| self.child(n[i], i ^ 7)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dmc::octree::Params;
    use crate::expr::compile;
    use glam::Vec3;

    fn tree(text: &str, max_depth: u8) -> Octree {
        let field = compile(text).unwrap();
        let params = Params {
            iso: 0.0,
            tolerance: 1e-3,
            max_depth,
            samples_per_cell: 3,
            prune: false,
            max_leaves: 1 << 20,
            accuracy_rule: true,
            vertex_reach: 0.0,
        };
        Octree::build(&field, Vec3::splat(-1.0), 2.0, params).unwrap()
    }

    /// Whether `r`'s cell (flattened where clamped) contains `vertex` and extends into octant `octant`.
    fn touches(t: &Octree, r: CellRef, octant: usize, vertex: [f32; 3]) -> bool {
        let (lo, hi) = t.cell(r.node);
        let eps = 1e-6;
        (0..3).all(|a| {
            let (l, h) = match r.side(a) {
                1 => (lo[a], lo[a]),
                2 => (hi[a], hi[a]),
                _ => (lo[a], hi[a]),
            };
            let contains = l <= vertex[a] + eps && h >= vertex[a] - eps;
            let plus = octant >> a & 1 == 1;
            let extends = r.side(a) != 0 || if plus { h > vertex[a] + eps } else { l < vertex[a] - eps };
            contains && extends
        })
    }

    #[test]
    fn one_dual_cell_per_octree_vertex_and_each_surrounds_its_vertex() {
        for (text, depth) in [("x + y", 0), ("length(x, y, z) - 0.5", 4), ("max(box(.3,.4,.5), -x)", 4)] {
            let t = tree(text, depth);
            // Distinct corners of all leaves = octree vertices.
            let mut corners = std::collections::BTreeSet::new();
            for n in t.leaves() {
                let node = t.nodes[n as usize];
                let span = 1u32 << (t.params.max_depth - node.depth);
                for c in 0..8u32 {
                    let bit = |a: u32| (c >> a & 1) * span;
                    corners.insert([node.coord[0] + bit(0), node.coord[1] + bit(1), node.coord[2] + bit(2)]);
                }
            }
            let mut cells = Vec::new();
            for_each_dual_cell(&t, |c| cells.push(*c));
            assert_eq!(cells.len(), corners.len(), "{text}");
            // Each cell's eight refs meet at one point: the common corner of their cells.
            for c in &cells {
                // The vertex is a corner of the smallest of the eight cells.
                let i = (0..8).max_by_key(|&i| t.nodes[c[i].node as usize].depth).unwrap();
                let (lo, hi) = t.cell(c[i].node);
                let v: [f32; 3] = std::array::from_fn(|a| match c[i].side(a) {
                    1 => lo[a],
                    2 => hi[a],
                    _ if i >> a & 1 == 1 => lo[a],
                    _ => hi[a],
                });
                for (i, &r) in c.iter().enumerate() {
                    assert!(touches(&t, r, i, v), "{text}: {c:?} around {v:?}");
                }
            }
        }
    }
}

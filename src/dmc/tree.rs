//! The octree DMC adapts: a cube of `2^depth` finest cells on a side, anchored at the lowest corner
//! of the bounds, whose finest cells are cubes of the bounds' longest side over `2^depth`, clipped
//! to the bounds: along a shorter side the last cell is cut by the bounds' face. A node that lies
//! wholly outside the bounds is [`Kind::Absent`]; one that crosses their far faces is the box where
//! the two meet, so every leaf, every vertex and every sample lies inside the bounds.
//!
//! Coordinates are integers in units of the finest cell, so a node's geometry never depends on the
//! order nodes were built or merged in.

use super::qef::Qef;
use glam::Vec3;

pub const NONE: u32 = u32::MAX;

/// Deepest octree the options accept: 2^16 finest cells per side is far beyond what fits in memory
/// near a surface and still exact in the integer coordinates used here.
pub const MAX_DEPTH_LIMIT: u8 = 16;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Split; its eight children are consecutive from [`Node::children`].
    Internal,
    /// A leaf the surface may pass through: it has a QEF and a vertex placed by it.
    Surface,
    /// A leaf whose interval bounds exclude the iso-level: wholly inside or outside, its vertex is
    /// its centre.
    Empty { inside: bool },
    /// Outside the grid: not part of the octree.
    Absent,
}

#[derive(Debug, Clone, Copy)]
pub struct Node {
    /// Lowest corner, in finest cells.
    pub coord: [u32; 3],
    pub level: u8,
    pub kind: Kind,
    pub children: u32,
    /// Index into [`Octree::qefs`] for surface leaves (and, during simplification, merged nodes).
    pub qef: u32,
    /// The dual vertex and `f - iso` there (leaves only).
    pub vertex: Vec3,
    pub value: f32,
}

pub struct Octree {
    pub nodes: Vec<Node>,
    pub qefs: Vec<Qef>,
    pub depth: u8,
    /// Finest cells along each axis: the grid the octree is clipped to.
    pub cells: [u32; 3],
    pub origin: Vec3,
    /// The bounds' far corner: lattice points beyond it are clipped onto it.
    pub max: Vec3,
    /// Side of a finest cell.
    pub h: f32,
}

impl Octree {
    /// A root (internal, to be built) over the bounds `[min, max]`.
    pub fn new(min: Vec3, max: Vec3, depth: u8) -> Octree {
        let h = (max - min).max_element() / (1u32 << depth) as f32;
        // Whole cells where an extent is a whole number of them (to rounding), else one more, cut.
        let cells =
            [0, 1, 2].map(|a| (((max[a] - min[a]) / h - 1e-3).ceil().max(1.0) as u32).min(1 << depth));
        let root = Node {
            coord: [0; 3],
            level: 0,
            kind: Kind::Internal,
            children: NONE,
            qef: NONE,
            vertex: Vec3::ZERO,
            value: 0.0,
        };
        Octree { nodes: vec![root], qefs: Vec::new(), depth, cells, origin: min, max, h }
    }

    /// Side of node `n` in finest cells.
    pub fn side(&self, n: u32) -> u32 {
        1 << (self.depth - self.nodes[n as usize].level)
    }

    /// The box of node `n` clipped to the grid, in finest cells: `[lo, hi]` per axis.
    pub fn int_box(&self, n: u32) -> ([u32; 3], [u32; 3]) {
        let node = &self.nodes[n as usize];
        let s = self.side(n);
        let hi = std::array::from_fn(|a| (node.coord[a] + s).min(self.cells[a]));
        (node.coord, hi)
    }

    /// World position of a lattice point given in finest cells (clipped to the bounds).
    pub fn point(&self, p: [u32; 3]) -> Vec3 {
        self.lattice(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
    }

    /// World position of a point given in (fractional) finest cells, clipped to the bounds.
    pub fn lattice(&self, p: Vec3) -> Vec3 {
        let q = self.origin + p * self.h;
        let last = Vec3::new(self.cells[0] as f32, self.cells[1] as f32, self.cells[2] as f32);
        // The far faces are the bounds' own, not the lattice's.
        Vec3::select(p.cmpge(last), self.max, q.min(self.max))
    }

    /// The world box of node `n` (clipped to the grid).
    pub fn world_box(&self, n: u32) -> (Vec3, Vec3) {
        let (lo, hi) = self.int_box(n);
        (self.point(lo), self.point(hi))
    }

    pub fn is_leaf(&self, n: u32) -> bool {
        !matches!(self.nodes[n as usize].kind, Kind::Internal)
    }

    /// Splits leaf `n` into eight children (absent where they miss the grid), returning the first.
    pub fn split(&mut self, n: u32) -> u32 {
        let first = self.nodes.len() as u32;
        let node = self.nodes[n as usize];
        let half = self.side(n) / 2;
        for c in 0..8u32 {
            let coord = std::array::from_fn(|a| node.coord[a] + ((c >> a) & 1) * half);
            let outside = (0..3).any(|a| coord[a] >= self.cells[a]);
            self.nodes.push(Node {
                coord,
                level: node.level + 1,
                kind: if outside { Kind::Absent } else { Kind::Surface },
                children: NONE,
                qef: NONE,
                vertex: Vec3::ZERO,
                value: 0.0,
            });
        }
        let node = &mut self.nodes[n as usize];
        node.kind = Kind::Internal;
        node.children = first;
        first
    }

    /// The leaf holding finest cell `q`, seen with `merged` (an internal node) as a leaf.
    pub fn locate(&self, q: [u32; 3], merged: u32) -> u32 {
        self.locate_from(0, q, merged)
    }

    /// The deepest node holding every finest cell of the box `[lo, hi]`, or a leaf (or `merged`)
    /// holding some of them.
    pub fn common_ancestor(&self, lo: [u32; 3], hi: [u32; 3], merged: u32) -> u32 {
        let mut n = 0u32;
        loop {
            let node = &self.nodes[n as usize];
            if n == merged || node.kind != Kind::Internal {
                return n;
            }
            let half = 1u32 << (self.depth - node.level - 1);
            let child =
                |q: [u32; 3]| (0..3).fold(0, |c, a| c | ((((q[a] - node.coord[a]) >= half) as u32) << a));
            let (a, b) = (child(lo), child(hi));
            if a != b {
                return n;
            }
            n = node.children + a;
        }
    }

    /// [`Octree::locate`] starting from node `n`, which holds `q`.
    pub fn locate_from(&self, start: u32, q: [u32; 3], merged: u32) -> u32 {
        let mut n = start;
        loop {
            let node = &self.nodes[n as usize];
            if n == merged || node.kind != Kind::Internal {
                return n;
            }
            let half = 1u32 << (self.depth - node.level - 1);
            let c = (0..3).fold(0, |c, a| c | ((((q[a] - node.coord[a]) >= half) as u32) << a));
            n = node.children + c;
        }
    }

    /// The leaves reachable from the root (merged nodes' old children are not), absent ones
    /// excluded, in depth-first order.
    pub fn leaves(&self) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            match self.nodes[n as usize].kind {
                Kind::Internal => stack.extend((0..8).map(|c| self.nodes[n as usize].children + c)),
                Kind::Absent => {}
                _ => out.push(n),
            }
        }
        out
    }
}

//! Feature isolation (§2): one vertex per leaf, at the minimiser of the leaf's QEF inside the leaf,
//! with the value of the field there; and the vertices of the degenerate boundary cells (see
//! [`super::dual`]), found by the same QEF restricted to the leaf's face, edge or corner on the root's
//! boundary.
//!
//! Choices:
//! - The vertex is kept in the leaf shrunk by [`SHRINK`] of its side, so two leaves never share a
//!   vertex position (a feature exactly on a cell face would otherwise give both cells the same
//!   point, and the mesh two coincident vertices). Boundary vertices keep their pinned coordinate.
//! - The stored value is `f(vertex) - iso`, evaluated, not the QEF's estimate: the sign of a vertex
//!   is then the sign of the field at a point of its leaf, which the pruning argument relies on.
//! - Sliver elimination (§4): where the cell straddles the iso-level, its QEF has rank one (the
//!   function is locally linear there) and the QEF restricted to `w = 0` has a residual within the
//!   tolerance, the restricted minimiser (a point on the estimated surface) is used instead. The
//!   crossings around such a vertex all land next to it and [`super::slivers`] merges them into it.
//!   Measured on a ball this halves the triangles and lifts the smallest angle from ~3° to ~25°.
//! - Except next to a feature on the surface ([`near_features`]): a vertex with a value of about
//!   zero is harmless while its neighbours have definite signs (its crossings then all land on it),
//!   but if the vertices around a cube's corner all sat on the surface their signs would be noise
//!   and the corner would be cut off. Leaves sharing a mixed dual cell with a surface feature (QEF
//!   rank two or more, vertex on the surface) keep the free minimiser.
//! - A pruned leaf's vertex is its centre (flattened onto the boundary for boundary cells); it never
//!   reaches the output (see `refine.rs`).

use super::dual::CellRef;
use super::octree::{Kind, Octree, NONE};
use super::qef::Solution;
use crate::field::Field;
use glam::Vec3;
use std::collections::HashMap;

/// Fraction of a leaf's side kept free between its vertex and its faces.
pub const SHRINK: f32 = 1e-4;

/// Places the vertex of every sampled leaf that has none yet.
pub fn isolate(tree: &mut Octree, field: &dyn Field, sliver_elimination: bool) {
    for n in 0..tree.nodes.len() as u32 {
        let node = tree.nodes[n as usize];
        if node.kind != Kind::Leaf || node.has_vertex {
            continue;
        }
        let (lo, hi) = shrunk(tree, n);
        let allow = sliver_elimination && node.straddles && !node.keep_free;
        let (solution, on_surface) = solve(tree, n, lo, hi, allow);
        let vertex = solution.position.as_vec3();
        let value = field.value(vertex) - tree.params.iso;
        let node = &mut tree.nodes[n as usize];
        node.vertex = vertex;
        node.value = value;
        node.has_vertex = true;
        node.on_surface = on_surface;
    }
}

/// Leaves whose vertex sliver elimination moved onto the surface but which share a mixed dual
/// cell with a feature leaf (QEF rank 2 or more: a crease or corner of the function). Near a
/// feature the vertices around it must keep the function's sign pattern, or the feature is cut
/// off (a chamfer across a cube's edge); these fall back to the free minimiser.
pub fn near_features(tree: &Octree, refs: &[[CellRef; 8]]) -> Vec<u32> {
    let is_feature = |n: u32| {
        let node = &tree.nodes[n as usize];
        node.kind == Kind::Leaf
            && node.straddles
            && node.value.abs() <= tree.params.tolerance
            && tree.qefs[node.qef as usize].rank() >= 2
    };
    let mut out: Vec<u32> = refs
        .iter()
        .filter(|cell| cell.iter().any(|r| is_feature(r.node)))
        .flat_map(|cell| cell.iter().map(|r| r.node))
        .filter(|&n| tree.nodes[n as usize].on_surface)
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

fn shrunk(tree: &Octree, n: u32) -> (Vec3, Vec3) {
    let (lo, hi) = tree.cell(n);
    let margin = (hi - lo) * SHRINK;
    (lo + margin, hi - margin)
}

/// The free minimiser, or (when allowed, the QEF is rank one and the restricted residual within
/// the tolerance) the minimiser on `w = 0`; and whether it is the latter.
fn solve(tree: &Octree, n: u32, lo: Vec3, hi: Vec3, restricted: bool) -> (Solution, bool) {
    let node = &tree.nodes[n as usize];
    let qef = &tree.qefs[node.qef as usize];
    if restricted && qef.rank() == 1 {
        let on_surface = qef.minimise_in_box(lo, hi, Some(0.0));
        if on_surface.rms <= tree.params.tolerance as f64 {
            return (on_surface, true);
        }
    }
    (qef.minimise_in_box(lo, hi, None), false)
}

/// The dual vertices met so far: position and `f - iso`, numbered densely.
#[derive(Debug, Default)]
pub struct DualVertices {
    pub positions: Vec<Vec3>,
    pub values: Vec<f32>,
    /// Per node, the id of its own vertex.
    of_node: Vec<u32>,
    /// Boundary copies of leaves.
    of_boundary: HashMap<CellRef, u32>,
}

impl DualVertices {
    pub fn new(tree: &Octree) -> DualVertices {
        DualVertices { of_node: vec![NONE; tree.nodes.len()], ..DualVertices::default() }
    }

    /// The id of the vertex of leaf reference `r`, placing it first if it is a boundary copy.
    pub fn id(&mut self, tree: &Octree, field: &dyn Field, r: CellRef) -> u32 {
        if r.clamp == 0 {
            let slot = self.of_node[r.node as usize];
            if slot != NONE {
                return slot;
            }
            let node = &tree.nodes[r.node as usize];
            debug_assert!(node.has_vertex);
            let id = self.push(node.vertex, node.value);
            self.of_node[r.node as usize] = id;
            return id;
        }
        if let Some(&id) = self.of_boundary.get(&r) {
            return id;
        }
        let (p, v) = boundary_vertex(tree, field, r);
        let id = self.push(p, v);
        self.of_boundary.insert(r, id);
        id
    }

    fn push(&mut self, p: Vec3, v: f32) -> u32 {
        self.positions.push(p);
        self.values.push(v);
        self.positions.len() as u32 - 1
    }
}

/// The vertex of a leaf's face, edge or corner on the root's boundary.
fn boundary_vertex(tree: &Octree, field: &dyn Field, r: CellRef) -> (Vec3, f32) {
    let (cell_lo, cell_hi) = tree.cell(r.node);
    let (mut lo, mut hi) = shrunk(tree, r.node);
    for a in 0..3 {
        let pinned = match r.side(a) {
            1 => cell_lo[a],
            2 => cell_hi[a],
            _ => continue,
        };
        lo[a] = pinned;
        hi[a] = pinned;
    }
    let node = &tree.nodes[r.node as usize];
    let p = match node.kind {
        Kind::Pruned => (lo + hi) * 0.5,
        _ => solve(tree, r.node, lo, hi, false).0.position.as_vec3().clamp(lo, hi),
    };
    (p, field.value(p) - tree.params.iso)
}

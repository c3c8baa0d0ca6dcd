//! Which leaves to treat again once the dual grid is known. Three rules, each a fixpoint the driver
//! in `mod.rs` iterates to:
//!
//! 1. **Un-prune** every pruned leaf in a dual cell whose vertices are not all on one side of the
//!    iso-level ("mixed"). Afterwards pruning changes nothing the contour can see. Let `T` be the
//!    unpruned octree and `T'` the pruned one after this fixpoint; the sampled leaves of `T'` are
//!    leaves of `T` (same cells, same QEF, same vertex), and each pruned leaf `P` of `T'` stands for
//!    a subtree of `T` on whose closed cell the field has one sign (interval bounds are
//!    conservative), so every vertex inside `P`, in either tree, has that sign. A mixed dual cell of
//!    `T'` cannot hold `P` (rule 1). A mixed dual cell of `T` at vertex `v` holding a descendant of
//!    `P` needs a leaf `Q` of the other sign touching `v`, outside `P`; the leaf of `T'` containing
//!    `Q` is `Q` itself or a pruned leaf of `Q`'s sign, and it touches `P` — so they share an octree
//!    vertex of `T'`, whose dual cell is mixed and holds `P`: excluded by rule 1. So both trees have
//!    exactly the same mixed dual cells, with the same vertices, and the same contour.
//! 2. **Represent** the surface: a sampled leaf whose samples straddle the iso-level but which lies
//!    in no mixed dual cell is split. DMC only sees the surface where dual vertices differ in sign; a
//!    leaf whose vertex sits exactly on a feature of the surface (a box corner: value 0) can hide a
//!    whole component from a coarse dual grid.
//! 3. **Accuracy**: where a triangle strays from the surface by more than the tolerance
//!    ([`super::contour::triangle_error`]), the largest sampled leaves of the dual cell that made it
//!    are split. The QEF residual measures how well one vertex explains the function's tangent
//!    planes, not how well flat triangles between vertices follow a curved surface: the distance
//!    field of a ball is a cone whose tangent planes all meet at the centre, so a single leaf
//!    explains it exactly and would mesh a ball as a handful of triangles.
//!
//! Rules 2 and 3 depend only on mixed dual cells and the contour, which rule 1 makes identical with
//! and without pruning, so they refine the same leaves in both.

use super::contour::{triangle_error, Contour};
use super::dual::CellRef;
use super::memo::Memo;
use super::octree::{Kind, Octree};
use crate::field::{finite_difference_gradient, Field};
use glam::Vec3;

fn is_mixed(cell: &[u32; 8], values: &[f32]) -> bool {
    let first = values[cell[0] as usize] < 0.0;
    cell.iter().any(|&v| (values[v as usize] < 0.0) != first)
}

/// Rule 1: pruned leaves in mixed dual cells.
pub fn to_unprune(tree: &Octree, refs: &[[CellRef; 8]], ids: &[[u32; 8]], values: &[f32]) -> Vec<u32> {
    let mut out: Vec<u32> = refs
        .iter()
        .zip(ids)
        .filter(|(_, cell)| is_mixed(cell, values))
        .flat_map(|(r, _)| r.iter().map(|r| r.node))
        .filter(|&n| tree.nodes[n as usize].kind == Kind::Pruned)
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// What to do to the octree after a contour: leaves to split, leaves whose vertex goes to the centre.
#[derive(Debug, Default)]
pub struct Plan {
    pub split: Vec<u32>,
    pub centre: Vec<u32>,
}

impl Plan {
    pub fn is_empty(&self) -> bool {
        self.split.is_empty() && self.centre.is_empty()
    }

    fn finish(mut self) -> Plan {
        for v in [&mut self.split, &mut self.centre] {
            v.sort_unstable();
            v.dedup();
        }
        // A leaf being split needs no centring.
        let split = &self.split;
        self.centre.retain(|n| split.binary_search(n).is_err());
        self
    }

    /// Split the largest splittable sampled leaves of a dual cell; where none can be split,
    /// centre its sampled leaves instead (when `centre_if_stuck`).
    fn treat(&mut self, tree: &Octree, cell: &[CellRef; 8], centre_if_stuck: bool) {
        let largest =
            cell.iter().filter(|r| splittable(tree, r.node)).map(|r| tree.nodes[r.node as usize].depth).min();
        match largest {
            Some(depth) => self.split.extend(
                cell.iter()
                    .map(|r| r.node)
                    .filter(|&n| splittable(tree, n) && tree.nodes[n as usize].depth == depth),
            ),
            None if centre_if_stuck => {
                self.centre.extend(cell.iter().map(|r| r.node).filter(|&n| {
                    tree.nodes[n as usize].kind == Kind::Leaf && !tree.nodes[n as usize].centred
                }))
            }
            None => {}
        }
    }
}

fn splittable(tree: &Octree, n: u32) -> bool {
    tree.nodes[n as usize].kind == Kind::Leaf && tree.nodes[n as usize].depth < tree.params.max_depth
}

/// Rules 2, 3 and 4 on a contour of the mixed dual cells `refs` (vertex ids `ids`); gradients and
/// triangle errors measured in earlier rounds come from `memo`.
///
/// Rule 4: a triangle facing away from the field's gradient at all three of its vertices (which lie
/// on the surface, so their gradient is the surface normal of their own sheet) is folded over.
/// Vertices far from their cells' centres can fold a dual cell. Its largest leaves are split; at
/// the maximum depth its leaves fall back to their centres instead, where the dual grid is that of
/// the paper's §5 variant and cannot fold, at the price of sharpness there.
pub fn plan(
    tree: &Octree,
    field: &dyn Field,
    refs: &[[CellRef; 8]],
    ids: &[[u32; 8]],
    values: &[f32],
    contour: &Contour,
    memo: &mut Memo,
) -> Plan {
    let mut plan = Plan::default();
    let mut represented = vec![false; tree.nodes.len()];
    for (r, cell) in refs.iter().zip(ids) {
        if is_mixed(cell, values) {
            for r in r {
                represented[r.node as usize] = true;
            }
        }
    }
    plan.split
        .extend(tree.leaves().filter(|&n| {
            splittable(tree, n) && tree.nodes[n as usize].straddles && !represented[n as usize]
        }));
    let tolerance = tree.params.tolerance;
    let h = tree.cell_size(tree.params.max_depth) * 1e-2;
    let mesh = &contour.mesh;
    let gradients: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|&p| {
            memo.gradient(p, || field.gradient(p).unwrap_or_else(|| finite_difference_gradient(field, p, h)))
        })
        .collect();
    let mut inaccurate = Vec::new();
    let mut folded = Vec::new();
    for t in 0..mesh.triangle_count() {
        let [a, b, c] = mesh.corners(t);
        let normal = (b - a).cross(c - a);
        if mesh.triangles[t].iter().all(|&v| normal.dot(gradients[v as usize]) < 0.0) {
            folded.push(contour.cell_of_triangle[t]);
        } else if memo.error([a, b, c], || triangle_error(mesh, t, field, tree.params.iso, h)) > tolerance {
            inaccurate.push(contour.cell_of_triangle[t]);
        }
    }
    for (cells, centre_if_stuck) in [(inaccurate, false), (folded, true)] {
        let mut cells = cells;
        cells.sort_unstable();
        cells.dedup();
        for c in cells {
            plan.treat(tree, &refs[c as usize], centre_if_stuck);
        }
    }
    plan.finish()
}

/// Rule 5: the dual cells that made intersecting triangles (the final check, after sliver
/// collapse) are treated like folded ones. It catches what rule 4 misses: two sheets of the
/// contour crossing where several features meet in one cell.
pub fn untangle(tree: &Octree, refs: &[[CellRef; 8]], contour: &Contour, pairs: &[[u32; 2]]) -> Plan {
    let mut plan = Plan::default();
    let mut cells: Vec<u32> = pairs.iter().flatten().map(|&t| contour.cell_of_triangle[t as usize]).collect();
    cells.sort_unstable();
    cells.dedup();
    for c in cells {
        plan.treat(tree, &refs[c as usize], true);
    }
    plan.finish()
}

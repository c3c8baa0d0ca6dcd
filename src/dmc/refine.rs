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
use super::octree::{Kind, Octree};
use crate::field::Field;

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

/// Rules 2 and 3: sampled leaves above the maximum depth that must be split.
pub fn to_refine(
    tree: &Octree,
    field: &dyn Field,
    refs: &[[CellRef; 8]],
    ids: &[[u32; 8]],
    values: &[f32],
    contour: &Contour,
) -> Vec<u32> {
    let splittable = |n: u32| {
        tree.nodes[n as usize].kind == Kind::Leaf && tree.nodes[n as usize].depth < tree.params.max_depth
    };
    let mut represented = vec![false; tree.nodes.len()];
    for (r, cell) in refs.iter().zip(ids) {
        if is_mixed(cell, values) {
            for r in r {
                represented[r.node as usize] = true;
            }
        }
    }
    let mut out: Vec<u32> = tree
        .leaves()
        .filter(|&n| splittable(n) && tree.nodes[n as usize].straddles && !represented[n as usize])
        .collect();
    let tolerance = tree.params.tolerance;
    let h = tree.cell_size(tree.params.max_depth) * 1e-2;
    let mut bad_cells: Vec<u32> = (0..contour.mesh.triangle_count())
        .filter(|&t| triangle_error(&contour.mesh, t, field, tree.params.iso, h) > tolerance)
        .map(|t| contour.cell_of_triangle[t])
        .collect();
    bad_cells.sort_unstable();
    bad_cells.dedup();
    for c in bad_cells {
        let cell = &refs[c as usize];
        let largest =
            cell.iter().filter(|r| splittable(r.node)).map(|r| tree.nodes[r.node as usize].depth).min();
        if let Some(depth) = largest {
            out.extend(
                cell.iter()
                    .map(|r| r.node)
                    .filter(|&n| splittable(n) && tree.nodes[n as usize].depth == depth),
            );
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Rule 4: sampled leaves of dual cells whose contour folds over (a triangle facing away from the
/// field's gradient by more than 90°). Vertices far from their cells' centres can fold a dual cell;
/// these leaves fall back to their centres, where the dual grid is regular and Marching Cubes
/// cannot fold (the paper's §5 variant), at the price of sharpness there.
pub fn to_centre(tree: &Octree, field: &dyn Field, refs: &[[CellRef; 8]], contour: &Contour) -> Vec<u32> {
    let h = tree.cell_size(tree.params.max_depth) * 1e-2;
    let mut out: Vec<u32> = (0..contour.mesh.triangle_count())
        .filter(|&t| {
            let [a, b, c] = contour.mesh.corners(t);
            let normal = (b - a).cross(c - a);
            let p = (a + b + c) / 3.0;
            let g =
                field.gradient(p).unwrap_or_else(|| crate::field::finite_difference_gradient(field, p, h));
            normal.dot(g) < 0.0
        })
        .flat_map(|t| refs[contour.cell_of_triangle[t] as usize].iter().map(|r| r.node))
        .filter(|&n| tree.nodes[n as usize].kind == Kind::Leaf && !tree.nodes[n as usize].centred)
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Rule 5: sampled, not yet centred leaves of the dual cells that made intersecting triangles (the
/// final check, after sliver collapse). Folds that rule 4 misses — two sheets of the contour
/// crossing where several features meet in one cell — are undone the same way.
pub fn tangled(tree: &Octree, refs: &[[CellRef; 8]], contour: &Contour, pairs: &[[u32; 2]]) -> Vec<u32> {
    let mut out: Vec<u32> = pairs
        .iter()
        .flatten()
        .flat_map(|&t| refs[contour.cell_of_triangle[t as usize] as usize].iter().map(|r| r.node))
        .filter(|&n| tree.nodes[n as usize].kind == Kind::Leaf && !tree.nodes[n as usize].centred)
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

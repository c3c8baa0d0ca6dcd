//! Bottom-up simplification: from the finest level up, eight leaf children become one leaf where
//! their summed QEF still fits one vertex within the tolerance **and** [`super::safety`] finds
//! the merge topologically safe. Nothing is sampled again (QEFs add) and nothing is undone, so the
//! pass is one sweep over the levels; the contour keeps the topology of the finest level's by
//! construction.
//!
//! A merged leaf's vertex is its QEF's minimiser inside it, so every vertex stays in its own leaf,
//! as the paper's do.

use super::build::place;
use super::fidelity::Fidelity;
use super::qef::Qef;
use super::safety::{merge_is_safe, Scratch};
use super::tree::{Kind, Octree};
use crate::field::Field;
use glam::Vec3;

#[derive(Debug, Clone, Copy, Default)]
pub struct SimplifyStats {
    pub merged: usize,
    /// Merges the QEF allowed and the safety test refused.
    pub unsafe_merges: usize,
    /// Merges refused because their triangles would stray beyond the tolerance.
    pub inaccurate_merges: usize,
    /// Merges refused by the QEF residual.
    pub qef_refused: usize,
}

/// Makes internal node `n` a leaf: empty if its children all were, on one side, else a surface
/// leaf with `qef`, vertex `vertex` and value `value`.
fn merge(tree: &mut Octree, n: u32, qef: Option<Qef>, vertex: Vec3, value: f32) {
    let first = tree.nodes[n as usize].children;
    let uniform = (first..first + 8)
        .map(|c| tree.nodes[c as usize].kind)
        .filter(|k| *k != Kind::Absent)
        .try_fold(None, |seen, k| match (seen, k) {
            (_, Kind::Empty { inside }) if seen.is_none() || seen == Some(inside) => Ok(Some(inside)),
            _ => Err(()),
        });
    let node = &mut tree.nodes[n as usize];
    match uniform {
        Ok(Some(inside)) => {
            node.kind = Kind::Empty { inside };
            node.value = super::dual::side_only(inside);
        }
        _ => {
            node.kind = Kind::Surface;
            node.value = value;
        }
    }
    node.vertex = vertex;
    if let Some(q) = qef {
        node.qef = tree.qefs.len() as u32;
        tree.qefs.push(q);
    }
}

/// A proposed merge: the node, its children's summed QEF (none if no child has one), the vertex
/// it would have and whether that vertex is free inside its box.
struct Proposal {
    node: u32,
    qef: Option<Qef>,
    vertex: Vec3,
    free: bool,
}

/// What the QEF says of making node `n` a leaf: `None` while a child is still internal, `Err`
/// where the summed QEF does not fit one vertex within the tolerance (a NaN residual, from a
/// degenerate QEF, refuses it too).
fn propose(tree: &Octree, n: u32, tolerance: f32) -> Option<Result<Proposal, ()>> {
    let first = tree.nodes[n as usize].children;
    let children = (first..first + 8).map(|c| tree.nodes[c as usize]);
    if children.clone().any(|c| c.kind == Kind::Internal) {
        return None;
    }
    let (lo, hi) = tree.world_box(n);
    let mut qef: Option<Qef> = None;
    for c in children.filter(|c| c.kind == Kind::Surface && c.qef != super::tree::NONE) {
        let q = &tree.qefs[c.qef as usize];
        match &mut qef {
            Some(sum) => sum.merge(q),
            None => qef = Some(*q),
        }
    }
    let Some(q) = &qef else {
        return Some(Ok(Proposal { node: n, qef, vertex: (lo + hi) * 0.5, free: true }));
    };
    let placed = place(q, lo, hi);
    if placed.rms.is_nan() || placed.rms > tolerance as f64 {
        return Some(Err(()));
    }
    Some(Ok(Proposal { node: n, qef, vertex: placed.vertex, free: placed.free }))
}

/// Merges bottom-up; `tolerance` (world units) bounds both the root-mean-square 4-D distance of a
/// leaf's sampled tangent planes from its vertex and the distance of the triangles a merge makes
/// from the surface ([`super::fidelity`]).
pub fn simplify(
    tree: &mut Octree,
    field: &dyn Field,
    iso: f32,
    tolerance: f32,
) -> Result<SimplifyStats, crate::Error> {
    let mut stats = SimplifyStats::default();
    let mut fidelity = Fidelity::new(field, iso, tolerance);
    let mut by_level: Vec<Vec<u32>> = vec![Vec::new(); tree.depth as usize + 1];
    for n in 0..tree.nodes.len() as u32 {
        if tree.nodes[n as usize].kind == Kind::Internal {
            by_level[tree.nodes[n as usize].level as usize].push(n);
        }
    }
    for level in (0..tree.depth as usize).rev() {
        // Reported as the second half of the "octree" phase (the stats count simplification there).
        let done = (tree.depth as usize - 1 - level) as f32 / tree.depth.max(1) as f32;
        crate::progress::checkpoint("octree", 0.5 + 0.5 * done)?;
        // Candidates whose children are all leaves, with the vertex the merged leaf would have;
        // each placed on its own (in parallel where there are threads), in the level's order.
        let proposed =
            crate::par::map(by_level[level].len(), |i| propose(tree, by_level[level][i], tolerance));
        let mut candidates: Vec<Proposal> = Vec::new();
        for p in proposed.into_iter().flatten() {
            match p {
                Ok(p) => candidates.push(p),
                Err(()) => stats.qef_refused += 1,
            }
        }
        if candidates.is_empty() {
            continue;
        }
        let mut points: Vec<Vec3> = candidates.iter().map(|c| c.vertex).collect();
        let centres: Vec<Vec3> = candidates
            .iter()
            .map(|c| {
                let (lo, hi) = tree.world_box(c.node);
                (lo + hi) * 0.5
            })
            .collect();
        let free: Vec<bool> = candidates.iter().map(|c| c.free).collect();
        let values = super::build::settle_vertices(field, iso, &mut points, &centres, &free, tree.h);
        // The candidates in eight classes by the parity of their position: two of one class are a
        // node apart, so no dual cell has leaves of both and their tests do not depend on each
        // other. Each class is tested against the merges of the classes before it, all at once.
        let side = 1u32 << (tree.depth as usize - level);
        let class = |n: u32| {
            let c = tree.nodes[n as usize].coord;
            (0..3).fold(0usize, |k, a| k | ((((c[a] / side) & 1) as usize) << a))
        };
        let mut classes: [Vec<usize>; 8] = Default::default();
        for (i, c) in candidates.iter().enumerate() {
            classes[class(c.node)].push(i);
        }
        for members in &classes {
            // The candidate vertices, read by the tests through the (still internal) nodes.
            for &i in members {
                let n = candidates[i].node as usize;
                tree.nodes[n].vertex = points[i];
                tree.nodes[n].value = values[i];
            }
            let tested = {
                let tree = &*tree;
                crate::par::map_with(members.len(), Scratch::default, |scratch, k| {
                    let i = members[k];
                    merge_is_safe(tree, candidates[i].node, values[i], field, iso, scratch)
                })
            };
            let mut safe = Vec::new();
            let mut stars = Vec::new();
            for (&i, star) in members.iter().zip(tested) {
                match star {
                    Some(star) => {
                        safe.push(i);
                        stars.push(star);
                    }
                    None => stats.unsafe_merges += 1,
                }
            }
            let within = fidelity.within(tree, &stars);
            for (&i, ok) in safe.iter().zip(within) {
                if !ok {
                    stats.inaccurate_merges += 1;
                    continue;
                }
                stats.merged += 1;
                merge(tree, candidates[i].node, candidates[i].qef.take(), points[i], values[i]);
            }
        }
    }
    Ok(stats)
}

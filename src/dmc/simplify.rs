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
use super::safety::merge_is_safe;
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
    pub safety_ms: f64,
    pub fidelity_ms: f64,
}

/// Merges bottom-up; `tolerance` (world units) bounds both the root-mean-square 4-D distance of a
/// leaf's sampled tangent planes from its vertex and the distance of the triangles a merge makes
/// from the surface ([`super::fidelity`]).
pub fn simplify(tree: &mut Octree, field: &dyn Field, iso: f32, tolerance: f32) -> SimplifyStats {
    let mut stats = SimplifyStats::default();
    let mut fidelity = Fidelity::new(field, iso, tolerance);
    let mut by_level: Vec<Vec<u32>> = vec![Vec::new(); tree.depth as usize + 1];
    for n in 0..tree.nodes.len() as u32 {
        if tree.nodes[n as usize].kind == Kind::Internal {
            by_level[tree.nodes[n as usize].level as usize].push(n);
        }
    }
    for level in (0..tree.depth as usize).rev() {
        // Candidates whose children are all leaves, with the vertex the merged leaf would have.
        let mut candidates: Vec<(u32, Option<Qef>, Vec3, bool)> = Vec::new();
        for &n in &by_level[level] {
            let first = tree.nodes[n as usize].children;
            let children = (first..first + 8).map(|c| tree.nodes[c as usize]);
            if children.clone().any(|c| c.kind == Kind::Internal) {
                continue;
            }
            let (lo, hi) = tree.world_box(n);
            let mut qef: Option<Qef> = None;
            let mut vertex = (lo + hi) * 0.5;
            let mut free = true;
            for c in children.filter(|c| c.kind == Kind::Surface && c.qef != super::tree::NONE) {
                let q = &tree.qefs[c.qef as usize];
                match &mut qef {
                    Some(sum) => sum.merge(q),
                    None => qef = Some(*q),
                }
            }
            if let Some(q) = &qef {
                let placed = place(q, lo, hi);
                if !(placed.rms <= tolerance as f64) {
                    stats.qef_refused += 1;
                    continue;
                }
                vertex = placed.vertex;
                free = placed.free;
            }
            candidates.push((n, qef, vertex, free));
        }
        if std::env::var_os("ISOFORGE_DMC_DEBUG").is_some() {
            eprintln!("level {level}: {} internal, {} candidates, so far {stats:?}", by_level[level].len(), candidates.len());
        }
        if candidates.is_empty() {
            continue;
        }
        let mut points: Vec<Vec3> = candidates.iter().map(|c| c.2).collect();
        let centres: Vec<Vec3> = candidates
            .iter()
            .map(|c| {
                let (lo, hi) = tree.world_box(c.0);
                (lo + hi) * 0.5
            })
            .collect();
        let free: Vec<bool> = candidates.iter().map(|c| c.3).collect();
        let values = super::build::settle_vertices(field, iso, &mut points, &centres, &free, tree.h);
        for (((n, qef, _, _), vertex), value) in candidates.into_iter().zip(points).zip(values) {
            // The candidate vertex, read by the tests below through the (still internal) node.
            tree.nodes[n as usize].vertex = vertex;
            tree.nodes[n as usize].value = value;
            let t0 = web_time::Instant::now();
            let safe = merge_is_safe(tree, n, value);
            stats.safety_ms += crate::mc::ms_since(t0);
            let Some(star) = safe else {
                stats.unsafe_merges += 1;
                continue;
            };
            let t0 = web_time::Instant::now();
            let within = fidelity.within(tree, &star);
            stats.fidelity_ms += crate::mc::ms_since(t0);
            if !within {
                if std::env::var_os("ISOFORGE_DMC_DEBUG").is_some() {
                    let (lo, hi) = tree.world_box(n);
                    eprintln!("inaccurate {level} {:?} {:?}", (lo + hi) * 0.5, fidelity.worst(tree, &star));
                }
                stats.inaccurate_merges += 1;
                continue;
            }
            stats.merged += 1;
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
                    node.value = if inside { -f32::MIN_POSITIVE } else { f32::MIN_POSITIVE };
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
    }
    if std::env::var_os("ISOFORGE_DMC_DEBUG").is_some() {
        eprintln!("{stats:?}");
        let mut hist = vec![[0usize; 3]; tree.depth as usize + 1];
        for n in tree.leaves() {
            let node = &tree.nodes[n as usize];
            let k = match node.kind { Kind::Surface => 0, Kind::Empty { inside: false } => 1, _ => 2 };
            hist[node.level as usize][k] += 1;
        }
        eprintln!("leaves per level [surface, empty out, empty in]: {hist:?}");
    }
    stats
}

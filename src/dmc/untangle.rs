//! The one repair DMC keeps: where the contour folds or crosses itself, the vertices of the leaves
//! whose dual cells made the offending triangles move toward their leaves' centres.
//!
//! **Why it cannot be avoided.** A vertex on its leaf's feature is what keeps a crease sharp and a
//! thin wall present, but vertices placed independently, each in its own leaf, do not make every
//! dual cell a convex hexahedron, and Marching Cubes in a non-convex cell can turn a triangle over
//! or pass one sheet through another. No placement rule local to one leaf prevents that (centring
//! smooth leaves and keeping feature vertices free folds the cells where the two meet; measured on
//! the scenes it made more crossings, not fewer).
//!
//! **Why it is safe.** The contour's topology is a function of the vertices' *signs* alone (the
//! case of every dual cell), so a vertex may move anywhere its sign stays: toward the centre if
//! the centre lies on the same side of the iso-level, else to the last point of the segment on its
//! side (a few bisection steps). The topology proven by [`super::safety`] is untouched, but for the
//! last resort below.
//!
//! Where a merged leaf's vertex has moved once and its triangles still cross, the leaf is un-merged: the eight leaves it
//! was made of come back, as they were before the merge (the state the merge's safety test
//! compared with, so the topology is still the finest level's).
//!
//! **The last resort.** A vertex whose centre is on the other side of the level can only go as
//! far as the level, and there its triangles may still cross (random noise grids: a dual cell of
//! vertices at their centres but one, left a hair inside on the level by the bisection, its
//! centre outside). At its last move such a vertex takes its centre's side and sits at the centre,
//! as a vertex within [`super::build::LEVEL_BAND`] of the level does when it is placed: its own
//! side was that of a part of the field thinner than its leaf, which the crossing was the only
//! trace of. This changes the finest level's contour there, so an unsimplified run, whose
//! contour may not cross at that place, can differ from the simplified one in topology (random
//! CSG trees keep that promise and the others with it, a soak of 120); the 3 of 600 random noise
//! grids whose crossings untangling left do not cross now.
//!
//! **Why it is bounded.** Each vertex moves at most three times, a leaf is un-merged at most once
//! per level, and at most [`ROUNDS`] rounds are made;
//! what crossings remain are counted by the caller.

use super::dual::VertexKey;
use super::tree::{Kind, Octree};
use crate::field::Field;
use crate::mesh::analysis::{folded_pairs, self_intersecting_pairs};
use crate::mesh::Mesh;
use glam::Vec3;

/// Rounds of moving (or un-merging) and contouring again.
pub const ROUNDS: usize = 10;

/// How far toward its centre (fraction of the way from where the QEF put it) a vertex is after
/// each of its moves: small steps first, so that a vertex leaves its feature only as far as it has
/// to.
const STEPS: [f32; 3] = [0.25, 0.6, 1.0];

/// Triangles that cross another or lie folded onto a neighbour.
pub fn offending_triangles(mesh: &Mesh) -> Vec<u32> {
    let mut out: Vec<u32> =
        self_intersecting_pairs(mesh).into_iter().chain(folded_pairs(mesh)).flatten().collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Moves the vertices of the surface leaves around `cells` (dual cells, by their eight keys)
/// toward their centres by one more of `STEPS` (`moves` counts each vertex's moves and
/// `origins` keeps where the QEF put it); a merged leaf whose vertex has moved once already is
/// un-merged instead, back to the eight leaves it was made of (the state before that merge, whose
/// topology is the same, see [`super::safety`]). Returns (vertices moved, leaves un-merged).
pub fn move_toward_centres(
    tree: &mut Octree,
    field: &dyn Field,
    iso: f32,
    cells: &[&[VertexKey; 8]],
    moves: &mut [u8],
    origins: &mut rustc_hash::FxHashMap<u32, Vec3>,
) -> (usize, usize) {
    let mut around: Vec<u32> = cells.iter().flat_map(|c| c.iter().map(|k| k.node)).collect();
    around.sort_unstable();
    around.dedup();
    let merged = |n: u32| tree.nodes[n as usize].children != super::tree::NONE;
    let exhausted = |n: u32| moves[n as usize] as usize >= STEPS.len();
    let unmerge: Vec<u32> = around.iter().copied().filter(|&n| merged(n)).collect();
    for &n in &unmerge {
        tree.nodes[n as usize].kind = Kind::Internal;
    }
    let nodes: Vec<u32> = around
        .into_iter()
        .filter(|&n| tree.nodes[n as usize].kind == Kind::Surface && !exhausted(n))
        .collect();
    for &n in &nodes {
        let step = STEPS[moves[n as usize] as usize];
        moves[n as usize] += 1;
        let (lo, hi) = tree.world_box(n);
        let node = tree.nodes[n as usize];
        let origin = *origins.entry(n).or_insert(node.vertex);
        let centre = origin + ((lo + hi) * 0.5 - origin) * step;
        let inside = node.value < 0.0;
        let same = |p: Vec3| (field.value(p) - iso < 0.0) == inside;
        let at_centre = field.value(centre) - iso;
        let centre_same = (at_centre < 0.0) == inside;
        if !centre_same && moves[n as usize] as usize == STEPS.len() {
            // The last move of a vertex whose centre is on the other side: it takes the centre's
            // side, at the centre (see the module docs, "the last resort").
            let node = &mut tree.nodes[n as usize];
            node.vertex = centre;
            node.value = super::dual::on_side(at_centre, at_centre < 0.0);
            continue;
        }
        let target = if centre_same {
            centre
        } else {
            // The farthest point toward the centre still on the vertex's side.
            let (mut good, mut bad) = (0.0f32, 1.0f32);
            for _ in 0..6 {
                let mid = 0.5 * (good + bad);
                if same(node.vertex + (centre - node.vertex) * mid) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            node.vertex + (centre - node.vertex) * good
        };
        let value = field.value(target) - iso;
        let node = &mut tree.nodes[n as usize];
        node.vertex = target;
        node.value = super::dual::on_side(value, inside);
    }
    (nodes.len(), unmerge.len())
}

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
//!
//! Rules 4 and 5 (folds, intersections; see [`plan`] and [`untangle`]) fall back to the leaf's
//! centre where no leaf can be split (after taking back into their leaves the vertices that
//! `vertex_reach` let out, see [`Plan`]). A centre on the other side of the iso-level than the free
//! vertex changes the signs Marching Cubes sees, and [`keep_signs`] keeps the free vertex's side
//! wherever the centre would add a component or a handle (a hole through a thin wall). That check
//! also looks at unmixed dual cells around the centred leaf; a pruned leaf there has one sign over
//! its whole cell, as its unpruned subtree does, so it is expected to decide alike with and without
//! pruning — tested on three scenes, not proved like rule 1.

use super::contour::{triangle_error, Contour};
use super::dual::CellRef;
use super::features::uncentred_value;
use super::memo::Memo;
use super::octree::{Kind, Octree};
use crate::field::{gradient_or_differences, Field};
use crate::tables::{triangle_table, EDGES};
use glam::Vec3;
use std::collections::HashMap;

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
    /// Leaves whose vertex goes back into the leaf ([`super::octree::Node::confined`]).
    pub confine: Vec<u32>,
    pub split: Vec<u32>,
    pub centre: Vec<u32>,
}

impl Plan {
    pub fn is_empty(&self) -> bool {
        self.split.is_empty() && self.centre.is_empty() && self.confine.is_empty()
    }

    fn finish(mut self) -> Plan {
        for v in [&mut self.split, &mut self.centre, &mut self.confine] {
            v.sort_unstable();
            v.dedup();
        }
        // A leaf being split needs no centring.
        let split = &self.split;
        self.centre.retain(|n| split.binary_search(n).is_err());
        self.confine.retain(|n| split.binary_search(n).is_err());
        self
    }

    /// Split the largest splittable sampled leaves of a dual cell; where none can be split,
    /// centre one of its sampled leaves instead (when `centre_if_stuck`): the one whose vertex is
    /// farthest from its centre (relative to its side), the likeliest to fold the cell; the next
    /// round centres another if the cell still folds or crosses. Centring all of them at once
    /// chamfered curved creases: on the cube minus sphere at depth 5 every triangle over 0.0067
    /// came from a dual cell with a centred leaf (max distance 0.0141 against 0.0037 one at a
    /// time; rotated box 0.0187 against 0.0086, fandisk 0.0208 against 0.0084). Before centring, vertices that
    /// left their leaves (`vertex_reach`) go back into them (`confine`), and the cell is centred only
    /// if it still folds or crosses: a vertex out of its leaf reaches into the dual cells of its
    /// neighbours, and centring the cell's own leaves does not move it (the rounded thin room at
    /// depth 5 kept 11 and 18 crossing pairs at reaches 0.5 and 1.0 without this step).
    fn treat(&mut self, tree: &Octree, cell: &[CellRef; 8], centre_if_stuck: bool) {
        let largest =
            cell.iter().filter(|r| splittable(tree, r.node)).map(|r| tree.nodes[r.node as usize].depth).min();
        match largest {
            Some(depth) => self.split.extend(
                cell.iter()
                    .map(|r| r.node)
                    .filter(|&n| splittable(tree, n) && tree.nodes[n as usize].depth == depth),
            ),
            None if centre_if_stuck && cell.iter().any(|r| out_of_leaf(tree, r.node)) => {
                self.confine.extend(cell.iter().map(|r| r.node).filter(|&n| out_of_leaf(tree, n)))
            }
            None if centre_if_stuck => {
                let off_centre = |n: u32| {
                    let (lo, hi) = tree.cell(n);
                    ((tree.nodes[n as usize].vertex - (lo + hi) * 0.5) / (hi - lo)).length()
                };
                let farthest = cell
                    .iter()
                    .map(|r| r.node)
                    .filter(|&n| tree.nodes[n as usize].kind == Kind::Leaf && !tree.nodes[n as usize].centred)
                    .max_by(|&a, &b| off_centre(a).total_cmp(&off_centre(b)));
                self.centre.extend(farthest)
            }
            None => {}
        }
    }
}

/// A sampled leaf whose vertex lies outside the leaf (only with `vertex_reach` above 0).
fn out_of_leaf(tree: &Octree, n: u32) -> bool {
    let node = &tree.nodes[n as usize];
    let (lo, hi) = tree.cell(n);
    node.kind == Kind::Leaf && !node.confined && (node.vertex.cmplt(lo).any() || node.vertex.cmpgt(hi).any())
}

fn splittable(tree: &Octree, n: u32) -> bool {
    tree.nodes[n as usize].kind == Kind::Leaf && tree.nodes[n as usize].depth < tree.params.max_depth
}

/// Rule 2 alone: the straddling sampled leaves in no mixed dual cell.
pub fn represent(tree: &Octree, refs: &[[CellRef; 8]], ids: &[[u32; 8]], values: &[f32]) -> Plan {
    let mut represented = vec![false; tree.nodes.len()];
    for (r, cell) in refs.iter().zip(ids) {
        if is_mixed(cell, values) {
            for r in r {
                represented[r.node as usize] = true;
            }
        }
    }
    let split = tree
        .leaves()
        .filter(|&n| splittable(tree, n) && tree.nodes[n as usize].straddles && !represented[n as usize])
        .collect();
    Plan { split, ..Plan::default() }
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
    let mut plan = represent(tree, refs, ids, values);
    let tolerance = tree.params.tolerance;
    let h = tree.cell_size(tree.params.max_depth) * 1e-2;
    let mesh = &contour.mesh;
    let gradients: Vec<Vec3> =
        mesh.positions.iter().map(|&p| memo.gradient(p, || gradient_or_differences(field, p, h))).collect();
    let mut inaccurate = Vec::new();
    let mut folded = Vec::new();
    for t in 0..mesh.triangle_count() {
        let [a, b, c] = mesh.corners(t);
        let normal = (b - a).cross(c - a);
        if mesh.triangles[t].iter().all(|&v| normal.dot(gradients[v as usize]) < 0.0) {
            folded.push(contour.cell_of_triangle[t]);
        } else if tree.params.accuracy_rule
            && memo.error([a, b, c], || triangle_error(mesh, t, field, tree.params.iso, h)) > tolerance
        {
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

/// Decides, once per centred leaf and in the first round its centre is used, whether its vertex
/// keeps the side of the iso-level of its free vertex; returns whether any does (the round must be
/// redone with those vertices).
///
/// Marching Cubes on the dual grid sees the surface only through the signs of the dual vertices,
/// so moving a vertex to its cell's centre changes the contour's topology wherever the centre lies
/// on the other side and the vertex was the only witness of its side there. A thin wall is the
/// case: the free vertex of a leaf at the wall (or at the edge where two walls meet) sits on the
/// wall's mid-surface, inside, and the leaf's centre lies outside the wall, so centring punches a
/// hole through it (the planar room got three handles this way at depths 5 and 6). On a smooth
/// surface the centre's side is harmless (the sheet passes on the other side of the vertex), and
/// there centring can also remove a bubble that a vertex on the zero set made.
///
/// So a centring may take topology away but never add any. Starting from the signs without any of
/// the centrings being decided, they are applied one at a time, in node order, each to the contour
/// of the mixed dual cells and of every dual cell around the leaf's dual vertices (its own and its
/// boundary copies, in `around`), built combinatorially as [`super::contour`] builds it. A centring
/// is kept when the contour has no more components and no larger genus with it than without it;
/// otherwise the leaf keeps its side ([`crate::dmc::octree::Node::keep_sign`]).
pub fn keep_signs(
    tree: &mut Octree,
    field: &dyn Field,
    values: &[f32],
    mixed: &[[u32; 8]],
    around: &[[CellRef; 8]],
    around_ids: &[[u32; 8]],
) -> bool {
    let candidates: Vec<u32> = tree.leaves().filter(|&n| unchecked_centre(tree, n)).collect();
    if candidates.is_empty() {
        return false;
    }
    let mut cells: Vec<[u32; 8]> = mixed.to_vec();
    cells.extend(around_ids.iter().filter(|c| !is_mixed(c, values)));
    // Per candidate, its dual vertices whose free vertex is on the other side than the centre.
    let mut flips: Vec<(u32, Vec<(u32, f32)>)> = Vec::new();
    for n in candidates {
        tree.nodes[n as usize].centre_checked = true;
        let mut free: Vec<(u32, f32)> = Vec::new();
        for (cell, cell_ids) in around.iter().zip(around_ids) {
            for (r, &id) in cell.iter().zip(cell_ids) {
                if r.node != n || free.iter().any(|&(f, _)| f == id) {
                    continue;
                }
                let v = uncentred_value(tree, field, *r);
                if (v < 0.0) != (values[id as usize] < 0.0) {
                    free.push((id, v));
                }
            }
        }
        if !free.is_empty() {
            flips.push((n, free));
        }
    }
    if flips.is_empty() {
        return false;
    }
    // From the signs without these centrings, each is applied in turn if it adds no topology.
    let mut signs: HashMap<u32, bool> =
        flips.iter().flat_map(|(_, free)| free.iter().map(|&(id, v)| (id, v < 0.0))).collect();
    let negative =
        |signs: &HashMap<u32, bool>, id: u32| signs.get(&id).copied().unwrap_or(values[id as usize] < 0.0);
    let mut without = contour_topology(&cells, |id| negative(&signs, id));
    let mut any = false;
    for (n, free) in flips {
        let with = contour_topology(&cells, |id| match free.iter().any(|&(f, _)| f == id) {
            true => values[id as usize] < 0.0,
            false => negative(&signs, id),
        });
        if with.components <= without.components && with.twice_genus() <= without.twice_genus() {
            for &(id, _) in &free {
                signs.insert(id, values[id as usize] < 0.0);
            }
            without = with;
        } else {
            let node = &mut tree.nodes[n as usize];
            node.keep_sign = true;
            node.has_vertex = false;
            any = true;
        }
    }
    any
}

/// A centred leaf whose centring [`keep_signs`] has not looked at yet.
pub fn unchecked_centre(tree: &Octree, n: u32) -> bool {
    let node = &tree.nodes[n as usize];
    node.kind == Kind::Leaf && node.centred && !node.centre_checked
}

/// The topology of a contour: Euler characteristic, components, boundary loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Topology {
    euler: i64,
    components: i64,
    boundary_loops: i64,
}

impl Topology {
    fn twice_genus(&self) -> i64 {
        2 * self.components - self.euler - self.boundary_loops
    }
}

/// The contour of `cells` (dual vertex ids in octant order) with the signs `negative`, as Marching
/// Cubes in [`super::contour`] builds it (mesh vertices named by their dual edge, triangles with a
/// repeated vertex dropped), reduced to its topology.
fn contour_topology(cells: &[[u32; 8]], negative: impl Fn(u32) -> bool) -> Topology {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    fn join(parent: &mut [usize], a: usize, b: usize) {
        let (ra, rb) = (root(parent, a), root(parent, b));
        parent[ra] = rb;
    }
    let table = triangle_table();
    let mut keys: HashMap<(u32, u32), usize> = HashMap::new();
    let mut edges: HashMap<(usize, usize), u32> = HashMap::new();
    let mut faces = 0i64;
    let mut parent: Vec<usize> = Vec::new();
    for ids in cells {
        let mut case = 0u8;
        for (corner, &id) in ids.iter().enumerate() {
            case |= (negative(id) as u8) << corner;
        }
        for t in table[case as usize].triangles() {
            let k = t.map(|e| {
                let [a, b] = EDGES[e as usize].map(|corner| ids[corner as usize]);
                (a.min(b), a.max(b))
            });
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                continue;
            }
            faces += 1;
            let v = k.map(|key| {
                let next = keys.len();
                let i = *keys.entry(key).or_insert(next);
                if i == parent.len() {
                    parent.push(i);
                }
                i
            });
            for j in 0..3 {
                let (a, b) = (v[j], v[(j + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                join(&mut parent, a, b);
            }
        }
    }
    let components = (0..parent.len()).filter(|&i| root(&mut parent, i) == i).count() as i64;
    // Boundary loops: components of the graph of edges used by one triangle.
    let mut loops: Vec<usize> = (0..parent.len()).collect();
    let mut on_boundary = vec![false; parent.len()];
    for (&(a, b), _) in edges.iter().filter(|&(_, &uses)| uses == 1) {
        join(&mut loops, a, b);
        on_boundary[a] = true;
        on_boundary[b] = true;
    }
    let boundary_loops =
        (0..loops.len()).filter(|&i| on_boundary[i] && root(&mut loops, i) == i).count() as i64;
    Topology { euler: keys.len() as i64 - edges.len() as i64 + faces, components, boundary_loops }
}

//! Feature isolation (§2): one vertex per leaf, at the minimiser of the leaf's QEF inside the leaf,
//! with the value of the field there; and the vertices of the degenerate boundary cells (see
//! [`super::dual`]), found by the same QEF restricted to the leaf's face, edge or corner on the root's
//! boundary.
//!
//! Choices (each measured; see the README's DMC notes):
//! - The vertex is kept in the leaf shrunk by [`SHRINK`] of its side, so two leaves never share a
//!   vertex position (a feature exactly on a cell face would otherwise give both cells the same
//!   point, and the mesh two coincident vertices). Boundary vertices keep their pinned coordinate.
//!   [`super::DmcOptions::vertex_reach`] lets the free vertex follow the minimiser out of the leaf
//!   by a fraction of its side (off by default): a leaf next to a thin wall's junction, holding
//!   part of one wall only, has its minimiser on the junction in the neighbouring leaf, and clamped
//!   to its own face the vertex leaves a gap between the crossings and the wall's inner edge that
//!   no split closes at the maximum depth (see the README, "Thin walls").
//! - The stored value is `f(vertex) - iso`, evaluated, not the QEF's estimate, so the sign of a
//!   vertex is the sign of the field at a point of its leaf (the pruning argument relies on it; a
//!   vertex out of its leaf keeps the side of the leaf's own minimiser, see [`reached_vertex`]).
//! - **Signs around features.** Dual Marching Cubes sees the surface only through the signs of the
//!   dual vertices. A vertex on a sharp edge has value 0 (outside, by the crate's rule), and so do
//!   its neighbours along the edge; the edge is reproduced only if the vertices of the flat cells
//!   beside it are definitely inside. A linear cell (QEF rank one) that straddles the surface would
//!   put its vertex at its centre, on whichever side the centre happens to be, and a whole edge of a
//!   box in general position came out chamfered. Such vertices are moved a quarter cell into the
//!   solid along the gradient (clamped to the leaf), which reproduces convex and concave edges alike.
//!   A vertex whose value is zero up to rounding gets a sign by rule, not by noise
//!   ([`snap_noise`]): outside, unless every sample of its leaf is inside.
//! - **Sliver elimination (§4).** Where a linear cell straddles the surface and the QEF restricted
//!   to `w = 0` has a residual within the tolerance (and the field there is within the tolerance of
//!   zero), the restricted minimiser, a point on the surface, becomes the vertex, *counted as
//!   inside*: its crossings then all land next to it, [`super::slivers`] merges them into it, and
//!   the sign pattern is that of the quarter-cell rule above. Measured on a ball this halves the
//!   triangles and lifts the smallest angle from about 3° to above 20°. Next to a feature
//!   ([`near_features`]) the restricted vertex is not used: surface vertices crowding a crease or a
//!   thin wall folded the contour there.
//! - A pruned leaf's vertex is its centre (flattened onto the boundary for boundary cells); it never
//!   reaches the output (see `refine.rs`). So is a *centred* leaf's, the fallback of refinement
//!   rules 4 and 5, unless the centre lies on the other side of the iso-level and that would add
//!   topology (`refine::keep_signs`): then the vertex moves from its free place toward the centre
//!   only halfway to the first sign change, keeping its side.

use super::dual::CellRef;
use super::octree::{Kind, Octree, NONE};
use crate::field::{gradient_or_differences, Field};
use crate::grid::in_box;
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
        let (vertex, value, on_surface) = if node.centred && !node.keep_sign {
            let (vertex, value) = centred_vertex(tree, field, CellRef { node: n, clamp: 0 });
            (vertex, value, false)
        } else if node.centred {
            let (vertex, value, _) = free_vertex(tree, field, n, false);
            let (lo, hi) = shrunk(tree, n);
            let (vertex, value) =
                toward_centre(field, tree.params.iso, vertex, value, (lo + hi) * 0.5, tree.size, node.inside);
            (vertex, value, false)
        } else {
            free_vertex(tree, field, n, sliver_elimination && !node.keep_free)
        };
        let node = &mut tree.nodes[n as usize];
        node.vertex = vertex;
        node.value = value;
        node.has_vertex = true;
        node.on_surface = on_surface;
    }
}

/// The vertex of sampled leaf `n` as feature isolation places it when not centred: position,
/// `f - iso` (its sign by the rules in the module docs), and whether sliver elimination (when
/// `on_surface_allowed`) put it on the surface.
fn free_vertex(tree: &Octree, field: &dyn Field, n: u32, on_surface_allowed: bool) -> (Vec3, f32, bool) {
    let node = &tree.nodes[n as usize];
    let iso = tree.params.iso;
    let (lo, hi) = shrunk(tree, n);
    let linear = node.straddles && node.rank == 1;
    let reach = (hi - lo) * if node.confined { 0.0 } else { tree.params.vertex_reach };
    let (mut vertex, mut value, inside) = reached_vertex(tree, field, n, lo, hi, reach);
    if on_surface_allowed && linear {
        let restricted = tree.qefs[node.qef as usize].minimise_in_box(lo, hi, Some(0.0));
        let p = restricted.position.as_vec3();
        let v = field.value(p) - iso;
        if restricted.rms <= tree.params.tolerance as f64 && v.abs() <= tree.params.tolerance {
            // On the surface, counted as inside (see the module docs).
            return (p, v.min(-f32::MIN_POSITIVE), true);
        }
    }
    if linear {
        // Move the vertex a quarter cell into the solid along the gradient.
        let h = (hi - lo).max_element();
        let g = gradient_or_differences(field, vertex, h * 1e-3);
        let slope = g.length();
        if slope > 1e-12 {
            let target = -0.25 * h * slope;
            vertex = (vertex - g * ((value - target) / (slope * slope))).clamp(lo, hi);
            value = field.value(vertex) - iso;
        }
    }
    (vertex, snap_noise(field, vertex, value, tree.size, inside), false)
}

/// The minimiser of leaf `n`'s QEF in its box `[lo, hi]` grown by `reach` on every side, `f - iso`
/// there, and the `inside` rule [`snap_noise`] is to give it if it lies on the surface; but the
/// minimiser in the box itself wherever the grown box's lies outside the box without fitting the
/// leaf's tangent planes strictly better, or on the other side of the iso-level than the box's
/// own minimiser. A reached vertex *on* the surface (a sharp edge just beyond the leaf) is let out
/// and counted on that minimiser's side.
///
/// Reach is for a vertex pressed against its leaf's face by a feature just beyond it (the junction
/// of two thin walls). On the rounded thin room (`--tol 0.01`, reach 0.25, depth 5) 204 of the 770
/// vertices out of their leaves had crossed the surface: leaves outside the room beside a rounded
/// outer edge, where the distance to the box is a cone whose tangent planes all meet on the box's
/// edge, inside the wall; those vertices joined the wall's own and folded the dual cells around
/// them. Others fitted worse out of the leaf than in it (root-mean-square 0.00064 against
/// 0.00013): the truncated pseudo-inverse's solution is accepted when it lies in the box, without
/// comparing it with the box's faces, so the grown box's "minimiser" can be a poorer fit than the
/// leaf's, moved a third of the leaf for nothing. With both kept in their leaves the rounded room
/// went from 4040 triangles to 1048 (README, "Thin walls"). Refusing vertices that land on the
/// surface as well (their sign by [`snap_noise`]'s rule, outside, differs from an inside minimiser)
/// kept the rotated box's edges from being reached at reach 1 (depth 5: max distance 0.0174 against
/// 0.0013). Keeping the side also keeps what the pruning argument of `refine` needs: the sign of a
/// vertex is the sign of the field at a point of its leaf.
fn reached_vertex(
    tree: &Octree,
    field: &dyn Field,
    n: u32,
    lo: Vec3,
    hi: Vec3,
    reach: Vec3,
) -> (Vec3, f32, bool) {
    let iso = tree.params.iso;
    let inside = tree.nodes[n as usize].inside;
    let qef = &tree.qefs[tree.nodes[n as usize].qef as usize];
    let reached = qef.minimise_in_box(lo - reach, hi + reach, None);
    let vertex = reached.position.as_vec3().clamp(lo - reach, hi + reach);
    let value = field.value(vertex) - iso;
    if in_box(vertex, (lo, hi)) {
        return (vertex, value, inside);
    }
    let own = qef.minimise_in_box(lo, hi, None);
    let inner = own.position.as_vec3().clamp(lo, hi);
    let inner_value = field.value(inner) - iso;
    let inner_negative = snap_noise(field, inner, inner_value, tree.size, inside) < 0.0;
    let snapped = |inside: bool| snap_noise(field, vertex, value, tree.size, inside);
    // Within rounding noise of the iso-level, the two rules give the two sides.
    let on_surface = snapped(true) != snapped(false);
    let same_side = on_surface || (snapped(inside) < 0.0) == inner_negative;
    match reached.rms < own.rms && same_side {
        true => (vertex, value, if on_surface { inner_negative } else { inside }),
        false => (inner, inner_value, inside),
    }
}

/// The value (`f - iso`) of the vertex of `r` (a sampled leaf or its boundary copy) as it would be
/// without centring: what a centred vertex that keeps its sign keeps the sign of.
pub fn uncentred_value(tree: &Octree, field: &dyn Field, r: CellRef) -> f32 {
    if r.clamp == 0 {
        return free_vertex(tree, field, r.node, false).1;
    }
    let (lo, hi) = vertex_box(tree, r);
    let p = free_minimiser(tree, r.node, lo, hi);
    snap_noise(field, p, field.value(p) - tree.params.iso, tree.size, tree.nodes[r.node as usize].inside)
}

/// Leaves whose vertex sliver elimination moved onto the surface but which share a mixed dual
/// cell with a feature leaf (straddling, QEF rank two or more: a crease, a corner, a curved or thin
/// part). They fall back to the free (biased) vertex.
pub fn near_features(tree: &Octree, refs: &[[CellRef; 8]]) -> Vec<u32> {
    let is_feature = |n: u32| {
        let node = &tree.nodes[n as usize];
        node.kind == Kind::Leaf && node.straddles && node.rank >= 2
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

/// The minimiser of the leaf's QEF in the box (the leaf, shrunk, or one of its boundary faces).
fn free_minimiser(tree: &Octree, n: u32, lo: Vec3, hi: Vec3) -> Vec3 {
    let node = &tree.nodes[n as usize];
    tree.qefs[node.qef as usize].minimise_in_box(lo, hi, None).position.as_vec3().clamp(lo, hi)
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

/// The box a vertex of `r` is kept in: the leaf shrunk by [`SHRINK`], flattened onto the root's
/// boundary where `r` is clamped.
fn vertex_box(tree: &Octree, r: CellRef) -> (Vec3, Vec3) {
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
    (lo, hi)
}

/// The vertex of a leaf's face, edge or corner on the root's boundary.
fn boundary_vertex(tree: &Octree, field: &dyn Field, r: CellRef) -> (Vec3, f32) {
    let node = &tree.nodes[r.node as usize];
    if node.kind == Kind::Pruned || (node.centred && !node.keep_sign) {
        return centred_vertex(tree, field, r);
    }
    let (lo, hi) = vertex_box(tree, r);
    let iso = tree.params.iso;
    let p = free_minimiser(tree, r.node, lo, hi);
    let value = snap_noise(field, p, field.value(p) - iso, tree.size, node.inside);
    if node.centred {
        return toward_centre(field, iso, p, value, (lo + hi) * 0.5, tree.size, node.inside);
    }
    (p, value)
}

/// The vertex `r` gets when its leaf is centred (refinement rules 4 and 5) or pruned: the centre of
/// its box, and `f - iso` there (a boundary vertex's sign by [`snap_noise`]).
fn centred_vertex(tree: &Octree, field: &dyn Field, r: CellRef) -> (Vec3, f32) {
    let (lo, hi) = vertex_box(tree, r);
    let p = (lo + hi) * 0.5;
    let value = field.value(p) - tree.params.iso;
    if r.clamp == 0 {
        return (p, value);
    }
    (p, snap_noise(field, p, value, tree.size, tree.nodes[r.node as usize].inside))
}

/// Distance from the iso-level (as a fraction of the root's side) below which a vertex's value is
/// rounding noise: the vertex lies on the surface, placed there by the QEF.
pub const ON_SURFACE: f32 = 1e-6;

/// `value` at `p`, or, when it is within rounding noise of the iso-level, the sign of the leaf's
/// samples: inside (`-MIN_POSITIVE`) when all of them are, else `0` (outside).
///
/// A vertex the QEF puts on a sharp corner or edge of the surface has a value that is zero up to
/// rounding, with a sign that is noise. Counted inside at a convex corner, it meets the inside
/// vertices of the solid only across faces of the dual cells that are ambiguous, and the table
/// (which separates inside corners there) leaves it alone: a tiny closed component around the
/// corner (the rotated box). Counted outside, as the crate's rule for a value of exactly zero says,
/// it joins the outside vertices across those faces, and the surface passes between it and the
/// solid, next to it (crossings are found by root finding).
///
/// A ridge of the field that only touches the iso-level inside the solid is the other case: the
/// disc where a union's two parts meet face to face (the rocket's body and nose) has `f = 0` and
/// `f < 0` on both sides. Its leaves' samples are all inside, and so is the vertex; counted outside,
/// it would be a flat closed component of its own.
fn snap_noise(field: &dyn Field, p: Vec3, value: f32, root_size: f32, inside: bool) -> f32 {
    let tiny = ON_SURFACE * root_size;
    // No gradient needed for values far from noise (slopes above 1000 are not expected).
    if value.abs() > tiny * 1e3 {
        return value;
    }
    let g = gradient_or_differences(field, p, tiny * 10.0);
    if value.abs() > tiny * g.length() {
        value
    } else if inside {
        -f32::MIN_POSITIVE
    } else {
        0.0
    }
}

/// The vertex of a centred leaf whose centre has the other sign than its free vertex (`value` at
/// `free`) and where that sign change would change the contour's topology (see
/// [`super::refine::keep_signs`]): the point of the segment from `free` to `centre` halfway to the
/// first sign change along it (found by bisection), so the vertex moves toward the centre but keeps
/// its side.
fn toward_centre(
    field: &dyn Field,
    iso: f32,
    free: Vec3,
    value: f32,
    centre: Vec3,
    root_size: f32,
    inside: bool,
) -> (Vec3, f32) {
    let side = value < 0.0;
    let at = |t: f32| {
        let p = free + (centre - free) * t;
        (p, snap_noise(field, p, field.value(p) - iso, root_size, inside))
    };
    let (p, v) = at(1.0);
    if (v < 0.0) == side {
        return (p, v);
    }
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..24 {
        let mid = 0.5 * (lo + hi);
        if (at(mid).1 < 0.0) == side {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    match at(0.5 * lo) {
        (p, v) if (v < 0.0) == side => (p, v),
        _ => (free, value),
    }
}

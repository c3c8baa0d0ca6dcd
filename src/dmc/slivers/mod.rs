//! Slivers, spikes and specks: the bad triangles Marching Cubes makes in the dual cells, removed in
//! two steps.
//!
//! **Why they arise.** Every mesh vertex is a root of the field on a dual edge, so where it falls
//! is the surface's business, not the octree's. A dual vertex on a crease lies *on* the surface
//! (the QEF puts it there), and every crossing on its dual edges crowds around it; two crossings on
//! edges of different dual vertices can land a hair apart; and Marching Cubes' fixed triangulation
//! of each cell then makes a sliver, or a triangle too small to have a meaningful normal that
//! stands across a crease (a spike), whatever the dual vertices' positions. Restricting the QEF
//! (vertices exactly on the level) only moves the crowding onto the vertex: the first step below
//! does that on the mesh, where it can be checked.
//!
//! 1. [`collapse`] (§4 of the paper, in the form that needs no restricted QEF): a crossing within
//!    [`SNAP`] of a finest cell of one of its dual edge's ends moves onto that end, and all
//!    crossings moved onto one dual vertex become one mesh vertex; the fan of slivers between them
//!    goes. A dual vertex that close to the surface is within `SNAP` cells of it, so the distance
//!    bound moves by at most that much. Collapsing can join two sheets that pass on either side of
//!    one vertex (a wall thinner than `2 * SNAP` cells); the contour's topology is compared before
//!    and after, and where it changed, nothing is collapsed.
//! 2. [`improve`]: what is left, removed by edge collapses and flips, each checked before it is
//!    made to keep the topology, the surface's shape and distance, and the absence of crossings
//!    (see there). This is a repair pass, bounded ([`PASSES`]) and measured
//!    ([`super::DmcStats::improved`]); it cannot be avoided by placing the dual vertices
//!    differently, for the reason above.

mod replay;

pub use replay::History;

use super::contour::{Contour, DualVertices};
use crate::mesh::analysis;

/// How close to a dual vertex (in finest cells) a crossing is moved onto it.
pub const SNAP: f32 = 0.1;

/// Collapses the slivers of `contour` (dual vertices in `vertices`, finest cells of side `h`);
/// how many triangles went.
pub fn collapse(contour: &mut Contour, vertices: &DualVertices, h: f32) -> usize {
    let reach = SNAP * h;
    let n = contour.crossings.len();
    let mut snapped_to = vec![u32::MAX; vertices.positions.len()];
    let mut remap: Vec<u32> = (0..n as u32).collect();
    let mut positions = contour.mesh.positions.clone();
    for (i, c) in contour.crossings.iter().enumerate() {
        let (a, b) = (vertices.positions[c.inside as usize], vertices.positions[c.outside as usize]);
        let length = (b - a).length();
        let end = if c.t * length < reach {
            c.inside
        } else if (1.0 - c.t) * length < reach {
            c.outside
        } else {
            continue;
        };
        let slot = &mut snapped_to[end as usize];
        if *slot == u32::MAX {
            *slot = i as u32;
            positions[i] = vertices.positions[end as usize];
        }
        remap[i] = *slot;
    }
    let mut triangles = Vec::with_capacity(contour.mesh.triangles.len());
    let mut cells = Vec::with_capacity(triangles.capacity());
    for (t, &c) in contour.mesh.triangles.iter().zip(&contour.cell_of_triangle) {
        let v = t.map(|v| remap[v as usize]);
        if v[0] != v[1] && v[1] != v[2] && v[0] != v[2] {
            triangles.push(v);
            cells.push(c);
        }
    }
    let removed = contour.mesh.triangles.len() - triangles.len();
    if removed == 0 {
        return 0;
    }
    let collapsed = crate::mesh::Mesh { positions, normals: Vec::new(), triangles };
    let (before, after) = (analysis::topology(&contour.mesh), analysis::topology(&collapsed));
    let same =
        |t: &analysis::Topology| (t.euler, t.components, t.is_closed_manifold(), t.degenerate_triangles);
    if same(&before) != same(&after) {
        return 0;
    }
    contour.mesh = collapsed;
    contour.cell_of_triangle = cells;
    removed
}

/// Triangles with an angle under this are slivers to remove.
pub const SLIVER_DEG: f64 = 10.0;

/// A triangle turned from the true normals at all three of its corners by more than this is a
/// spike (or a notch across a crease) to remove, and no change may make one.
pub const SPIKE_DEG: f64 = 30.0;

/// Edges shorter than this fraction of a finest cell are removed whatever their triangles' angles:
/// crossings that root finding put within a hair of each other, on different dual vertices' edges
/// (so [`collapse`] did not join them), make clusters of triangles too small to see whose normals
/// are rounding noise.
pub const SHORT_EDGE: f64 = 0.02;

/// A change is refused if one of its new triangles turns away from the true normals at all its
/// corners by more than this (and more than the worst triangle it replaces): the new triangles
/// must lie along the surface, on one side of a crease or the other, never across it.
pub const MAX_TURN_DEG: f64 = 30.0;

/// Passes over the remaining bad triangles.
pub const PASSES: usize = 4;

/// What [`improve`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Improved {
    pub collapses: usize,
    pub flips: usize,
    /// Bad triangles (slivers, spikes, specks) before, and left where no allowed change removes
    /// them.
    pub bad_before: usize,
    pub left: usize,
    /// Of the collapses and flips, those redone from the previous run's [`History`] without
    /// searching (see [`improve`]).
    pub replayed: usize,
}

type Corners = [glam::DVec3; 3];

/// A proposed change: per face, its new corners, or `None` where it goes.
type Change = Vec<(u32, Option<[u32; 3]>)>;

/// The smallest angle, in degrees: the one opposite the shortest side (one `acos`, not three).
fn min_angle(c: &Corners) -> f64 {
    let e = [c[1] - c[0], c[2] - c[1], c[0] - c[2]];
    let shortest =
        (0..3).min_by(|&i, &j| e[i].length_squared().total_cmp(&e[j].length_squared())).unwrap_or(0);
    let (u, v) = (-e[(shortest + 1) % 3], e[(shortest + 2) % 3]);
    let l = (u.length_squared() * v.length_squared()).sqrt();
    if l == 0.0 {
        return 0.0;
    }
    (u.dot(v) / l).clamp(-1.0, 1.0).acos().to_degrees()
}

fn normal(c: &Corners) -> glam::DVec3 {
    (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero()
}

/// How one triangle fares: its smallest angle, its turn from the surface, and whether it is bad.
#[derive(Debug, Clone, Copy)]
struct Shape {
    angle: f64,
    deviation: f64,
    bad: bool,
}

/// Worst angle, worst deviation and bad triangles over a set of triangles.
#[derive(Debug, Clone, Copy)]
struct Summary {
    angle: f64,
    deviation: f64,
    bad: usize,
}

impl Summary {
    fn new() -> Summary {
        Summary { angle: f64::INFINITY, deviation: 0.0, bad: 0 }
    }

    fn add(&mut self, s: Shape) {
        self.angle = self.angle.min(s.angle);
        self.deviation = self.deviation.max(s.deviation);
        self.bad += s.bad as usize;
    }
}

struct Work<'a> {
    positions: &'a [glam::Vec3],
    /// The true unit normal at each mesh vertex (every vertex is a root, on the surface), and the
    /// gradient's length there.
    normals: Vec<glam::DVec3>,
    gradient_length: Vec<f32>,
    field: &'a dyn crate::field::Field,
    iso: f32,
    /// Farthest a new triangle may lie from the surface, unless the ones it replaces lay farther.
    tolerance: f32,
    /// Shortest edge kept.
    short: f64,
    /// Per face, its estimated distance from the surface once measured.
    distance: Vec<f32>,
    triangles: Vec<[u32; 3]>,
    /// Per face, [`Work::shape`] of its triangle as it stands: every change weighs the faces it
    /// replaces, and a bad face's neighbours are weighed again for each of its nine changes.
    shapes: Vec<Shape>,
    alive: Vec<bool>,
    faces_of: Vec<Vec<u32>>,
    fixed: Vec<bool>,
    nearby: crate::mesh::buckets::TriangleBuckets,
    /// A buffer for the triangles near a new one.
    candidates: Vec<u32>,
    /// The changes applied so far, as (old triangle, new triangle or `None`) per face, and whether
    /// it was a flip.
    log: Vec<(replay::Logged, bool)>,
}

impl Work<'_> {
    fn corners(&self, t: [u32; 3]) -> Corners {
        t.map(|v| self.positions[v as usize].as_dvec3())
    }

    fn shape(&self, t: [u32; 3]) -> Shape {
        let c = self.corners(t);
        let angle = min_angle(&c);
        let n = normal(&c);
        let deviation = if n == glam::DVec3::ZERO {
            180.0
        } else {
            let cos = t.iter().map(|&v| self.normals[v as usize].dot(n)).fold(-1.0, f64::max);
            cos.clamp(-1.0, 1.0).acos().to_degrees()
        };
        let short = (0..3).any(|i| (c[(i + 1) % 3] - c[i]).length() < self.short);
        Shape { angle, deviation, bad: angle < SLIVER_DEG || deviation > SPIKE_DEG || short }
    }

    fn bounds(&self, f: u32) -> (glam::DVec3, glam::DVec3) {
        crate::mesh::buckets::bounds(&self.corners(self.triangles[f as usize]))
    }

    /// Whether `change` is an improvement that keeps the surface where it was, and how good: it
    /// leaves fewer bad triangles, or as many with a larger worst angle, and turns no new triangle
    /// from the surface by more than [`MAX_TURN_DEG`] (or than the worst it replaces). Returns
    /// (bad triangles after, worst angle after).
    fn better(&self, change: &[(u32, Option<[u32; 3]>)]) -> Option<(usize, f64)> {
        let (mut before, mut after) = (Summary::new(), Summary::new());
        for &(f, t) in change {
            let old = self.triangles[f as usize];
            if t == Some(old) {
                continue;
            }
            before.add(self.shapes[f as usize]);
            if let Some(t) = t {
                after.add(self.shape(t));
            }
        }
        if after.deviation > before.deviation.max(MAX_TURN_DEG) {
            return None;
        }
        if !(after.bad < before.bad || (after.bad == before.bad && after.angle > before.angle)) {
            return None;
        }
        Some((after.bad, after.angle))
    }

    /// Whether no new triangle of `change` crosses or folds onto a triangle nearby (the costly
    /// part of the checks, asked of the best changes first).
    fn clear(&mut self, change: &[(u32, Option<[u32; 3]>)]) -> bool {
        let mut candidates = std::mem::take(&mut self.candidates);
        let clear = self.clear_with(change, &mut candidates);
        self.candidates = candidates;
        clear
    }

    /// [`Work::clear`] with a buffer for the triangles nearby. One look-up over the box of all the
    /// new triangles: a collapse makes several around one vertex and a flip two across an edge
    /// (3.1 per change checked on the gear at 128 cells), which share most of their
    /// neighbourhood, and a look-up per triangle was most of this check's cost.
    fn clear_with(&mut self, change: &[(u32, Option<[u32; 3]>)], candidates: &mut Vec<u32>) -> bool {
        let new: Vec<([u32; 3], Corners)> = change
            .iter()
            .filter_map(|&(f, t)| t.filter(|&t| t != self.triangles[f as usize]))
            .map(|t| (t, self.corners(t)))
            .collect();
        let Some((lo, hi)) = new
            .iter()
            .map(|(_, c)| crate::mesh::buckets::bounds(c))
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
        else {
            return true;
        };
        candidates.clear();
        self.nearby.query(lo, hi, candidates);
        candidates.retain(|&g| !change.iter().any(|&(f, _)| f == g));
        let nearby: Vec<([u32; 3], Corners, (glam::DVec3, glam::DVec3))> = candidates
            .iter()
            .map(|&g| {
                let u = self.triangles[g as usize];
                let d = self.corners(u);
                (u, d, crate::mesh::buckets::bounds(&d))
            })
            .collect();
        for &(t, c) in &new {
            // Triangles whose boxes miss this one's can neither cross it nor share an edge with it.
            let (tlo, thi) = crate::mesh::buckets::bounds(&c);
            let near = nearby
                .iter()
                .filter(|(_, _, (ulo, uhi))| ulo.cmple(thi).all() && uhi.cmpge(tlo).all())
                .map(|&(u, d, _)| (u, d));
            let in_change =
                change.iter().filter_map(|&(_, u)| u).filter(|&u| u != t).map(|u| (u, self.corners(u)));
            for (u, d) in near.chain(in_change) {
                if crate::mesh::analysis::self_intersect::indexed_pair_intersects((t, c), (u, d)) {
                    return false;
                }
                // Neighbours across an edge: not folded onto each other.
                let mut shared = (0..3).filter(|&i| u.contains(&t[i]));
                if let (Some(i), Some(j), None) = (shared.next(), shared.next(), shared.next()) {
                    let Some(x) = u.iter().position(|v| !t.contains(v)) else { continue };
                    let o = c[i];
                    if crate::mesh::analysis::tri_tri::folded_across_edge(
                        c[j] - o,
                        c[3 - i - j] - o,
                        d[x] - o,
                    ) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// The first-order distance `|f - iso| / |∇f|` of `t`'s farthest sample, the points
    /// [`crate::mesh::analysis::surface_error()`] measures: the centroid and halfway from it to each
    /// corner (the corners are roots, on the surface), with the gradient's length taken as the
    /// corners' mean (known already: four values per triangle, no gradient to evaluate).
    fn distance_of(&self, t: [u32; 3]) -> f32 {
        let c = t.map(|v| self.positions[v as usize]);
        let centroid = (c[0] + c[1] + c[2]) / 3.0;
        let points = [centroid, (centroid + c[0]) * 0.5, (centroid + c[1]) * 0.5, (centroid + c[2]) * 0.5];
        let mut values = [0.0; 4];
        self.field.values(&points, &mut values);
        let g = t.iter().map(|&v| self.gradient_length[v as usize]).sum::<f32>() / 3.0;
        let worst = values.iter().map(|v| (v - self.iso).abs()).fold(0.0, f32::max);
        if g > 0.0 && g.is_finite() {
            worst / g
        } else {
            f32::INFINITY
        }
    }

    /// Whether no new triangle of `change` turns from the true normal at its centre by more than
    /// [`MAX_TURN_DEG`], or than the worst triangle it replaces, unless the change removes a
    /// sliver. [`Work::better`] judges the turn at the corners, which a triangle with a corner on
    /// each side of a crease passes; asked of every change, this rule left slivers at creases it
    /// could not remove any more (the gyroid at 64 cells: smallest angle 1.5° -> 0.03°).
    fn along_surface(&self, change: &[(u32, Option<[u32; 3]>)]) -> bool {
        let replaced = change.iter().filter(|&&(f, t)| t != Some(self.triangles[f as usize]));
        let old: Vec<[u32; 3]> = replaced.clone().map(|&(f, _)| self.triangles[f as usize]).collect();
        if old.iter().any(|&t| min_angle(&self.corners(t)) < SLIVER_DEG) {
            return true;
        }
        let new: Vec<[u32; 3]> = replaced.filter_map(|&(_, t)| t).collect();
        let after = self.centre_deviation(&new);
        after <= MAX_TURN_DEG || after <= self.centre_deviation(&old)
    }

    /// The largest angle, in degrees, between one of `tris`' normals and the true normal at its
    /// centre (180 for a triangle without a normal; 0 where the field has no gradient).
    fn centre_deviation(&self, tris: &[[u32; 3]]) -> f64 {
        tris.iter()
            .map(|&t| {
                let c = self.corners(t);
                let n = normal(&c);
                let Some(g) = self.field.gradient(((c[0] + c[1] + c[2]) / 3.0).as_vec3()) else { return 0.0 };
                if n == glam::DVec3::ZERO {
                    return 180.0;
                }
                n.dot(g.as_dvec3().normalize_or_zero()).clamp(-1.0, 1.0).acos().to_degrees()
            })
            .fold(0.0, f64::max)
    }

    /// Whether the new triangles of `change` lie no farther from the surface than the tolerance,
    /// or than the triangles they replace (measured only when a new one is beyond the tolerance).
    fn near_surface(&mut self, change: &[(u32, Option<[u32; 3]>)]) -> bool {
        let farthest = change
            .iter()
            .filter_map(|&(f, t)| t.filter(|&t| t != self.triangles[f as usize]))
            .map(|t| self.distance_of(t))
            .fold(0.0, f32::max);
        if farthest <= self.tolerance {
            return true;
        }
        change.iter().any(|&(f, _)| {
            if self.distance[f as usize].is_nan() {
                self.distance[f as usize] = self.distance_of(self.triangles[f as usize]);
            }
            self.distance[f as usize] >= farthest
        })
    }

    /// The vertices sharing an edge with `v`, sorted (a fan is a few triangles: a linear scan).
    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::with_capacity(8);
        for &f in &self.faces_of[v as usize] {
            for w in self.triangles[f as usize] {
                if w != v && !out.contains(&w) {
                    out.push(w);
                }
            }
        }
        out.sort_unstable();
        out
    }

    /// The change collapsing `b` onto `a` (with `a`'s other triangles, unchanged, for reference),
    /// if it keeps the surface a closed manifold of the same topology: the link condition (the
    /// two ends share exactly the two neighbours across the edge), and no vertex left with fewer
    /// than three neighbours.
    fn collapse_change(&self, a: u32, b: u32) -> Option<Change> {
        if self.fixed[a as usize] || self.fixed[b as usize] {
            return None;
        }
        let shared: Vec<u32> = self.faces_of[b as usize]
            .iter()
            .copied()
            .filter(|&f| self.triangles[f as usize].contains(&a))
            .collect();
        if shared.len() != 2 {
            return None;
        }
        let (na, nb) = (self.neighbours(a), self.neighbours(b));
        let common: Vec<u32> = na.iter().copied().filter(|v| nb.binary_search(v).is_ok()).collect();
        let opposite =
            shared.iter().filter_map(|&f| self.triangles[f as usize].into_iter().find(|&v| v != a && v != b));
        if common.len() != 2 || !opposite.clone().all(|v| common.contains(&v)) {
            return None;
        }
        // The vertex left has |na ∪ nb| - 2 = na + nb - 4 neighbours; each opposite one, one fewer.
        if opposite.clone().any(|v| self.neighbours(v).len() <= 3) || na.len() + nb.len() < 7 {
            return None;
        }
        let moved = self.faces_of[b as usize].iter().map(|&f| {
            let t = self.triangles[f as usize];
            (f, (!t.contains(&a)).then(|| t.map(|v| if v == b { a } else { v })))
        });
        let kept = self.faces_of[a as usize]
            .iter()
            .filter(|&&f| !self.triangles[f as usize].contains(&b))
            .map(|&f| (f, Some(self.triangles[f as usize])));
        Some(moved.chain(kept).collect())
    }

    /// The change flipping the edge `(a, b)` of face `f`, if the new edge is not there already.
    fn flip_change(&self, f: u32, a: u32, b: u32) -> Option<Change> {
        if self.fixed[a as usize] || self.fixed[b as usize] {
            return None;
        }
        let t = self.triangles[f as usize];
        let c = *t.iter().find(|&&v| v != a && v != b)?;
        let g = *self.faces_of[a as usize]
            .iter()
            .find(|&&g| g != f && self.triangles[g as usize].contains(&b))?;
        let d = *self.triangles[g as usize].iter().find(|&&v| v != a && v != b)?;
        if c == d || self.neighbours(c).contains(&d) {
            return None;
        }
        // Oriented as f: a -> b -> c.
        let i = t.iter().position(|&v| v == a)?;
        let (a, b) = if t[(i + 1) % 3] == b { (a, b) } else { (b, a) };
        Some(vec![(f, Some([a, d, c])), (g, Some([b, c, d]))])
    }

    fn apply(&mut self, change: &[(u32, Option<[u32; 3]>)], flip: bool) {
        self.log.push((change.iter().map(|&(f, t)| (self.triangles[f as usize], t)).collect(), flip));
        for &(f, t) in change {
            let old = self.triangles[f as usize];
            if t == Some(old) {
                continue;
            }
            self.distance[f as usize] = f32::NAN;
            for v in old {
                self.faces_of[v as usize].retain(|&g| g != f);
            }
            match t {
                None => {
                    self.alive[f as usize] = false;
                    self.nearby.remove(f);
                }
                Some(t) => {
                    self.triangles[f as usize] = t;
                    self.shapes[f as usize] = self.shape(t);
                    for v in t {
                        self.faces_of[v as usize].push(f);
                    }
                    let (lo, hi) = self.bounds(f);
                    self.nearby.insert(f, lo, hi);
                }
            }
        }
    }

    fn bad_faces(&self) -> Vec<(f64, u32)> {
        let mut out: Vec<(f64, u32)> = (0..self.triangles.len() as u32)
            .filter(|&f| self.alive[f as usize])
            .filter_map(|f| {
                let s = self.shapes[f as usize];
                // Worst first: spikes by their turn, then slivers and specks by their angle.
                s.bad.then_some((s.angle - s.deviation, f))
            })
            .collect();
        out.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        out
    }
}

/// The side of the cubes in which triangles are found near a change: two finest cells, about a
/// triangle's size.
fn near_cube(h: f32) -> f64 {
    2.0 * h as f64
}

/// Removes the bad triangles Marching Cubes leaves in the dual cells, by collapsing edges and
/// flipping them: slivers (an angle under [`SLIVER_DEG`]), spikes (turned more than
/// [`SPIKE_DEG`] from the surface at every corner) and specks (an edge under [`SHORT_EDGE`]).
///
/// No vertex moves: every one stays where root finding (or [`collapse`]) put it. Why this repair
/// cannot be avoided by placing the dual vertices differently: see the module docs.
///
/// **Why it is safe.** Every change is checked before it is made: collapses only under the link
/// condition (so the surface keeps its topology and stays a closed manifold), flips only to an edge
/// not already there; the new triangles must leave fewer bad ones than the old (or as many with a
/// larger worst angle), lie along the surface (within [`MAX_TURN_DEG`] of the true normal at a
/// corner, or no worse than the worst triangle they replace; at their centres too where no
/// sliver goes: `Work::along_surface`), stay within the tolerance of the
/// surface (or no farther than the old ones), and neither cross nor fold onto any triangle nearby
/// (the analysis's exact tests, on the triangles in [`crate::mesh::buckets`] of two finest cells,
/// about a triangle's size).
///
/// **Why it is bounded.** At most [`PASSES`] passes over the bad triangles, each change removing
/// a vertex or replacing two triangles by better ones; the caller reports what it did.
///
/// **Contouring again.** Untangling contours the whole octree again after moving a few vertices,
/// so most of the mesh is the one the previous run improved. `history` holds that run's start
/// and its changes: those whose triangles, and every triangle around their vertices, are the same
/// here are made again in their order without the search for the best change, each checked
/// again for crossings (the one check that looks beyond those triangles); the passes then take
/// what is left. `history` then holds this run.
pub fn improve(
    contour: &mut Contour,
    field: &dyn crate::field::Field,
    iso: f32,
    tolerance: f32,
    h: f32,
    history: &mut History,
) -> Improved {
    let mesh = &contour.mesh;
    let n = mesh.positions.len();
    let mut faces_of = vec![Vec::new(); n];
    let mut edge_count: rustc_hash::FxHashMap<(u32, u32), u32> = Default::default();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (i, &v) in t.iter().enumerate() {
            faces_of[v as usize].push(f as u32);
            let w = t[(i + 1) % 3];
            *edge_count.entry((v.min(w), v.max(w))).or_default() += 1;
        }
    }
    let mut fixed = vec![false; n];
    for (&(a, b), &count) in &edge_count {
        if count != 2 {
            fixed[a as usize] = true;
            fixed[b as usize] = true;
        }
    }
    let (mut scratch, mut gradients) = (Vec::new(), Vec::new());
    crate::field::gradients_or_differences(field, &mesh.positions, h * 1e-2, &mut scratch, &mut gradients);
    let mut work = Work {
        positions: &mesh.positions,
        normals: gradients.iter().map(|g| g.as_dvec3().normalize_or_zero()).collect(),
        gradient_length: gradients.iter().map(|g| g.length()).collect(),
        field,
        iso,
        tolerance,
        short: SHORT_EDGE * h as f64,
        distance: vec![f32::NAN; mesh.triangles.len()],
        triangles: mesh.triangles.clone(),
        shapes: Vec::new(),
        alive: vec![true; mesh.triangles.len()],
        faces_of,
        fixed,
        nearby: crate::mesh::buckets::TriangleBuckets::build(
            near_cube(h),
            mesh.triangles
                .iter()
                .map(|t| crate::mesh::buckets::bounds(&t.map(|v| mesh.positions[v as usize].as_dvec3()))),
        ),
        candidates: Vec::new(),
        log: Vec::new(),
    };
    work.shapes = work.triangles.iter().map(|&t| work.shape(t)).collect();
    let mut bad = work.bad_faces();
    let mut out = Improved { bad_before: bad.len(), ..Improved::default() };
    out.replayed = replay::replay(&mut work, history, near_cube(h));
    for pass in 0..PASSES {
        // The list taken before the replay serves the first pass if nothing was redone.
        if pass > 0 || out.replayed > 0 {
            bad = work.bad_faces();
        }
        let mut changed = 0;
        for &(_, f) in &bad {
            if !work.alive[f as usize] || !work.shapes[f as usize].bad {
                continue;
            }
            let t = work.triangles[f as usize];
            let mut options: Vec<((usize, f64), Change, bool)> = Vec::new();
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                for (change, flip) in [
                    (work.flip_change(f, a, b), true),
                    (work.collapse_change(a, b), false),
                    (work.collapse_change(b, a), false),
                ] {
                    let Some(change) = change else { continue };
                    if let Some(score) = work.better(&change) {
                        options.push((score, change, flip));
                    }
                }
            }
            // The best change that crosses nothing and stays near the surface (the costly checks
            // asked only as far down the list as needed): fewest bad triangles, then the largest
            // worst angle.
            options.sort_by(|x, y| x.0 .0.cmp(&y.0 .0).then(y.0 .1.total_cmp(&x.0 .1)));
            if let Some((_, change, flip)) = options.into_iter().find(|(_, change, _)| {
                work.along_surface(change) && work.clear(change) && work.near_surface(change)
            }) {
                work.apply(&change, flip);
                changed += 1;
            }
        }
        if changed == 0 {
            break;
        }
    }
    out.left = work.bad_faces().len();
    for (_, flip) in &work.log {
        if *flip {
            out.flips += 1;
        } else {
            out.collapses += 1;
        }
    }
    *history = History::new(&mesh.positions, &mesh.triangles, std::mem::take(&mut work.log));
    let mut triangles = Vec::with_capacity(work.triangles.len());
    let mut cells = Vec::with_capacity(work.triangles.len());
    for (f, t) in work.triangles.iter().enumerate() {
        if work.alive[f] {
            triangles.push(*t);
            cells.push(contour.cell_of_triangle[f]);
        }
    }
    contour.mesh.triangles = triangles;
    contour.cell_of_triangle = cells;
    out
}

//! Feature-sensitive decimation (the EMC paper's §5): Garland–Heckbert quadric edge collapses that
//! leave the feature lines where they are, and never break the mesh on the way down.
//!
//! EMC places vertices exactly on creases and corners but pays for it with MC's triangle count, a
//! few hundred thousand at 256³. Collapsing edges in order of quadric error removes the triangles
//! on flat and gently curved parts first; the feature lines are constraints, not costs:
//! - a vertex on one feature edge (a line's end) or on three or more (a corner) never moves, and
//!   neither does a vertex on an open or non-manifold edge;
//! - a vertex on exactly two feature edges is only removed by sliding it onto a neighbour along its
//!   line, and only while every original point of the line stays within
//!   [`DecimateOptions::feature_tolerance`] of the shortened polyline (so straight creases thin
//!   out to their corners and curved ones keep the vertices they need);
//! - a free vertex merges into a constrained one at the constrained one's position, and two free
//!   vertices meet at the point of least quadric error (feature-edge quadrics, planes through each
//!   crease perpendicular to its faces, pull the optimum away from the lines); with a field, that
//!   point then moves off the surface against its faces' sag (`balance`), and under an error
//!   bound the midpoint and the two ends are tried where it fails;
//! - where the collapses stop short of the target, rounds of evening out the free vertices
//!   (`relax`) and collapsing again follow.
//!
//! Every collapse is checked before it is made (see `check`): the link condition and the local
//! edge orientations (the mesh stays a closed oriented 2-manifold of the same Euler
//! characteristic), no face turned by more than [`DecimateOptions::max_normal_turn_deg`], no
//! degenerate faces, no new angle below [`DecimateOptions::min_angle_deg`] unless the faces it
//! replaces were already worse, no crossing with any face nearby ([`crate::mesh::buckets`] of
//! the faces and the analysis's exact triangle-pair test), and with a field, no new vertex or face
//! sample farther than [`DecimateOptions::max_error`] from the zero set.

mod balance;
mod check;
mod quadric;
mod queue;
mod relax;
mod slivers;

use crate::error::Error;
use crate::field::Field;
use crate::mesh::buckets::{bounds, TriangleBuckets};
use crate::mesh::Mesh;
use crate::progress::checkpoint;
use check::Plan;
use glam::{DVec3, Vec3};
use quadric::Quadric;
use queue::{Candidate, Queue};
use std::collections::HashMap;

/// What to decimate to and how careful to be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecimateOptions {
    /// Stop once at most this many triangles are left (or no collapse passes the checks).
    pub target_triangles: usize,
    /// Refuse a collapse that puts a vertex or a face sample (centroid, and halfway from it to each
    /// corner: what [`crate::mesh::analysis::surface_error()`] measures) farther than this from the
    /// field's zero set. Without a field, bounds the quadric's RMS distance instead.
    pub max_error: Option<f64>,
    /// How far an original feature-line vertex may end up from the decimated feature polyline.
    pub feature_tolerance: f64,
    /// Largest turn of a face's normal in one collapse: more means the collapse folds the surface.
    pub max_normal_turn_deg: f64,
    /// New triangles may not have a smaller angle than this, unless one of the triangles they
    /// replace already had: decimation should not add slivers to EMC's.
    pub min_angle_deg: f64,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        DecimateOptions {
            target_triangles: 0,
            max_error: None,
            feature_tolerance: 0.0,
            max_normal_turn_deg: 60.0,
            min_angle_deg: 10.0,
        }
    }
}

/// A decimated mesh with its feature lines renumbered.
#[derive(Debug, Clone, Default)]
pub struct Decimated {
    pub mesh: Mesh,
    pub feature_edges: Vec<[u32; 2]>,
    pub collapses: usize,
}

/// How a vertex may move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Free,
    /// On exactly two feature edges: slides along its line only.
    Line,
    /// A corner, a line's end, or on an open or non-manifold edge.
    Fixed,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Decimates `mesh` towards `options.target_triangles`, keeping `feature_edges` (vertex index
/// pairs) as constraints; `field`, where given, bounds the error and gives moved vertices their
/// normals. Fails only with [`Error::Cancelled`], from a [`checkpoint`] ("decimate") every few
/// thousand collapses: on a large mesh this takes seconds, and a page must be able to stop it.
pub fn decimate(
    mesh: &Mesh,
    feature_edges: &[[u32; 2]],
    field: Option<&dyn Field>,
    options: &DecimateOptions,
) -> Result<Decimated, Error> {
    let mut state = State::new(mesh, feature_edges, field, options);
    state.run()?;
    // Where the collapses stop short of the target (every one left refused by the bound or the
    // checks), the free vertices move towards their neighbours' centre (on the surface, balanced
    // against their faces' sag) and the collapses refused are tried again: a round of greedy
    // collapses leaves triangles of uneven size, the small ones kept only because a neighbour is
    // too large to grow.
    for _ in 0..MAX_ROUNDS {
        let before = state.alive_count;
        if before <= options.target_triangles || field.is_none() {
            break;
        }
        state.relax();
        state.push_all();
        state.run()?;
        if (before - state.alive_count) * ROUND_GAIN < before {
            break;
        }
    }
    // The slivers' passes trade no distance for angles: under the bound if one was given, or
    // else under the largest distance the collapses left.
    if field.is_some() && options.max_error.is_none() {
        let worst = state.largest_distance();
        state.options.max_error = Some(worst);
    }
    state.collapse_slivers();
    state.relax_slivers();
    state.improve_angles();
    // The slivers left have their corners on feature lines: Steiner points, where the target
    // leaves room for their triangles (any room, where the checks stopped the collapses short of
    // it), then the same passes again.
    let room =
        if state.alive_count > options.target_triangles { usize::MAX } else { options.target_triangles };
    for _ in 0..SPLIT_ROUNDS {
        if state.split_slivers(room) == 0 {
            break;
        }
        state.collapse_slivers();
        state.relax_slivers();
        state.improve_angles();
    }
    Ok(state.finish(mesh))
}

/// Rounds of relaxing and collapsing again after the first pass, at most; on the cube minus a
/// ball at 128 cells with twice EMC's error as the bound, they take the first pass's 7 944
/// triangles to 7 556, 7 458 and 7 424.
const MAX_ROUNDS: usize = 3;
/// Another round follows only while the last one removed more than one in this many triangles.
const ROUND_GAIN: usize = 100;

/// Rounds of Steiner points for the slivers the other passes leave, at most: on EMC's gear at 64
/// cells decimated towards a tenth, one round takes the share under 10° from 3.4 % to 0.7 % with
/// 92 triangles more, a second to 0.4 % with 10 more, a third changes nothing.
const SPLIT_ROUNDS: usize = 2;

/// Heap entries looked at between two checkpoints.
const POPS_PER_CHECKPOINT: usize = 4096;

struct State<'a> {
    pos: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    alive_count: usize,
    faces_of: Vec<Vec<u32>>,
    kind: Vec<Kind>,
    moved: Vec<bool>,
    quadric: Vec<Quadric>,
    area: Vec<f64>,
    stamp: Vec<u32>,
    /// Per current feature edge, the original feature vertices it stands for (besides its ends).
    lines: HashMap<(u32, u32), Vec<DVec3>>,
    line_neighbours: Vec<Vec<u32>>,
    grid: TriangleBuckets,
    /// The faces alive when `grid` was built.
    grid_faces: usize,
    heap: Queue,
    field: Option<&'a dyn Field>,
    options: DecimateOptions,
    /// Below this squared length a face normal counts as degenerate.
    tiny_area: f64,
    fd_step: f32,
    collapses: usize,
}

impl<'a> State<'a> {
    fn new(
        mesh: &Mesh,
        feature_edges: &[[u32; 2]],
        field: Option<&'a dyn Field>,
        options: &DecimateOptions,
    ) -> Self {
        let n = mesh.positions.len();
        let pos: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let tris: Vec<[u32; 3]> = mesh.triangles.clone();
        let alive: Vec<bool> = tris.iter().map(|&[a, b, c]| a != b && b != c && a != c).collect();
        let mut faces_of = vec![Vec::new(); n];
        for (f, t) in tris.iter().enumerate().filter(|(f, _)| alive[*f]) {
            for &v in t {
                faces_of[v as usize].push(f as u32);
            }
        }
        let (lo, hi) =
            pos.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), &p| (l.min(p), h.max(p)));
        let diagonal = if n > 0 { (hi - lo).length() } else { 1.0 };
        let mut state = State {
            kind: vec![Kind::Free; n],
            moved: vec![false; n],
            quadric: vec![Quadric::default(); n],
            area: vec![0.0; n],
            stamp: vec![0; n],
            lines: HashMap::new(),
            line_neighbours: vec![Vec::new(); n],
            grid: TriangleBuckets::build(1.0, std::iter::empty()),
            grid_faces: 0,
            heap: Queue::default(),
            alive_count: alive.iter().filter(|&&a| a).count(),
            pos,
            tris,
            alive,
            faces_of,
            field,
            options: *options,
            tiny_area: (1e-12 * diagonal * diagonal).powi(2),
            fd_step: (1e-4 * diagonal).max(1e-6) as f32,
            collapses: 0,
        };
        state.classify(feature_edges);
        state.init_quadrics();
        state.init_grid();
        state.push_all();
        state
    }

    /// Every edge's cheapest allowed collapse onto the heap.
    fn push_all(&mut self) {
        for v in 0..self.pos.len() as u32 {
            for w in self.neighbours(v) {
                if v < w {
                    self.push(v, w);
                }
            }
        }
    }

    fn corners(&self, f: u32) -> [DVec3; 3] {
        self.tris[f as usize].map(|v| self.pos[v as usize])
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut out: Vec<u32> = self.faces_of[v as usize]
            .iter()
            .flat_map(|&f| self.tris[f as usize])
            .filter(|&w| w != v)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Kinds from the feature degree, open and non-manifold edges and vertices whose faces do not
    /// form one disc; feature edges that are not mesh edges are ignored.
    fn classify(&mut self, feature_edges: &[[u32; 2]]) {
        let mut edge_faces: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for t in self.tris.iter().zip(&self.alive).filter(|(_, &alive)| alive).map(|(t, _)| t) {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                let e = edge_faces.entry(key(a, b)).or_default();
                if a < b {
                    e.0 += 1;
                } else {
                    e.1 += 1;
                }
            }
        }
        for (&(a, b), &(forward, backward)) in &edge_faces {
            if forward != 1 || backward != 1 {
                self.kind[a as usize] = Kind::Fixed;
                self.kind[b as usize] = Kind::Fixed;
            }
        }
        for v in 0..self.pos.len() as u32 {
            if !self.fan_is_one_disc(v) {
                self.kind[v as usize] = Kind::Fixed;
            }
        }
        for &[a, b] in feature_edges {
            if a == b || !edge_faces.contains_key(&key(a, b)) || self.lines.contains_key(&key(a, b)) {
                continue;
            }
            self.lines.insert(key(a, b), Vec::new());
            self.line_neighbours[a as usize].push(b);
            self.line_neighbours[b as usize].push(a);
        }
        for v in 0..self.pos.len() {
            let degree = self.line_neighbours[v].len();
            if degree > 0 && self.kind[v] == Kind::Free {
                self.kind[v] = if degree == 2 { Kind::Line } else { Kind::Fixed };
            }
        }
    }

    /// Whether the faces around `v` (each `v, a, b` counter-clockwise) chain `a → b` into a single
    /// cycle through all of them.
    fn fan_is_one_disc(&self, v: u32) -> bool {
        let faces = &self.faces_of[v as usize];
        if faces.is_empty() {
            return true;
        }
        let next: HashMap<u32, u32> = faces.iter().map(|&f| self.opposite_edge(f, v)).collect();
        if next.len() != faces.len() {
            return false;
        }
        let start = self.opposite_edge(faces[0], v).0;
        let (mut at, mut steps) = (start, 0);
        while let Some(&b) = next.get(&at) {
            at = b;
            steps += 1;
            if at == start || steps > faces.len() {
                break;
            }
        }
        at == start && steps == faces.len()
    }

    /// For face `f` with corner `v`: the other two corners in counter-clockwise order after `v`.
    fn opposite_edge(&self, f: u32, v: u32) -> (u32, u32) {
        let t = self.tris[f as usize];
        let i = t.iter().position(|&w| w == v).unwrap_or(0);
        (t[(i + 1) % 3], t[(i + 2) % 3])
    }

    /// Area-weighted face planes at every corner, plus for each feature edge the planes through it
    /// perpendicular to its two faces, weighted heavily so that nothing is placed across a crease.
    fn init_quadrics(&mut self) {
        for f in 0..self.tris.len() as u32 {
            if !self.alive[f as usize] {
                continue;
            }
            let [a, b, c] = self.corners(f);
            let n = (b - a).cross(c - a);
            let area = 0.5 * n.length();
            let Some(unit) = n.try_normalize() else { continue };
            let q = Quadric::plane(unit, a, area);
            for v in self.tris[f as usize] {
                self.quadric[v as usize].add(&q);
                self.area[v as usize] += area / 3.0;
            }
        }
        // Sorted: sums in a fixed order make the same input give the same output, run after run.
        let mut edges: Vec<(u32, u32)> = self.lines.keys().copied().collect();
        edges.sort_unstable();
        for (a, b) in edges {
            let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
            let along = pb - pa;
            for &f in &self.faces_of[a as usize] {
                if !self.tris[f as usize].contains(&b) {
                    continue;
                }
                let [x, y, z] = self.corners(f);
                let Some(normal) = along.cross((y - x).cross(z - x)).try_normalize() else { continue };
                let q = Quadric::plane(normal, pa, 10.0 * along.length_squared());
                self.quadric[a as usize].add(&q);
                self.quadric[b as usize].add(&q);
            }
        }
    }

    fn init_grid(&mut self) {
        let (mut total, mut count) = (0.0, 0usize);
        for f in 0..self.tris.len() as u32 {
            if self.alive[f as usize] {
                let [a, b, c] = self.corners(f);
                total += (b - a).length() + (c - b).length() + (a - c).length();
                count += 3;
            }
        }
        let mean = if count > 0 { total / count as f64 } else { 1.0 };
        let boxes: Vec<(DVec3, DVec3)> =
            (0..self.tris.len() as u32).map(|f| bounds(&self.corners(f))).collect();
        self.grid = TriangleBuckets::build(4.0 * mean, boxes.into_iter());
        self.grid_faces = self.alive_count;
        for f in 0..self.tris.len() as u32 {
            if !self.alive[f as usize] {
                self.grid.remove(f);
            }
        }
    }

    fn insert_face(&mut self, f: u32) {
        let c = self.corners(f);
        let (lo, hi) = bounds(&c);
        self.grid.insert(f, lo, hi);
    }

    /// The cheapest allowed way to collapse the edge `v`–`w`, if any, onto the heap.
    fn push(&mut self, v: u32, w: u32) {
        let (kv, kw) = (self.kind[v as usize], self.kind[w as usize]);
        let on_line = self.lines.contains_key(&key(v, w));
        let mut options: Vec<(u32, u32, DVec3)> = Vec::new();
        match (kv, kw) {
            (Kind::Free, Kind::Free) => {
                let (pv, pw) = (self.pos[v as usize], self.pos[w as usize]);
                let mut q = self.quadric[v as usize];
                q.add(&self.quadric[w as usize]);
                let mid = 0.5 * (pv + pw);
                let mut points = vec![pv, pw, mid];
                // An optimum far off the edge comes from nearly parallel planes: not trusted.
                if let Some(p) = q.minimizer().filter(|p| (*p - mid).length() <= (pw - pv).length()) {
                    points.push(p);
                }
                let best = points.into_iter().min_by(|a, b| q.eval(*a).total_cmp(&q.eval(*b)));
                options.extend(best.map(|p| (v, w, p)));
            }
            (Kind::Free, _) => options.push((v, w, self.pos[w as usize])),
            (_, Kind::Free) => options.push((w, v, self.pos[v as usize])),
            _ if on_line => {
                if kv == Kind::Line {
                    options.push((v, w, self.pos[w as usize]));
                }
                if kw == Kind::Line {
                    options.push((w, v, self.pos[v as usize]));
                }
            }
            _ => {}
        }
        let stamps = [self.stamp[v as usize], self.stamp[w as usize]];
        let best = options
            .into_iter()
            .map(|(remove, keep, target)| (self.cost(remove, keep, target), remove, keep, target))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((cost, remove, keep, target)) = best {
            let stamps = if remove == v { stamps } else { [stamps[1], stamps[0]] };
            self.heap.push(Candidate { cost, remove, keep, target, stamps });
        }
    }

    /// Mean squared distance to the merged planes, plus a small share of the squared edge length so
    /// that on a flat patch (zero quadric error everywhere) short edges go first.
    fn cost(&self, remove: u32, keep: u32, target: DVec3) -> f64 {
        let mut q = self.quadric[remove as usize];
        q.add(&self.quadric[keep as usize]);
        let area = (self.area[remove as usize] + self.area[keep as usize]).max(f64::MIN_POSITIVE);
        let length = (self.pos[remove as usize] - self.pos[keep as usize]).length_squared();
        q.eval(target) / area + 1e-5 * length
    }

    fn run(&mut self) -> Result<(), Error> {
        let start = self.alive_count;
        let span = start.saturating_sub(self.options.target_triangles).max(1) as f32;
        let mut pops = 0usize;
        while self.alive_count > self.options.target_triangles {
            let Some(c) = self.heap.pop() else { break };
            pops += 1;
            if pops % POPS_PER_CHECKPOINT == 0 {
                checkpoint("decimate", (start - self.alive_count) as f32 / span)?;
            }
            let (r, k) = (c.remove as usize, c.keep as usize);
            if self.faces_of[r].is_empty() || c.stamps != [self.stamp[r], self.stamp[k]] {
                continue;
            }
            if let Some(bound) = self.options.max_error {
                if self.field.is_none() && c.cost.sqrt() > bound {
                    continue;
                }
            }
            // Under an error bound, two free vertices may also meet halfway or at either end
            // where the quadric's best point makes a sliver or sags too far; without one, the
            // edge's cost stands only for the point it was computed at.
            let mut placements = vec![c.target];
            let bounded = self.options.max_error.is_some() && self.field.is_some();
            if bounded && self.kind[r] == Kind::Free && self.kind[k] == Kind::Free {
                for p in [0.5 * (self.pos[r] + self.pos[k]), self.pos[k], self.pos[r]] {
                    if !placements.contains(&p) {
                        placements.push(p);
                    }
                }
            }
            if let Some(plan) = self.check(c.remove, c.keep, &placements, 0.0) {
                self.apply(c.remove, c.keep, plan);
                // Faces grow as they go: buckets sized for the first ones would record each
                // survivor in dozens of cubes and make every crossing query scan them.
                if 2 * self.alive_count < self.grid_faces {
                    self.init_grid();
                }
            }
        }
        Ok(())
    }

    fn apply(&mut self, u: u32, v: u32, plan: Plan) {
        let p = plan.target;
        for &f in &plan.removed {
            self.alive[f as usize] = false;
            self.grid.remove(f);
            for w in self.tris[f as usize] {
                if w != u && w != v {
                    self.faces_of[w as usize].retain(|&g| g != f);
                }
            }
        }
        self.alive_count -= plan.removed.len();
        for &(f, t) in &plan.changed {
            self.tris[f as usize] = t;
        }
        self.faces_of[v as usize] = plan.changed.iter().map(|c| c.0).collect();
        self.faces_of[u as usize].clear();
        if self.pos[v as usize] != p {
            self.moved[v as usize] = true;
        }
        self.pos[v as usize] = p;
        let q = self.quadric[u as usize];
        self.quadric[v as usize].add(&q);
        self.area[v as usize] += self.area[u as usize];
        if let Some((w, points)) = plan.line {
            self.lines.remove(&key(u, v));
            self.lines.remove(&key(w, u));
            self.lines.insert(key(w, v), points);
            for (x, y) in [(w, v), (v, w)] {
                for n in &mut self.line_neighbours[x as usize] {
                    if *n == u {
                        *n = y;
                    }
                }
            }
            self.line_neighbours[u as usize].clear();
        }
        for &(f, _) in &plan.changed {
            self.insert_face(f);
        }
        self.collapses += 1;
        let ring = self.neighbours(v);
        self.stamp[v as usize] += 1;
        for &w in &ring {
            self.stamp[w as usize] += 1;
        }
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for &x in ring.iter().chain(std::iter::once(&v)) {
            for y in self.neighbours(x) {
                edges.push(key(x, y));
            }
        }
        edges.sort_unstable();
        edges.dedup();
        for (a, b) in edges {
            self.push(a, b);
        }
    }

    /// The surviving faces and the vertices they use, renumbered; moved vertices get the field's
    /// normal there, or the average of their faces' without a field gradient.
    fn finish(self, input: &Mesh) -> Decimated {
        let mut index = vec![u32::MAX; self.pos.len()];
        let mut mesh = Mesh::default();
        let mut old_of_new = Vec::new();
        for f in (0..self.tris.len()).filter(|&f| self.alive[f]) {
            let t = self.tris[f].map(|w| {
                if index[w as usize] == u32::MAX {
                    index[w as usize] = old_of_new.len() as u32;
                    old_of_new.push(w);
                }
                index[w as usize]
            });
            mesh.triangles.push(t);
        }
        mesh.positions = old_of_new.iter().map(|&w| self.pos[w as usize].as_vec3()).collect();
        if input.normals.len() == input.positions.len() {
            let mut face_normals = Mesh {
                positions: mesh.positions.clone(),
                normals: vec![],
                triangles: mesh.triangles.clone(),
            };
            face_normals.compute_normals_from_faces();
            mesh.normals = old_of_new
                .iter()
                .enumerate()
                .map(|(i, &w)| {
                    if !self.moved[w as usize] {
                        return input.normals[w as usize];
                    }
                    let p = mesh.positions[i];
                    let from_field = self.field.and_then(|f| f.gradient(p)).and_then(|g| g.try_normalize());
                    from_field.unwrap_or(face_normals.normals[i])
                })
                .collect::<Vec<Vec3>>();
        }
        let mut feature_edges: Vec<[u32; 2]> = self
            .lines
            .keys()
            .map(|&(a, b)| [index[a as usize], index[b as usize]])
            .filter(|e| e[0] != u32::MAX && e[1] != u32::MAX)
            .collect();
        feature_edges.sort_unstable();
        Decimated { mesh, feature_edges, collapses: self.collapses }
    }
}

/// Smallest interior angle of a triangle, in radians (0 for a degenerate one).
fn min_angle(c: &[DVec3; 3]) -> f64 {
    // One `acos`, of the largest cosine, not three: it is monotone, so the smallest angle is the
    // same number (a degenerate corner counts as 0).
    let mut largest = f64::NEG_INFINITY;
    for i in 0..3 {
        let (a, b) = (c[(i + 1) % 3] - c[i], c[(i + 2) % 3] - c[i]);
        let s = a.length() * b.length();
        if s.is_nan() || s <= 0.0 {
            return 0.0;
        }
        largest = largest.max((a.dot(b) / s).clamp(-1.0, 1.0));
    }
    largest.acos()
}

/// Distance from `x` to the segment `a`–`b`.
pub(crate) fn segment_distance(x: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let t =
        if d.length_squared() > 0.0 { ((x - a).dot(d) / d.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (x - (a + t * d)).length()
}

#[cfg(test)]
mod tests;

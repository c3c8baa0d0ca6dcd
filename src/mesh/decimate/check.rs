//! The checks a collapse must pass before it is made (see the module doc of `decimate`): the
//! faces around the kept vertex stay a closed oriented fan, a feature line stays within its
//! tolerance, no face turns over, degenerates or gets a new sliver, no new face crosses another,
//! and with a field, no face sample leaves the error bound.

use super::{bounds, key, min_angle, segment_distance, Kind, State};
use crate::field::finite_difference_gradient;
use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use glam::{DVec3, Vec3};

/// The faces a checked collapse deletes and rewrites, and for a collapse along a feature line the
/// line's far vertex and the new feature edge's original points.
pub(super) struct Plan {
    pub(super) removed: Vec<u32>,
    pub(super) changed: Vec<(u32, [u32; 3])>,
    pub(super) line: Option<(u32, Vec<DVec3>)>,
    /// Where the kept vertex goes.
    pub(super) target: DVec3,
}

impl State<'_> {
    /// Everything a collapse of `u` into `v` must pass (see the module doc), tried at each of
    /// `placements` for `v` in turn; the faces it rewrites and where `v` goes for the first that
    /// passes. New angles must also exceed `angle_above` (radians; the sliver passes ask for better
    /// than the sliver they remove).
    pub(super) fn check(&mut self, u: u32, v: u32, placements: &[DVec3], angle_above: f64) -> Option<Plan> {
        let fan_u = self.faces_of[u as usize].clone();
        let fan_v = self.faces_of[v as usize].clone();
        let removed: Vec<u32> =
            fan_u.iter().copied().filter(|&f| self.tris[f as usize].contains(&v)).collect();
        if removed.len() != 2 {
            return None;
        }
        let mut changed: Vec<(u32, [u32; 3])> = Vec::new();
        for &f in fan_u.iter().chain(&fan_v) {
            if !removed.contains(&f) {
                changed.push((f, self.tris[f as usize].map(|w| if w == u { v } else { w })));
            }
        }
        if changed.len() < 3 || !self.fan_stays_manifold(v, &changed) {
            return None;
        }
        let line = self.line_check(u, v)?;
        let old_min =
            fan_u.iter().chain(&fan_v).map(|&f| min_angle(&self.corners(f))).fold(f64::INFINITY, f64::min);
        let floor = self.options.min_angle_deg.to_radians().min(old_min.max(angle_above));
        let free = self.kind[u as usize] == Kind::Free && self.kind[v as usize] == Kind::Free;
        for &p in placements {
            // The cheap, purely geometric checks first: most refusals are new slivers.
            let Some(corners) = self.reshaped(&changed, v, p, floor) else { continue };
            let balanced = if free { self.balanced(p, &corners) } else { p };
            let (p, corners) = match self.reshaped(&changed, v, balanced, floor) {
                Some(moved) if balanced != p => (balanced, moved),
                _ => (p, corners),
            };
            if self.within_error(p, &corners) && !self.crosses(&changed, &corners, &removed) {
                return Some(Plan { removed, changed, line, target: p });
            }
        }
        None
    }

    /// The corners of faces `changed` with vertex `v` at `p`, unless one of them degenerates, gets
    /// an angle under `floor` or turns by more than [`DecimateOptions::max_normal_turn_deg`] from
    /// the face it rewrites.
    ///
    /// [`DecimateOptions::max_normal_turn_deg`]: super::DecimateOptions::max_normal_turn_deg
    pub(super) fn reshaped(
        &self,
        changed: &[(u32, [u32; 3])],
        v: u32,
        p: DVec3,
        floor: f64,
    ) -> Option<Vec<[DVec3; 3]>> {
        let at = |w: u32| if w == v { p } else { self.pos[w as usize] };
        let cos_turn = self.options.max_normal_turn_deg.to_radians().cos();
        let mut corners = Vec::with_capacity(changed.len());
        for &(f, t) in changed {
            let c = t.map(at);
            let n_new = (c[1] - c[0]).cross(c[2] - c[0]);
            if n_new.length_squared() <= self.tiny_area || min_angle(&c) < floor {
                return None;
            }
            let old = self.corners(f);
            let n_old = (old[1] - old[0]).cross(old[2] - old[0]);
            if n_old.try_normalize().is_some_and(|o| o.dot(n_new.normalize()) < cos_turn) {
                return None;
            }
            corners.push(c);
        }
        Some(corners)
    }

    /// Whether any of the rewritten faces `changed` (at `corners`) crosses another of them or a
    /// face nearby; faces in `removed` are about to go and do not count.
    pub(super) fn crosses(
        &mut self,
        changed: &[(u32, [u32; 3])],
        corners: &[[DVec3; 3]],
        removed: &[u32],
    ) -> bool {
        for i in 0..changed.len() {
            for j in i + 1..changed.len() {
                if indexed_pair_intersects((changed[i].1, corners[i]), (changed[j].1, corners[j])) {
                    return true;
                }
            }
        }
        let changed_ids: Vec<u32> = changed.iter().map(|c| c.0).collect();
        // One query over the whole fan rather than one per face: the fan's faces share most of
        // their neighbours, and a query costs a search per cube it touches.
        let boxes: Vec<(DVec3, DVec3)> = corners.iter().map(bounds).collect();
        let (lo, hi) =
            boxes.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), b| (l.min(b.0), h.max(b.1)));
        let mut nearby = Vec::new();
        self.grid.query(lo, hi, &mut nearby);
        for &g in &nearby {
            if !self.alive[g as usize] || removed.contains(&g) || changed_ids.contains(&g) {
                continue;
            }
            let c = self.corners(g);
            let (g_lo, g_hi) = bounds(&c);
            for (i, &(_, t)) in changed.iter().enumerate() {
                let (f_lo, f_hi) = boxes[i];
                let overlap = f_lo.cmple(g_hi).all() && g_lo.cmple(f_hi).all();
                if overlap && indexed_pair_intersects((t, corners[i]), (self.tris[g as usize], c)) {
                    return true;
                }
            }
        }
        false
    }

    /// Around the kept vertex, each neighbour must be reached by exactly one face edge out and one
    /// in (a closed, consistently oriented fan, which also rules out the link-condition failures:
    /// a neighbour shared off the collapsed edge would be reached twice), and no two faces may
    /// share all three corners (the tetrahedron flattened into a double-sided triangle).
    pub(super) fn fan_stays_manifold(&self, v: u32, changed: &[(u32, [u32; 3])]) -> bool {
        let mut ends: Vec<(u32, i32, i32)> = Vec::new();
        let mut sorted: Vec<[u32; 3]> = Vec::new();
        for &(_, t) in changed {
            let Some(i) = t.iter().position(|&w| w == v) else { return false };
            let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
            for (w, out, into) in [(a, 1, 0), (b, 0, 1)] {
                match ends.iter_mut().find(|e| e.0 == w) {
                    Some(e) => {
                        e.1 += out;
                        e.2 += into;
                    }
                    None => ends.push((w, out, into)),
                }
            }
            let mut s = t;
            s.sort_unstable();
            sorted.push(s);
        }
        sorted.sort_unstable();
        ends.iter().all(|e| e.1 == 1 && e.2 == 1) && sorted.windows(2).all(|w| w[0] != w[1])
    }

    /// For a collapse along a feature line: the line's vertex on the far side of `u`, and the
    /// original points the new feature edge will stand for, all within the tolerance of it. `Some(None)`
    /// for collapses that leave the lines alone.
    pub(super) fn line_check(&self, u: u32, v: u32) -> Option<Option<(u32, Vec<DVec3>)>> {
        if !self.lines.contains_key(&key(u, v)) {
            return Some(None);
        }
        let w = *self.line_neighbours[u as usize].iter().find(|&&w| w != v)?;
        if w == v || self.lines.contains_key(&key(w, v)) {
            return None;
        }
        let mut points = self.lines[&key(w, u)].clone();
        points.extend_from_slice(&self.lines[&key(u, v)]);
        points.push(self.pos[u as usize]);
        let (a, b) = (self.pos[w as usize], self.pos[v as usize]);
        let tolerance = self.options.feature_tolerance;
        points.iter().all(|&x| segment_distance(x, a, b) <= tolerance).then_some(Some((w, points)))
    }

    /// With a field: the new vertex and the sample points of the new faces within
    /// [`DecimateOptions::max_error`] of the zero set (the first sample outside ends the check).
    pub(super) fn within_error(&self, p: DVec3, faces: &[[DVec3; 3]]) -> bool {
        let Some(bound) = self.options.max_error else { return true };
        self.field.is_none()
            || (self.distance(p) <= bound
                && faces.iter().all(|c| face_samples(c).iter().all(|&x| self.distance(x) <= bound)))
    }

    /// The largest distance estimate over the surviving faces, their samples and corners.
    pub(super) fn largest_distance(&self) -> f64 {
        let faces: Vec<[DVec3; 3]> = (0..self.tris.len() as u32)
            .filter(|&f| self.alive[f as usize])
            .map(|f| self.corners(f))
            .collect();
        let corners = faces.iter().flatten().map(|&p| self.distance(p)).fold(0.0, f64::max);
        corners.max(self.face_distance(&faces))
    }

    /// The largest distance estimate over the faces' samples: each centroid and the points halfway
    /// from it to the corners, what [`crate::mesh::analysis::surface_error()`] measures inside a
    /// face. 0 without a field.
    pub(super) fn face_distance(&self, faces: &[[DVec3; 3]]) -> f64 {
        faces.iter().flat_map(face_samples).map(|x| self.distance(x)).fold(0.0, f64::max)
    }

    /// The field's value and gradient at `x` from one evaluation (a compiled program's forward
    /// pass gives both), the gradient by central differences where the field has none.
    pub(super) fn value_and_gradient(&self, x: DVec3) -> Option<(f32, Vec3)> {
        let field = self.field?;
        let x = x.as_vec3();
        let (value, gradient) = field.value_and_gradient(x);
        Some((value, gradient.unwrap_or_else(|| finite_difference_gradient(field, x, self.fd_step))))
    }

    /// One Newton step's estimate of the distance from `x` to the field's zero set, `|f| / |∇f|`
    /// (exact for signed distances); 0 without a field.
    pub(super) fn distance(&self, x: DVec3) -> f64 {
        let Some((value, gradient)) = self.value_and_gradient(x) else { return 0.0 };
        let g = gradient.length();
        if g > 1e-12 {
            (value / g).abs() as f64
        } else {
            f64::INFINITY
        }
    }
}

/// The points of a face where its distance is measured: the centroid and the points halfway from
/// it to each corner, what [`crate::mesh::analysis::surface_error()`] samples inside a face.
pub(super) fn face_samples(c: &[DVec3; 3]) -> [DVec3; 4] {
    let centre = (c[0] + c[1] + c[2]) / 3.0;
    [centre, 0.5 * (centre + c[0]), 0.5 * (centre + c[1]), 0.5 * (centre + c[2])]
}

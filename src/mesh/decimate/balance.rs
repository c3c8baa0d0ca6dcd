//! Where a merged free vertex goes when a field is known: off the surface by as much as its faces
//! sag on the other side.
//!
//! On a curved part, faces between vertices on the surface lie on one side of it, deepest near
//! their centroids; the error bound then limits a face's size to what its sag allows. Moving the
//! shared vertex along the normal, to the other side, shifts every sample of its faces the same
//! way by a known share (1 for the vertex, 2/3 halfway to it, 1/3 at a centroid, 1/6 halfway to the
//! other corners) and lets the vertex's offset and the faces' sag split the bound: on a ball, faces
//! twice as large in area for the same maximum distance. The quadric optimum already leans that
//! way, but only by what the original faces' planes say, not by what the field measures.

use super::check::face_samples;
use super::State;
use glam::DVec3;

/// Halvings of the offset interval: the optimum to 2⁻⁴⁰ of its width.
const SEARCH_STEPS: usize = 40;

impl State<'_> {
    /// `p` moved along the field's normal there to where the largest distance of `p` and of the
    /// face samples of `faces` (corner triples with `p` among them, as `within_error` samples them)
    /// is least, to first order; `p` itself without a field, a usable normal, or a gain.
    pub(super) fn balanced(&self, p: DVec3, faces: &[[DVec3; 3]]) -> DVec3 {
        let Some((s_p, normal)) = self.signed_distance(p) else { return p };
        // (signed distance, its change per unit of offset) for every sample.
        let mut lines = vec![(s_p, 1.0)];
        for c in faces {
            let Some(at) = c.iter().position(|&x| x == p) else { continue };
            for (k, x) in face_samples(c).into_iter().enumerate() {
                let share = match k {
                    0 => 1.0 / 3.0,
                    k if k - 1 == at => 2.0 / 3.0,
                    _ => 1.0 / 6.0,
                };
                let Some((s, g)) = self.signed_distance(x) else { return p };
                lines.push((s, share * g.dot(normal)));
            }
        }
        let worst = |offset: f64| lines.iter().map(|&(s, a)| (s + a * offset).abs()).fold(0.0, f64::max);
        let now = worst(0.0);
        // The largest useful offset: past `now`, the vertex alone is worse than everything today.
        let (mut lo, mut hi) = (-now, now);
        for _ in 0..SEARCH_STEPS {
            let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if worst(a) <= worst(b) {
                hi = b;
            } else {
                lo = a;
            }
        }
        let offset = 0.5 * (lo + hi);
        if worst(offset) < 0.99 * now {
            p + offset * normal
        } else {
            p
        }
    }

    /// `f / |∇f|` at `x` (the signed distance, for a distance field) and the unit normal there.
    pub(super) fn signed_distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let (value, gradient) = self.value_and_gradient(x)?;
        let gradient = gradient.as_dvec3();
        let length = gradient.length();
        (length > 1e-12).then(|| (value as f64 / length, gradient / length))
    }
}

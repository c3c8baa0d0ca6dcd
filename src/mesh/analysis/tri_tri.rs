//! Triangle-triangle intersection predicates in `f64`.
//!
//! Inputs are `f32` mesh positions; their differences and pairwise products are exact in `f64`, so
//! these tests decide correctly except for configurations within about 1e-12 (relative) of touching.
//! That is "robust enough" to count the crossings of a mesher's output, not an exact predicate.

use glam::DVec3;

/// Relative tolerance for "coplanar", "parallel" and "on a boundary ray", as a sine of an angle.
/// Far above `f64` rounding (1e-16) and far below anything an `f32` mesh can express on purpose.
const TOL: f64 = 1e-9;

/// Whether two closed triangles have a common point, by the separating axis theorem: they are
/// disjoint exactly when one of the face normals, the nine edge-edge cross products or (for coplanar
/// and degenerate triangles) an in-plane edge normal separates their projections. Touching counts
/// as intersecting. Zero-area triangles are handled (as segments or points).
pub fn triangles_intersect(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    // Work relative to one corner: smaller magnitudes, smaller rounding.
    let o = a[0];
    let a = a.map(|p| p - o);
    let b = b.map(|p| p - o);
    let ea = [a[1] - a[0], a[2] - a[1], a[0] - a[2]];
    let eb = [b[1] - b[0], b[2] - b[1], b[0] - b[2]];
    let na = ea[0].cross(a[2] - a[0]);
    let nb = eb[0].cross(b[2] - b[0]);
    let separates = |axis: DVec3| {
        let (a_lo, a_hi) = project(&a, axis);
        let (b_lo, b_hi) = project(&b, axis);
        a_hi < b_lo || b_hi < a_lo
    };
    // Face normals first: on a surface mesh almost every candidate pair is settled by them.
    if separates(na) || separates(nb) {
        return false;
    }
    for e in &ea {
        for f in &eb {
            if separates(e.cross(*f)) {
                return false;
            }
        }
    }
    for e in ea.iter().chain(&eb) {
        if separates(na.cross(*e)) || separates(nb.cross(*e)) {
            return false;
        }
    }
    true
}

fn project(t: &[DVec3; 3], axis: DVec3) -> (f64, f64) {
    let d = [t[0].dot(axis), t[1].dot(axis), t[2].dot(axis)];
    (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
}

/// Whether triangles `(0, a[0], a[1])` and `(0, b[0], b[1])`, which share the apex at the origin
/// (translate first), overlap anywhere beyond it.
///
/// Both are convex and contain the apex, so near it each looks like its wedge (the angle at the
/// apex) and overlapping beyond it is a property of the two wedges:
/// - coplanar: the wedges overlap in a positive angle, which happens exactly when a side ray of one
///   lies strictly inside the other or the wedges coincide;
/// - otherwise their intersection lies on the line where the planes meet, and they overlap when one
///   direction of that line lies in both closed wedges (a fold that touches along an edge counts).
///
/// Zero-area triangles have no wedge and never count.
pub fn overlap_beyond_shared_vertex(a: &[DVec3; 2], b: &[DVec3; 2]) -> bool {
    let na = a[0].cross(a[1]);
    let nb = b[0].cross(b[1]);
    if na == DVec3::ZERO || nb == DVec3::ZERO {
        return false;
    }
    let line = na.cross(nb);
    if line.length() <= TOL * na.length() * nb.length() {
        return [
            strictly_inside(a, na, b[0]),
            strictly_inside(a, na, b[1]),
            strictly_inside(b, nb, a[0]),
            strictly_inside(b, nb, a[1]),
        ]
        .contains(&true)
            || same_rays(a, b);
    }
    [line, -line].iter().any(|&d| in_closed_wedge(a, na, d) && in_closed_wedge(b, nb, d))
}

/// Triangles lying on top of each other across a shared edge closer than this are folded.
pub const FOLD_DEG: f64 = 1.0;

/// Whether triangles `(0, e, c)` and `(0, e, d)`, which share the edge from the origin to `e`
/// (translate first), are folded onto each other: both on the same side of the edge, their
/// half-planes within [`FOLD_DEG`]. Across an edge, two triangles meet only along it unless they
/// fold; an exact test would miss the folds DMC makes (its vertices lie on the planes of the
/// primitives only up to the QEF solve's and `f32`'s rounding: measured tilts of 1e-4° to 0.3°).
/// Triangles thinner than 1e-3 of the edge have no reliable side and never count.
pub fn folded_across_edge(e: DVec3, c: DVec3, d: DVec3) -> bool {
    folded_within(e, c, d, FOLD_DEG)
}

/// [`folded_across_edge`] with the half-planes within `max_deg` of each other.
pub fn folded_within(e: DVec3, c: DVec3, d: DVec3, max_deg: f64) -> bool {
    let (nc, nd) = (e.cross(c), e.cross(d));
    let thin = 1e-3 * e.length_squared();
    if nc.length() <= thin || nd.length() <= thin {
        return false;
    }
    nc.dot(nd) > max_deg.to_radians().cos() * nc.length() * nd.length()
}

/// Normalised sines of the angles from the first side ray to `x` and from `x` to the second, both
/// measured around the wedge's normal `n = r[0] x r[1]`: both positive inside the wedge.
fn wedge_sines(r: &[DVec3; 2], n: DVec3, x: DVec3) -> (f64, f64) {
    let nl = n.length() * x.length();
    (r[0].cross(x).dot(n) / (nl * r[0].length()), x.cross(r[1]).dot(n) / (nl * r[1].length()))
}

fn strictly_inside(r: &[DVec3; 2], n: DVec3, x: DVec3) -> bool {
    let (s0, s1) = wedge_sines(r, n, x);
    s0 > TOL && s1 > TOL
}

fn in_closed_wedge(r: &[DVec3; 2], n: DVec3, x: DVec3) -> bool {
    let (s0, s1) = wedge_sines(r, n, x);
    s0 >= -TOL && s1 >= -TOL
}

fn same_rays(a: &[DVec3; 2], b: &[DVec3; 2]) -> bool {
    let parallel =
        |x: DVec3, y: DVec3| x.dot(y) > 0.0 && x.cross(y).length() <= TOL * x.length() * y.length();
    (parallel(a[0], b[0]) && parallel(a[1], b[1])) || (parallel(a[0], b[1]) && parallel(a[1], b[0]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(p: [[f64; 3]; 3]) -> [DVec3; 3] {
        p.map(DVec3::from)
    }

    fn w(p: [[f64; 3]; 2]) -> [DVec3; 2] {
        p.map(DVec3::from)
    }

    const XY: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn crossing_triangles_intersect_and_separated_ones_do_not() {
        let a = t(XY);
        let piercing = t([[0.2, 0.2, -1.0], [0.3, 0.2, 1.0], [0.2, 0.3, 1.0]]);
        assert!(triangles_intersect(&a, &piercing));
        assert!(triangles_intersect(&piercing, &a));
        let above = t([[0.2, 0.2, 0.1], [0.3, 0.2, 1.0], [0.2, 0.3, 1.0]]);
        assert!(!triangles_intersect(&a, &above));
        // Crosses the plane of `a`, but beyond its hypotenuse.
        let beside = t([[0.6, 0.6, -1.0], [0.7, 0.6, 1.0], [0.6, 0.7, 1.0]]);
        assert!(!triangles_intersect(&a, &beside));
        // Each crosses the other's plane, so neither normal separates; the hypotenuse of `a` crossed
        // with the vertical edge of `b` does.
        let hooked = t([[0.7, 0.5, -1.0], [0.7, 0.5, 1.0], [1.5, 0.5, 0.0]]);
        assert!(!triangles_intersect(&a, &hooked));
        let linked = t([[0.3, 0.5, -1.0], [0.3, 0.5, 1.0], [1.5, 0.5, 0.0]]);
        assert!(triangles_intersect(&a, &linked));
    }

    #[test]
    fn coplanar_triangles_need_the_in_plane_axes() {
        let a = t(XY);
        let overlapping = t([[0.2, 0.2, 0.0], [2.0, 0.2, 0.0], [0.2, 2.0, 0.0]]);
        assert!(triangles_intersect(&a, &overlapping));
        // Across the hypotenuse: the normals and edge crosses are all parallel to z and cannot separate.
        let across = t([[0.6, 0.6, 0.0], [2.0, 0.6, 0.0], [0.6, 2.0, 0.0]]);
        assert!(!triangles_intersect(&a, &across));
        let touching = t([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]]);
        assert!(triangles_intersect(&a, &touching), "closed triangles touching at a corner");
    }

    #[test]
    fn a_degenerate_triangle_is_tested_as_a_segment() {
        let a = t(XY);
        let through = t([[0.2, 0.2, -1.0], [0.2, 0.2, 0.0], [0.2, 0.2, 1.0]]);
        assert!(triangles_intersect(&a, &through));
        let past = t([[0.7, 0.7, -1.0], [0.7, 0.7, 0.0], [0.7, 0.7, 1.0]]);
        assert!(!triangles_intersect(&a, &past));
    }

    #[test]
    fn coplanar_wedges_overlap_only_in_a_positive_angle() {
        let a = w([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert!(overlap_beyond_shared_vertex(&a, &w([[1.0, 1.0, 0.0], [-1.0, 2.0, 0.0]])));
        assert!(
            overlap_beyond_shared_vertex(&a, &w([[0.0, 2.0, 0.0], [3.0, 0.0, 0.0]])),
            "same wedge, flipped"
        );
        // Fan neighbours two steps apart, and a wedge sharing only a side ray: no overlap.
        assert!(!overlap_beyond_shared_vertex(&a, &w([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])));
        assert!(!overlap_beyond_shared_vertex(&a, &w([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])));
    }

    #[test]
    fn tilted_wedges_overlap_when_their_common_line_runs_through_both() {
        let a = w([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // Contains the direction (1, 1, 0), which lies inside `a`.
        assert!(overlap_beyond_shared_vertex(&a, &w([[0.5, 0.5, 1.0], [0.5, 0.5, -1.0]])));
        // Contains only (-1, -1, 0): the planes meet in a line that leaves `a` on the other side.
        assert!(!overlap_beyond_shared_vertex(&a, &w([[-0.5, -0.5, 1.0], [-0.5, -0.5, -1.0]])));
        // A steep neighbour on a cone around the apex.
        assert!(!overlap_beyond_shared_vertex(&a, &w([[-1.0, 0.0, 0.3], [0.0, -1.0, 0.3]])));
        // An edge of `b` lying in `a`: the fold touches along a segment.
        assert!(overlap_beyond_shared_vertex(&a, &w([[1.0, 1.0, 0.0], [1.0, 1.0, 1.0]])));
        // Degenerate wedge.
        assert!(!overlap_beyond_shared_vertex(&a, &w([[1.0, 1.0, 0.0], [2.0, 2.0, 0.0]])));
    }
}

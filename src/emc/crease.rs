//! Is the crease a cell's normals suggest really there? §4.2's test compares the normals at the
//! crossings of one cell, up to √3 cells apart: on a surface curved to a radius of a few cells
//! they open past θ_sharp without any crease (the torus's tube at 24 cells, the gyroid, the
//! rocket's nose cone and body), and a fan there puts a feature line where the surface is smooth,
//! with a fold of the fan wherever the solved "crease" point lies off the surface.
//!
//! Where the input is a function, the surface can be walked between two crossings whose normals
//! disagree: bisect the path between them, each time keeping the half whose ends' normals differ
//! more. A crease keeps its whole jump in the half that contains it however short the halves get;
//! a smooth bend's difference shrinks with the length (a thirty-second of the path: a degree or
//! two on a surface one cell in radius). The component is smooth when no path between its
//! disagreeing pairs keeps a jump past θ_sharp at that scale: the same threshold, taken where it
//! means what the paper meant it to, next to the crease rather than a cell away. The answer
//! depends on the surface between the two crossings only, not on the cell, so two cells that
//! share those crossings decide alike.

use super::edges::EdgeSampler;
use super::feature::sharp_third_sheet;
use glam::Vec3;

/// Halvings of the path between two crossings: the last piece is 1/32 of it (at most 0.05 cells).
const HALVINGS: usize = 5;
/// Disagreeing pairs of crossings walked, the most different first; a crease between two groups
/// of crossings separates the widest pairs, so these find it where any would.
const PAIRS: usize = 4;
/// After this many halvings, a path whose jump has not shrunk below [`KEPT`] of the first one is
/// a crease: a smooth bend's would be a quarter of it by now. Real creases, most of the sharp
/// cells of a CAD part, are then settled with two root findings rather than five.
const SETTLED_AFTER: usize = 2;
const KEPT: f32 = 0.8;
/// Pairs whose normals are nearly opposite (a thin sheet seen from both sides) have no direction
/// to walk the surface in: their mean normal is shorter than this, and the crease is kept.
const MIN_MEAN: f32 = 0.2;

/// What [`fine_scale`] saw. `smooth`: every walked pair of crossings with normals less alike
/// than θ is joined by a surface without a jump past it at 1/32 of their distance (`false` where
/// one keeps a jump, or where the sampler cannot walk the surface: stored and sampled inputs, where
/// the paper's test stands). `between`: a point of the surface (with its normal) that a walk met
/// between two crossings and that turns past θ against both: a face between two creases too
/// narrow for the cell's crossings to land on (see [`super::strip`]).
pub struct FineScale {
    pub smooth: bool,
    pub between: Option<(Vec3, Vec3)>,
}

/// Whether a sharp component's crossings `pts` (normals `nrm`) are joined smoothly at the fine
/// scale, and the face between the walked crossings where one was met.
pub fn fine_scale(pts: &[Vec3], nrm: &[Vec3], sampler: &dyn EdgeSampler, theta_sharp: f32) -> FineScale {
    let mut pairs: Vec<(f32, usize, usize)> = Vec::new();
    for i in 0..nrm.len() {
        for j in i + 1..nrm.len() {
            let d = nrm[i].dot(nrm[j]);
            if d < theta_sharp {
                pairs.push((d, i, j));
            }
        }
    }
    if pairs.is_empty() {
        return FineScale { smooth: false, between: None };
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut between = None;
    let smooth = pairs.iter().take(PAIRS).all(|&(_, i, j)| {
        let walked = walk((pts[i], nrm[i]), (pts[j], nrm[j]), sampler, theta_sharp, true);
        between = between.or(walked.as_ref().and_then(|w| w.between));
        walked.map(|w| w.smooth) == Some(true)
    });
    FineScale { smooth, between }
}

/// A sharp component that looks like three sheets but has two at the fine scale: its third
/// sheet (the normal most different from the widest pair's, sharp against both) is joined to one
/// of the two by a smooth path, and not to the other. A rounded edge tessellated in strips, each turning under θ,
/// meeting a flat face, is one crease: taken as a corner, the outer strips' planes and the face's
/// meet off the surface (a fifth of a cell on the fandisk at 64 cells), and so do the tangent
/// planes of an edge. Gives a point on the crease, found by walking from one sheet of the widest
/// pair to the other, where that works; `None` otherwise, and where the sampler cannot walk.
pub fn two_sheet_crease(
    pts: &[Vec3],
    nrm: &[Vec3],
    sampler: &dyn EdgeSampler,
    theta_sharp: f32,
) -> Option<Crease> {
    let [a, b, c] = sharp_third_sheet(nrm, theta_sharp)?;
    // Joined to exactly one: on a cone, whose normals spread like a corner's, the third joins
    // both smoothly, and the crease the walk finds between the two is the apex.
    let joins = [a, b].map(|s| path_is_smooth((pts[s], nrm[s]), (pts[c], nrm[c]), sampler, theta_sharp));
    if !matches!(joins, [Some(true), Some(false)] | [Some(false), Some(true)]) {
        return None;
    }
    crease_between((pts[a], nrm[a]), (pts[b], nrm[b]), sampler, theta_sharp)
}

/// Whether the surface between crossings `a` and `b` (point, unit normal) bends without a jump
/// past `theta_sharp` at 1/32 of their distance; `None` where it cannot be walked (see
/// [`fine_scale`]).
pub fn path_is_smooth(
    a: (Vec3, Vec3),
    b: (Vec3, Vec3),
    sampler: &dyn EdgeSampler,
    theta_sharp: f32,
) -> Option<bool> {
    walk(a, b, sampler, theta_sharp, true).map(|w| w.smooth)
}

/// Where the surface between crossings `a` and `b` jumps past `theta_sharp`: a point within 1/64
/// of their distance of the crease, near the surface; `None` where the path is smooth or cannot be
/// walked. A start for resampling a crease that the tangent planes at the crossings miss.
pub fn crease_between(
    a: (Vec3, Vec3),
    b: (Vec3, Vec3),
    sampler: &dyn EdgeSampler,
    theta_sharp: f32,
) -> Option<Crease> {
    walk(a, b, sampler, theta_sharp, false).filter(|w| !w.smooth).map(|w| w.crease)
}

/// Where a walk between two crossings ended: the middle of the last piece it kept, and that
/// piece's ends on the surface with their normals, one on each side of the crease when there is
/// one.
pub struct Crease {
    pub at: Vec3,
    pub sides: [(Vec3, Vec3); 2],
}

/// What [`walk`] found: whether the path is smooth, where it ended, and the first point it
/// sampled whose normal turns past θ against both ends'.
struct Walk {
    smooth: bool,
    crease: Crease,
    between: Option<(Vec3, Vec3)>,
}

/// Bisects the path between crossings `a` and `b`, keeping the half whose ends' normals differ
/// more. Points of the chord are taken to the surface along the pair's mean normal, on a segment
/// long enough to reach a surface bent to a radius of half the chord. `settle_early` ends the walk
/// of a jump that has not shrunk after [`SETTLED_AFTER`] halvings (enough to call it a crease,
/// not to say where it is).
fn walk(
    a: (Vec3, Vec3),
    b: (Vec3, Vec3),
    sampler: &dyn EdgeSampler,
    theta_sharp: f32,
    settle_early: bool,
) -> Option<Walk> {
    let mean = a.1 + b.1;
    if mean.length() < MIN_MEAN {
        return None;
    }
    let mean = mean.normalize();
    let chord = b.0 - a.0;
    let reach = 0.75 * chord.length();
    if reach == 0.0 {
        return None;
    }
    let sample_at = |s: f32| {
        let q = a.0 + chord * s;
        let (from, to) = (q - mean * reach, q + mean * reach);
        sampler.crossing_point_on_segment(from, to)
    };
    let (mut s0, mut p0, mut n0, mut s1, mut p1, mut n1) = (0.0f32, a.0, a.1, 1.0f32, b.0, b.1);
    let first_jump = n0.angle_between(n1);
    let mut settled = false;
    let mut between = None;
    for halving in 0..HALVINGS {
        if settle_early && halving == SETTLED_AFTER && n0.angle_between(n1) >= KEPT * first_jump {
            settled = true;
            break;
        }
        let s = 0.5 * (s0 + s1);
        let (p, n) = sample_at(s)?;
        if n == Vec3::ZERO {
            return None;
        }
        if between.is_none() && a.1.dot(n) < theta_sharp && b.1.dot(n) < theta_sharp {
            between = Some((p, n));
        }
        if n0.dot(n) < n.dot(n1) {
            (s1, p1, n1) = (s, p, n);
        } else {
            (s0, p0, n0) = (s, p, n);
        }
    }
    let crease = Crease { at: (p0 + p1) * 0.5, sides: [(p0, n0), (p1, n1)] };
    Some(Walk { smooth: !settled && n0.dot(n1) >= theta_sharp, crease, between })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emc::edges::FieldRoots;

    fn on_circle(radius: f32, deg: f32) -> (Vec3, Vec3) {
        let (s, c) = deg.to_radians().sin_cos();
        (Vec3::new(radius * c, radius * s, 0.0), Vec3::new(c, s, 0.0))
    }

    /// A cylinder one cell in radius: crossings 60° apart around it disagree past θ = 0.9, and
    /// the walk finds the surface smooth.
    #[test]
    fn a_tight_cylinder_is_smooth() {
        let field = |p: Vec3| p.x.hypot(p.y) - 1.0;
        let sampler = FieldRoots { field: &field, iso: 0.0, directed: true, h: 1.0 };
        let (a, b) = (on_circle(1.0, -30.0), on_circle(1.0, 30.0));
        assert!(a.1.dot(b.1) < 0.9, "the case this is for");
        assert_eq!(path_is_smooth(a, b, &sampler, 0.9), Some(true));
        assert!(fine_scale(&[a.0, b.0], &[a.1, b.1], &sampler, 0.9).smooth);
    }

    /// Two planes meeting at 40° (normals 40° apart): the jump stays whole at every halving.
    #[test]
    fn a_crease_stays_sharp() {
        let n1 = Vec3::new(0.0, 1.0, 0.0);
        let n2 = Vec3::new(40f32.to_radians().sin(), 40f32.to_radians().cos(), 0.0);
        let field = move |p: Vec3| p.dot(n1).max(p.dot(n2)) - 0.3;
        let sampler = FieldRoots { field: &field, iso: 0.0, directed: true, h: 1.0 };
        let crease_x = 0.3 * (1.0 - n2.y) / n2.x;
        let a = (Vec3::new(crease_x - 0.6, 0.3, 0.2), n1);
        let along = Vec3::new(n2.y, -n2.x, 0.0);
        let b = (Vec3::new(crease_x, 0.3, 0.2) + along * 0.5, n2);
        assert!(field(b.0).abs() < 1e-5);
        assert_eq!(path_is_smooth(a, b, &sampler, 0.9), Some(false));
        assert!(!fine_scale(&[a.0, b.0], &[a.1, b.1], &sampler, 0.9).smooth);
    }

    /// Without a function behind the crossings the paper's test stands.
    #[test]
    fn samplers_that_cannot_walk_keep_the_crease() {
        let values = [0.0f32; 8];
        let grid = crate::grid::Grid::with_resolution(Vec3::ZERO, Vec3::ONE, 1).unwrap();
        let sampler = crate::emc::edges::SampleInterpolation { values: &values, grid: &grid };
        let (a, b) = (on_circle(1.0, -30.0), on_circle(1.0, 30.0));
        assert!(!fine_scale(&[a.0, b.0], &[a.1, b.1], &sampler, 0.9).smooth);
    }

    /// A flat face meeting a rounded edge tessellated in strips 0.3 cells wide, the first at 45°
    /// to the face and each next one 20° further: crossings on the face, the first strip and the
    /// third look like a corner by their normals, but the first strip joins the third smoothly, and
    /// the crease found is the one between the face and the first strip.
    #[test]
    fn strips_after_a_face_make_one_crease() {
        let normal = |deg: f32| Vec3::new(deg.to_radians().sin(), deg.to_radians().cos(), 0.0);
        let tangent = |deg: f32| Vec3::new(deg.to_radians().cos(), -deg.to_radians().sin(), 0.0);
        let angles = [0.0f32, 45.0, 65.0, 85.0];
        // Each strip starts where the one before ends; the face's plane passes through the origin.
        let mut starts = vec![Vec3::ZERO];
        for &deg in &angles[1..] {
            starts.push(*starts.last().unwrap() + tangent(deg) * 0.3);
        }
        let planes: Vec<(Vec3, f32)> =
            (0..4).map(|i| (normal(angles[i]), normal(angles[i]).dot(starts[i.max(1) - 1]))).collect();
        let field = move |p: Vec3| planes.iter().map(|(n, d)| p.dot(*n) - d).fold(f32::MIN, f32::max);
        let sampler = FieldRoots { field: &field, iso: 0.0, directed: true, h: 1.0 };
        let z = Vec3::Z * 0.2;
        let face = (Vec3::new(-0.5, 0.0, 0.0) + z, normal(0.0));
        let first_strip = (tangent(45.0) * 0.15 + z, normal(45.0));
        let third_strip = (starts[2] + tangent(85.0) * 0.15 + z, normal(85.0));
        for (p, _) in [face, first_strip, third_strip] {
            assert!(field(p).abs() < 1e-5, "{p} on the surface");
        }
        let (pts, nrm) = ([face.0, first_strip.0, third_strip.0], [face.1, first_strip.1, third_strip.1]);
        let crease = two_sheet_crease(&pts, &nrm, &sampler, 0.9).expect("one crease");
        assert!(crease.at.truncate().length() < 0.05, "crease found at {}", crease.at);
        let [(_, n0), (_, n1)] = crease.sides;
        assert!(n0.dot(normal(0.0)) > 0.999 && n1.dot(normal(45.0)) > 0.999, "sides {n0} {n1}");
    }
}

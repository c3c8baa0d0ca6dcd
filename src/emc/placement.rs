//! Where a feature point goes once the tangent planes are solved.
//!
//! The least-squares point is exact on a clean crease, but EMC fans it to the cell's MC polygon,
//! and MC's polygon is only what the corner signs saw: where a crease skims a cell's edge or corner,
//! the surface crosses some cell edges twice, the polygon misses that part, and a fan around the
//! exact point folds over. Giving up there (plain MC) cuts the crease off by up to a fifth of a cell,
//! which on a box turned against the grid was the whole of EMC's maximum error. So the point is
//! placed by a short list of candidates, best first, and the first whose fan does not fold is taken:
//!
//! 1. the solved point slid along its feature line into the cell (an edge's planes fix it only up
//!    to that line; a corner must already lie in the cell);
//! 2. for an edge, the point of the feature line nearest to that one whose fan is valid, first
//!    inside the cell, then in the cell grown by half a cell; for a corner, the solved point itself
//!    when it lies in the grown cell. These are still exactly on the crease;
//! 3. the solved point clamped into the cell, then into the grown cell (off the crease, but near);
//! 4. the first valid point on the way from the polygon's centroid (where MC's centre vertex would
//!    be) to the in-cell point of 1 or 3: it still bends the patch toward the crease;
//! 5. the point of a lattice over the cell nearest to the feature whose fan is valid: where the
//!    crease runs just outside the cell (the fandisk's groove rim, whose top face lies within 1 %
//!    of a cell of a grid plane), even MC's centre folds, but points further in do not. It comes
//!    after 4 because nearness to the feature *line* is a poor guide where the polygon only sees
//!    a corner of the crease: there the line's nearest lattice points are off the surface.
//!
//! Where none is valid, the component stays plain MC. Points stay strictly inside the cell in 1
//! and 3 (a fan triangle lying in a cell face would overlap the neighbour's).

use super::feature::{crease_direction, FeatureKind};
use crate::grid::in_box;
use crate::mesh::analysis::tri_tri::folded_across_edge;
use glam::Vec3;

/// How far (in cells) points placed in the cell stay off its faces.
pub(crate) const INSET: f32 = 1e-2;
/// Samples along a feature line when searching it for a valid fan.
const LINE_SAMPLES: usize = 32;
/// How far (in cells) a fan centre may leave its cell, where the planes meet just outside it.
pub const GROWTH: f32 = 0.5;
/// How far (in cells) a centre on its feature, and on the surface, may leave its cell where none
/// nearer is (see [`place_far`]).
pub const FAR_GROWTH: f32 = 2.0;
/// Lattice points per axis when searching the cell for a valid fan near the feature.
const LATTICE_SAMPLES: usize = 8;
/// Steps from the polygon's centroid toward the target in the last resort.
const TOWARD_STEPS: usize = 10;

/// The surface component a feature point is placed for: its MC polygon and the field normals at
/// the polygon's vertices, the cell it lies in, and the grid's box, which no centre may leave
/// (a cell on the grid's border grows only inward: the mesh stays in the bounds).
pub struct Component<'a> {
    pub pts: &'a [Vec3],
    pub nrm: &'a [Vec3],
    pub cell_min: Vec3,
    pub cell_max: Vec3,
    pub domain: (Vec3, Vec3),
}

/// A domain that limits nothing, for components placed on their own.
pub const UNBOUNDED: (Vec3, Vec3) = (Vec3::NEG_INFINITY, Vec3::INFINITY);

impl Component<'_> {
    /// The component's cell grown by `growth` cells on every side (shrunk where negative), within
    /// the grid's box.
    pub fn grown(&self, growth: f32) -> (Vec3, Vec3) {
        let margin = (self.cell_max - self.cell_min) * growth;
        ((self.cell_min - margin).max(self.domain.0), (self.cell_max + margin).min(self.domain.1))
    }
}

/// Where a fan centre went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub position: Vec3,
    /// On the solved feature (candidates 1 and 2): a feature vertex. Otherwise (3 to 5) only an
    /// approximation that bends the patch toward it.
    pub on_feature: bool,
    /// On the solved feature but, where the input can tell, off the surface (see
    /// [`Placed::check_surface`]): not reported as a feature vertex.
    pub off_surface: bool,
}

impl Placement {
    /// Whether the centre is reported as a feature vertex: on its feature and not known to be
    /// off the surface.
    pub fn is_feature_vertex(&self) -> bool {
        self.on_feature && !self.off_surface
    }
}

/// The position of the feature point of `component` whose least-squares solution is `solved`,
/// or `None` when no candidate gives a fan that does not fold (the component stays plain MC).
///
/// A centre outside the cell comes with the best centre inside it (`inside`), where it moves if
/// its fan turns out to cut a neighbour's triangles (see [`super::untangle`]); a component that
/// has no valid centre inside its cell is not given one outside either.
pub fn place(solved: Vec3, kind: FeatureKind, component: &Component) -> Option<Placed> {
    place_grown(solved, kind, component, GROWTH)
}

/// A centre on the solved feature up to [`FAR_GROWTH`] cells from the component's cell, for a
/// component [`place`] gave no point on it: where a thin wedge of the part (a ball meeting a face
/// at a shallow angle) lies between grid points, the cells along its crease see no surface, and
/// their neighbours see the two sheets but not the crease, which is a cell or more away. A point
/// there is on two planes; the caller keeps it only where it is also on the surface.
pub fn place_far(solved: Vec3, kind: FeatureKind, component: &Component) -> Option<Placed> {
    // The solved point itself first, where its fan is valid: the line's samples step over it.
    if in_box(solved, component.grown(FAR_GROWTH)) && fan_is_valid(solved, component.pts, component.nrm) {
        let at = Placement { position: solved, on_feature: true, off_surface: false };
        if let Some(placed) = with_inside(at, solved, kind, component) {
            return Some(placed);
        }
    }
    place_grown(solved, kind, component, FAR_GROWTH).filter(|placed| placed.at.on_feature)
}

fn place_grown(solved: Vec3, kind: FeatureKind, component: &Component, growth: f32) -> Option<Placed> {
    with_inside(place_within(solved, kind, component, growth)?, solved, kind, component)
}

/// `at`, with the best centre inside the cell where `at` is not strictly inside it; `None` where
/// it is not and the cell has no valid centre.
fn with_inside(at: Placement, solved: Vec3, kind: FeatureKind, component: &Component) -> Option<Placed> {
    let p = at.position;
    // Strictly inside: a centre in a face of the cell would lay fan triangles in that face, over
    // the neighbour's (a centre inside is the apex of a cone that meets the boundary only in its
    // polygon's edges).
    if p.cmpgt(component.cell_min).all() && p.cmplt(component.cell_max).all() {
        return Some(Placed { at, inside: None });
    }
    let inside = place_within(solved, kind, component, -INSET)?;
    Some(Placed { at, inside: Some(inside) })
}

/// A fan centre, and where it goes if it must stay in its cell (only when it is outside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    pub at: Placement,
    pub inside: Option<Placement>,
}

impl Placed {
    /// Marks a centre placed on its solved feature as off the surface where `distance` (an
    /// estimate of the distance to the surface, where the input can tell) exceeds `tolerance`:
    /// the feature's line can run past the end of its crease (where a third sheet the component
    /// does not see cuts it off), and a point there is on two planes but not on the part. It
    /// keeps its place (and takes part in flips as before); only its report changes.
    pub fn check_surface(&mut self, distance: impl Fn(Vec3) -> Option<f32>, tolerance: f32) {
        for at in std::iter::once(&mut self.at).chain(self.inside.as_mut()) {
            at.off_surface = at.on_feature && distance(at.position).is_some_and(|d| d > tolerance);
        }
    }
}

fn place_within(solved: Vec3, kind: FeatureKind, component: &Component, growth: f32) -> Option<Placement> {
    let (pts, nrm) = (component.pts, component.nrm);
    let inner = component.grown(-INSET);
    let grown = component.grown(growth);
    let valid = |c: Vec3| fan_is_valid(c, pts, nrm);
    let line = match kind {
        FeatureKind::Edge => crease_direction(nrm),
        _ => None,
    };
    let in_box = |(lo, hi): (Vec3, Vec3)| match line {
        Some(dir) => line_in_box(solved, dir, lo, hi)
            .map(|(s0, s1)| (solved + dir * 0.0f32.clamp(s0, s1)).clamp(lo, hi)),
        None => in_box(solved, (lo, hi)).then_some(solved),
    };
    let on_crease = in_box(inner);
    let along = |bounds: (Vec3, Vec3)| match line {
        Some(dir) => search_line(solved, dir, bounds, valid),
        None => in_box(bounds).filter(|&c| valid(c)),
    };
    let clamped = solved.clamp(inner.0, inner.1);
    let exact = on_crease.filter(|&c| valid(c)).or_else(|| along(inner)).or_else(|| along(grown));
    if let Some(position) = exact {
        return Some(Placement { position, on_feature: true, off_surface: false });
    }
    let off_feature = |c: Vec3| match line {
        Some(dir) => (c - solved).reject_from_normalized(dir).length(),
        None => (c - solved).length(),
    };
    Some(clamped)
        .filter(|&c| valid(c))
        .or_else(|| Some(solved.clamp(grown.0, grown.1)).filter(|&c| valid(c)))
        .or_else(|| {
            let centroid = pts.iter().sum::<Vec3>() / pts.len() as f32;
            let target = on_crease.unwrap_or(clamped);
            (0..TOWARD_STEPS)
                .rev()
                .map(|q| centroid.lerp(target, q as f32 / TOWARD_STEPS as f32))
                .find(|&c| valid(c))
        })
        .or_else(|| nearest_valid_in_box(inner, off_feature, valid))
        .map(|position| Placement { position, on_feature: false, off_surface: false })
}

/// The point of a lattice over `bounds` nearest to the feature (by `off_feature`) whose fan is
/// valid. Where a crease runs just outside the cell and only a corner of the cell sees it, no
/// point of the line and no clamped point gives a valid fan, but points a little further in do.
fn nearest_valid_in_box(
    bounds: (Vec3, Vec3),
    off_feature: impl Fn(Vec3) -> f32,
    valid: impl Fn(Vec3) -> bool,
) -> Option<Vec3> {
    let (lo, hi) = bounds;
    let n = LATTICE_SAMPLES;
    let mut lattice: Vec<(f32, Vec3)> = (0..n * n * n)
        .map(|q| {
            let at = Vec3::new((q % n) as f32, (q / n % n) as f32, (q / (n * n)) as f32);
            let c = lo + (hi - lo) * (at + 0.5) / n as f32;
            (off_feature(c), c)
        })
        .collect();
    lattice.sort_by(|a, b| a.0.total_cmp(&b.0));
    lattice.into_iter().map(|(_, c)| c).find(|&c| valid(c))
}

/// The parameter interval `[s0, s1]` of the line `p + s dir` inside `[lo, hi]`, if it meets it.
pub(crate) fn line_in_box(p: Vec3, dir: Vec3, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
    let (mut s0, mut s1) = (f32::NEG_INFINITY, f32::INFINITY);
    for a in 0..3 {
        if dir[a] == 0.0 {
            if p[a] < lo[a] || p[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo[a] - p[a]) / dir[a], (hi[a] - p[a]) / dir[a]);
        s0 = s0.max(t0.min(t1));
        s1 = s1.min(t0.max(t1));
    }
    (s0 <= s1).then_some((s0, s1))
}

/// The valid point of the line `p + s dir` inside `bounds` nearest to `p`, among evenly spaced
/// samples of the part of the line in the box.
fn search_line(p: Vec3, dir: Vec3, bounds: (Vec3, Vec3), valid: impl Fn(Vec3) -> bool) -> Option<Vec3> {
    let (lo, hi) = bounds;
    let (s0, s1) = line_in_box(p, dir, lo, hi)?;
    let mut steps: Vec<f32> =
        (0..=LINE_SAMPLES).map(|q| s0 + (s1 - s0) * q as f32 / LINE_SAMPLES as f32).collect();
    steps.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    steps.into_iter().map(|s| (p + dir * s).clamp(lo, hi)).find(|&c| valid(c))
}

/// A fan around `center` is valid when every triangle faces the way the field's normals at its
/// two polygon vertices do (no fold-over) and none is degenerate. Where those normals are nearly
/// perpendicular to the triangle, they cannot tell which way it faces: polygon vertices on a crease
/// that bounds a flat face (the rocket's bottom rim at 40 cells lies in a grid plane) carry the
/// side's normal while the triangle lies in the face. Such a triangle must also not fold onto
/// its neighbours in the fan (on the rim, chords between points of the circle folded).
fn fan_is_valid(center: Vec3, pts: &[Vec3], nrm: &[Vec3]) -> bool {
    let n = pts.len();
    let rel = |p: Vec3| (p - center).as_dvec3();
    (0..n).all(|q| {
        let r = (q + 1) % n;
        let normal = (pts[q] - center).cross(pts[r] - center);
        let scale = (pts[q] - center).length() * (pts[r] - center).length();
        let reference = nrm[q] + nrm[r];
        let facing = normal.dot(reference);
        let blind = facing < 0.2 * normal.length() * reference.length();
        let folds = || {
            let (before, after) = ((q + n - 1) % n, (r + 1) % n);
            folded_across_edge(rel(pts[q]), rel(pts[r]), rel(pts[before]))
                || folded_across_edge(rel(pts[r]), rel(pts[q]), rel(pts[after]))
        };
        normal.length() > 1e-6 * scale && facing > 0.0 && !(blind && folds())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crease that skims the corner of the cell: the polygon is a small triangle around corner
    /// (0, 0, 1) while the two planes meet well inside the cell, so a fan around the exact point
    /// folds. Taken from the rotated box at res 32.
    #[test]
    fn a_crease_skimming_a_corner_still_gets_a_point_on_or_near_it() {
        let a = Vec3::new(-0.477535, 0.29708743, -0.8268612);
        let b = Vec3::new(0.8571673, 0.3641869, -0.3641869);
        let pts = [
            Vec3::new(0.0, 0.0, 0.99338245),
            Vec3::new(0.0, 0.018419504, 1.0),
            Vec3::new(0.5092139, 0.0, 1.0),
        ];
        let nrm = [a, a, b];
        let solved = Vec3::new(0.377, 0.136, 0.824);
        assert!(!fan_is_valid(solved, &pts, &nrm), "the exact point folds: the case this module is for");
        let component =
            Component { pts: &pts, nrm: &nrm, cell_min: Vec3::ZERO, cell_max: Vec3::ONE, domain: UNBOUNDED };
        let placed = place(solved, FeatureKind::Edge, &component).expect("a valid fan").at;
        assert!(!placed.on_feature, "no point of the crease gives a valid fan here");
        let p = placed.position;
        assert!(fan_is_valid(p, &pts, &nrm));
        let centroid = pts.iter().sum::<Vec3>() / 3.0;
        let dir = a.cross(b).normalize();
        let off_crease = |q: Vec3| (q - solved).reject_from_normalized(dir).length();
        assert!(
            off_crease(p) < off_crease(centroid),
            "{p}: {} against MC's centre {}",
            off_crease(p),
            off_crease(centroid)
        );
    }

    /// The rim of the fandisk's groove at res 64 (cell units): the top surface lies within 1 % of
    /// a cell of the cell's top face and the crease runs just above it, so no point of the crease,
    /// no clamped point and not even MC's centre gives a valid fan; points lower in the cell do.
    #[test]
    fn a_crease_just_outside_the_cell_gets_a_valid_fan_from_the_lattice() {
        let (groove, top) = (Vec3::new(0.9965218, 0.0, -0.083333254), Vec3::new(0.0, 0.104166664, 0.9945599));
        let pts = [
            Vec3::new(28.816696, 36.0, 42.0),
            Vec3::new(28.0, 36.0, 42.9911),
            Vec3::new(28.0, 35.91408, 43.0),
            Vec3::new(29.0, 35.91408, 43.0),
            Vec3::new(29.0, 35.0, 42.97113),
            Vec3::new(28.816696, 35.0, 42.0),
        ];
        let nrm = [
            groove,
            top,
            Vec3::new(0.0, 0.101929165, 0.9947917),
            Vec3::new(0.0, 0.10192924, 0.9947917),
            Vec3::new(0.9583333, 0.0, -0.28565246),
            groove,
        ];
        let centroid = pts.iter().sum::<Vec3>() / pts.len() as f32;
        assert!(!fan_is_valid(centroid, &pts, &nrm), "the case this is for");
        let solved = Vec3::new(28.93747, 35.679848, 43.019165);
        let cell = Component {
            pts: &pts,
            nrm: &nrm,
            cell_min: Vec3::new(28.0, 35.0, 42.0),
            cell_max: Vec3::new(29.0, 36.0, 43.0),
            domain: UNBOUNDED,
        };
        let placed = place(solved, FeatureKind::Edge, &cell).expect("a valid fan").at;
        assert!(!placed.on_feature);
        assert!(fan_is_valid(placed.position, &pts, &nrm));
        let off_crease =
            (placed.position - solved).reject_from_normalized(groove.cross(top).normalize()).length();
        assert!(off_crease < 0.15, "{} is {off_crease} cells from the crease", placed.position);
    }

    /// A component on planes x = 0.5 (normal +x) and y = 0.5 (normal +y) between z = 0.2 and 0.8.
    fn crease_x_y_half() -> ([Vec3; 4], [Vec3; 4]) {
        let pts = [
            Vec3::new(0.5, 0.0, 0.8),
            Vec3::new(0.5, 0.0, 0.2),
            Vec3::new(0.0, 0.5, 0.2),
            Vec3::new(0.0, 0.5, 0.8),
        ];
        (pts, [Vec3::X, Vec3::X, Vec3::Y, Vec3::Y])
    }

    #[test]
    fn an_edge_point_outside_the_cell_is_slid_along_its_line_into_it() {
        // Planes x = 0.5 (normal +x) and y = 0.5 (normal +y): the crease is the line x = y = 0.5.
        let (pts, nrm) = crease_x_y_half();
        let component =
            Component { pts: &pts, nrm: &nrm, cell_min: Vec3::ZERO, cell_max: Vec3::ONE, domain: UNBOUNDED };
        // The fan is valid for 0.2 < z < 0.8 only: the nearest valid point of the crease is taken.
        let placed = place(Vec3::new(0.5, 0.5, 1.4), FeatureKind::Edge, &component).unwrap().at;
        let p = placed.position;
        assert!(placed.on_feature);
        assert!((p.x - 0.5).abs() < 1e-6 && (p.y - 0.5).abs() < 1e-6, "{p} is off the crease");
        assert!(p.z > 0.75 && p.z < 0.8, "{p} is not the nearest valid point");
    }

    #[test]
    fn a_point_on_its_line_but_off_the_surface_is_not_reported_as_a_feature_vertex() {
        // The crease x = y = 0.5 of the test above, cut off at z = 0.7 by a third face the
        // component does not see: its nearest valid point (z near 0.78) lies past the crease's end.
        let (pts, nrm) = crease_x_y_half();
        let component =
            Component { pts: &pts, nrm: &nrm, cell_min: Vec3::ZERO, cell_max: Vec3::ONE, domain: UNBOUNDED };
        let solved = Vec3::new(0.5, 0.5, 1.4);
        let mut placed = place(solved, FeatureKind::Edge, &component).unwrap();
        let third_face = |p: Vec3| Some((p.z - 0.7).abs());
        placed.check_surface(third_face, 0.01);
        assert!(placed.at.on_feature && placed.at.off_surface && !placed.at.is_feature_vertex());
        // Where the input cannot tell, or the point is on the surface, it stays a feature vertex.
        let mut unknown = place(solved, FeatureKind::Edge, &component).unwrap();
        unknown.check_surface(|_| None, 0.01);
        assert!(unknown.at.is_feature_vertex());
        let mut on_it = place(solved, FeatureKind::Edge, &component).unwrap();
        on_it.check_surface(|_| Some(0.001), 0.01);
        assert!(on_it.at.is_feature_vertex());
    }

    #[test]
    fn a_line_that_misses_the_box_has_no_interval() {
        assert_eq!(line_in_box(Vec3::new(2.0, 0.5, 0.5), Vec3::Y, Vec3::ZERO, Vec3::ONE), None);
        let (s0, s1) = line_in_box(Vec3::new(0.5, 0.5, 0.5), Vec3::X, Vec3::ZERO, Vec3::ONE).unwrap();
        assert!((s0 + 0.5).abs() < 1e-6 && (s1 - 0.5).abs() < 1e-6);
    }
}

//! Feature points of curved creases and corners, resampled next to the feature.
//!
//! §4.3 intersects the tangent planes at the component's edge crossings, up to a cell away from
//! the crease. On a curved sheet those planes meet off the crease by O(s²/R) (samples s from it,
//! radius R): on the fandisk's groove (5 cells in radius at 64 cells) one point in ten was 0.03 to
//! 0.09 cells off. Where the input is a function, each sheet can be sampled again where it meets
//! the solved point: a short segment along the sheet's normal, a tenth of a cell into the sheet
//! from the point, crosses it there. The planes at those new samples (two for an edge, three for a
//! corner) meet the feature within O((s/10)²/R), and one more round does the same from the better
//! point.

use super::edges::EdgeSampler;
use super::feature::{feature_point, sharp_third_sheet, third_sheet, widest_pair_indices, FeatureKind};
use super::placement::{Component, GROWTH};
use crate::grid::in_box;
use glam::Vec3;

/// How far (in cells) into each sheet, from the solved point, the sheet is sampled again.
const INTO_SHEET: f32 = 0.1;
/// Half lengths (in cells) of the segments along the sheet's normal tried in turn: the longest
/// reaches a sheet the solved point is far from; near a sharp crease it leaves the solid's wedge
/// through the other sheet at both ends, and a shorter one crosses its own sheet only.
const REACHES: [f32; 3] = [0.5, 0.2, 0.08];
/// Rounds of resampling; the second starts from a point already within ~1 % of a cell.
const ROUNDS: usize = 2;
/// A sheet is flat where its crossings' normals agree to within this (1 - cos).
const FLAT: f32 = 1e-6;
/// A round that moves the point less than this (in cells) ends the resampling.
const SETTLED: f32 = 1e-3;
/// How far (in cells) resampling may move the point: further means the segments found another
/// sheet, and the tangent-plane point is kept.
const MAX_MOVE: f32 = 0.25;

/// The feature point `solved` of a component with crossings `pts` and normals `nrm`, moved onto its
/// crease or corner by resampling each sheet through `sampler`; `None` where the sampler cannot
/// (stored or sampled inputs) or a new sample does not belong to its sheet. Where every sheet is
/// flat the tangent planes are exact and `solved` comes back as it is, without sampling.
pub fn resample_feature(
    solved: Vec3,
    kind: FeatureKind,
    pts: &[Vec3],
    nrm: &[Vec3],
    sampler: &dyn EdgeSampler,
    cell: f32,
) -> Option<Vec3> {
    let sheets = sheet_normals(nrm, kind)?;
    let nearest = |n: Vec3| (0..sheets.len()).max_by(|&a, &b| n.dot(sheets[a]).total_cmp(&n.dot(sheets[b])));
    // Flat sheets: their tangent planes are the sheets, and the solved point is exact already.
    if nrm.iter().all(|&n| nearest(n).is_some_and(|k| n.dot(sheets[k]) > 1.0 - FLAT)) {
        return Some(solved);
    }
    // A sheet's crossings lie on one side of the feature, which says which way is "into" it; an
    // edge point moves across its line only, keeping its place along it.
    let line = (kind == FeatureKind::Edge).then(|| sheets[0].cross(sheets[1]).normalize_or_zero());
    let mut into = Vec::with_capacity(sheets.len());
    for (k, &normal) in sheets.iter().enumerate() {
        let members: Vec<Vec3> =
            pts.iter().zip(nrm).filter(|(_, &n)| nearest(n) == Some(k)).map(|(&p, _)| p).collect();
        let centre = members.iter().sum::<Vec3>() / members.len() as f32;
        let mut across = (centre - solved).reject_from_normalized(normal);
        if let Some(dir) = line {
            across = across.reject_from_normalized(dir);
        }
        into.push(across.try_normalize()?);
    }
    let mut point = solved;
    for _ in 0..ROUNDS {
        let mut qs = Vec::with_capacity(sheets.len());
        let mut ms = Vec::with_capacity(sheets.len());
        for (k, &normal) in sheets.iter().enumerate() {
            // A new sample must face its own sheet's way rather than another's.
            match sheet_sample(sampler, point + into[k] * INTO_SHEET * cell, normal, cell) {
                Some((q, m)) if nearest(m) == Some(k) => {
                    qs.push(q);
                    ms.push(m);
                }
                _ => break,
            }
        }
        if qs.len() < sheets.len() {
            break;
        }
        let moved = feature_point(&qs, &ms, kind);
        let settled = moved.distance(point) < SETTLED * cell;
        point = moved;
        if settled {
            break;
        }
    }
    if point == solved {
        return None;
    }
    (point.distance(solved) <= MAX_MOVE * cell).then_some(point)
}

/// One normal per sheet: the two most different ones, and for a corner the one most different
/// from both.
fn sheet_normals(nrm: &[Vec3], kind: FeatureKind) -> Option<Vec<Vec3>> {
    let (a, b) = widest_pair_indices(nrm)?;
    let mut sheets = vec![nrm[a], nrm[b]];
    if kind == FeatureKind::Corner {
        sheets.push(nrm[third_sheet(nrm, nrm[a], nrm[b])]);
    }
    Some(sheets)
}

/// The feature point of a sharp component, resampled ([`resample_feature`]), and what it is. An
/// edge component with a crossing whose normal is sharp (below `theta_sharp`) against both of
/// the edge's sheets has a third sheet: it is resampled as a corner first, kept when that works
/// and lands within half a cell of the component's cell. The paper's corner test `φ` looks only
/// at how far normals leave the plane of the two most different ones, and where the fandisk's
/// cylindrical top meets its chamfer and a side face the top's normal stays within it
/// (|n·n*| = 0.67).
pub fn resample_component(
    solved: Vec3,
    kind: FeatureKind,
    component: &Component,
    sampler: &dyn EdgeSampler,
    theta_sharp: f32,
) -> Option<(FeatureKind, Vec3)> {
    let (pts, nrm) = (component.pts, component.nrm);
    let cell = (component.cell_max - component.cell_min).min_element();
    let near = component.grown(GROWTH);
    if kind == FeatureKind::Edge && sharp_third_sheet(nrm, theta_sharp).is_some() {
        let guess = feature_point(pts, nrm, FeatureKind::Corner);
        let corner = resample_feature(guess, FeatureKind::Corner, pts, nrm, sampler, cell)
            .filter(|&c| in_box(c, near));
        if let Some(corner) = corner {
            return Some((FeatureKind::Corner, corner));
        }
    }
    resample_feature(solved, kind, pts, nrm, sampler, cell).map(|p| (kind, p))
}

/// Where the segment through `p` along `normal` (from inside to outside) crosses the surface, and
/// the normal there.
fn sheet_sample(sampler: &dyn EdgeSampler, p: Vec3, normal: Vec3, cell: f32) -> Option<(Vec3, Vec3)> {
    REACHES.iter().find_map(|reach| {
        let (from, to) = (p - normal * reach * cell, p + normal * reach * cell);
        sampler.crossing_point_on_segment(from, to)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emc::edges::FieldRoots;

    /// A cylinder of radius 2 (cells) along y, capped by the plane y = 0.3: the crease is the
    /// circle of radius 2 at y = 0.3. The tangent planes of crossings 20° apart around the
    /// cylinder meet outside the circle; resampled, the point lands on it.
    #[test]
    fn an_edge_point_of_a_curved_crease_lands_on_it() {
        let field = |p: Vec3| (p.x.hypot(p.z) - 2.0).max(p.y - 0.3);
        let sampler = FieldRoots { field: &field, iso: 0.0, directed: true, h: 1.0 };
        let on_cylinder = |deg: f32| {
            let (s, c) = deg.to_radians().sin_cos();
            (Vec3::new(2.0 * c, 0.0, 2.0 * s), Vec3::new(c, 0.0, s))
        };
        let (a, b) = (on_cylinder(-10.0), on_cylinder(10.0));
        let pts = [a.0, b.0, Vec3::new(1.4, 0.3, 0.3), Vec3::new(1.4, 0.3, -0.3)];
        let nrm = [a.1, b.1, Vec3::Y, Vec3::Y];
        let off_circle = |p: Vec3| (p.x.hypot(p.z) - 2.0).abs().max((p.y - 0.3).abs());
        let solved = feature_point(&pts, &nrm, FeatureKind::Edge);
        assert!(off_circle(solved) > 0.02, "{solved}: the case this is for");
        let p = resample_feature(solved, FeatureKind::Edge, &pts, &nrm, &sampler, 1.0).expect("resampled");
        assert!(off_circle(p) < 1e-3, "{p} is {} off the crease", off_circle(p));
        assert!(p.distance(solved) < 0.1, "{p} moved along the crease");
    }

    #[test]
    fn samplers_without_a_function_leave_the_point_alone() {
        let values = [0.0f32; 8];
        let grid = crate::grid::Grid::with_resolution(Vec3::ZERO, Vec3::ONE, 1).unwrap();
        let sampler = crate::emc::edges::SampleInterpolation { values: &values, grid: &grid };
        // A curved sheet (two normals 6° apart) and a flat one: worth resampling, where one can.
        let pts = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let nrm = [Vec3::X, Vec3::new(1.0, 0.1, 0.0).normalize(), Vec3::Y];
        assert_eq!(resample_feature(Vec3::ONE, FeatureKind::Edge, &pts, &nrm, &sampler, 1.0), None);
    }
}

//! Feature detection and feature sampling of EMC (§4.2, §4.3): is the surface inside a cell sharp,
//! and where is the edge or corner it hides?

use crate::grid::in_box;
use glam::{DVec3, Vec3};
use nalgebra::{Matrix3, Vector3};

/// What the normal cone of one surface component says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeatureKind {
    /// Normals nearly agree: plain MC triangles are fine.
    Smooth,
    /// Normals spread in one plane: a sharp edge crosses the cell.
    Edge,
    /// Normals spread in all directions: a corner sits in the cell.
    Corner,
}

/// Classifies the normals of one component. `theta_sharp` bounds the opening of the normal cone
/// (min nᵢ·nⱼ below it is sharp); `phi_corner` bounds how far normals leave the plane spanned by the
/// two most different ones (max |nᵢ·n*| above it is a corner).
pub fn classify(normals: &[Vec3], theta_sharp: f32, phi_corner: f32) -> FeatureKind {
    let (theta, across) = widest_pair(normals);
    if theta >= theta_sharp {
        return FeatureKind::Smooth;
    }
    let axis = across.normalize_or_zero();
    if axis == Vec3::ZERO {
        // Opposite normals (a thin sheet): no edge direction to speak of; treat as an edge.
        return FeatureKind::Edge;
    }
    let phi = normals.iter().map(|n| n.dot(axis).abs()).fold(0.0f32, f32::max);
    if phi > phi_corner {
        FeatureKind::Corner
    } else {
        FeatureKind::Edge
    }
}

/// The two most different normals: their dot product (the opening of the normal cone, 1 for fewer
/// than two normals) and their cross product (along the crease they meet in, not normalised).
fn widest_pair(normals: &[Vec3]) -> (f32, Vec3) {
    match widest_pair_indices(normals) {
        Some((i, j)) => (normals[i].dot(normals[j]), normals[i].cross(normals[j])),
        None => (1.0, Vec3::ZERO),
    }
}

/// Which two normals are the most different (smallest dot product), if there are two; the first
/// such pair when several tie.
pub fn widest_pair_indices(normals: &[Vec3]) -> Option<(usize, usize)> {
    let mut widest = (1.0f32, None);
    for i in 0..normals.len() {
        for j in i + 1..normals.len() {
            let d = normals[i].dot(normals[j]);
            if d < widest.0 || widest.1.is_none() {
                widest = (d, Some((i, j)));
            }
        }
    }
    widest.1
}

/// The normal most different from both `na` and `nb` (smallest larger dot product): a corner's
/// third sheet.
pub fn third_sheet(nrm: &[Vec3], na: Vec3, nb: Vec3) -> usize {
    let closeness = |n: Vec3| n.dot(na).max(n.dot(nb));
    (0..nrm.len()).min_by(|&i, &j| closeness(nrm[i]).total_cmp(&closeness(nrm[j]))).unwrap_or(0)
}

/// The widest pair of a component's normals and a third sheet sharp (below `theta_sharp`)
/// against both of them, as indices `[a, b, third]`; `None` where every normal is near one of
/// the pair (a plain edge).
pub fn sharp_third_sheet(nrm: &[Vec3], theta_sharp: f32) -> Option<[usize; 3]> {
    let (a, b) = widest_pair_indices(nrm)?;
    let c = third_sheet(nrm, nrm[a], nrm[b]);
    (nrm[c].dot(nrm[a]) < theta_sharp && nrm[c].dot(nrm[b]) < theta_sharp).then_some([a, b, c])
}

/// Direction of the feature line of an edge component: across its two most different normals.
pub fn crease_direction(normals: &[Vec3]) -> Option<Vec3> {
    let dir = widest_pair(normals).1.normalize_or_zero();
    (dir != Vec3::ZERO).then_some(dir)
}

/// How far (as a fraction of the component's extent) the tangent planes may miss an edge's point
/// before the component is solved as a corner instead. Planes of one crease meet it exactly (up to
/// curvature: a hundredth of the extent on the scenes' cylinders at 32 cells); three surfaces
/// whose normals still pass the corner test `φ` as an edge miss it by a fifth of a cell and more.
const EDGE_MISS: f64 = 0.05;

/// The feature point of a sharp component and what it turned out to be. An edge whose planes do
/// not all pass near its point is re-solved as a corner and kept as one where that fits better:
/// `φ` looks only at how far normals leave the plane of the two most different ones, and where a
/// cylindrical top meets two planes at a blunt corner the third normal can stay inside `φ`, so
/// the corner's three planes were solved as a line, a fifth of a cell off all of them. The corner
/// must lie in `near` (the cell, grown): on a strongly curved surface (a groove a few cells wide)
/// the planes of one crease also miss its line, and their "corner" lies cells away.
pub fn sharp_point(
    points: &[Vec3],
    normals: &[Vec3],
    kind: FeatureKind,
    near: (Vec3, Vec3),
) -> (FeatureKind, Vec3) {
    let solved = feature_point(points, normals, kind);
    if kind != FeatureKind::Edge {
        return (kind, solved);
    }
    let extent =
        points.iter().flat_map(|a| points.iter().map(move |b| a.distance(*b))).fold(0.0f32, f32::max) as f64;
    let miss = plane_miss(points, normals, solved);
    if miss <= EDGE_MISS * extent {
        return (kind, solved);
    }
    let corner = feature_point(points, normals, FeatureKind::Corner);
    if in_box(corner, near) && plane_miss(points, normals, corner) < 0.5 * miss {
        (FeatureKind::Corner, corner)
    } else {
        (kind, solved)
    }
}

/// The largest distance from `x` to a tangent plane `(pᵢ, nᵢ)`.
fn plane_miss(points: &[Vec3], normals: &[Vec3], x: Vec3) -> f64 {
    points
        .iter()
        .zip(normals)
        .map(|(p, n)| n.as_dvec3().dot(x.as_dvec3() - p.as_dvec3()).abs())
        .fold(0.0, f64::max)
}

/// The point that best lies on all tangent planes (pᵢ, nᵢ), by the SVD pseudo-inverse of the normal
/// matrix with the samples' centroid as origin (so the minimum-norm solution stays near the samples).
/// For an edge the smallest singular value is dropped: the planes only pin the point to a line,
/// and the centroid picks the point on it.
pub fn feature_point(points: &[Vec3], normals: &[Vec3], kind: FeatureKind) -> Vec3 {
    let n = points.len() as f64;
    let centroid = points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
    // Normal equations AᵀA x = Aᵀb are exact for least squares; AᵀA is 3×3 and symmetric.
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    for (p, nrm) in points.iter().zip(normals) {
        let nv = Vector3::new(nrm.x as f64, nrm.y as f64, nrm.z as f64);
        let b = nrm.as_dvec3().dot(p.as_dvec3() - centroid);
        ata += nv * nv.transpose();
        atb += nv * b;
    }
    let svd = ata.svd(true, true);
    let (u, v_t) = (svd.u.expect("requested"), svd.v_t.expect("requested"));
    let sigma = svd.singular_values;
    let largest = sigma.max();
    let keep = match kind {
        FeatureKind::Corner => 3,
        _ => 2,
    };
    // Singular values of AᵀA come sorted descending; drop the ones past `keep` and tiny ones.
    let mut inv = Vector3::zeros();
    for k in 0..3 {
        if k < keep && sigma[k] > largest * 1e-3 {
            inv[k] = 1.0 / sigma[k];
        }
    }
    let x = v_t.transpose() * Matrix3::from_diagonal(&inv) * u.transpose() * atb;
    (centroid + DVec3::new(x[0], x[1], x[2])).as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_planes_meet_in_their_edge() {
        // Planes x = 0.3 and y = 0.6; samples scattered on both.
        let pts = [
            Vec3::new(0.3, 0.1, 0.0),
            Vec3::new(0.3, 0.2, 1.0),
            Vec3::new(0.0, 0.6, 0.5),
            Vec3::new(1.0, 0.6, 0.2),
        ];
        let nrm = [Vec3::X, Vec3::X, Vec3::Y, Vec3::Y];
        assert_eq!(classify(&nrm, 0.9, 0.7), FeatureKind::Edge);
        let p = feature_point(&pts, &nrm, FeatureKind::Edge);
        assert!((p.x - 0.3).abs() < 1e-5 && (p.y - 0.6).abs() < 1e-5, "{p}");
        // The free coordinate comes from the centroid.
        assert!((p.z - 0.425).abs() < 1e-5, "{p}");
    }

    #[test]
    fn three_planes_meet_in_their_corner() {
        let pts = [Vec3::new(0.2, 0.9, 0.1), Vec3::new(0.7, 0.4, 0.8), Vec3::new(0.1, 0.5, 0.3)];
        let nrm = [Vec3::X, Vec3::Y, Vec3::Z];
        assert_eq!(classify(&nrm, 0.9, 0.7), FeatureKind::Corner);
        let p = feature_point(&pts, &nrm, FeatureKind::Corner);
        assert!((p - Vec3::new(0.2, 0.4, 0.3)).length() < 1e-5, "{p}");
    }

    /// Where the fandisk's cylindrical top meets its chamfer and a side face (res 64, in cell
    /// units): the top's normal leaves the plane of the other two by |n·n*| = 0.67, under φ = 0.7,
    /// so the normal cone calls it an edge, whose line misses the top's plane by a quarter cell.
    #[test]
    fn a_blunt_corner_the_phi_test_calls_an_edge_is_solved_as_a_corner() {
        let pts = [
            Vec3::new(52.0, 7.277778, 30.0),
            Vec3::new(52.0, 8.0, 30.169893),
            Vec3::new(51.0, 8.0, 30.252394),
            Vec3::new(51.0, 7.277778, 30.0),
        ];
        let side = Vec3::new(0.0, -1.0, 0.0);
        let chamfer = Vec3::new(1.0, 0.0, 1.0).normalize();
        let nrm = [side, chamfer, Vec3::new(0.0, -0.31640625, 0.9486238), side];
        assert_eq!(classify(&nrm, 0.9, 0.7), FeatureKind::Edge);
        let edge_point = feature_point(&pts, &nrm, FeatureKind::Edge);
        assert!(plane_miss(&pts, &nrm, edge_point) > 0.2, "the case this is for");
        let cell = (Vec3::new(50.5, 6.5, 29.5), Vec3::new(52.5, 8.5, 31.5));
        let (kind, p) = sharp_point(&pts, &nrm, FeatureKind::Edge, cell);
        assert_eq!(kind, FeatureKind::Corner);
        assert!(plane_miss(&pts, &nrm, p) < 1e-4, "{p} is off a plane");
    }

    /// The fandisk's groove (radius 2.4 cells at res 32) meeting its top: the groove's two normals
    /// differ by 24°, so the crease's planes miss its line, but their "corner" lies 1.7 cells out
    /// of the cell: the component stays an edge.
    #[test]
    fn a_crease_of_a_narrow_groove_stays_an_edge() {
        let pts = [
            Vec3::new(20.0, 11.0, 20.93753),
            Vec3::new(20.0, 11.23765, 21.0),
            Vec3::new(19.191652, 12.0, 21.0),
            Vec3::new(19.062742, 12.0, 20.0),
            Vec3::new(19.062742, 11.0, 20.0),
        ];
        let wall = Vec3::new(-0.94280905, 0.0, 0.3333334);
        let nrm = [
            Vec3::new(0.0, -0.26041666, 0.96549636),
            Vec3::new(0.0, -0.2480391, 0.9687501),
            Vec3::new(-0.9965218, 0.0, -0.083333254),
            wall,
            wall,
        ];
        let cell = (Vec3::new(18.5, 10.5, 19.5), Vec3::new(20.5, 12.5, 21.5));
        let (kind, p) = sharp_point(&pts, &nrm, FeatureKind::Edge, cell);
        assert_eq!(kind, FeatureKind::Edge);
        assert_eq!(p, feature_point(&pts, &nrm, FeatureKind::Edge));
    }

    #[test]
    fn a_gently_curved_patch_is_smooth() {
        let nrm = [Vec3::new(0.0, 0.1, 1.0).normalize(), Vec3::new(0.1, 0.0, 1.0).normalize(), Vec3::Z];
        assert_eq!(classify(&nrm, 0.9, 0.7), FeatureKind::Smooth);
    }
}

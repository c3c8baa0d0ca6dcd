//! Feature detection and feature sampling of EMC (§4.2, §4.3): is the surface inside a cell sharp,
//! and where is the edge or corner it hides?

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
    let mut widest = (1.0f32, Vec3::ZERO);
    for i in 0..normals.len() {
        for j in i + 1..normals.len() {
            let d = normals[i].dot(normals[j]);
            if d < widest.0 {
                widest = (d, normals[i].cross(normals[j]));
            }
        }
    }
    widest
}

/// Direction of the feature line of an edge component: across its two most different normals.
pub fn crease_direction(normals: &[Vec3]) -> Option<Vec3> {
    let dir = widest_pair(normals).1.normalize_or_zero();
    (dir != Vec3::ZERO).then_some(dir)
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

    #[test]
    fn a_gently_curved_patch_is_smooth() {
        let nrm = [Vec3::new(0.0, 0.1, 1.0).normalize(), Vec3::new(0.1, 0.0, 1.0).normalize(), Vec3::Z];
        assert_eq!(classify(&nrm, 0.9, 0.7), FeatureKind::Smooth);
    }
}

//! Triangle shape quality and the integrals a solid's boundary must get right (area, volume).
//!
//! Shape statistics skip triangles whose shape is undefined rather than report infinities that
//! would swamp every mean: angles skip triangles with a zero-length edge, aspect ratios skip
//! zero-area triangles. [`super::topology()`] counts both kinds as degenerate.

use crate::mesh::Mesh;
use glam::DVec3;
use serde::Serialize;

/// Interior angles of all triangles, in degrees.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AngleStats {
    pub min_deg: f64,
    pub max_deg: f64,
    /// Counts per 5-degree bin: `[0, 5)`, `[5, 10)`, ..., `[175, 180]` (edges absorb rounding, see
    /// [`angle_stats`]). Sums to three per measured triangle.
    #[serde(serialize_with = "serialize_bins")]
    pub histogram_5deg: [u32; 36],
    /// Triangles whose angles were measured (those with no zero-length edge).
    pub measured_triangles: usize,
}

/// serde only serialises arrays of up to 32 elements by itself.
fn serialize_bins<S: serde::Serializer>(bins: &[u32; 36], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(bins)
}

/// Interior angles of every triangle with three non-zero edges. An empty result has
/// `min_deg = max_deg = 0`.
///
/// Angles come from `atan2(|u x v|, u . v)`, which stays accurate near 0 and 180 degrees where
/// `acos` of a dot product loses half its digits; slivers are exactly what this is meant to show.
/// An angle within 1e-9 degrees below a bin edge is counted in the bin above, so exact 45, 60 and
/// 90 degree angles are not split between bins by rounding.
pub fn angle_stats(mesh: &Mesh) -> AngleStats {
    let mut stats = AngleStats {
        min_deg: f64::INFINITY,
        max_deg: f64::NEG_INFINITY,
        histogram_5deg: [0; 36],
        measured_triangles: 0,
    };
    for t in 0..mesh.triangles.len() {
        let p = corners(mesh, t);
        let e = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
        if e.contains(&DVec3::ZERO) {
            continue;
        }
        stats.measured_triangles += 1;
        for k in 0..3 {
            // Angle at corner k, between the edges leaving it.
            let (u, v) = (e[k], -e[(k + 2) % 3]);
            let deg = u.cross(v).length().atan2(u.dot(v)).to_degrees();
            stats.min_deg = stats.min_deg.min(deg);
            stats.max_deg = stats.max_deg.max(deg);
            stats.histogram_5deg[bin(deg)] += 1;
        }
    }
    if stats.measured_triangles == 0 {
        stats.min_deg = 0.0;
        stats.max_deg = 0.0;
    }
    stats
}

/// The 5-degree bin of `deg`. Angles within 1e-9 degrees below a bin edge go up: 60 degrees is
/// often computed as 59.99999999999999, and an equilateral mesh should not straddle two bins.
fn bin(deg: f64) -> usize {
    (((deg + 1e-9) / 5.0) as usize).min(35)
}

/// Mean and maximum aspect ratio over the triangles with non-zero area, `(0, 0)` when there are none.
///
/// Aspect ratio here is `longest edge / (2 sqrt(3) inradius)`: 1 for an equilateral triangle, growing
/// without bound for needles and caps alike (the inradius `2 area / perimeter` vanishes for both),
/// so one number flags every shape that hurts normals and simulations.
pub fn aspect_ratios(mesh: &Mesh) -> (f64, f64) {
    let mut sum = 0.0;
    let mut max = 0.0f64;
    let mut count = 0usize;
    for t in 0..mesh.triangles.len() {
        let p = corners(mesh, t);
        let double_area = (p[1] - p[0]).cross(p[2] - p[0]).length();
        if double_area == 0.0 {
            continue;
        }
        let lengths = [(p[1] - p[0]).length(), (p[2] - p[1]).length(), (p[0] - p[2]).length()];
        let perimeter: f64 = lengths.iter().sum();
        let inradius = double_area / perimeter;
        let longest = lengths[0].max(lengths[1]).max(lengths[2]);
        let aspect = longest / (2.0 * 3f64.sqrt() * inradius);
        sum += aspect;
        max = max.max(aspect);
        count += 1;
    }
    if count == 0 {
        (0.0, 0.0)
    } else {
        (sum / count as f64, max)
    }
}

pub fn surface_area(mesh: &Mesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| {
            let p = corners(mesh, t);
            0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
        })
        .sum()
}

/// Enclosed volume by the divergence theorem (sum of the signed tetrahedra from the origin to each
/// face): positive when faces wind counter-clockwise seen from outside, negative for an inside-out
/// mesh. Only meaningful for closed meshes; for open ones it depends on where the origin is.
pub fn signed_volume(mesh: &Mesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| {
            let p = corners(mesh, t);
            p[0].dot(p[1].cross(p[2]))
        })
        .sum::<f64>()
        / 6.0
}

fn corners(mesh: &Mesh, t: usize) -> [DVec3; 3] {
    mesh.corners(t).map(|p| p.as_dvec3())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures::*;
    use glam::Vec3;
    use std::f64::consts::PI;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn volumes_and_areas_of_the_platonic_fixtures_are_exact() {
        let s3 = 3f64.sqrt();
        assert!(close(signed_volume(&tetrahedron()), 1.0 / 6.0, 1e-12));
        assert!(close(surface_area(&tetrahedron()), 1.5 + s3 / 2.0, 1e-6));
        assert!(close(signed_volume(&octahedron()), 4.0 / 3.0, 1e-12));
        assert!(close(surface_area(&octahedron()), 4.0 * s3, 1e-6));
        assert!(close(signed_volume(&cube()), 1.0, 1e-12));
        assert!(close(surface_area(&cube()), 6.0, 1e-12));
        // Closed meshes: the origin does not matter.
        let moved = translated(&octahedron(), Vec3::new(10.0, -3.0, 7.0));
        assert!(close(signed_volume(&moved), 4.0 / 3.0, 1e-5));
    }

    #[test]
    fn inside_out_meshes_have_negative_volume() {
        let mut m = cube();
        for t in &mut m.triangles {
            t.swap(0, 1);
        }
        assert!(close(signed_volume(&m), -1.0, 1e-12));
    }

    #[test]
    fn angles_of_the_fixtures() {
        let oct = angle_stats(&octahedron());
        assert!(close(oct.min_deg, 60.0, 1e-9) && close(oct.max_deg, 60.0, 1e-9));
        assert_eq!(oct.histogram_5deg[12], 24);
        let tet = angle_stats(&tetrahedron());
        assert!(close(tet.min_deg, 45.0, 1e-9));
        assert!(close(tet.max_deg, 90.0, 1e-9));
        // Three right angles at the corner, 45s on the legs, 60s on the slanted face.
        assert_eq!(tet.histogram_5deg[18], 3);
        assert_eq!(tet.histogram_5deg[9], 6);
        assert_eq!(tet.histogram_5deg[12], 3);
        assert_eq!(tet.histogram_5deg.iter().sum::<u32>(), 12);
    }

    #[test]
    fn degenerate_triangles_are_skipped_by_shape_statistics() {
        let m = mesh(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[[0, 1, 2], [0, 0, 1]]);
        let a = angle_stats(&m);
        assert_eq!(a.measured_triangles, 1, "the collinear one has angles 0, 0, 180");
        assert!(close(a.max_deg, 180.0, 1e-9) && a.min_deg == 0.0);
        assert_eq!(a.histogram_5deg[35], 1);
        assert_eq!(aspect_ratios(&m), (0.0, 0.0));
    }

    #[test]
    fn aspect_ratio_is_one_for_equilateral_and_grows_for_slivers() {
        let (mean, max) = aspect_ratios(&octahedron());
        assert!(close(mean, 1.0, 1e-6) && close(max, 1.0, 1e-6));
        // Right isosceles triangle: legs 1, inradius (2 - sqrt 2) / 2, hypotenuse sqrt 2.
        let expected = 2f64.sqrt() / (3f64.sqrt() * (2.0 - 2f64.sqrt()));
        let (_, max) = aspect_ratios(&tetrahedron());
        assert!(close(max, expected, 1e-6), "{max} vs {expected}");
        let needle = mesh(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.01, 0.0]], &[[0, 1, 2]]);
        assert!(aspect_ratios(&needle).1 > 20.0);
    }

    #[test]
    fn mc_sphere_area_volume_and_angle_census() {
        let r = SPHERE_RADIUS as f64;
        let mut previous_error = f64::INFINITY;
        for res in [16, 32, 64] {
            let (m, _) = mc_sphere(res);
            let area = surface_area(&m);
            let volume = signed_volume(&m);
            let area_err = (area / (4.0 * PI * r * r) - 1.0).abs();
            let volume_err = (volume / (4.0 / 3.0 * PI * r * r * r) - 1.0).abs();
            assert!(area_err < 0.03, "res {res}: area {area}");
            assert!(volume_err < 0.03, "res {res}: volume {volume}");
            assert!(volume_err < previous_error, "res {res}: volume error did not shrink");
            previous_error = volume_err;
            let angles = angle_stats(&m);
            assert_eq!(angles.measured_triangles, m.triangle_count());
            let total: u32 = angles.histogram_5deg.iter().sum();
            assert_eq!(total as usize, 3 * m.triangle_count());
            assert!(angles.min_deg >= 0.0 && angles.max_deg < 180.0);
            let (mean, max) = aspect_ratios(&m);
            assert!(mean >= 1.0 && max >= mean);
        }
    }
}

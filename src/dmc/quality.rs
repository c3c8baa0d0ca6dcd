//! The measure of triangle quality DMC is held to: slivers (triangles with an angle under
//! [`super::slivers::SLIVER_DEG`]) and spikes (faces turned away from the surface).
//!
//! A face's normal deviation is measured against the *nearest* of several true normals, at its
//! corners and at its centroid and the points halfway from the centroid to each corner, all
//! projected onto the surface. Against the gradient at the centroid alone (the analysis'
//! `normal_dev_deg_max`), a face lying flat against one side of a crease, with its centroid a
//! hair from the other side, would count as turned by the crease's whole dihedral angle; against
//! the nearest normal it counts as what it is, flat. A face that cuts across a crease (a notch or
//! a spike) has every sample on one side or the other, none parallel to it, so it still shows, by
//! about half the dihedral angle; a face turned over shows near 180°.

use crate::field::{gradient_or_differences, Field};
use crate::mesh::Mesh;
use glam::Vec3;

#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quality {
    /// Share of the triangles with an angle under 10°.
    pub sliver_fraction: f64,
    pub min_angle_deg: f64,
    /// Largest per-face normal deviation (see the module docs), degrees, and the face it is on.
    pub normal_dev_deg_max: f64,
    pub worst_face: usize,
    /// Faces deviating by more than 20°.
    pub faces_over_20deg: usize,
}

/// Newton steps onto the level set (`h`: a finite-difference step for fields without gradients).
fn project(field: &dyn Field, iso: f32, mut p: Vec3, h: f32) -> Vec3 {
    for _ in 0..6 {
        let g = gradient_or_differences(field, p, h);
        let f = field.value(p) - iso;
        let l = g.length_squared();
        if l <= 0.0 || !l.is_finite() || !f.is_finite() {
            break;
        }
        let step = g * (f / l);
        p -= step;
        if step.length() < h * 1e-3 {
            break;
        }
    }
    p
}

/// Measures `mesh` against the `iso` level of `field`; `h` is a length well below the triangles'
/// (a finest cell's side), for finite differences.
pub fn measure(mesh: &Mesh, field: &dyn Field, iso: f32, h: f32) -> Quality {
    let mut q = Quality { min_angle_deg: 180.0, ..Quality::default() };
    let step = h * 1e-2;
    let mut slivers = 0;
    let mut counted = 0;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            continue;
        }
        counted += 1;
        let c = mesh.corners(t).map(|p| p.as_dvec3());
        let e = [c[1] - c[0], c[2] - c[1], c[0] - c[2]];
        let smallest = (0..3)
            .map(|k| {
                let (u, v) = (e[k], -e[(k + 2) % 3]);
                u.cross(v).length().atan2(u.dot(v)).to_degrees()
            })
            .fold(180.0, f64::min);
        q.min_angle_deg = q.min_angle_deg.min(smallest);
        slivers += (smallest < super::slivers::SLIVER_DEG) as usize;
        let n = e[0].cross(-e[2]).normalize_or_zero();
        if n == glam::DVec3::ZERO {
            continue;
        }
        let corners = mesh.corners(t);
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        let samples = [
            corners[0],
            corners[1],
            corners[2],
            project(field, iso, centroid, step),
            project(field, iso, (centroid + corners[0]) * 0.5, step),
            project(field, iso, (centroid + corners[1]) * 0.5, step),
            project(field, iso, (centroid + corners[2]) * 0.5, step),
        ];
        let deviation = samples
            .iter()
            .map(|&p| gradient_or_differences(field, p, step).as_dvec3().normalize_or_zero())
            .filter(|g| *g != glam::DVec3::ZERO)
            .map(|g| n.cross(g).length().atan2(n.dot(g)).to_degrees())
            .fold(f64::INFINITY, f64::min);
        if deviation.is_finite() {
            if deviation > q.normal_dev_deg_max {
                q.normal_dev_deg_max = deviation;
                q.worst_face = t;
            }
            q.faces_over_20deg += (deviation > 20.0) as usize;
        }
    }
    q.sliver_fraction = if counted == 0 { 0.0 } else { slivers as f64 / counted as f64 };
    q
}

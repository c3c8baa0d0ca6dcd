//! The triangle quality DMC is held to: slivers (an angle under 10°) and spikes, a face's normal
//! deviation measured as [`super::normals::face_deviation`] measures it for EMC (against the
//! nearest of the true normals at seven points of the face), so that both methods answer to one
//! measure.

use super::normals::face_deviation;
use isoforge::{Field, Mesh};

/// An angle under this makes a triangle a sliver.
pub const SLIVER_DEG: f64 = 10.0;

#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quality {
    /// Share of the triangles with an angle under [`SLIVER_DEG`].
    pub sliver_fraction: f64,
    pub min_angle_deg: f64,
    /// Largest per-face normal deviation, degrees, and the face it is on.
    pub normal_dev_deg_max: f64,
    pub worst_face: usize,
    /// Faces deviating by more than 20°.
    pub faces_over_20deg: usize,
}

/// Measures `mesh` against the zero set of `field`; `cell` is the finest cell's side.
pub fn measure(mesh: &Mesh, field: &dyn Field, cell: f32) -> Quality {
    let mut q = Quality { min_angle_deg: 180.0, ..Quality::default() };
    let (mut slivers, mut counted) = (0, 0);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            continue;
        }
        counted += 1;
        let corners = mesh.corners(t);
        let c = corners.map(|p| p.as_dvec3());
        let e = [c[1] - c[0], c[2] - c[1], c[0] - c[2]];
        let smallest = (0..3)
            .map(|k| {
                let (u, v) = (e[k], -e[(k + 2) % 3]);
                u.cross(v).length().atan2(u.dot(v)).to_degrees()
            })
            .fold(180.0, f64::min);
        q.min_angle_deg = q.min_angle_deg.min(smallest);
        slivers += (smallest < SLIVER_DEG) as usize;
        if let Some(deviation) = face_deviation(field, corners, cell) {
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

//! Garland–Heckbert error quadrics: the sum of squared distances to a set of planes, kept as one
//! symmetric 4×4 form so that merging two vertices' planes is one addition.

use glam::{DMat3, DVec3};

/// `Q(p) = pᵀ A p + 2 b·p + c`, the weighted sum of squared distances from `p` to some planes.
#[derive(Debug, Clone, Copy)]
pub struct Quadric {
    a: DMat3,
    b: DVec3,
    c: f64,
}

impl Default for Quadric {
    fn default() -> Self {
        Quadric { a: DMat3::ZERO, b: DVec3::ZERO, c: 0.0 }
    }
}

impl Quadric {
    /// The plane through `point` with unit normal `normal`, weighted by `weight`.
    pub fn plane(normal: DVec3, point: DVec3, weight: f64) -> Quadric {
        let d = -normal.dot(point);
        let n = normal;
        Quadric {
            a: DMat3::from_cols(n * n.x, n * n.y, n * n.z) * weight,
            b: n * d * weight,
            c: d * d * weight,
        }
    }

    pub fn add(&mut self, other: &Quadric) {
        self.a += other.a;
        self.b += other.b;
        self.c += other.c;
    }

    pub fn eval(&self, p: DVec3) -> f64 {
        (p.dot(self.a * p) + 2.0 * self.b.dot(p) + self.c).max(0.0)
    }

    /// The point of least error, where the planes pin one down: `None` when they are (nearly)
    /// parallel, as on a flat or cylindrical patch, where every point of a plane or a line is as
    /// good and the caller falls back to the edge's own points.
    pub fn minimizer(&self) -> Option<DVec3> {
        let det = self.a.determinant();
        let scale = self.a.x_axis.length() + self.a.y_axis.length() + self.a.z_axis.length();
        // Written so that a NaN determinant also counts as singular.
        if det.abs().partial_cmp(&(1e-9 * scale * scale * scale)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let p = self.a.inverse() * -self.b;
        p.is_finite().then_some(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_meet_at_their_corner_and_measure_squared_distance() {
        let mut q = Quadric::default();
        let corner = DVec3::new(0.3, -0.2, 0.5);
        for n in [DVec3::X, DVec3::Y, DVec3::Z] {
            q.add(&Quadric::plane(n, corner, 1.0));
        }
        assert!((q.minimizer().unwrap() - corner).length() < 1e-12);
        assert!((q.eval(corner + DVec3::new(0.1, 0.2, 0.0)) - 0.05).abs() < 1e-12);
        let mut flat = Quadric::plane(DVec3::Z, corner, 2.0);
        assert!(flat.minimizer().is_none(), "one plane pins no point");
        flat.add(&Quadric::plane(DVec3::Z, corner, 1.0));
        assert!((flat.eval(corner + DVec3::Z) - 3.0).abs() < 1e-12);
    }
}

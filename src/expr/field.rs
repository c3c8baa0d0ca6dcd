//! A compiled program is a [`Field`]: meshers sample it in batches and take exact normals from it.

use super::program::Program;
use crate::field::Field;
use glam::Vec3;

impl Field for Program {
    fn value(&self, p: Vec3) -> f32 {
        self.eval(p)
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        Some(self.eval_grad(p).1)
    }

    fn value_and_gradient(&self, p: Vec3) -> (f32, Option<Vec3>) {
        let (v, g) = self.eval_grad(p);
        (v, Some(g))
    }

    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        self.eval_many(points, out);
    }

    fn gradients(&self, points: &[Vec3], out: &mut [Option<Vec3>]) {
        self.eval_grad_many_as(points, out, Some);
    }

    fn values_and_gradients(&self, points: &[Vec3], values: &mut [f32], gradients: &mut [Option<Vec3>]) {
        let mut both = vec![(0.0, Vec3::ZERO); points.len().min(values.len()).min(gradients.len())];
        self.eval_value_grad_many(points, &mut both);
        unzip_into(&both, values, gradients);
    }

    fn interval(&self, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
        Some(self.eval_interval(lo, hi))
    }
}

/// Writes `(value, gradient)` pairs, as the one-pass evaluators return them, into the two slices
/// of [`Field::values_and_gradients`].
pub(super) fn unzip_into(both: &[(f32, Vec3)], values: &mut [f32], gradients: &mut [Option<Vec3>]) {
    for ((v, g), &(bv, bg)) in values.iter_mut().zip(gradients.iter_mut()).zip(both) {
        (*v, *g) = (bv, Some(bg));
    }
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use super::*;
    use crate::grid::Grid;
    use crate::mc::{mesh_field, McOptions};

    #[test]
    fn programs_can_be_shared_between_threads() {
        fn assert_send_sync<T: Send + Sync>() {}
        assert_send_sync::<Program>();
        let p = std::sync::Arc::new(compile("sphere(0.5)").unwrap());
        let q = p.clone();
        let v = std::thread::spawn(move || q.eval(Vec3::X)).join().unwrap();
        assert_eq!(v, 0.5);
    }

    #[test]
    fn a_compiled_sphere_meshes_with_exact_normals() {
        let program = compile("r = 0.7; sphere(r)").unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 24).unwrap();
        let (mesh, _) = mesh_field(&program, &grid, &McOptions::default()).unwrap();
        assert!(mesh.triangle_count() > 100);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((p.length() - 0.7).abs() < 0.02, "vertex {p} off the sphere");
            assert!((*n - p.normalize()).length() < 1e-3, "normal {n} at {p}");
        }
    }
}

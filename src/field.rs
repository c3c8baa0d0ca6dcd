//! What gets meshed: anything that has a value (and ideally a gradient) at every point of space.
//!
//! Convention used everywhere in the library: **a point is inside when its value is below the
//! iso-level**; the gradient points outward. Signed distance functions (negative inside) follow it.

use crate::error::Error;
use crate::grid::Grid;
use glam::Vec3;

/// A scalar field over space. Implementations with an analytic gradient override [`Field::gradient`];
/// the papers' feature detection and our vertex normals are only as good as that gradient.
pub trait Field {
    fn value(&self, p: Vec3) -> f32;

    /// The exact gradient where the field knows it; `None` asks the caller to estimate one.
    fn gradient(&self, _p: Vec3) -> Option<Vec3> {
        None
    }

    /// Conservative bounds `(lo, hi)` of the value over the box `[lo, hi]`, where the field can give
    /// them (compiled expressions can): octrees use them to skip space the surface cannot reach.
    fn interval(&self, _lo: Vec3, _hi: Vec3) -> Option<(f32, f32)> {
        None
    }

    /// Values at many points at once. Evaluators that vectorise override this; grids call it per row.
    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = self.value(*p);
        }
    }
}

/// Any `Fn(Vec3) -> f32` closure is a field (without a gradient).
impl<F: Fn(Vec3) -> f32> Field for F {
    fn value(&self, p: Vec3) -> f32 {
        self(p)
    }
}

/// A closure for the value paired with one for the exact gradient.
pub struct WithGradient<V, G> {
    pub value: V,
    pub gradient: G,
}

impl<V: Fn(Vec3) -> f32, G: Fn(Vec3) -> Vec3> Field for WithGradient<V, G> {
    fn value(&self, p: Vec3) -> f32 {
        (self.value)(p)
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        Some((self.gradient)(p))
    }
}

/// Central-difference gradient with step `h`: the fallback for fields that know no gradient.
pub fn finite_difference_gradient(field: &dyn Field, p: Vec3, h: f32) -> Vec3 {
    let dx = Vec3::new(h, 0.0, 0.0);
    let dy = Vec3::new(0.0, h, 0.0);
    let dz = Vec3::new(0.0, 0.0, h);
    Vec3::new(
        field.value(p + dx) - field.value(p - dx),
        field.value(p + dy) - field.value(p - dy),
        field.value(p + dz) - field.value(p - dz),
    ) / (2.0 * h)
}

/// Samples `field` at every point of `grid`, row by row through [`Field::values`].
/// Fails on the first non-finite value, naming it, because meshing it would be silently wrong.
pub fn sample_grid(field: &dyn Field, grid: &Grid) -> Result<Vec<f32>, Error> {
    let [nx, ny, nz] = grid.points();
    let mut values = vec![0.0f32; grid.point_count()];
    let mut row = vec![Vec3::ZERO; nx];
    for k in 0..nz {
        for j in 0..ny {
            for (i, p) in row.iter_mut().enumerate() {
                *p = grid.position(i, j, k);
            }
            let start = grid.index(0, j, k);
            field.values(&row, &mut values[start..start + nx]);
        }
    }
    check_finite(&values, grid)?;
    Ok(values)
}

/// Fails with [`Error::NonFiniteSample`] naming the first NaN or infinite sample.
pub fn check_finite(values: &[f32], grid: &Grid) -> Result<(), Error> {
    if values.len() != grid.point_count() {
        let p = grid.points();
        return Err(Error::InvalidGrid(format!(
            "expected {} x {} x {} = {} samples, got {}",
            p[0],
            p[1],
            p[2],
            grid.point_count(),
            values.len()
        )));
    }
    if let Some(n) = values.iter().position(|v| !v.is_finite()) {
        let [i, j, k] = grid.unindex(n);
        return Err(Error::NonFiniteSample {
            index: [i, j, k],
            position: grid.position(i, j, k).to_array(),
            value: values[n],
        });
    }
    Ok(())
}

/// A sampled volume (CT/MRI stack, or any precomputed grid) seen as a continuous field through
/// trilinear interpolation; its gradient is the interpolant's own, so it is consistent with MC.
pub struct SampledField<'a> {
    pub grid: Grid,
    pub values: &'a [f32],
}

impl SampledField<'_> {
    fn locate(&self, p: Vec3) -> ([usize; 3], Vec3) {
        let q = (p - self.grid.origin) / self.grid.spacing;
        let mut base = [0usize; 3];
        let mut frac = Vec3::ZERO;
        for a in 0..3 {
            let c = self.grid.cells[a];
            let t = q[a].clamp(0.0, c as f32);
            let b = (t.floor() as usize).min(c - 1);
            base[a] = b;
            frac[a] = t - b as f32;
        }
        (base, frac)
    }

    fn corners(&self, b: [usize; 3]) -> [f32; 8] {
        std::array::from_fn(|c| {
            self.values[self.grid.index(b[0] + (c & 1), b[1] + ((c >> 1) & 1), b[2] + ((c >> 2) & 1))]
        })
    }
}

impl Field for SampledField<'_> {
    fn value(&self, p: Vec3) -> f32 {
        let (b, t) = self.locate(p);
        let v = self.corners(b);
        let x00 = v[0] + (v[1] - v[0]) * t.x;
        let x10 = v[2] + (v[3] - v[2]) * t.x;
        let x01 = v[4] + (v[5] - v[4]) * t.x;
        let x11 = v[6] + (v[7] - v[6]) * t.x;
        let y0 = x00 + (x10 - x00) * t.y;
        let y1 = x01 + (x11 - x01) * t.y;
        y0 + (y1 - y0) * t.z
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let (b, t) = self.locate(p);
        let v = self.corners(b);
        let lerp = |a: f32, b: f32, s: f32| a + (b - a) * s;
        let dx = lerp(lerp(v[1] - v[0], v[3] - v[2], t.y), lerp(v[5] - v[4], v[7] - v[6], t.y), t.z);
        let dy = lerp(lerp(v[2] - v[0], v[3] - v[1], t.x), lerp(v[6] - v[4], v[7] - v[5], t.x), t.z);
        let dz = lerp(lerp(v[4] - v[0], v[5] - v[1], t.x), lerp(v[6] - v[2], v[7] - v[3], t.x), t.y);
        Some(Vec3::new(dx, dy, dz) / self.grid.spacing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_field_reproduces_a_linear_function_and_its_gradient() {
        let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [4, 5, 6]).unwrap();
        let f = |p: Vec3| 2.0 * p.x - 3.0 * p.y + 0.5 * p.z + 1.0;
        let values = sample_grid(&f, &grid).unwrap();
        let s = SampledField { grid, values: &values };
        for p in [Vec3::new(0.1, 0.2, 0.3), Vec3::new(-0.77, 0.5, 0.99), Vec3::new(0.999, -0.999, 0.0)] {
            assert!((s.value(p) - f(p)).abs() < 1e-5);
            assert!((s.gradient(p).unwrap() - Vec3::new(2.0, -3.0, 0.5)).length() < 1e-4);
        }
    }

    #[test]
    fn non_finite_samples_are_named() {
        let grid = Grid::new(Vec3::ZERO, Vec3::ONE, [2, 2, 2]).unwrap();
        let f = |p: Vec3| {
            if p.x > 0.9 && p.y < 0.1 && p.z < 0.1 {
                f32::NAN
            } else {
                1.0
            }
        };
        let err = sample_grid(&f, &grid).unwrap_err();
        assert!(matches!(err, Error::NonFiniteSample { index: [2, 0, 0], .. }), "{err}");
        assert!(err.to_string().contains("(2, 0, 0)"));
    }
}

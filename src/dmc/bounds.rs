//! The octree covers the finest grid exactly (the bounds grown to whole finest cells, as Marching
//! Cubes' grid is), and every sample and vertex lies in it. [`Clipped`] is the field as DMC sees
//! it: its distance from the level in units of length, `(f - iso) / s` with `s` the field's
//! [`Field::steepness`] (1 for a signed distance), intersected with that box, `max(that, box)`.
//! DMC contours its zero level. Where the solid reaches a face of the box the surface closes on
//! that face, so the output stays a closed solid inside the bounds. For an exact distance whose
//! shape lies inside the bounds it is the field itself everywhere (a point's distance to the shape
//! is at least its distance to the box). Outside the box, where a field may not be finite, it
//! continues from the box instead: the field on the box plus the largest per-axis distance to it,
//! positive (only root finding between a vertex and its copy on the box's face comes near).
//!
//! Why in units of length: the box's distance is in them, and so are the QEF's residuals, the
//! tolerance and the band of vertices taken to be on the level. A 16-bit volume of thousands of
//! units per cell, clipped by a distance in world units, became, wherever its solid reached a
//! face, a plateau a few units under the level, flat beside the data: vertices settled on it a
//! hair inside, which untangling could not move off the level (random noise grids crossed
//! themselves), and the data's sigmoid rims fitted no QEF within a tolerance read in its units.
//! Scaled by a power of two, a volume and its level give the same mesh.

use crate::field::Field;
use glam::Vec3;

/// `field` (inside where below `iso`) as a distance from its level, intersected with the box
/// `[min, max]`, evaluated only at points of the box (others are clamped onto it first). Its
/// level is 0.
pub struct Clipped<'a> {
    pub field: &'a dyn Field,
    pub iso: f32,
    pub min: Vec3,
    pub max: Vec3,
    /// The field's [`Field::steepness`], by which its distance from the level is divided.
    pub slope: f32,
}

impl<'a> Clipped<'a> {
    /// `field`'s distance from `iso`, in units of length, clipped to `[min, max]`.
    pub fn new(field: &'a dyn Field, iso: f32, min: Vec3, max: Vec3) -> Clipped<'a> {
        Clipped { field, iso, min, max, slope: field.steepness() }
    }

    /// A value of the field as DMC sees it: its distance from the level in units of length.
    fn scaled(&self, value: f32) -> f32 {
        (value - self.iso) / self.slope
    }

    /// Signed distance to the box (negative inside) and its gradient.
    fn box_distance(&self, p: Vec3) -> (f32, Vec3) {
        let centre = (self.min + self.max) * 0.5;
        let d = p - centre;
        let q = d.abs() - (self.max - self.min) * 0.5;
        let outside = q.max(Vec3::ZERO);
        let length = outside.length();
        if length > 0.0 {
            return (length, outside / length * Vec3::select(d.cmplt(Vec3::ZERO), -Vec3::ONE, Vec3::ONE));
        }
        let axis = largest_axis(q);
        let mut g = Vec3::ZERO;
        g[axis] = if d[axis] < 0.0 { -1.0 } else { 1.0 };
        (q.max_element(), g)
    }

    fn clamp(&self, p: Vec3) -> Vec3 {
        p.clamp(self.min, self.max)
    }

    /// The clipped value at `p` from the field's value there.
    fn combine(&self, value: f32, p: Vec3) -> f32 {
        let c = self.clamp(p);
        if value.is_finite() || c == p {
            return self.scaled(value).max(self.box_distance(p).0);
        }
        self.scaled(self.field.value(c)).max(0.0) + (p - c).abs().max_element()
    }

    /// The clipped gradient at `p` from the field's value and gradient there.
    fn combine_gradient(&self, value: f32, gradient: Option<Vec3>, p: Vec3) -> Option<Vec3> {
        let c = self.clamp(p);
        let scale = |g: Vec3| g / self.slope;
        if value.is_finite() || c == p {
            let (d, g) = self.box_distance(p);
            return if d > self.scaled(value) { Some(g) } else { gradient.map(scale) };
        }
        // The continuation: the field on the box, constant along the axes p lies beyond it on,
        // plus the max-norm distance, whose gradient is the axis of the largest gap.
        let out = p - c;
        let mut away = Vec3::ZERO;
        let axis = largest_axis(out.abs());
        away[axis] = out[axis].signum();
        if self.field.value(c) < self.iso {
            return Some(away);
        }
        let free = Vec3::select(out.cmpeq(Vec3::ZERO), Vec3::ONE, Vec3::ZERO);
        self.field.gradient(c).map(|g| scale(g) * free + away)
    }
}

fn largest_axis(v: Vec3) -> usize {
    if v.x >= v.y && v.x >= v.z {
        0
    } else if v.y >= v.z {
        1
    } else {
        2
    }
}

impl Field for Clipped<'_> {
    fn value(&self, p: Vec3) -> f32 {
        self.combine(self.field.value(p), p)
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        self.combine_gradient(self.field.value(p), self.field.gradient(p), p)
    }

    fn interval(&self, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
        // max(f, box): the box term is convex, so its largest value over the query is at a
        // corner, and its smallest at least the gap where the query misses the bounds. Where the
        // field's own bound is not finite (it is undefined somewhere outside), none is given.
        let (flo, fhi) = self.field.interval(lo, hi)?;
        if !(flo.is_finite() && fhi.is_finite()) {
            return None;
        }
        let (flo, fhi) = (self.scaled(flo), self.scaled(fhi));
        let box_hi = if lo.cmpge(self.min).all() && hi.cmple(self.max).all() {
            // Every corner inside the box, where its distance is the largest of the per-axis
            // ones: the same maximum, axis by axis (the crust asks this of every node).
            let (centre, half) = ((self.min + self.max) * 0.5, (self.max - self.min) * 0.5);
            let q = |p: Vec3| (p - centre).abs() - half;
            q(lo).max(q(hi)).max_element()
        } else {
            let corners = (0..8).map(|c| {
                Vec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                )
            });
            corners.map(|p| self.box_distance(p).0).fold(f32::NEG_INFINITY, f32::max)
        };
        let gap = (lo - self.max).max(self.min - hi).max_element();
        let low = if gap > 0.0 { flo.max(gap) } else { flo };
        Some((low, fhi.max(box_hi)))
    }

    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        self.field.values(points, out);
        for (o, &p) in out.iter_mut().zip(points) {
            *o = self.combine(*o, p);
        }
    }

    fn gradients(&self, points: &[Vec3], out: &mut [Option<Vec3>]) {
        let mut values = vec![0.0; points.len()];
        self.values_and_gradients(points, &mut values, out);
    }

    fn values_and_gradients(&self, points: &[Vec3], values: &mut [f32], gradients: &mut [Option<Vec3>]) {
        self.field.values_and_gradients(points, values, gradients);
        for ((v, g), &p) in values.iter_mut().zip(gradients.iter_mut()).zip(points) {
            if v.is_finite() || self.clamp(p) == p {
                // `combine` and `combine_gradient` in one, the box's distance found once.
                let (d, box_gradient) = self.box_distance(p);
                let scaled = self.scaled(*v);
                *g = if d > scaled { Some(box_gradient) } else { g.map(|g| g / self.slope) };
                *v = scaled.max(d);
            } else {
                *g = self.combine_gradient(*v, *g, p);
                *v = self.combine(*v, p);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_undefined_outside_the_bounds_continues_from_them_and_closes_on_them() {
        let (min, max) = (Vec3::new(-1.0, -1.0, -0.5), Vec3::new(1.0, 1.0, 0.5));
        let field = |p: Vec3| {
            if p.cmpge(min).all() && p.cmple(max).all() {
                p.z - 0.2
            } else {
                f32::NAN
            }
        };
        let clipped = Clipped::new(&field, 0.0, min, max);
        for p in [Vec3::new(0.3, -0.2, 0.9), Vec3::new(0.0, 0.0, 0.1), Vec3::new(0.5, 0.5, 3.0)] {
            assert!((clipped.value(p) - (p.z - 0.2)).abs() < 1e-6, "at {p}");
        }
        // Below the plane, where the solid meets the floor of the box, the surface closes there.
        assert!(clipped.value(Vec3::new(0.0, 0.0, -0.4)) < 0.0);
        assert!(clipped.value(Vec3::new(0.0, 0.0, -0.6)) > 0.0);
        assert!(clipped.value(Vec3::new(1.5, 0.0, -0.4)) > 0.0);
    }

    /// A volume in thousands of units per cell whose solid reaches a face of the bounds is seen
    /// as a distance from its level, closed on the face: a little way in from the face, the box
    /// (unscaled, the solid's inside was a plateau a few units under the level), deeper in, the
    /// data over its steepness. Scaled by a power of two, volume and level give the same field.
    #[test]
    fn a_steep_volume_is_clipped_as_a_distance_from_its_level() {
        let grid = crate::Grid::new(Vec3::ZERO, Vec3::ONE, [9, 9, 9]).unwrap();
        let sampled =
            |k: f32| crate::field::sample_grid(&|p: Vec3| k * (p.x - 0.5) + 7.0 * k, &grid).unwrap();
        let (values, doubled) = (sampled(1000.0), sampled(2048.0));
        let field = |values| crate::field::SampledField {
            grid,
            values,
            gradient: crate::field::SampleGradient::Trilinear,
        };
        let (data, data_doubled) = (field(&values), field(&doubled));
        let clipped = Clipped::new(&data, 7000.0, Vec3::ZERO, Vec3::ONE);
        // A tenth from the face y = 0, where the data is 300 under its level: the box's -0.1.
        let p = Vec3::new(0.2, 0.1, 0.5);
        assert!((clipped.value(p) + 0.1).abs() < 1e-4, "{}", clipped.value(p));
        assert!(clipped.value(Vec3::new(0.2, 0.0, 0.5)) >= 0.0);
        let deep = Vec3::new(0.45, 0.5, 0.5);
        assert!((clipped.value(deep) + 0.05).abs() < 1e-4, "{}", clipped.value(deep));
        // The same volume in other units, 2048 per unit of length instead of 1000.
        let other = Clipped::new(&data_doubled, 7.0 * 2048.0, Vec3::ZERO, Vec3::ONE);
        for q in [p, deep, Vec3::new(0.7, 0.3, 0.9)] {
            assert!((other.value(q) - clipped.value(q)).abs() < 1e-5, "at {q}");
        }
    }

    /// An exact distance whose shape lies inside the bounds is its own clip, values and gradients
    /// alike, so DMC's octree over such a part is the one it was before the field was clipped:
    /// every scene, over the whole of its finest grid.
    #[test]
    fn every_scene_is_its_own_clip() {
        for name in crate::scenes::SCENE_NAMES {
            let scene = crate::scenes::scene(name).unwrap();
            let field = scene.field.as_ref();
            let (min, max) = (scene.min, scene.max);
            let grid =
                crate::dmc::finest_grid(min, max, crate::dmc::DmcOptions::default().max_depth).unwrap();
            let (root, size) = (grid.origin, grid.max() - grid.origin);
            let clipped = Clipped::new(field, 0.0, min, max);
            let n = 20;
            for i in 0..=n {
                for j in 0..=n {
                    for k in 0..=n {
                        let p = root + Vec3::new(i as f32, j as f32, k as f32) / n as f32 * size;
                        let (a, b) = (field.value(p), clipped.value(p));
                        assert_eq!(a, b, "{name}: value at {p}");
                        assert_eq!(field.gradient(p), clipped.gradient(p), "{name}: gradient at {p}");
                    }
                }
            }
        }
    }
}

//! The octree's root is a cube around the requested bounds, larger than them when they are not
//! cubic (and always a little larger, see `ROOT_GROWTH`). What lies outside the bounds must neither
//! be evaluated (a field may be undefined there) nor meshed (the user asked for the bounds).
//! [`Clipped`] is the field intersected with the bounds box. Inside the box it is the field
//! wherever the surface can be, and where the solid reaches a face of the box the surface closes
//! on that face, so the output stays a closed solid. Outside the box it is the field on the box
//! plus the largest per-axis distance to it (the max norm): positive, and equal to the field
//! itself wherever the field grows like that across the face (a plane parallel to it, the walls of
//! a box, a part well inside), so the octree's fits outside the bounds see what they saw before the
//! field was clipped (the planar room's octree is the same, see the test below).

use crate::field::Field;
use glam::Vec3;

/// `field` (inside where below `iso`) intersected with the box `[min, max]`, evaluated only at
/// points of the box (others are clamped onto it first).
pub struct Clipped<'a> {
    pub field: &'a dyn Field,
    pub iso: f32,
    pub min: Vec3,
    pub max: Vec3,
}

impl Clipped<'_> {
    /// Signed distance to the box (negative inside).
    fn box_distance(&self, p: Vec3) -> f32 {
        let centre = (self.min + self.max) * 0.5;
        let q = (p - centre).abs() - (self.max - self.min) * 0.5;
        let outside = q.max(Vec3::ZERO).length();
        if outside > 0.0 {
            outside
        } else {
            q.max_element()
        }
    }

    /// The nearest point of the box, and the axes along which `p` lies beyond it.
    fn clamp(&self, p: Vec3) -> Vec3 {
        p.clamp(self.min, self.max)
    }

    /// The clipped value from the field's value at the clamped point.
    fn combine(&self, value: f32, p: Vec3) -> f32 {
        let c = self.clamp(p);
        if c == p {
            value.max(self.iso + self.box_distance(p))
        } else {
            value.max(self.iso) + (p - c).abs().max_element()
        }
    }

    /// The clipped gradient from the field's value and gradient at the clamped point.
    fn combine_gradient(&self, value: f32, gradient: Option<Vec3>, p: Vec3) -> Option<Vec3> {
        let c = self.clamp(p);
        let face_normal = |p: Vec3| {
            let centre = (self.min + self.max) * 0.5;
            let d = p - centre;
            let q = d.abs() - (self.max - self.min) * 0.5;
            let axis = if q.x >= q.y && q.x >= q.z {
                0
            } else if q.y >= q.z {
                1
            } else {
                2
            };
            let mut g = Vec3::ZERO;
            g[axis] = if d[axis] < 0.0 { -1.0 } else { 1.0 };
            g
        };
        if c == p {
            return if self.iso + self.box_distance(p) > value { Some(face_normal(p)) } else { gradient };
        }
        // The distance beyond the box is the largest per-axis gap (the box's own distance in the
        // max norm), so the clipped field continues fields built of max() as they are.
        let out = p - c;
        let gap = out.abs();
        let axis = if gap.x >= gap.y && gap.x >= gap.z {
            0
        } else if gap.y >= gap.z {
            1
        } else {
            2
        };
        let mut away = Vec3::ZERO;
        away[axis] = out[axis].signum();
        if value < self.iso {
            return Some(away);
        }
        // Along the axes where p is beyond the box, the clamped point does not move with p.
        let free = Vec3::select(out.cmpeq(Vec3::ZERO), Vec3::ONE, Vec3::ZERO);
        gradient.map(|g| g * free + away)
    }
}

impl Field for Clipped<'_> {
    fn value(&self, p: Vec3) -> f32 {
        self.combine(self.field.value(self.clamp(p)), p)
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let c = self.clamp(p);
        self.combine_gradient(self.field.value(c), self.field.gradient(c), p)
    }

    fn interval(&self, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
        // Inside the box the value lies in [field's low, max(field's high, iso)]; outside it is
        // max(field on the face, iso) plus a distance that is at least the gap to the box and at
        // most the box term's largest value over the query, found at one of its corners (the box
        // term is convex).
        let (flo, fhi) = self.field.interval(self.clamp(lo), self.clamp(hi))?;
        let corners = (0..8).map(|c| {
            Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            )
        });
        let farthest = corners.map(|p| self.box_distance(p)).fold(0.0f32, f32::max);
        let gap = (lo - self.max).max(self.min - hi).max_element();
        let low = if gap > 0.0 { flo.max(self.iso) + gap } else { flo };
        Some((low, fhi.max(self.iso) + farthest))
    }

    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        let clamped: Vec<Vec3> = points.iter().map(|&p| self.clamp(p)).collect();
        self.field.values(&clamped, out);
        for (o, &p) in out.iter_mut().zip(points) {
            *o = self.combine(*o, p);
        }
    }

    fn gradients(&self, points: &[Vec3], out: &mut [Option<Vec3>]) {
        let clamped: Vec<Vec3> = points.iter().map(|&p| self.clamp(p)).collect();
        self.field.gradients(&clamped, out);
        let mut values = vec![0.0; points.len()];
        self.field.values(&clamped, &mut values);
        for ((o, &p), &v) in out.iter_mut().zip(points).zip(&values) {
            *o = self.combine_gradient(v, *o, p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_parallel_to_a_face_is_unchanged_outside_and_nothing_outside_is_evaluated() {
        let (min, max) = (Vec3::new(-1.0, -1.0, -0.5), Vec3::new(1.0, 1.0, 0.5));
        let field = |p: Vec3| {
            assert!(p.cmpge(min).all() && p.cmple(max).all(), "evaluated outside the bounds at {p}");
            p.z - 0.2
        };
        let clipped = Clipped { field: &field, iso: 0.0, min, max };
        for p in [Vec3::new(0.3, -0.2, 0.9), Vec3::new(0.0, 0.0, 0.1), Vec3::new(0.5, 0.5, 3.0)] {
            assert!((clipped.value(p) - (p.z - 0.2)).abs() < 1e-6, "at {p}");
        }
        // Below the plane, where the solid meets the floor of the box, the surface closes there.
        assert!(clipped.value(Vec3::new(0.0, 0.0, -0.4)) < 0.0);
        assert!(clipped.value(Vec3::new(0.0, 0.0, -0.6)) > 0.0);
        assert!(clipped.value(Vec3::new(1.5, 0.0, -0.4)) > 0.0);
    }

    /// A field made of max() (a box's distance, a room's walls) continues across the faces of the
    /// bounds exactly as the clipped field does, values and gradients alike, so DMC's octree over
    /// the planar room is the one it was before the field was clipped.
    #[test]
    fn the_planar_room_is_unchanged_across_its_bounds() {
        let room = crate::expr::compile(
            "b = max(abs(x) - 0.8, abs(y) - 0.8, abs(z) - 0.5); room = abs(b) - 0.008; \
             door = translate(max(abs(x) - 0.2, abs(y) - 0.1, abs(z) - 0.325), 0, -0.8, -0.125); max(room, -door)",
        )
        .unwrap();
        let (min, max) = (Vec3::new(-1.0, -1.0, -0.7), Vec3::new(1.0, 1.0, 0.7));
        let clipped = Clipped { field: &room, iso: 0.0, min, max };
        let n = 24;
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    let t = Vec3::new(i as f32, j as f32, k as f32) / n as f32;
                    let p = Vec3::splat(-1.03) + t * 2.1;
                    let (a, b) = (room.value(p), clipped.value(p));
                    assert!((a - b).abs() <= 1e-6, "value at {p}: {a} vs {b}");
                    let (ga, gb) = (room.gradient(p).unwrap(), clipped.gradient(p).unwrap());
                    assert!((ga - gb).length() <= 1e-6, "gradient at {p}: {ga} vs {gb}");
                }
            }
        }
    }
}

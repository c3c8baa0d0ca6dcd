//! The shape library, written once against [`Emit`] so the same formulas build tape nodes (in the
//! compiler) and compute numbers directly (in the reference tree walk).
//!
//! Every primitive is an exact signed distance (negative inside) unless its doc says otherwise.
//! They are written so that on the surface itself the gradient comes from a `min(…, 0)` term
//! rather than from a `sqrt` at zero, whose derivative is undefined.

use super::ops::{BinaryOp, UnaryOp, MAX_POWI};

/// Something that can combine values with the primitive operations: a graph builder or a
/// calculator. `as_constant` lets formulas take a cheaper or more exact path for known numbers.
pub trait Emit {
    type V: Copy + PartialEq;
    fn constant(&mut self, c: f32) -> Self::V;
    fn unary(&mut self, op: UnaryOp, a: Self::V) -> Self::V;
    fn binary(&mut self, op: BinaryOp, a: Self::V, b: Self::V) -> Self::V;
    fn as_constant(&self, v: Self::V) -> Option<f32>;

    fn add(&mut self, a: Self::V, b: Self::V) -> Self::V {
        self.binary(BinaryOp::Add, a, b)
    }
    fn sub(&mut self, a: Self::V, b: Self::V) -> Self::V {
        self.binary(BinaryOp::Sub, a, b)
    }
    fn mul(&mut self, a: Self::V, b: Self::V) -> Self::V {
        self.binary(BinaryOp::Mul, a, b)
    }
    fn div(&mut self, a: Self::V, b: Self::V) -> Self::V {
        self.binary(BinaryOp::Div, a, b)
    }
    fn min(&mut self, a: Self::V, b: Self::V) -> Self::V {
        self.binary(BinaryOp::Min, a, b)
    }
    fn max(&mut self, a: Self::V, b: Self::V) -> Self::V {
        self.binary(BinaryOp::Max, a, b)
    }
    fn neg(&mut self, a: Self::V) -> Self::V {
        self.unary(UnaryOp::Neg, a)
    }
    fn abs(&mut self, a: Self::V) -> Self::V {
        self.unary(UnaryOp::Abs, a)
    }
    fn sqrt(&mut self, a: Self::V) -> Self::V {
        self.unary(UnaryOp::Sqrt, a)
    }
    fn square(&mut self, a: Self::V) -> Self::V {
        self.unary(UnaryOp::Powi(2), a)
    }
    fn mul_c(&mut self, a: Self::V, c: f32) -> Self::V {
        let c = self.constant(c);
        self.mul(a, c)
    }
    fn max0(&mut self, a: Self::V) -> Self::V {
        let zero = self.constant(0.0);
        self.max(a, zero)
    }
    fn min0(&mut self, a: Self::V) -> Self::V {
        let zero = self.constant(0.0);
        self.min(a, zero)
    }

    /// `a^b`; a small constant integer exponent becomes `Powi`, exact for negative bases too.
    fn pow(&mut self, a: Self::V, b: Self::V) -> Self::V {
        match self.as_constant(b) {
            Some(e) if e.fract() == 0.0 && e.abs() <= MAX_POWI as f32 => {
                self.unary(UnaryOp::Powi(e as i32), a)
            }
            _ => self.binary(BinaryOp::Pow, a, b),
        }
    }
    fn clamp(&mut self, a: Self::V, lo: Self::V, hi: Self::V) -> Self::V {
        let m = self.max(a, lo);
        self.min(m, hi)
    }
    /// `a + (b - a) t`, GLSL's mix.
    fn mix(&mut self, a: Self::V, b: Self::V, t: Self::V) -> Self::V {
        let d = self.sub(b, a);
        let dt = self.mul(d, t);
        self.add(a, dt)
    }
    fn sum_squares(&mut self, vs: &[Self::V]) -> Self::V {
        let mut acc = self.square(vs[0]);
        for &v in &vs[1..] {
            let s = self.square(v);
            acc = self.add(acc, s);
        }
        acc
    }
    /// Euclidean length; of one value it is `abs`, which is exact where `sqrt(a^2)` would round.
    fn length(&mut self, vs: &[Self::V]) -> Self::V {
        if vs.len() == 1 {
            return self.abs(vs[0]);
        }
        let s = self.sum_squares(vs);
        self.sqrt(s)
    }
    fn dot(&mut self, a: &[Self::V], b: &[Self::V]) -> Self::V {
        let mut acc = self.mul(a[0], b[0]);
        for i in 1..a.len().min(b.len()) {
            let t = self.mul(a[i], b[i]);
            acc = self.add(acc, t);
        }
        acc
    }
    /// `Σ c_j p_j`, leaving out terms whose coefficient is exactly zero (so rotations by right
    /// angles cost nothing extra, and an infinite coordinate does not turn into NaN via `0 * inf`).
    fn linear(&mut self, coeffs: [f64; 3], p: [Self::V; 3]) -> Self::V {
        let mut acc: Option<Self::V> = None;
        for (c, &v) in coeffs.iter().zip(&p) {
            if *c == 0.0 {
                continue;
            }
            acc = Some(match (acc, *c) {
                (None, 1.0) => v,
                (None, -1.0) => self.neg(v),
                (Some(a), 1.0) => self.add(a, v),
                (Some(a), -1.0) => self.sub(a, v),
                (None, c) => self.mul_c(v, c as f32),
                (Some(a), c) => {
                    let t = self.mul_c(v, c as f32);
                    self.add(a, t)
                }
            });
        }
        acc.unwrap_or_else(|| self.constant(0.0))
    }
}

type P<E> = [<E as Emit>::V; 3];

pub fn sphere<E: Emit>(e: &mut E, p: P<E>, r: E::V) -> E::V {
    let l = e.length(&p);
    e.sub(l, r)
}

/// Axis-aligned box with half extents `h`.
pub fn cuboid<E: Emit>(e: &mut E, p: P<E>, h: P<E>) -> E::V {
    let q: Vec<E::V> = (0..3)
        .map(|i| {
            let a = e.abs(p[i]);
            e.sub(a, h[i])
        })
        .collect();
    let outside: Vec<E::V> = q.iter().map(|&v| e.max0(v)).collect();
    let outside = e.length(&outside);
    let m = e.max(q[1], q[2]);
    let m = e.max(q[0], m);
    let inside = e.min0(m);
    e.add(outside, inside)
}

/// `h` are the outer half extents; the edges are rounded with radius `r` (at most the smallest
/// half extent), which keeps the box the same size as `box(h)`.
pub fn rounded_box<E: Emit>(e: &mut E, p: P<E>, h: P<E>, r: E::V) -> E::V {
    let inner = h.map(|hi| e.sub(hi, r));
    let d = cuboid(e, p, inner);
    e.sub(d, r)
}

/// Capped cylinder of radius `r` around the z axis, from `z = -h` to `z = h`.
pub fn cylinder<E: Emit>(e: &mut E, p: P<E>, r: E::V, h: E::V) -> E::V {
    let radial = e.length(&p[..2]);
    let dr = e.sub(radial, r);
    let az = e.abs(p[2]);
    let dz = e.sub(az, h);
    let m = e.max(dr, dz);
    let inside = e.min0(m);
    let o = [e.max0(dr), e.max0(dz)];
    let outside = e.length(&o);
    e.add(inside, outside)
}

/// Solid cone: base disc of radius `r` in the plane `z = 0`, apex at `(0, 0, h)`; `r, h > 0`.
///
/// Worked in the half-plane `(u, v) = (|xy|, z)`, where the cone is the triangle (0,0), (r,0),
/// (0,h). Inside, the distance is the larger of the signed distances to the base line and the
/// slanted line (exact for a convex section). Outside, it is the distance to the nearer of the two
/// boundary segments, switched on only where the point is outside.
pub fn cone<E: Emit>(e: &mut E, p: P<E>, r: E::V, h: E::V) -> E::V {
    let u = e.length(&p[..2]);
    let v = p[2];
    let slant_len = e.length(&[h, r]);
    // Signed distance to the slanted line u/r + v/h = 1, positive away from the axis.
    let uh = e.mul(u, h);
    let vr = e.mul(v, r);
    let rh = e.mul(r, h);
    let s = e.add(uh, vr);
    let s = e.sub(s, rh);
    let s_slant = e.div(s, slant_len);
    let s_base = e.neg(v);
    let m = e.max(s_base, s_slant);
    // Squared distance to the slanted segment from (r, 0) to (0, h), in the segment's own frame:
    // the offset along its normal (`s_slant`) and how far the point lies beyond either end along
    // it. Beside the segment the second is exactly 0, so just outside the side the distance is
    // `|s_slant|` with the side's exact gradient. (The length of the offset vector to the nearest
    // point, the textbook form, is rounding noise there, and so is the direction of its gradient.)
    let wu = e.sub(u, r);
    let along = {
        let nr = e.neg(r);
        let dot = e.dot(&[wu, v], &[nr, h]);
        e.div(dot, slant_len)
    };
    let zero = e.constant(0.0);
    let on_segment = e.clamp(along, zero, slant_len);
    let beyond = e.sub(along, on_segment);
    let d_slant = e.sum_squares(&[s_slant, beyond]);
    // Squared distance to the base segment from (0, 0) to (r, 0).
    let over = e.max0(wu);
    let d_base = e.sum_squares(&[over, v]);
    let d2 = e.min(d_slant, d_base);
    let dist = e.sqrt(d2);
    let sm = e.unary(UnaryOp::Sign, m);
    let outside_only = e.max0(sm);
    let outside = e.mul(outside_only, dist);
    let inside = e.min0(m);
    e.add(outside, inside)
}

/// Torus around the z axis: ring radius `big_r`, tube radius `r`.
pub fn torus<E: Emit>(e: &mut E, p: P<E>, big_r: E::V, r: E::V) -> E::V {
    let radial = e.length(&p[..2]);
    let ring = e.sub(radial, big_r);
    let d = e.length(&[ring, p[2]]);
    e.sub(d, r)
}

/// Points within `r` of the segment from `a` to `b`.
pub fn capsule<E: Emit>(e: &mut E, p: P<E>, a: P<E>, b: P<E>, r: E::V) -> E::V {
    let pa: Vec<E::V> = (0..3).map(|i| e.sub(p[i], a[i])).collect();
    let ba: Vec<E::V> = (0..3).map(|i| e.sub(b[i], a[i])).collect();
    let along = e.dot(&pa, &ba);
    let len2 = e.sum_squares(&ba);
    let t = e.div(along, len2);
    let (zero, one) = (e.constant(0.0), e.constant(1.0));
    let t = e.clamp(t, zero, one);
    let off: Vec<E::V> = (0..3)
        .map(|i| {
            let bt = e.mul(ba[i], t);
            e.sub(pa[i], bt)
        })
        .collect();
    let l = e.length(&off);
    e.sub(l, r)
}

/// `n·p - d` with `n` normalised. `None` when `n` is the constant zero vector.
pub fn plane<E: Emit>(e: &mut E, p: P<E>, n: P<E>, d: E::V) -> Option<E::V> {
    let dot = match constants(e, &n) {
        Some(c) => {
            let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            if len == 0.0 || !len.is_finite() {
                return None;
            }
            e.linear(c.map(|v| v / len), p)
        }
        None => {
            let len = e.length(&n);
            let dot = e.dot(&n, &p);
            e.div(dot, len)
        }
    };
    Some(e.sub(dot, d))
}

/// Polynomial smooth minimum with blend width `k > 0`; equals `min(a, b)` when they differ by
/// more than `k`.
pub fn smooth_min<E: Emit>(e: &mut E, a: E::V, b: E::V, k: E::V) -> E::V {
    let diff = e.sub(b, a);
    let q = e.div(diff, k);
    let half = e.constant(0.5);
    let q = e.mul(half, q);
    let q = e.add(half, q);
    let (zero, one) = (e.constant(0.0), e.constant(1.0));
    let h = e.clamp(q, zero, one);
    let blend = e.mix(b, a, h);
    let one_minus = e.sub(one, h);
    let bump = e.mul(h, one_minus);
    let bump = e.mul(k, bump);
    e.sub(blend, bump)
}

pub fn smooth_max<E: Emit>(e: &mut E, a: E::V, b: E::V, k: E::V) -> E::V {
    let (na, nb) = (e.neg(a), e.neg(b));
    let m = smooth_min(e, na, nb, k);
    e.neg(m)
}

/// Coordinates at which a shape is evaluated so that it appears moved by `d`.
pub fn translate<E: Emit>(e: &mut E, p: P<E>, d: P<E>) -> P<E> {
    [0, 1, 2].map(|i| e.sub(p[i], d[i]))
}

/// Coordinates at which a shape is evaluated so that it appears rotated by `degrees` about
/// `axis` (right-hand rule). `None` when the axis is the constant zero vector.
pub fn rotate<E: Emit>(e: &mut E, p: P<E>, axis: P<E>, degrees: E::V) -> Option<P<E>> {
    if let (Some(n), Some(deg)) = (constants(e, &axis), e.as_constant(degrees)) {
        let r = rotation_matrix(n, deg as f64)?;
        // Evaluate at R^T p: row i of R^T is column i of R.
        return Some([0, 1, 2].map(|i| e.linear([r[0][i], r[1][i], r[2][i]], p)));
    }
    // General case, all in the tape: p' = c p - s (n × p) + (1 - c)(n · p) n.
    let len = e.length(&axis);
    let n = axis.map(|a| e.div(a, len));
    let rad = e.mul_c(degrees, std::f32::consts::PI / 180.0);
    let (c, s) = (e.unary(UnaryOp::Cos, rad), e.unary(UnaryOp::Sin, rad));
    let one = e.constant(1.0);
    let one_minus_c = e.sub(one, c);
    let np = e.dot(&n, &p);
    let k = e.mul(one_minus_c, np);
    Some([0, 1, 2].map(|i| {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let a = e.mul(n[j], p[l]);
        let b = e.mul(n[l], p[j]);
        let cross = e.sub(a, b);
        let cp = e.mul(c, p[i]);
        let sc = e.mul(s, cross);
        let kn = e.mul(k, n[i]);
        let t = e.sub(cp, sc);
        e.add(t, kn)
    }))
}

/// `R = c I + s [n]× + (1 - c) n nᵀ`, in f64, with exact sines and cosines at multiples of 90°
/// so that right-angle rotations map axes onto axes without a 1e-8 wobble.
pub fn rotation_matrix(axis: [f64; 3], degrees: f64) -> Option<[[f64; 3]; 3]> {
    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if len == 0.0 || !len.is_finite() || !degrees.is_finite() {
        return None;
    }
    let n = axis.map(|a| a / len);
    let d = degrees.rem_euclid(360.0);
    let (s, c) = if d == 0.0 {
        (0.0, 1.0)
    } else if d == 90.0 {
        (1.0, 0.0)
    } else if d == 180.0 {
        (0.0, -1.0)
    } else if d == 270.0 {
        (-1.0, 0.0)
    } else {
        d.to_radians().sin_cos()
    };
    let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            let id = if i == j { 1.0 } else { 0.0 };
            let x = c * id + s * k[i][j] + (1.0 - c) * n[i] * n[j];
            // Round-off residue (1e-17) would otherwise cost a multiply per coordinate.
            *v = if x.abs() < 1e-12 { 0.0 } else { x };
        }
    }
    Some(r)
}

/// Coordinates for a uniform scale by `s` (the caller multiplies the result by `s`).
pub fn scale<E: Emit>(e: &mut E, p: P<E>, s: E::V) -> P<E> {
    p.map(|v| e.div(v, s))
}

/// Coordinates that reflect the half-space `p[axis] >= 0` onto the other side.
pub fn mirror<E: Emit>(e: &mut E, p: P<E>, axis: usize) -> P<E> {
    let mut q = p;
    q[axis] = e.abs(p[axis]);
    q
}

fn constants<E: Emit>(e: &E, v: &P<E>) -> Option<[f64; 3]> {
    Some([e.as_constant(v[0])? as f64, e.as_constant(v[1])? as f64, e.as_constant(v[2])? as f64])
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use super::super::testutil::Rng;
    use super::rotation_matrix;
    use glam::Vec3;

    fn at(src: &str, p: [f32; 3]) -> f32 {
        compile(src).unwrap_or_else(|e| panic!("{src}: {e}")).eval(Vec3::from_array(p))
    }

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-5
    }

    #[test]
    fn sphere_is_distance_minus_radius() {
        let p = compile("sphere(0.75)").unwrap();
        let mut rng = Rng::new(40);
        for _ in 0..200 {
            let q = rng.vec3(-2.0, 2.0);
            assert!(close(p.eval(q), q.length() - 0.75), "at {q}");
        }
    }

    #[test]
    fn box_distance_is_exact_at_known_points() {
        let b = "box(0.5, 0.4, 0.3)";
        assert!(close(at(b, [1.0, 0.0, 0.0]), 0.5), "face");
        assert!(close(at(b, [1.0, 1.0, 0.0]), (0.5f32 * 0.5 + 0.6 * 0.6).sqrt()), "edge");
        assert!(close(at(b, [1.5, -1.4, 1.3]), 3f32.sqrt()), "corner");
        assert!(close(at(b, [0.0, 0.0, 0.0]), -0.3), "centre: nearest face is z");
        assert!(close(at(b, [0.45, 0.0, 0.0]), -0.05));
        let r = "rounded_box(0.5, 0.4, 0.3, 0.1)";
        assert!(close(at(r, [1.0, 0.0, 0.0]), 0.5), "same outer size as the box");
        let corner = Vec3::new(0.4, 0.3, 0.2) + Vec3::ONE.normalize() * 0.6;
        assert!(close(at(r, corner.to_array()), 0.5), "rounded corner");
    }

    #[test]
    fn cylinder_cone_torus_capsule_and_plane_at_known_points() {
        let c = "cylinder(0.4, 0.6)";
        assert!(close(at(c, [1.0, 0.0, 0.0]), 0.6));
        assert!(close(at(c, [0.0, 0.0, 1.0]), 0.4));
        assert!(close(at(c, [0.7, 0.0, 1.0]), 0.5), "beyond the rim: 0.3-0.4-0.5 triangle");
        assert!(close(at(c, [0.0, 0.1, 0.0]), -0.3));
        let k = "cone(0.5, 0.8)";
        assert!(close(at(k, [0.0, 0.0, 1.8]), 1.0), "above the apex");
        assert!(close(at(k, [0.0, 0.0, -1.0]), 1.0), "below the base");
        assert!(close(at(k, [0.9, 0.0, -0.3]), 0.5), "beyond the base rim");
        assert!(close(at(k, [0.0, 0.3, 0.0]), 0.0), "on the base disc");
        let slant = (0.5f32 * 0.5 + 0.8 * 0.8).sqrt();
        assert!(close(at(k, [0.0, 0.0, 0.4]), -0.4 * 0.5 / slant), "inside: distance to the side");
        let t = "torus(0.6, 0.2)";
        assert!(close(at(t, [0.6, 0.0, 0.0]), -0.2));
        assert!(close(at(t, [0.0, 0.0, 0.0]), 0.4));
        assert!(close(at(t, [0.0, -0.6, 0.5]), 0.3));
        let s = "capsule(0, 0, 0, 1, 0, 0, 0.25)";
        assert!(close(at(s, [0.5, 1.0, 0.0]), 0.75));
        assert!(close(at(s, [-1.0, 0.0, 0.0]), 0.75));
        assert!(close(at(s, [2.0, 0.0, 0.0]), 0.75));
        let pl = "plane(0, 3, 4, 1)";
        assert!(close(at(pl, [7.0, 3.0, 4.0]), 4.0), "normal is normalised: (3·3 + 4·4)/5 - 1");
    }

    /// Just outside the slanted side, the distance is a few ulps: were it the length of an offset
    /// vector made of rounding noise, its gradient would point anywhere, even nowhere. (Found as
    /// surface-error projections running off a countersink in the `cube_with_cutouts` scene.)
    #[test]
    fn cone_gradient_is_the_side_normal_right_at_the_side() {
        let (r, h) = (0.3f32, 0.3f32);
        let cone = compile("cone(0.3, 0.3)").unwrap();
        let moved = compile("translate(rotate(cone(0.3, 0.3), 0, 1, 0, 90), -0.65, 0.1, -0.25)").unwrap();
        let normal = Vec3::new(h, 0.0, r).normalize();
        let mut rng = Rng::new(43);
        let (mut worst, mut worst_local) = (0.0f32, 0.0f32);
        for i in 0..4000 {
            // A point on the side (away from the rim and the apex), nudged by up to 1e-6 along the normal.
            let along = rng.range(0.05, 0.95);
            let angle = rng.range(0.0, std::f32::consts::TAU);
            let (u, v) = (r * (1.0 - along), h * along);
            let nudge = rng.range(-1e-6, 1e-6) * (i % 2) as f32;
            let local = Vec3::new(u * angle.cos(), u * angle.sin(), v) + nudge * normal.rotate_z(angle);
            let expected = normal.rotate_z(angle);
            let (_, g) = cone.eval_grad(local);
            worst_local = worst_local.max((g - expected).length());
            // The same point on the rotated and moved cone: axis z becomes x.
            let world = Vec3::new(local.z, local.y, -local.x) + Vec3::new(-0.65, 0.1, -0.25);
            let (_, g) = moved.eval_grad(world);
            let expected = Vec3::new(expected.z, expected.y, -expected.x);
            worst = worst.max((g - expected).length());
        }
        assert!(
            worst_local < 1e-3 && worst < 1e-3,
            "gradient off the side normal by {worst_local}, {worst} moved"
        );
    }

    #[test]
    fn translate_shifts_and_scale_keeps_distances() {
        let mut rng = Rng::new(41);
        let base = compile("torus(0.6, 0.2)").unwrap();
        let moved = compile("translate(torus(0.6, 0.2), 0.25, -0.5, 1)").unwrap();
        let big = compile("scale(torus(0.6, 0.2), 2)").unwrap();
        let d = Vec3::new(0.25, -0.5, 1.0);
        for _ in 0..100 {
            let p = rng.vec3(-1.5, 1.5);
            assert!(close(moved.eval(p + d), base.eval(p)));
            assert!(close(big.eval(p * 2.0), 2.0 * base.eval(p)), "a scaled distance is still a distance");
        }
    }

    #[test]
    fn rotate_by_right_angles_maps_axes_onto_axes() {
        // A rod along x, rotated 90° about z, lies along y (right-hand rule).
        let rod = "box(1, 0.1, 0.1)";
        let turned = compile(&format!("rotate({rod}, 0, 0, 1, 90)")).unwrap();
        assert!(turned.eval(Vec3::new(0.0, 0.9, 0.0)) < 0.0);
        assert!(turned.eval(Vec3::new(0.9, 0.0, 0.0)) > 0.0);
        assert_eq!(turned.eval(Vec3::new(0.0, 1.5, 0.0)), 0.5, "exact, no 1e-8 wobble");
        // About x, y goes to z; about y, z goes to x.
        let p = compile("rotate(translate(sphere(0.1), 0, 1, 0), 1, 0, 0, 90)").unwrap();
        assert_eq!(p.eval(Vec3::new(0.0, 0.0, 1.0)), -0.1);
        let p = compile("rotate(translate(sphere(0.1), 0, 0, 1), 0, 2, 0, 90)").unwrap();
        assert_eq!(p.eval(Vec3::new(1.0, 0.0, 0.0)), -0.1);
        // Right-angle rotations need no more instructions than a relabelling of axes.
        let plain = compile(rod).unwrap().instruction_count();
        assert!(turned.instruction_count() <= plain, "{turned}");
        let r = rotation_matrix([1.0, 1.0, 1.0], 120.0).unwrap();
        let x_to = [r[0][0], r[1][0], r[2][0]];
        assert!((x_to[1] - 1.0).abs() < 1e-12, "120° about the diagonal cycles x to y: {x_to:?}");
        assert!(rotation_matrix([0.0; 3], 10.0).is_none());
    }

    #[test]
    fn rotation_with_varying_parameters_matches_the_constant_path() {
        // The same angle, once as a constant and once through an expression the folder cannot see
        // through (x * 0 is not folded): the general tape formula must agree with the matrix.
        let fixed = compile("rotate(box(0.5, 0.2, 0.1), 1, 2, 3, 35)").unwrap();
        let varying = compile("rotate(box(0.5, 0.2, 0.1), 1 + x * 0, 2, 3, 35 + y * 0)").unwrap();
        assert!(varying.instruction_count() > fixed.instruction_count());
        let mut rng = Rng::new(42);
        for _ in 0..100 {
            let p = rng.vec3(-1.0, 1.0);
            assert!((fixed.eval(p) - varying.eval(p)).abs() < 1e-5, "at {p}");
        }
    }

    #[test]
    fn mirrors_and_booleans() {
        let m = compile("mirror_x(translate(sphere(0.2), 0.5, 0, 0))").unwrap();
        assert_eq!(m.eval(Vec3::new(-0.5, 0.0, 0.0)), -0.2);
        assert_eq!(m.eval(Vec3::new(0.5, 0.0, 0.0)), -0.2);
        let m = compile("mirror_z(translate(sphere(0.2), 0, 0, 0.5))").unwrap();
        assert_eq!(m.eval(Vec3::new(0.0, 0.0, -0.5)), -0.2);
        assert!(close(at("subtract(sphere(1), sphere(0.5))", [0.0, 0.0, 0.0]), 0.5));
        assert!(close(at("intersect(sphere(1), box(0.2, 2, 2))", [0.0, 0.0, 0.0]), -0.2));
        assert!(close(at("shell(sphere(1), 0.1)", [0.0, 0.0, 0.0]), 0.9));
        assert!(close(at("offset(sphere(1), 0.25)", [2.0, 0.0, 0.0]), 0.75));
        // Smooth blends equal the sharp ones away from the seam, and dip below them on it.
        let s = compile("smooth_union(sphere(0.5), translate(sphere(0.5), 0.8, 0, 0), 0.2)").unwrap();
        let h = compile("union(sphere(0.5), translate(sphere(0.5), 0.8, 0, 0))").unwrap();
        assert_eq!(s.eval(Vec3::new(-0.3, 0.0, 0.0)), h.eval(Vec3::new(-0.3, 0.0, 0.0)));
        let seam = Vec3::new(0.4, 0.3, 0.0);
        assert!(s.eval(seam) < h.eval(seam) - 0.01);
        let si = compile("smooth_intersect(sphere(0.5), translate(sphere(0.5), 0.8, 0, 0), 0.2)").unwrap();
        let hi = compile("intersect(sphere(0.5), translate(sphere(0.5), 0.8, 0, 0))").unwrap();
        assert!(si.eval(Vec3::new(0.4, 0.0, 0.0)) > hi.eval(Vec3::new(0.4, 0.0, 0.0)));
        let ss = compile("smooth_subtract(sphere(0.5), translate(sphere(0.5), 0.8, 0, 0), 0.2)").unwrap();
        assert_eq!(
            ss.eval(Vec3::new(-0.45, 0.0, 0.0)),
            at("subtract(sphere(0.5), translate(sphere(0.5), 0.8, 0, 0))", [-0.45, 0.0, 0.0])
        );
    }
}

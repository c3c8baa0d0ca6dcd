//! Shared test helpers: a seeded PRNG (no dependency) and one program per primitive, operator
//! and function, so every property test covers the whole vocabulary.

use glam::Vec3;

/// SplitMix64: tiny, seedable, good enough to scatter test points.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        let unit = (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        lo + (hi - lo) * unit
    }

    pub fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Every shape, combinator, transform and math function at least once, with parameters that keep
/// interesting features inside the cube [-1.5, 1.5]^3.
pub const CASES: &[&str] = &[
    "sphere(0.8)",
    "box(0.5, 0.4, 0.3)",
    "rounded_box(0.5, 0.4, 0.3, 0.1)",
    "cylinder(0.4, 0.6)",
    "cone(0.5, 0.8)",
    "torus(0.6, 0.2)",
    "capsule(-0.3, 0, 0.1, 0.3, 0.2, -0.1, 0.2)",
    "plane(1, 2, 3, 0.1)",
    "union(sphere(0.5), box(0.3, 0.3, 0.6), cylinder(0.2, 1))",
    "intersect(sphere(0.7), box(0.5, 0.5, 0.5))",
    "subtract(box(0.6, 0.6, 0.6), sphere(0.75))",
    "smooth_union(sphere(0.5), translate(sphere(0.4), 0.5, 0, 0), 0.2)",
    "smooth_intersect(sphere(0.7), box(0.5, 0.5, 0.5), 0.15)",
    "smooth_subtract(box(0.6, 0.6, 0.6), sphere(0.7), 0.1)",
    "shell(sphere(0.6), 0.1)",
    "offset(box(0.4, 0.3, 0.2), 0.1)",
    "translate(box(0.3, 0.2, 0.1), 0.2, -0.1, 0.3)",
    "rotate(box(0.5, 0.2, 0.1), 1, 1, 0, 30)",
    "rotate(cylinder(0.2, 0.7), 0, 1, 0, 90)",
    "rotate(box(0.5, 0.2, 0.1), x, 1, 0.5, 40 + 10 * y)",
    "scale(torus(0.6, 0.2), 1.5)",
    "mirror_x(translate(sphere(0.3), 0.4, 0, 0))",
    "mirror_y(translate(box(0.2, 0.2, 0.2), 0, 0.5, 0.1))",
    "mirror_z(translate(cone(0.3, 0.4), 0, 0, 0.2))",
    "sin(3 * x) * cos(2 * y) + tan(0.5 * z)",
    "asin(0.5 * x) + acos(0.4 * y) + atan(2 * z)",
    "atan2(y, x) + atan2(z - 2, x)",
    "exp(x) + log(y * y + 0.5)",
    "sqrt(x * x + 1) + abs(y) + floor(3 * z)",
    "pow(x * x + 0.5, y) + pow(abs(z) + 0.1, 1.5)",
    "x^3 - 2^y + z^-2",
    "-x^2 + (y - z) / (x * x + 0.5)",
    "clamp(x, -0.2, 0.3) + mix(y, z, 0.3)",
    "length(x, y) + length(z) + length(x, y, z, 1)",
    "min(x, y, z) + max(x, 2 * y, z)",
    "r = 0.4; s = translate(sphere(r), 0.3, 0, 0); union(s, rotate(s, 0, 0, 1, 120), rotate(s, 0, 0, 1, 240))",
];

/// Central difference of `f` at `p` with step `h`.
pub fn central_difference(f: impl Fn(Vec3) -> f32, p: Vec3, h: f32) -> Vec3 {
    Vec3::new(
        f(p + Vec3::X * h) - f(p - Vec3::X * h),
        f(p + Vec3::Y * h) - f(p - Vec3::Y * h),
        f(p + Vec3::Z * h) - f(p - Vec3::Z * h),
    ) / (2.0 * h)
}

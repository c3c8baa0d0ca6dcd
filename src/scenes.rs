//! Named test objects shared by the CLI, tests, benches and the demo. Each is an exact signed
//! distance (or a well-behaved implicit function) with an analytic gradient.

use crate::error::Error;
use crate::field::Field;
use glam::Vec3;

/// A named field with the bounds it should be meshed in.
pub struct Scene {
    pub name: &'static str,
    pub min: Vec3,
    pub max: Vec3,
    pub field: Box<dyn Field + Send + Sync>,
    /// Euler characteristic of the true surface, where it is known analytically.
    pub euler: Option<i64>,
}

pub const SCENE_NAMES: [&str; 5] = ["sphere", "torus", "gyroid", "cube_minus_sphere", "two_spheres_touching"];

/// Looks up a scene by name.
pub fn scene(name: &str) -> Result<Scene, Error> {
    let cube = (Vec3::splat(-1.0), Vec3::splat(1.0));
    let (field, euler): (Box<dyn Field + Send + Sync>, Option<i64>) = match name {
        "sphere" => (Box::new(Sphere { center: Vec3::ZERO, radius: 0.8 }), Some(2)),
        "torus" => (Box::new(Torus { major: 0.6, minor: 0.25 }), Some(0)),
        "gyroid" => {
            (Box::new(ClippedGyroid { frequency: 2.0 * std::f32::consts::PI / 1.2, radius: 0.9 }), None)
        }
        "cube_minus_sphere" => (Box::new(CubeMinusSphere { half: 0.6, radius: 0.75 }), Some(-8)),
        "two_spheres_touching" => (
            Box::new(Union(
                Sphere { center: Vec3::new(-0.4, 0.0, 0.0), radius: 0.4 },
                Sphere { center: Vec3::new(0.4, 0.0, 0.0), radius: 0.4 },
            )),
            None,
        ),
        _ => {
            return Err(Error::UnknownName {
                kind: "scene",
                name: name.to_string(),
                known: SCENE_NAMES.iter().map(|s| s.to_string()).collect(),
            })
        }
    };
    let name = SCENE_NAMES.iter().find(|&&n| n == name).copied().unwrap_or("scene");
    Ok(Scene { name, min: cube.0, max: cube.1, field, euler })
}

pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

impl Field for Sphere {
    fn value(&self, p: Vec3) -> f32 {
        (p - self.center).length() - self.radius
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        Some((p - self.center).normalize_or(Vec3::X))
    }
}

/// Torus around the z axis.
pub struct Torus {
    pub major: f32,
    pub minor: f32,
}

impl Field for Torus {
    fn value(&self, p: Vec3) -> f32 {
        let q = glam::Vec2::new(p.truncate().length() - self.major, p.z);
        q.length() - self.minor
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let radial = p.truncate().normalize_or(glam::Vec2::X);
        let ring = (radial * self.major).extend(0.0);
        Some((p - ring).normalize_or(Vec3::Z))
    }
}

/// Gyroid sheet intersected with a ball, so the surface is closed inside the bounds.
pub struct ClippedGyroid {
    pub frequency: f32,
    pub radius: f32,
}

impl ClippedGyroid {
    fn gyroid(&self, p: Vec3) -> (f32, Vec3) {
        let q = p * self.frequency;
        let (sx, cx) = q.x.sin_cos();
        let (sy, cy) = q.y.sin_cos();
        let (sz, cz) = q.z.sin_cos();
        let v = sx * cy + sy * cz + sz * cx;
        let g = Vec3::new(cx * cy - sz * sx, -sx * sy + cy * cz, -sy * sz + cz * cx) * self.frequency;
        // Scaled so the value is roughly a distance near the surface.
        (v / self.frequency, g / self.frequency)
    }
}

impl Field for ClippedGyroid {
    fn value(&self, p: Vec3) -> f32 {
        self.gyroid(p).0.max(p.length() - self.radius)
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let (g, dg) = self.gyroid(p);
        let s = p.length() - self.radius;
        Some(if g >= s { dg } else { p.normalize_or(Vec3::X) })
    }
}

/// An axis-aligned cube with a ball carved out of its middle. The ball pokes through all six faces,
/// so the solid is a frame of genus 5 (Euler characteristic -8) with sharp edges, corners and
/// curved creases.
pub struct CubeMinusSphere {
    pub half: f32,
    pub radius: f32,
}

impl Field for CubeMinusSphere {
    fn value(&self, p: Vec3) -> f32 {
        box_distance(p, Vec3::splat(self.half)).0.max(self.radius - p.length())
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let (b, db) = box_distance(p, Vec3::splat(self.half));
        let s = self.radius - p.length();
        Some(if b >= s { db } else { -p.normalize_or(Vec3::X) })
    }
}

/// Exact signed distance to an axis-aligned box and its gradient.
pub fn box_distance(p: Vec3, half: Vec3) -> (f32, Vec3) {
    let q = p.abs() - half;
    let outside = q.max(Vec3::ZERO);
    let sign = Vec3::new(p.x.signum(), p.y.signum(), p.z.signum());
    if outside.length_squared() > 0.0 {
        (outside.length(), (outside.normalize() * sign))
    } else {
        let m = q.max_element();
        let axis = if q.x == m {
            Vec3::X
        } else if q.y == m {
            Vec3::Y
        } else {
            Vec3::Z
        };
        (m, axis * sign)
    }
}

/// Union (minimum) of two fields; the gradient is the active branch's.
pub struct Union<A, B>(pub A, pub B);

impl<A: Field, B: Field> Field for Union<A, B> {
    fn value(&self, p: Vec3) -> f32 {
        self.0.value(p).min(self.1.value(p))
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        if self.0.value(p) <= self.1.value(p) {
            self.0.gradient(p)
        } else {
            self.1.gradient(p)
        }
    }
}

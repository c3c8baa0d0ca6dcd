//! Named test objects shared by the CLI, tests, benches and the demo. Each is a program in the
//! expression language (see [`crate::expr`]), compiled on lookup, so every scene is exact signed
//! distance (or a well-behaved implicit function) with an exact gradient, and its text can be
//! shown, edited and meshed again (the demo loads [`Scene::source`] into its editor).
//!
//! Every scene is a closed surface that keeps at least two cells at resolution 32 away from its
//! bounds (tested), so meshes of it are closed too.
//!
//! The hand-written fields at the end of the file ([`Sphere`], [`Torus`], …) are the reference the
//! text versions of the first five scenes are tested against, and small fixtures for unit tests.

use crate::error::Error;
use crate::expr;
use crate::field::Field;
use glam::Vec3;

/// A named field with the bounds it should be meshed in.
pub struct Scene {
    pub name: &'static str,
    pub min: Vec3,
    pub max: Vec3,
    /// The compiled [`Scene::source`].
    pub field: Box<expr::Program>,
    /// Euler characteristic of the true surface, where it is known analytically. A mesh only has
    /// it once the grid resolves the shape: `thin_room`'s walls need far finer grids than usual.
    pub euler: Option<i64>,
    /// The program text `field` was compiled from.
    pub source: &'static str,
}

/// What a scene is before its text is compiled.
struct Entry {
    name: &'static str,
    min: [f32; 3],
    max: [f32; 3],
    euler: Option<i64>,
    source: &'static str,
}

const CUBE: ([f32; 3], [f32; 3]) = ([-1.0; 3], [1.0; 3]);

const ENTRIES: [Entry; 12] = [
    Entry { name: "sphere", min: CUBE.0, max: CUBE.1, euler: Some(2), source: SPHERE },
    Entry { name: "torus", min: CUBE.0, max: CUBE.1, euler: Some(0), source: TORUS },
    // The clipping ball reaches 0.9: ±1.05 keeps it two cells inside at resolution 32.
    Entry { name: "gyroid", min: [-1.05; 3], max: [1.05; 3], euler: None, source: GYROID },
    Entry { name: "cube_minus_sphere", min: CUBE.0, max: CUBE.1, euler: Some(-8), source: CUBE_MINUS_SPHERE },
    // One surface or two, depending on where the touching point falls in the grid.
    Entry { name: "two_spheres_touching", min: CUBE.0, max: CUBE.1, euler: None, source: TWO_SPHERES },
    Entry { name: "rotated_box", min: [-0.85; 3], max: [0.85; 3], euler: Some(2), source: ROTATED_BOX },
    Entry {
        name: "fandisk",
        min: [-0.9, -0.6, -0.55],
        max: [0.9, 0.6, 0.55],
        euler: Some(2),
        source: FANDISK,
    },
    Entry {
        name: "thin_room",
        min: [-1.0, -1.0, -0.7],
        max: [1.0, 1.0, 0.7],
        euler: Some(2),
        source: THIN_ROOM,
    },
    Entry { name: "rocket", min: [-0.7, -0.7, -1.0], max: [0.7, 0.7, 1.0], euler: Some(2), source: ROCKET },
    Entry { name: "milling", min: [-1.0, -0.8, -0.5], max: [1.0, 0.8, 0.5], euler: Some(2), source: MILLING },
    Entry { name: "cube_with_cutouts", min: CUBE.0, max: CUBE.1, euler: Some(0), source: CUBE_WITH_CUTOUTS },
    Entry { name: "gear", min: [-0.8, -0.8, -0.3], max: [0.8, 0.8, 0.3], euler: Some(-12), source: GEAR },
];

/// The scene names, in a fixed order (the first five are the original analytic scenes).
pub const SCENE_NAMES: [&str; ENTRIES.len()] = {
    let mut names = [""; ENTRIES.len()];
    let mut i = 0;
    while i < ENTRIES.len() {
        names[i] = ENTRIES[i].name;
        i += 1;
    }
    names
};

const SPHERE: &str = "\
// A ball of radius 0.8 about the origin.
sphere(0.8)
";

const TORUS: &str = "\
// A ring of radius 0.6 around the z axis; the tube's radius is 0.25.
torus(0.6, 0.25)
";

const GYROID: &str = "\
// A gyroid sheet of period 1.2, divided by its frequency so that near the surface the value is
// roughly a distance, and clipped by a ball of radius 0.9 so that the surface is closed.
pi = 3.141592653589793;
f = 2 * pi / 1.2;
gyroid = (sin(f * x) * cos(f * y) + sin(f * y) * cos(f * z) + sin(f * z) * cos(f * x)) / f;
intersect(gyroid, sphere(0.9))
";

const CUBE_MINUS_SPHERE: &str = "\
// A cube minus a ball that pokes through all six faces: a frame of genus 5 (Euler
// characteristic -8) with sharp edges, corners and curved creases.
subtract(box(0.6, 0.6, 0.6), sphere(0.75))
";

const TWO_SPHERES: &str = "\
// Two balls of radius 0.4 that touch at the origin.
union(translate(sphere(0.4), -0.4, 0, 0), translate(sphere(0.4), 0.4, 0, 0))
";

const ROTATED_BOX: &str = "\
// A box turned about two axes by angles that line none of its edges or faces up with the grid.
b = box(0.5, 0.35, 0.25);
rotate(rotate(b, 0, 0, 1, 33), 1, 2, 0.5, 31)
";

const FANDISK: &str = "\
// A fandisk-like CAD part: a block with a cylindrical top, a planar chamfer, a step down and a
// cylindrical groove across the top, meeting in sharp creases and corners.
block = box(0.7, 0.4, 0.35);
top = translate(rotate(cylinder(1.2, 1), 0, 1, 0, 90), 0, 0, -0.85); // axis x; z = 0.35 at y = 0
chamfer = plane(1, 0, 1, 0.6);                                       // the sloped +x end
step = translate(box(0.3, 0.5, 0.25), -0.6, 0, 0.35);                // lowers x < -0.3 to z = 0.1
groove = translate(rotate(cylinder(0.15, 1), 1, 0, 0, 90), 0.05, 0, 0.3); // along y
subtract(intersect(block, top, chamfer), union(step, groove))
";

const THIN_ROOM: &str = "\
// A room 1.6 wide whose walls, floor and ceiling are 0.016 thick (1/100 of the room, a quarter of
// a cell at resolution 32), with a door in the -y wall. One closed surface, inside and out.
room = shell(box(0.8, 0.8, 0.5), 0.008);
door = translate(box(0.2, 0.1, 0.325), 0, -0.8, -0.125); // z from -0.45 up to 0.2
subtract(room, door)
";

const ROCKET: &str = "\
// A rocket along z: a cylindrical body, a conical nose, and five thin fins 72 degrees apart
// (none of them lined up with the grid), their leading edges swept back.
body = translate(cylinder(0.16, 0.5), 0, 0, -0.15);             // z from -0.65 to 0.35
nose = translate(cone(0.16, 0.45), 0, 0, 0.35);                 // apex at z = 0.8
fin = intersect(translate(box(0.2, 0.035, 0.17), 0.3, 0, -0.55), // x 0.1 to 0.5, z -0.72 to -0.38
                plane(0.6, 0, 1, -0.2435));                      // from (0.16, -0.38) sloping down
union(body, nose,
      rotate(fin, 0, 0, 1, 10), rotate(fin, 0, 0, 1, 82), rotate(fin, 0, 0, 1, 154),
      rotate(fin, 0, 0, 1, 226), rotate(fin, 0, 0, 1, 298))
";

const MILLING: &str = "\
// A block milled by a ball-end tool of radius 0.15 whose centre follows a polyline in the plane
// of the top face. The swept envelope of the ball is the union of one capsule per segment (the
// tool's shank stays above the block).
r = 0.15;
h = 0.3;
block = box(0.8, 0.6, h);
path = union(capsule(-0.6, -0.35, h, 0.5, -0.35, h, r),
             capsule(0.5, -0.35, h, 0.55, 0.05, h, r),
             capsule(0.55, 0.05, h, -0.1, 0.1, h, r),
             capsule(-0.1, 0.1, h, -0.55, 0.35, h, r));
subtract(block, path)
";

const CUBE_WITH_CUTOUTS: &str = "\
// A cube with shapes cut out by CSG: a round hole through it (so the solid has genus 1), a ball
// taken off one corner, a slot across the top face and a conical countersink in the -x face.
cube = box(0.6, 0.6, 0.6);
hole = rotate(cylinder(0.18, 1), 1, 0, 0, 90);                   // along y
corner = translate(sphere(0.4), 0.6, 0.6, 0.6);
slot = translate(box(0.7, 0.1, 0.15), 0, -0.25, 0.6);            // along x, 0.15 deep
sink = translate(rotate(cone(0.3, 0.3), 0, 1, 0, 90), -0.65, 0.1, -0.25); // apex towards +x
subtract(cube, union(hole, corner, slot, sink))
";

const GEAR: &str = "\
// A spur gear of 50 primitives: a disc with 40 teeth, a raised hub, a bore with a keyway and six
// lightening holes. Genus 7 (the bore and the holes): Euler characteristic -12.
disc = cylinder(0.6, 0.12);
tooth = translate(box(0.07, 0.024, 0.12), 0.62, 0, 0);
hub = cylinder(0.24, 0.2);
bore = cylinder(0.1, 1);
key = translate(box(0.03, 0.025, 1), 0.11, 0, 0);
hole = translate(cylinder(0.08, 1), 0.4, 0, 0);
teeth = union(
  rotate(tooth, 0, 0, 1, 0), rotate(tooth, 0, 0, 1, 9), rotate(tooth, 0, 0, 1, 18), rotate(tooth, 0, 0, 1, 27), rotate(tooth, 0, 0, 1, 36),
  rotate(tooth, 0, 0, 1, 45), rotate(tooth, 0, 0, 1, 54), rotate(tooth, 0, 0, 1, 63), rotate(tooth, 0, 0, 1, 72), rotate(tooth, 0, 0, 1, 81),
  rotate(tooth, 0, 0, 1, 90), rotate(tooth, 0, 0, 1, 99), rotate(tooth, 0, 0, 1, 108), rotate(tooth, 0, 0, 1, 117), rotate(tooth, 0, 0, 1, 126),
  rotate(tooth, 0, 0, 1, 135), rotate(tooth, 0, 0, 1, 144), rotate(tooth, 0, 0, 1, 153), rotate(tooth, 0, 0, 1, 162), rotate(tooth, 0, 0, 1, 171),
  rotate(tooth, 0, 0, 1, 180), rotate(tooth, 0, 0, 1, 189), rotate(tooth, 0, 0, 1, 198), rotate(tooth, 0, 0, 1, 207), rotate(tooth, 0, 0, 1, 216),
  rotate(tooth, 0, 0, 1, 225), rotate(tooth, 0, 0, 1, 234), rotate(tooth, 0, 0, 1, 243), rotate(tooth, 0, 0, 1, 252), rotate(tooth, 0, 0, 1, 261),
  rotate(tooth, 0, 0, 1, 270), rotate(tooth, 0, 0, 1, 279), rotate(tooth, 0, 0, 1, 288), rotate(tooth, 0, 0, 1, 297), rotate(tooth, 0, 0, 1, 306),
  rotate(tooth, 0, 0, 1, 315), rotate(tooth, 0, 0, 1, 324), rotate(tooth, 0, 0, 1, 333), rotate(tooth, 0, 0, 1, 342), rotate(tooth, 0, 0, 1, 351));
subtract(union(disc, hub, teeth), union(bore, key, rotate(hole, 0, 0, 1, 0), rotate(hole, 0, 0, 1, 60), rotate(hole, 0, 0, 1, 120), rotate(hole, 0, 0, 1, 180), rotate(hole, 0, 0, 1, 240), rotate(hole, 0, 0, 1, 300)))
";

fn entry(name: &str) -> Result<&'static Entry, Error> {
    ENTRIES.iter().find(|e| e.name == name).ok_or_else(|| Error::UnknownName {
        kind: "scene",
        name: name.to_string(),
        known: SCENE_NAMES.iter().map(|s| s.to_string()).collect(),
    })
}

/// Looks up a scene by name and compiles its program.
pub fn scene(name: &str) -> Result<Scene, Error> {
    let e = entry(name)?;
    let program = expr::compile(e.source)?;
    Ok(Scene {
        name: e.name,
        min: Vec3::from(e.min),
        max: Vec3::from(e.max),
        field: Box::new(program),
        euler: e.euler,
        source: e.source,
    })
}

/// A scene's program text, without compiling it.
pub fn source(name: &str) -> Result<&'static str, Error> {
    Ok(entry(name)?.source)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The hand-written field each original scene was before it became text.
    fn reference(name: &str) -> Option<Box<dyn Field>> {
        Some(match name {
            "sphere" => Box::new(Sphere { center: Vec3::ZERO, radius: 0.8 }),
            "torus" => Box::new(Torus { major: 0.6, minor: 0.25 }),
            "gyroid" => Box::new(ClippedGyroid { frequency: 2.0 * std::f32::consts::PI / 1.2, radius: 0.9 }),
            "cube_minus_sphere" => Box::new(CubeMinusSphere { half: 0.6, radius: 0.75 }),
            "two_spheres_touching" => Box::new(Union(
                Sphere { center: Vec3::new(-0.4, 0.0, 0.0), radius: 0.4 },
                Sphere { center: Vec3::new(0.4, 0.0, 0.0), radius: 0.4 },
            )),
            _ => return None,
        })
    }

    #[test]
    fn text_scenes_match_the_hand_written_fields() {
        let mut seed = 0x1234_5678_9abc_def0u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.2 - 1.1
        };
        let mut compared = 0;
        for name in SCENE_NAMES {
            let Some(reference) = reference(name) else { continue };
            let scene = scene(name).unwrap();
            compared += 1;
            for _ in 0..2000 {
                let p = Vec3::new(next(), next(), next());
                let (a, b) = (scene.field.value(p), reference.value(p));
                assert!((a - b).abs() < 1e-5, "{name} at {p}: {a} vs {b}");
                let (ga, gb) = (scene.field.gradient(p).unwrap(), reference.gradient(p).unwrap());
                assert!((ga - gb).length() < 1e-4, "{name} at {p}: {ga} vs {gb}");
            }
        }
        assert_eq!(compared, 5);
    }

    #[test]
    fn names_sources_and_lookups_agree() {
        for (i, name) in SCENE_NAMES.iter().enumerate() {
            assert!(!SCENE_NAMES[..i].contains(name), "{name} twice");
            let s = scene(name).unwrap();
            assert_eq!(s.name, *name);
            assert_eq!(s.source, source(name).unwrap());
            assert!(s.source.starts_with("// "), "{name}: a scene says what it is");
        }
        let err = scene("spehre").err().unwrap().to_string();
        assert!(err.contains("unknown scene 'spehre'") && err.contains("cube_with_cutouts"), "{err}");
        assert!(source("nope").is_err());
    }
}

//! Reading the inputs EMC meshes besides fields: triangle meshes (to remesh, paper §5.3) and
//! oriented point clouds (to reconstruct a surface from, §5.2).
//!
//! Everything reads from bytes, never from paths, so the same code serves the CLI and the browser.
//! Formats:
//! - meshes: Wavefront OBJ (`v` and `f`; polygons fan-triangulated; negative indices), STL (binary
//!   and ASCII; identical corners are welded into shared vertices), PLY (ASCII, binary little- and
//!   big-endian; `vertex` x y z and a `face` list), OFF (and its COFF/NOFF variants);
//! - point clouds: PLY whose vertices carry `nx ny nz`, and XYZ text (`x y z nx ny nz` per line)
//!   or CGAL's PWN (the same text, optionally after a line holding the number of points).
//!
//! Malformed input is an [`Error::Io`] naming the format and the line (text) or the element and
//! byte offset (binary); an unknown format name is an [`Error::InvalidOption`]. No input makes a
//! reader panic, and counts declared in headers are never trusted for allocation: a 100-byte file
//! claiming a billion vertices fails at its end instead of asking for gigabytes.
//!
//! Polygons that repeat a vertex after welding (zero area, no orientation) are dropped, and so are
//! the degenerate triangles of a fan over such a polygon.

mod obj;
mod off;
mod ply;
mod stl;
mod xyz;

use crate::error::Error;
use crate::mesh::Mesh;
use glam::Vec3;
use std::collections::HashMap;

/// Points sampled from a surface, each with its unit outward normal: the input of surface
/// reconstruction. The tangent plane of each point is its local estimate of the surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    pub positions: Vec<Vec3>,
    /// One unit normal per point, pointing out of the solid.
    pub normals: Vec<Vec3>,
}

impl PointCloud {
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Smallest box holding every point; `(+inf, -inf)` when there are none.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    /// Checks the cloud can be meshed: as many normals as points, all finite, normals of unit length
    /// (within 1e-3; see [`PointCloud::normalized`] to fix them).
    pub fn validate(&self) -> Result<(), Error> {
        if self.positions.len() != self.normals.len() {
            return Err(Error::InvalidOption(format!(
                "point cloud has {} positions but {} normals; every point needs a normal",
                self.positions.len(),
                self.normals.len()
            )));
        }
        if self.positions.is_empty() {
            return Err(Error::InvalidOption("point cloud has no points".into()));
        }
        for (i, (p, n)) in self.positions.iter().zip(&self.normals).enumerate() {
            if !p.is_finite() || !n.is_finite() {
                return Err(Error::InvalidOption(format!("point {i} at {p} with normal {n} is not finite")));
            }
            if (n.length() - 1.0).abs() > 1e-3 {
                return Err(Error::InvalidOption(format!(
                    "point {i} has normal {n} of length {}; normals must be unit vectors",
                    n.length()
                )));
            }
        }
        Ok(())
    }

    /// The cloud with every normal scaled to unit length; fails on a zero normal.
    pub fn normalized(mut self) -> Result<PointCloud, Error> {
        for (i, n) in self.normals.iter_mut().enumerate() {
            let Some(unit) = unit_normal(*n) else {
                return Err(Error::InvalidOption(format!(
                    "point {i} has normal {n}, which has no direction"
                )));
            };
            *n = unit;
        }
        Ok(self)
    }
}

/// `n` scaled to unit length, or `None` for a zero or non-finite vector. It is divided by its
/// largest component first: `normalize` squares the components, and the square underflows for
/// normals shorter than about 1e-19 (found by the read_points fuzz target: (1e-45, -3e-23, 0)
/// came out 0.71 long) and overflows for ones longer than about 1e19 (which then had "no
/// direction"), while the direction of any finite non-zero vector is well defined.
fn unit_normal(n: Vec3) -> Option<Vec3> {
    let largest = n.abs().max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    let unit = (n / largest).normalize();
    unit.is_finite().then_some(unit)
}

/// Mesh formats [`read_mesh`] understands, by the names (file extensions) it accepts as hints.
pub const MESH_FORMATS: [&str; 4] = ["obj", "stl", "ply", "off"];
/// Point cloud formats [`read_points`] understands.
pub const POINT_FORMATS: [&str; 3] = ["ply", "xyz", "pwn"];

/// Reads a triangle mesh. `format_hint` is a format name or a file name whose extension names one
/// (`"stl"`, `".PLY"`, `"part.obj"`); without it the format is recognised from the content (PLY by
/// its magic line, binary STL by its exact size, ASCII STL by `solid`, OFF by its header, OBJ by
/// `v`/`f` lines).
///
/// The mesh has positions and triangles, no normals: triangles keep the file's winding, which for
/// every one of these formats means counter-clockwise seen from outside.
pub fn read_mesh(bytes: &[u8], format_hint: Option<&str>) -> Result<Mesh, Error> {
    let format = match format_hint {
        Some(hint) => format_name(hint, &MESH_FORMATS, "mesh")?,
        None => sniff_mesh(bytes)?,
    };
    let mesh = match format {
        "obj" => obj::read(bytes)?,
        "stl" => stl::read(bytes)?,
        "ply" => ply::read(bytes)?.into_mesh()?,
        "off" => off::read(bytes)?,
        _ => unreachable!("format_name only returns listed names"),
    };
    if mesh.triangles.is_empty() {
        return Err(Error::Io(format!(
            "{} file has no faces (of non-zero area) to mesh",
            format.to_uppercase()
        )));
    }
    Ok(mesh)
}

/// Reads an oriented point cloud: a PLY file whose vertices have `nx ny nz`, or text with
/// `x y z nx ny nz` on each line (XYZ, or CGAL's PWN, which may start with a line holding the
/// number of points; spaces, tabs or commas between; `#` starts a comment; further columns such as
/// colours are ignored). Normals are scaled to unit length. `format_hint` works as in
/// [`read_mesh`] (`"xyz"`, `"pts"` and `"txt"` all mean XYZ text, `"pwn"` PWN); without it, files
/// starting with `ply` are PLY and everything else is point text.
pub fn read_points(bytes: &[u8], format_hint: Option<&str>) -> Result<PointCloud, Error> {
    let format = match format_hint {
        Some(hint) => match format_name(hint, &["ply", "xyz", "pwn", "pts", "txt"], "point cloud")? {
            "ply" => "ply",
            "pwn" => "pwn",
            _ => "xyz",
        },
        None if bytes.starts_with(b"ply") => "ply",
        None => "xyz",
    };
    let cloud = match format {
        "ply" => ply::read(bytes)?.into_points()?,
        "pwn" => xyz::read(bytes, "PWN")?,
        _ => xyz::read(bytes, "XYZ")?,
    };
    if cloud.is_empty() {
        return Err(Error::Io(format!("{} file has no points", format.to_uppercase())));
    }
    Ok(cloud)
}

/// The format a hint names: the hint itself or the extension of a file name, any case.
fn format_name(hint: &str, known: &[&'static str], kind: &str) -> Result<&'static str, Error> {
    let extension = hint.rsplit('.').next().unwrap_or(hint).trim().to_ascii_lowercase();
    known.iter().copied().find(|&k| k == extension).ok_or_else(|| {
        Error::InvalidOption(format!("unknown {kind} format '{hint}'; known: {}", known.join(", ")))
    })
}

fn sniff_mesh(bytes: &[u8]) -> Result<&'static str, Error> {
    if bytes.starts_with(b"ply") {
        return Ok("ply");
    }
    if stl::is_binary(bytes) || bytes.starts_with(b"solid") {
        return Ok("stl");
    }
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(1 << 16)]);
    let mut first = true;
    for line in text.lines() {
        let line = strip_comment(line, '#').trim_start_matches('\u{feff}');
        let Some(token) = line.split_whitespace().next() else { continue };
        if first && off::is_header(token) {
            return Ok("off");
        }
        first = false;
        if matches!(token, "v" | "f" | "vn" | "vt" | "o" | "g" | "usemtl" | "mtllib") {
            return Ok("obj");
        }
    }
    Err(Error::Io(format!(
        "cannot tell the mesh format from the content; name one of {}",
        MESH_FORMATS.join(", ")
    )))
}

/// `line` up to the first `marker`.
fn strip_comment(line: &str, marker: char) -> &str {
    line.split(marker).next().unwrap_or("")
}

/// Parses a finite `f32`, or says why not.
fn parse_f32(token: &str) -> Result<f32, String> {
    match token.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("coordinate '{token}' is {v}; coordinates must be finite")),
        Err(_) => Err(format!("expected a number, found '{}'", shorten(token))),
    }
}

/// At most 40 characters of `token`, so garbage does not flood an error message.
fn shorten(token: &str) -> String {
    if token.chars().count() <= 40 {
        token.to_string()
    } else {
        token.chars().take(40).collect::<String>() + "..."
    }
}

/// Appends the fan `p0 p1 p2, p0 p2 p3, ...` of a polygon, leaving out triangles that repeat a vertex.
fn push_fan(polygon: &[u32], triangles: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        let t = [polygon[0], polygon[k], polygon[k + 1]];
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            triangles.push(t);
        }
    }
}

/// Merges corners with bit-identical coordinates (`-0.0` and `0.0` count as one) into shared
/// vertices: STL stores every triangle's corners separately.
#[derive(Default)]
struct Welder {
    index: HashMap<[u32; 3], u32>,
    positions: Vec<Vec3>,
}

impl Welder {
    fn vertex(&mut self, p: Vec3) -> u32 {
        // Adding 0.0 turns -0.0 into 0.0 and leaves everything else alone.
        let key = (p + Vec3::ZERO).to_array().map(f32::to_bits);
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            (self.positions.len() - 1) as u32
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hints_accept_names_extensions_and_file_names() {
        assert_eq!(format_name("OBJ", &MESH_FORMATS, "mesh").unwrap(), "obj");
        assert_eq!(format_name(".stl", &MESH_FORMATS, "mesh").unwrap(), "stl");
        assert_eq!(format_name("dir.v2/part.Ply", &MESH_FORMATS, "mesh").unwrap(), "ply");
        assert_eq!(format_name("scans/ball.PWN", &POINT_FORMATS, "point cloud").unwrap(), "pwn");
        let err = format_name("gltf", &MESH_FORMATS, "mesh").unwrap_err();
        assert!(
            matches!(&err, Error::InvalidOption(m) if m.contains("'gltf'") && m.contains("off")),
            "{err}"
        );
    }

    #[test]
    fn welding_merges_signed_zeros_and_keeps_distinct_points() {
        let mut w = Welder::default();
        let a = w.vertex(Vec3::new(0.0, 1.0, 2.0));
        let b = w.vertex(Vec3::new(-0.0, 1.0, 2.0));
        let c = w.vertex(Vec3::new(0.0, 1.0, 2.000001));
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(w.positions.len(), 2);
    }

    #[test]
    fn fans_skip_collapsed_triangles() {
        let mut t = Vec::new();
        push_fan(&[0, 1, 1, 2, 3], &mut t);
        assert_eq!(t, vec![[0, 1, 2], [0, 2, 3]]);
        push_fan(&[4, 5], &mut t);
        assert_eq!(t.len(), 2);
    }

    #[test]
    fn point_clouds_are_validated_and_normalized() {
        let cloud = PointCloud { positions: vec![Vec3::ZERO], normals: vec![Vec3::new(0.0, 2.0, 0.0)] };
        assert!(cloud.validate().is_err());
        let unit = cloud.normalized().unwrap();
        assert_eq!(unit.normals[0], Vec3::Y);
        unit.validate().unwrap();
        assert!(PointCloud { positions: vec![Vec3::ZERO], normals: vec![Vec3::ZERO] }.normalized().is_err());
        assert!(PointCloud { positions: vec![Vec3::ZERO], normals: vec![] }.validate().is_err());
        assert!(PointCloud::default().validate().is_err());
    }
}

//! Writing meshes in the formats mesh tools read: OBJ (text, easy to diff), binary STL (what
//! slicers and CAD expect), binary PLY (compact, keeps vertex sharing and normals) and binary glTF
//! (GLB, what web viewers load; see [`glb`]).
//!
//! Writers refuse inconsistent meshes (indices past the vertex list, a normal count that is neither
//! zero nor one per vertex) with [`std::io::ErrorKind::InvalidInput`] instead of writing a file
//! that some other program fails on later, far from the cause.

use crate::error::Error;
use crate::mesh::Mesh;
use std::io::{self, BufWriter, Write};
use std::path::Path;

pub mod glb;
pub use glb::write_glb;

/// An export format, named as in file extensions and in the JavaScript `exportMesh`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Obj,
    Stl,
    Ply,
    Glb,
}

impl Format {
    pub const NAMES: [&'static str; 4] = ["obj", "stl", "ply", "glb"];

    /// The format called `name` (`obj`, `stl`, `ply`, `glb`, any case).
    pub fn parse(name: &str) -> Result<Format, Error> {
        match name.to_ascii_lowercase().as_str() {
            "obj" => Ok(Format::Obj),
            "stl" => Ok(Format::Stl),
            "ply" => Ok(Format::Ply),
            "glb" => Ok(Format::Glb),
            _ => Err(Error::UnknownName {
                kind: "export format",
                name: name.to_string(),
                known: Format::NAMES.iter().map(|s| s.to_string()).collect(),
            }),
        }
    }

    /// The writer of this format.
    pub fn writer(self) -> fn(&Mesh, &mut dyn Write) -> io::Result<()> {
        match self {
            Format::Obj => write_obj,
            Format::Stl => write_stl_binary,
            Format::Ply => write_ply_binary,
            Format::Glb => write_glb,
        }
    }
}

/// The mesh encoded in `format` in memory, for the browser (a download) and for callers that
/// send the bytes elsewhere. Inconsistent meshes are refused as by the writers.
pub fn to_bytes(mesh: &Mesh, format: Format) -> Result<Vec<u8>, Error> {
    let mut bytes = Vec::new();
    format.writer()(mesh, &mut bytes)
        .map_err(|e| Error::InvalidOption(format!("cannot export the mesh: {e}")))?;
    Ok(bytes)
}

/// Wavefront OBJ: `v` lines, then `vn` lines when the mesh has normals, then `f` lines with 1-based
/// indices (`f a//a b//b c//c` with normals, `f a b c` without). Coordinates are written with the
/// shortest representation that reads back to the same `f32`, so a round trip is lossless.
pub fn write_obj(mesh: &Mesh, w: &mut dyn Write) -> io::Result<()> {
    let has_normals = check(mesh)?;
    let mut w = BufWriter::new(w);
    writeln!(w, "# isoforge: {} vertices, {} triangles", mesh.positions.len(), mesh.triangles.len())?;
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    if has_normals {
        for n in &mesh.normals {
            writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
        }
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| v as u64 + 1);
        if has_normals {
            writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
        } else {
            writeln!(w, "f {a} {b} {c}")?;
        }
    }
    w.flush()
}

/// The mesh as OBJ text (see [`write_obj`]), for the browser where there is no file to write to.
///
/// # Panics
/// When the mesh is inconsistent (see the module documentation).
pub fn to_obj_string(mesh: &Mesh) -> String {
    let mut bytes = Vec::new();
    if let Err(e) = write_obj(mesh, &mut bytes) {
        panic!("cannot write OBJ: {e}");
    }
    String::from_utf8(bytes).expect("OBJ output is ASCII")
}

/// Binary STL: an 80-byte header, the triangle count, then per triangle its unit face normal, three
/// corners and a zero attribute word, all little-endian: `84 + 50 * triangles` bytes. STL has no
/// shared vertices or vertex normals, so those are lost. Zero-area faces get a zero normal.
pub fn write_stl_binary(mesh: &Mesh, w: &mut dyn Write) -> io::Result<()> {
    check(mesh)?;
    let count = u32::try_from(mesh.triangles.len())
        .map_err(|_| invalid("binary STL holds at most 2^32 - 1 triangles"))?;
    let mut w = BufWriter::new(w);
    // The header must not start with "solid", or readers take the file for ASCII STL.
    let mut header = [b' '; 80];
    let label = b"isoforge binary STL";
    header[..label.len()].copy_from_slice(label);
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    for t in 0..mesh.triangles.len() {
        let normal = mesh.face_normal(t).normalize_or_zero();
        for v in std::iter::once(normal).chain(mesh.corners(t)) {
            for x in v.to_array() {
                w.write_all(&x.to_le_bytes())?;
            }
        }
        w.write_all(&[0, 0])?;
    }
    w.flush()
}

/// Binary little-endian PLY: `x y z` (and `nx ny nz` when the mesh has normals) as floats per
/// vertex, and each face as a `uchar` count followed by `int` indices, the layout most readers
/// (MeshLab, Blender, Open3D) expect.
pub fn write_ply_binary(mesh: &Mesh, w: &mut dyn Write) -> io::Result<()> {
    let has_normals = check(mesh)?;
    if i32::try_from(mesh.positions.len()).is_err() {
        return Err(invalid("PLY 'int' indices cannot address more than 2^31 - 1 vertices"));
    }
    let mut w = BufWriter::new(w);
    let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment isoforge\n");
    header += &format!("element vertex {}\n", mesh.positions.len());
    let names: &[&str] = if has_normals { &["x", "y", "z", "nx", "ny", "nz"] } else { &["x", "y", "z"] };
    for name in names {
        header += &format!("property float {name}\n");
    }
    header += &format!("element face {}\n", mesh.triangles.len());
    header += "property list uchar int vertex_indices\nend_header\n";
    w.write_all(header.as_bytes())?;
    for (i, p) in mesh.positions.iter().enumerate() {
        let normal = has_normals.then(|| mesh.normals[i]);
        for v in std::iter::once(*p).chain(normal) {
            for x in v.to_array() {
                w.write_all(&x.to_le_bytes())?;
            }
        }
    }
    for t in &mesh.triangles {
        w.write_all(&[3])?;
        for &v in t {
            w.write_all(&(v as i32).to_le_bytes())?;
        }
    }
    w.flush()
}

/// Writes `mesh` to `path` in the format its extension names (`.obj`, `.stl`, `.ply`, `.glb`,
/// any case).
pub fn write_by_extension(mesh: &Mesh, path: &Path) -> Result<(), Error> {
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or_default();
    let writer = Format::parse(extension)
        .map_err(|_| {
            Error::InvalidOption(format!(
                "cannot export '{}': unknown extension '{}'; use .obj, .stl, .ply or .glb",
                path.display(),
                extension.to_ascii_lowercase()
            ))
        })?
        .writer();
    let io_error = |e: io::Error| Error::Io(format!("cannot write '{}': {e}", path.display()));
    let mut file = std::fs::File::create(path).map_err(io_error)?;
    writer(mesh, &mut file).map_err(io_error)
}

/// Checks the mesh can be written; returns whether it has normals.
fn check(mesh: &Mesh) -> io::Result<bool> {
    let n = mesh.positions.len();
    if !mesh.normals.is_empty() && mesh.normals.len() != n {
        return Err(invalid(&format!(
            "mesh has {} normals for {n} vertices; expected one per vertex or none",
            mesh.normals.len()
        )));
    }
    if let Some(message) = mesh.index_error() {
        return Err(invalid(&message));
    }
    Ok(!mesh.normals.is_empty())
}

fn invalid(message: &str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures::{cube, mc_sphere, octahedron};
    use glam::Vec3;

    fn count_lines(text: &str, prefix: &str) -> usize {
        text.lines().filter(|l| l.starts_with(prefix)).count()
    }

    #[test]
    fn obj_has_one_line_per_vertex_normal_and_face_and_reads_back() {
        let (m, _) = mc_sphere(12);
        assert_eq!(m.normals.len(), m.positions.len());
        let text = to_obj_string(&m);
        assert_eq!(count_lines(&text, "v "), m.vertex_count());
        assert_eq!(count_lines(&text, "vn "), m.vertex_count());
        assert_eq!(count_lines(&text, "f "), m.triangle_count());
        // Read positions and faces back: exact round trip.
        let positions: Vec<Vec3> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                Vec3::new(c[0], c[1], c[2])
            })
            .collect();
        assert_eq!(positions, m.positions);
        let first_face = text.lines().find(|l| l.starts_with("f ")).unwrap();
        let [a, b, c] = m.triangles[0].map(|v| v + 1);
        assert_eq!(first_face, format!("f {a}//{a} {b}//{b} {c}//{c}"));
    }

    #[test]
    fn obj_without_normals_has_plain_faces() {
        let text = to_obj_string(&cube());
        assert_eq!(count_lines(&text, "vn "), 0);
        assert_eq!(count_lines(&text, "v "), 8);
        assert!(text.lines().any(|l| l == "f 1 3 4"), "{text}");
    }

    #[test]
    fn stl_size_header_and_first_normal() {
        let m = cube();
        let mut bytes = Vec::new();
        write_stl_binary(&m, &mut bytes).unwrap();
        assert_eq!(bytes.len(), 84 + 50 * m.triangle_count());
        assert!(!bytes.starts_with(b"solid"));
        assert_eq!(u32::from_le_bytes(bytes[80..84].try_into().unwrap()), 12);
        let f = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        // The first cube face is the bottom (z = 0): normal -z.
        assert_eq!([f(84), f(88), f(92)], [0.0, 0.0, -1.0]);
    }

    #[test]
    fn ply_header_and_size() {
        let (m, _) = mc_sphere(10);
        let mut bytes = Vec::new();
        write_ply_binary(&m, &mut bytes).unwrap();
        let end = b"end_header\n";
        let header_len = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        let header = std::str::from_utf8(&bytes[..header_len]).unwrap();
        assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"));
        assert!(header.contains(&format!("element vertex {}\n", m.vertex_count())));
        assert!(header.contains(&format!("element face {}\n", m.triangle_count())));
        assert!(header.contains("property float nz\n"));
        assert!(header.contains("property list uchar int vertex_indices\n"));
        let body = 24 * m.vertex_count() + 13 * m.triangle_count();
        assert_eq!(bytes.len(), header_len + body);
        // First vertex's x reads back.
        let x = f32::from_le_bytes(bytes[header_len..header_len + 4].try_into().unwrap());
        assert_eq!(x, m.positions[0].x);
    }

    #[test]
    fn ply_without_normals_stores_positions_only() {
        let m = octahedron();
        let mut bytes = Vec::new();
        write_ply_binary(&m, &mut bytes).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(!text.contains("property float nx"));
        let header_len = text.find("end_header\n").unwrap() + "end_header\n".len();
        assert_eq!(bytes.len(), header_len + 12 * 6 + 13 * 8);
    }

    #[test]
    fn inconsistent_meshes_are_refused() {
        let mut m = octahedron();
        m.normals = vec![Vec3::X; 2];
        let err = write_obj(&m, &mut Vec::new()).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("2 normals for 6 vertices"), "{err}");
        let mut m = octahedron();
        m.triangles.push([0, 1, 6]);
        let err = write_ply_binary(&m, &mut Vec::new()).unwrap_err();
        assert!(err.to_string().contains("triangle 8"), "{err}");
        assert!(write_stl_binary(&m, &mut Vec::new()).is_err());
    }

    #[test]
    fn write_by_extension_picks_the_format_and_rejects_unknown_ones() {
        let dir = std::env::temp_dir().join(format!("isoforge-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let m = cube();
        for (name, starts) in [
            ("a.obj", &b"# isoforge"[..]),
            ("b.STL", b"isoforge binary STL"),
            ("c.ply", b"ply\n"),
            ("d.glb", b"glTF"),
        ] {
            let path = dir.join(name);
            write_by_extension(&m, &path).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            assert!(bytes.starts_with(starts), "{name}");
        }
        let err = write_by_extension(&m, &dir.join("d.gltf")).unwrap_err();
        assert!(
            matches!(&err, Error::InvalidOption(msg) if msg.contains("'gltf'") && msg.contains(".glb")),
            "{err}"
        );
        assert!(matches!(write_by_extension(&m, &dir.join("noext")), Err(Error::InvalidOption(_))));
        assert!(write_by_extension(&m, &dir.join("x.obj.gz")).is_err());
        let err = write_by_extension(&m, &dir.join("missing").join("e.obj")).unwrap_err();
        assert!(matches!(err, Error::Io(_)), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn to_bytes_matches_each_writer_and_format_names_parse() {
        let (m, _) = mc_sphere(8);
        for name in Format::NAMES {
            let format = Format::parse(&name.to_uppercase()).unwrap();
            let mut direct = Vec::new();
            format.writer()(&m, &mut direct).unwrap();
            assert_eq!(to_bytes(&m, format).unwrap(), direct, "{name}");
        }
        assert_eq!(to_bytes(&m, Format::Stl).unwrap().len(), 84 + 50 * m.triangle_count());
        let err = Format::parse("gltf").unwrap_err();
        assert!(err.to_string().contains("glb"), "{err}");
        let mut bad = octahedron();
        bad.normals = vec![Vec3::X];
        let err = to_bytes(&bad, Format::Glb).unwrap_err();
        assert!(err.to_string().contains("1 normals for 6 vertices"), "{err}");
    }
}

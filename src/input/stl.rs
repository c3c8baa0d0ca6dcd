//! STL, binary and ASCII. STL lists every triangle with its own three corners; corners with
//! identical coordinates are welded so the mesh has shared vertices (and a topology). The stored
//! facet normals are ignored: the winding decides the orientation, as in every other format.
//!
//! Binary files are recognised by their exact size (`84 + 50 * count` bytes), because some
//! exporters start binary headers with `solid`, the word that marks ASCII files.

use super::{parse_f32, push_fan, shorten, Welder};
use crate::error::Error;
use crate::mesh::Mesh;
use glam::Vec3;

/// Whether `bytes` has the exact size of a binary STL with the triangle count it declares.
pub(super) fn is_binary(bytes: &[u8]) -> bool {
    declared_count(bytes).is_some_and(|count| bytes.len() as u64 == 84 + 50 * count)
}

fn declared_count(bytes: &[u8]) -> Option<u64> {
    let count: [u8; 4] = bytes.get(80..84)?.try_into().ok()?;
    Some(u32::from_le_bytes(count) as u64)
}

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    if !is_binary(bytes) && bytes.starts_with(b"solid") {
        read_ascii(bytes)
    } else {
        read_binary(bytes)
    }
}

fn read_binary(bytes: &[u8]) -> Result<Mesh, Error> {
    let Some(count) = declared_count(bytes) else {
        return Err(Error::Io(format!(
            "binary STL needs an 84-byte header, the file has {} bytes (ASCII STL starts with 'solid')",
            bytes.len()
        )));
    };
    let needed = 84 + 50 * count;
    // A count that disagrees with the length either way means the header or the file is damaged;
    // meshing the declared part would silently drop (or invent) triangles.
    if bytes.len() as u64 != needed {
        let room = (bytes.len() as u64).saturating_sub(84) / 50;
        return Err(Error::Io(format!(
            "binary STL declares {count} triangles ({needed} bytes) but the file has {} bytes (room for {room})",
            bytes.len()
        )));
    }
    let mut welder = Welder::default();
    let mut triangles = Vec::with_capacity(count as usize);
    for (t, record) in bytes[84..needed as usize].chunks_exact(50).enumerate() {
        let float = |k: usize| {
            f32::from_le_bytes([record[4 * k], record[4 * k + 1], record[4 * k + 2], record[4 * k + 3]])
        };
        // Floats 0..3 are the facet normal; 3..12 the corners.
        let corners: [Vec3; 3] =
            std::array::from_fn(|c| Vec3::new(float(3 + 3 * c), float(4 + 3 * c), float(5 + 3 * c)));
        if let Some(bad) = corners.iter().find(|p| !p.is_finite()) {
            return Err(Error::Io(format!(
                "binary STL triangle {t} (byte {}) has corner {bad}; coordinates must be finite",
                84 + 50 * t
            )));
        }
        let ids = corners.map(|p| welder.vertex(p));
        push_fan(&ids, &mut triangles);
    }
    Ok(Mesh { positions: welder.positions, normals: Vec::new(), triangles })
}

/// ASCII STL, line by line: `solid`, then per facet `facet normal`, `outer loop`, three
/// `vertex x y z` (the format has triangles only: a loop of four is a damaged file, not a quad),
/// `endloop`, `endfacet`, and finally `endsolid`.
/// Several solids in one file are read into one mesh.
fn read_ascii(bytes: &[u8]) -> Result<Mesh, Error> {
    let text = String::from_utf8_lossy(bytes);
    let mut welder = Welder::default();
    let mut triangles = Vec::new();
    let mut loop_ids: Option<Vec<u32>> = None;
    let mut in_solid = false;
    let mut last_line = 0;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        last_line = line_no;
        let fail = |msg: String| Error::Io(format!("ASCII STL line {line_no}: {msg}"));
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else { continue };
        match keyword {
            "solid" if !in_solid && loop_ids.is_none() => in_solid = true,
            "endsolid" if in_solid && loop_ids.is_none() => in_solid = false,
            "facet" | "endfacet" if in_solid && loop_ids.is_none() => {}
            "outer" if in_solid && loop_ids.is_none() => loop_ids = Some(Vec::with_capacity(3)),
            "vertex" if loop_ids.is_some() => {
                let mut c = [0.0f32; 3];
                for (a, slot) in c.iter_mut().enumerate() {
                    let token = tokens
                        .next()
                        .ok_or_else(|| fail(format!("vertex has {a} coordinates; it needs x y z")))?;
                    *slot = parse_f32(token).map_err(&fail)?;
                }
                let id = welder.vertex(Vec3::from(c));
                if let Some(ids) = loop_ids.as_mut() {
                    ids.push(id);
                }
            }
            "endloop" if loop_ids.is_some() => {
                let ids = loop_ids.take().unwrap_or_default();
                if ids.len() != 3 {
                    return Err(fail(format!("facet has {} vertices; STL facets are triangles", ids.len())));
                }
                push_fan(&ids, &mut triangles);
            }
            other => {
                let expected = match (in_solid, loop_ids.is_some()) {
                    (false, _) => "'solid'",
                    (true, false) => "'facet', 'outer loop', 'endfacet' or 'endsolid'",
                    (true, true) => "'vertex' or 'endloop'",
                };
                return Err(fail(format!("expected {expected}, found '{}'", shorten(other))));
            }
        }
    }
    if in_solid || loop_ids.is_some() {
        return Err(Error::Io(format!(
            "ASCII STL line {last_line}: the file ends inside a {}",
            if loop_ids.is_some() { "facet" } else { "solid (no 'endsolid')" }
        )));
    }
    Ok(Mesh { positions: welder.positions, normals: Vec::new(), triangles })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TETRA: &str = "solid tetra\n\
        facet normal 0 0 -1\n outer loop\n  vertex 0 0 0\n  vertex 0 1 0\n  vertex 1 0 0\n endloop\nendfacet\n\
        facet normal 0 -1 0\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 0 1\n endloop\nendfacet\n\
        facet normal -1 0 0\n outer loop\n  vertex 0 0 0\n  vertex 0 0 1\n  vertex 0 1 0\n endloop\nendfacet\n\
        facet normal 1 1 1\n outer loop\n  vertex 1 0 0\n  vertex 0 1 0\n  vertex 0 0 1\n endloop\nendfacet\n\
        endsolid tetra\n";

    #[test]
    fn ascii_corners_are_welded() {
        let m = read(TETRA.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles.len(), 4);
        assert_eq!(m.triangles[0], [0, 1, 2]);
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let broken = TETRA.replace("  vertex 0 0 1\n endloop", "  vertex 0 0\n endloop");
        let err = read(broken.as_bytes()).unwrap_err().to_string();
        assert!(err.contains("line 13:") && err.contains("2 coordinates"), "{err}");
        let err = read(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n").unwrap_err().to_string();
        assert!(err.contains("ends inside a facet"), "{err}");
        let err = read(b"solid x\nbanana\n").unwrap_err().to_string();
        assert!(err.contains("line 2:") && err.contains("'banana'"), "{err}");
    }

    #[test]
    fn binary_headers_starting_with_solid_are_still_binary() {
        let mut bytes = b"solid but binary".to_vec();
        bytes.resize(80, b' ');
        bytes.extend_from_slice(&1u32.to_le_bytes());
        for v in [[0.0f32, 0.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for x in v {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0, 0]);
        let m = read(&bytes).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        let err = read(&bytes[..100]).unwrap_err().to_string();
        assert!(err.contains("line 1:"), "a truncated 'solid' file is read as ASCII: {err}");
        let err = read_binary(&bytes[..100]).unwrap_err().to_string();
        assert!(err.contains("declares 1 triangles"), "{err}");
    }

    #[test]
    fn lying_counts_and_four_vertex_facets_are_refused() {
        let mut bytes = vec![b' '; 80];
        bytes.extend_from_slice(&1u32.to_le_bytes());
        for _ in 0..2 {
            for x in [0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
            bytes.extend_from_slice(&[0, 0]);
        }
        let err = read(&bytes).unwrap_err().to_string();
        assert!(err.contains("declares 1 triangles") && err.contains("room for 2"), "{err}");
        let quad = TETRA.replacen("  vertex 1 0 0\n endloop", "  vertex 1 0 0\n  vertex 1 1 0\n endloop", 1);
        assert_ne!(quad, TETRA);
        let err = read(quad.as_bytes()).unwrap_err().to_string();
        assert!(err.contains("facet has 4 vertices; STL facets are triangles"), "{err}");
    }
}

//! Wavefront OBJ: `v x y z` vertices and `f` polygons. Face corners may be `i`, `i/t`, `i//n` or
//! `i/t/n`; only the vertex index counts. Indices are 1-based, negative ones count back from the
//! last vertex read so far. Every other statement (`vt`, `vn`, `g`, `usemtl`, ...) is ignored.

use super::{parse_f32, push_fan, shorten, strip_comment};
use crate::error::Error;
use crate::mesh::Mesh;
use glam::Vec3;

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    let text = String::from_utf8_lossy(bytes);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles = Vec::new();
    let mut polygon = Vec::new();
    // Faces may name vertices that come later in the file; checked once all are read.
    let mut forward: Option<(usize, u64)> = None;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let fail = |msg: String| Error::Io(format!("OBJ line {line_no}: {msg}"));
        let mut tokens = strip_comment(line, '#').split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut c = [0.0f32; 3];
                for (a, slot) in c.iter_mut().enumerate() {
                    let token = tokens
                        .next()
                        .ok_or_else(|| fail(format!("vertex has {a} coordinates; 'v' needs x y z")))?;
                    *slot = parse_f32(token).map_err(&fail)?;
                }
                positions.push(Vec3::from(c));
            }
            Some("f") => {
                polygon.clear();
                for corner in tokens {
                    let index = corner.split('/').next().unwrap_or("");
                    let i: i64 = index
                        .parse()
                        .map_err(|_| fail(format!("expected a vertex index, found '{}'", shorten(corner))))?;
                    let count = positions.len() as i64;
                    let resolved = match i {
                        0 => return Err(fail("vertex index 0; OBJ indices start at 1".into())),
                        // Not `-i > count`: -i64::MIN overflows (found by the read_mesh fuzz target).
                        i if i < -count => {
                            return Err(fail(format!("relative index {i} reaches before the first vertex")))
                        }
                        i if i < 0 => count + i,
                        i => i - 1,
                    };
                    let resolved = u32::try_from(resolved)
                        .map_err(|_| fail(format!("vertex index {i} is too large")))?;
                    if resolved as i64 >= count && forward.is_none_or(|(_, m)| m < resolved as u64) {
                        forward = Some((line_no, resolved as u64));
                    }
                    polygon.push(resolved);
                }
                if polygon.len() < 3 {
                    return Err(fail(format!("face has {} vertices; faces need at least 3", polygon.len())));
                }
                push_fan(&polygon, &mut triangles);
            }
            _ => {}
        }
    }
    if let Some((line_no, index)) = forward {
        if index >= positions.len() as u64 {
            return Err(Error::Io(format!(
                "OBJ line {line_no}: vertex index {} is past the {} vertices in the file",
                index + 1,
                positions.len()
            )));
        }
    }
    Ok(Mesh { positions, normals: Vec::new(), triangles })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_negative_indices_and_ignored_statements() {
        let text = "# a square and a triangle\nmtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                    vt 0 0\nvn 0 0 1\ng square\nf 1/1/1 2/1/1 3//1 4\nv 0 0 1\nf -5 -4 -1\n";
        let m = read(text.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    }

    #[test]
    fn forward_references_are_allowed_but_out_of_range_ones_are_not() {
        let m = read(b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        let err = read(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap_err().to_string();
        assert!(err.contains("line 4") && err.contains("index 4"), "{err}");
    }

    #[test]
    fn errors_name_the_line() {
        for (text, line, what) in [
            ("v 0 0\n", 1, "2 coordinates"),
            ("v 0 0 0\nv 1 x 0\n", 2, "'x'"),
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3"),
            ("v 0 0 0\n\nf 0 1 1\n", 3, "index 0"),
            ("v 0 0 0\nf -2 1 1\n", 2, "before the first"),
            ("v nan 0 0\n", 1, "finite"),
        ] {
            let err = read(text.as_bytes()).unwrap_err();
            let msg = err.to_string();
            assert!(matches!(err, Error::Io(_)), "{msg}");
            assert!(msg.contains(&format!("line {line}:")) && msg.contains(what), "{text:?}: {msg}");
        }
    }
}

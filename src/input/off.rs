//! OFF (Object File Format, Geomview): an `OFF` line, the counts `vertices faces edges`, then one
//! vertex `x y z` per line and one face `n i0 .. i(n-1)` per line (0-based indices). Extra values
//! on a line (the colours of COFF, normals of NOFF, per-face colours) are ignored; `#` starts a
//! comment. The 4D and n-dimensional variants and binary OFF are refused.

use super::{parse_f32, push_fan, shorten, strip_comment};
use crate::error::Error;
use crate::mesh::Mesh;
use glam::Vec3;

/// Whether `token` is an OFF header keyword this reader handles (`OFF`, `COFF`, `NOFF`, `STOFF`, ...).
pub(super) fn is_header(token: &str) -> bool {
    token.strip_suffix("OFF").is_some_and(|prefix| prefix.chars().all(|c| matches!(c, 'S' | 'T' | 'C' | 'N')))
}

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(n, l)| (n + 1, strip_comment(l, '#').trim_start_matches('\u{feff}')))
        .filter(|(_, l)| !l.trim().is_empty());
    let fail = |line_no: usize, msg: String| Error::Io(format!("OFF line {line_no}: {msg}"));

    let (line_no, header) = lines.next().ok_or_else(|| Error::Io("OFF file is empty".into()))?;
    let mut tokens = header.split_whitespace();
    let keyword = tokens.next().unwrap_or("");
    if !is_header(keyword) {
        let msg = if keyword.ends_with("OFF") {
            format!("'{}' files are not supported; only 3D OFF (OFF, COFF, NOFF, STOFF) is", shorten(keyword))
        } else {
            format!("expected the 'OFF' header, found '{}'", shorten(keyword))
        };
        return Err(fail(line_no, msg));
    }
    let mut rest: Vec<&str> = tokens.collect();
    let mut counts_line = line_no;
    if rest.first() == Some(&"BINARY") {
        return Err(fail(line_no, "binary OFF is not supported".into()));
    }
    if rest.is_empty() {
        let (n, l) = lines.next().ok_or_else(|| fail(line_no, "the file ends before the counts".into()))?;
        rest = l.split_whitespace().collect();
        counts_line = n;
    }
    let count = |k: usize, what: &str| -> Result<usize, Error> {
        let token = rest.get(k).ok_or_else(|| fail(counts_line, format!("missing the {what} count")))?;
        token
            .parse()
            .map_err(|_| fail(counts_line, format!("{what} count '{}' is not a count", shorten(token))))
    };
    let (vertices, faces) = (count(0, "vertex")?, count(1, "face")?);

    let mut positions = Vec::with_capacity(vertices.min(bytes.len() / 6));
    for v in 0..vertices {
        let (n, line) = lines
            .next()
            .ok_or_else(|| Error::Io(format!("OFF file ends after {v} of its {vertices} vertices")))?;
        let mut c = [0.0f32; 3];
        let mut tokens = line.split_whitespace();
        for (a, slot) in c.iter_mut().enumerate() {
            let token = tokens
                .next()
                .ok_or_else(|| fail(n, format!("vertex has {a} coordinates; it needs x y z")))?;
            *slot = parse_f32(token).map_err(|e| fail(n, e))?;
        }
        positions.push(Vec3::from(c));
    }

    let mut triangles = Vec::new();
    let mut polygon = Vec::new();
    for f in 0..faces {
        let (n, line) =
            lines.next().ok_or_else(|| Error::Io(format!("OFF file ends after {f} of its {faces} faces")))?;
        let mut tokens = line.split_whitespace();
        let size = tokens.next().unwrap_or("");
        let size: usize = size
            .parse()
            .map_err(|_| fail(n, format!("expected the face's vertex count, found '{}'", shorten(size))))?;
        if size < 3 {
            return Err(fail(n, format!("face has {size} vertices; faces need at least 3")));
        }
        polygon.clear();
        for k in 0..size {
            let token =
                tokens.next().ok_or_else(|| fail(n, format!("face lists {k} of its {size} vertices")))?;
            let index: u32 = token
                .parse()
                .map_err(|_| fail(n, format!("expected a vertex index, found '{}'", shorten(token))))?;
            if index as usize >= positions.len() {
                return Err(fail(
                    n,
                    format!("vertex index {index} is past the {} vertices", positions.len()),
                ));
            }
            polygon.push(index);
        }
        push_fan(&polygon, &mut triangles);
    }
    if let Some((n, _)) = lines.next() {
        return Err(fail(
            n,
            format!(
                "data after the declared {vertices} vertices and {faces} faces; the counts are too small"
            ),
        ));
    }
    Ok(Mesh { positions, normals: Vec::new(), triangles })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_on_the_header_line_comments_and_colours() {
        let text = "COFF 4 2 0 # a square\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n\n1 1 0 1 1 1 1\n0 1 0 1 1 1 1\n\
                    3 0 1 2 255 0 0\n3 0 2 3\n";
        let m = read(text.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn errors_name_the_line() {
        for (text, what) in [
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6: vertex index 3"),
            ("OFF\n3 1 0\n0 0 0\n1 0\n", "line 4: vertex has 2"),
            ("OFF\n3 x 0\n", "line 2: face count 'x'"),
            ("4OFF\n", "line 1: '4OFF' files are not supported"),
            ("OFF\n3 1 0\n0 0 0\n", "after 1 of its 3 vertices"),
            ("PLY\n", "line 1: expected the 'OFF' header"),
        ] {
            let err = read(text.as_bytes()).unwrap_err().to_string();
            assert!(err.contains(what), "{text:?}: {err}");
        }
        assert!(is_header("OFF") && is_header("NOFF") && is_header("STCOFF") && !is_header("nOFF"));
    }
}

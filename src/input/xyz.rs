//! Point text, one point `x y z nx ny nz` per line: XYZ and CGAL's PWN ("points with normals",
//! which CGAL reads with its XYZ reader, so the two differ only in the name). Values are separated
//! by spaces, tabs or commas; further columns (colours, confidences) are ignored; blank lines and
//! `#` comments are skipped. The first data line may instead hold the number of points alone, as
//! CGAL writes it: it is checked against the points read, so a truncated file fails instead of
//! giving a cloud with a hole in it, and it is never used to allocate.

use super::{parse_f32, shorten, PointCloud};
use crate::error::Error;
use glam::Vec3;

/// Reads the text; `format` ("XYZ" or "PWN") names the format in errors.
pub(super) fn read(bytes: &[u8], format: &str) -> Result<PointCloud, Error> {
    let text = String::from_utf8_lossy(bytes);
    let mut cloud = PointCloud::default();
    // (line number, count) of a count line, once one has been read.
    let mut declared: Option<(usize, usize)> = None;
    let mut first = true;
    for (n, line) in text.lines().enumerate() {
        let fail = |msg: String| Error::Io(format!("{format} line {}: {msg}", n + 1));
        let line = super::strip_comment(line, '#').trim_start_matches('\u{feff}');
        let tokens: Vec<&str> =
            line.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()).collect();
        if tokens.is_empty() {
            continue;
        }
        let is_first = std::mem::replace(&mut first, false);
        if is_first && tokens.len() == 1 {
            let count = tokens[0].parse::<usize>().map_err(|_| {
                fail(format!(
                    "expected the number of points or a point x y z nx ny nz, found '{}'",
                    shorten(tokens[0])
                ))
            })?;
            declared = Some((n + 1, count));
            continue;
        }
        if tokens.len() < 6 {
            return Err(fail(format!(
                "found {} values; each point needs x y z nx ny nz (a point cloud needs normals)",
                tokens.len()
            )));
        }
        let mut v = [0.0f32; 6];
        for (slot, token) in v.iter_mut().zip(&tokens) {
            *slot = parse_f32(token).map_err(&fail)?;
        }
        let Some(normal) = super::unit_normal(Vec3::new(v[3], v[4], v[5])) else {
            return Err(fail(format!("normal ({}, {}, {}) has no direction", v[3], v[4], v[5])));
        };
        cloud.positions.push(Vec3::new(v[0], v[1], v[2]));
        cloud.normals.push(normal);
    }
    if let Some((line, count)) = declared {
        if count != cloud.len() {
            return Err(Error::Io(format!(
                "{format} line {line}: the file declares {count} points but holds {}",
                cloud.len()
            )));
        }
    }
    Ok(cloud)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separators_comments_and_extra_columns() {
        let text = "# x y z nx ny nz\n0 0 0 0 0 3\n\n1,2,3, 1,0,0, 255\n4\t5\t6\t0\t-1\t0\n";
        let cloud = read(text.as_bytes(), "XYZ").unwrap();
        assert_eq!(cloud.positions, vec![Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)]);
        assert_eq!(cloud.normals, vec![Vec3::Z, Vec3::X, -Vec3::Y]);
    }

    #[test]
    fn errors_name_the_line() {
        let err = read(b"0 0 0 0 0 1\n1 2 3\n", "XYZ").unwrap_err().to_string();
        assert!(err.contains("line 2:") && err.contains("normals"), "{err}");
        let err = read(b"0 0 0 0 0 0\n", "XYZ").unwrap_err().to_string();
        assert!(err.contains("line 1:") && err.contains("no direction"), "{err}");
        let err = read(b"\n\n0 0 zero 0 0 1\n", "XYZ").unwrap_err().to_string();
        assert!(err.contains("line 3:") && err.contains("'zero'"), "{err}");
    }

    #[test]
    fn pwn_with_and_without_the_count_line() {
        let points = "-0.5 0.1 0.2 -1 0 0\n0.5 0.1 0.2 1 0 0\n0 0.4 -0.1 0 2 0\n";
        let bare = read(points.as_bytes(), "PWN").unwrap();
        assert_eq!(bare.len(), 3);
        assert_eq!(bare.normals[2], Vec3::Y);
        let counted = read(format!("# CGAL\n3\n{points}").as_bytes(), "PWN").unwrap();
        assert_eq!(counted, bare);
    }

    #[test]
    fn malformed_pwn_names_the_line() {
        for (text, what) in [
            // A count that does not match: truncated or padded files.
            ("4\n0 0 0 0 0 1\n1 1 1 0 0 1\n", "PWN line 1: the file declares 4 points but holds 2"),
            ("\n# c\n1\n0 0 0 0 0 1\n1 1 1 0 0 1\n", "PWN line 3: the file declares 1 points but holds 2"),
            // A count is only allowed first; later it is a point missing its values.
            ("0 0 0 0 0 1\n2\n", "PWN line 2: found 1 values"),
            ("-3\n0 0 0 0 0 1\n", "PWN line 1: expected the number of points"),
            ("2.5\n", "PWN line 1: expected the number of points"),
            ("1\n0 0 0 0 0\n", "PWN line 2: found 5 values"),
            ("1\n0 0 0 nan 0 1\n", "PWN line 2: coordinate 'nan' is NaN"),
            ("1\n0 0 0 0 0 0\n", "PWN line 2: normal (0, 0, 0) has no direction"),
        ] {
            let err = read(text.as_bytes(), "PWN").unwrap_err().to_string();
            assert!(err.contains(what), "{text:?}: {err}");
        }
        // A huge declared count is checked at the end, never allocated.
        let err = read(b"18446744073709551615\n0 0 0 0 0 1\n", "PWN").unwrap_err().to_string();
        assert!(err.contains("declares 18446744073709551615 points but holds 1"), "{err}");
    }
}

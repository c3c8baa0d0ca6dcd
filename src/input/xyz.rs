//! XYZ point text: `x y z nx ny nz` per line, separated by spaces, tabs or commas. Further
//! columns (colours, confidences) are ignored; blank lines and `#` comments are skipped.

use super::{parse_f32, PointCloud};
use crate::error::Error;
use glam::Vec3;

pub(super) fn read(bytes: &[u8]) -> Result<PointCloud, Error> {
    let text = String::from_utf8_lossy(bytes);
    let mut cloud = PointCloud::default();
    for (n, line) in text.lines().enumerate() {
        let fail = |msg: String| Error::Io(format!("XYZ line {}: {msg}", n + 1));
        let line = super::strip_comment(line, '#').trim_start_matches('\u{feff}');
        let tokens: Vec<&str> =
            line.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()).collect();
        if tokens.is_empty() {
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
    Ok(cloud)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separators_comments_and_extra_columns() {
        let text = "# x y z nx ny nz\n0 0 0 0 0 3\n\n1,2,3, 1,0,0, 255\n4\t5\t6\t0\t-1\t0\n";
        let cloud = read(text.as_bytes()).unwrap();
        assert_eq!(cloud.positions, vec![Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)]);
        assert_eq!(cloud.normals, vec![Vec3::Z, Vec3::X, -Vec3::Y]);
    }

    #[test]
    fn errors_name_the_line() {
        let err = read(b"0 0 0 0 0 1\n1 2 3\n").unwrap_err().to_string();
        assert!(err.contains("line 2:") && err.contains("normals"), "{err}");
        let err = read(b"0 0 0 0 0 0\n").unwrap_err().to_string();
        assert!(err.contains("line 1:") && err.contains("no direction"), "{err}");
        let err = read(b"\n\n0 0 zero 0 0 1\n").unwrap_err().to_string();
        assert!(err.contains("line 3:") && err.contains("'zero'"), "{err}");
    }
}

//! OBJ that keeps the quads (`f a b c d`), since the point of the quad method is the quad mesh;
//! the triangle writers would lose the face structure.

use crate::error::Error;
use glam::Vec3;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// `v` lines, then one `f` line of four 1-based indices per quad. Refuses an index past the
/// vertex list rather than writing a file other programs choke on.
pub fn write_obj(positions: &[Vec3], quads: &[[u32; 4]], w: &mut dyn Write) -> io::Result<()> {
    if quads.iter().flatten().any(|&v| v as usize >= positions.len()) {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, "quad index past the vertex list"));
    }
    let mut w = BufWriter::new(w);
    writeln!(w, "# isoforge quad mesh: {} vertices, {} quads", positions.len(), quads.len())?;
    for p in positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for q in quads {
        let [a, b, c, d] = q.map(|v| v as u64 + 1);
        writeln!(w, "f {a} {b} {c} {d}")?;
    }
    w.flush()
}

/// [`write_obj`] to a file, errors naming the path.
pub fn write_obj_file(positions: &[Vec3], quads: &[[u32; 4]], path: &Path) -> Result<(), Error> {
    let io_error = |e: io::Error| Error::Io(format!("cannot write '{}': {e}", path.display()));
    let mut file = std::fs::File::create(path).map_err(io_error)?;
    write_obj(positions, quads, &mut file).map_err(io_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_round_trips_as_six_quad_lines() {
        let c = crate::quad::mesh::tests::cube();
        let mut bytes = Vec::new();
        write_obj(&c.positions, &c.quads, &mut bytes).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let faces: Vec<Vec<u32>> = text
            .lines()
            .filter_map(|l| l.strip_prefix("f "))
            .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(faces.len(), 6);
        assert_eq!(faces[0], c.quads[0].iter().map(|v| v + 1).collect::<Vec<_>>());
        assert!(write_obj(&c.positions[..4], &c.quads, &mut Vec::new()).is_err());
    }
}

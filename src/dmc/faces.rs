//! Which inside corners an ambiguous face of a dual cell joins: the field at the face's centre
//! decides.
//!
//! A face whose inside corners sit on one diagonal can be crossed by the contour either way.
//! Marching Cubes' default table always separates them, which on the grid's own lattice is one
//! consistent choice. A dual cell's corners are not a lattice: they are the QEF's vertices, drawn
//! onto the features, and a vertex stopped at its leaf's corner can sit a fifth of a cell deep in
//! the solid of a rounded edge, beside the neighbour whose solid it shares, the face between them
//! in the solid too. Separating them there cut the solid along the edge into a rod of its own that
//! joined it again at the edge's ends: a handle (seed 8503258 of `props_csg`, an offset box at 32
//! cells whose rounded edge of half a cell runs along a grid line, meshed as a torus). So the
//! function decides: a face joins its inside corners where the field is inside at the face's
//! centre, the mean of its four corners' leaf centres (on the finest level, the midpoint of the
//! grid edge the face is dual to).
//!
//! Leaf centres, not vertices: the decision depends on the octree alone, so untangling, which
//! moves vertices, never changes it, and a merge's safety test ([`super::safety`]) decides the
//! faces of its star by the same rule, so its proof covers the contour as built. Both dual cells
//! sharing a face see the same four leaves; the centre is their mean summed in an order fixed by
//! the positions alone, so both get the same point, the same decision, and the contour stays
//! crack-free.

use crate::field::Field;
use crate::tables::{face_is_ambiguous, FACES};
use glam::Vec3;

/// The bits (face `f` at bit `f`, [`FACES`]' numbering) of the ambiguous faces of a dual cell of
/// MC case `case` that join their inside corners: where the field at the face's centre is below
/// `iso`. `corner(k)` is the leaf centre of the cell's corner `k`, asked for the corners of
/// ambiguous faces only (most cells have none, and the safety test asks for every cell of a
/// star). A face whose two inside or two outside corners are one leaf (a degenerate cell of an
/// adaptive octree) keeps the default, separated.
pub fn joined_faces(case: u8, corner: impl Fn(usize) -> Vec3, field: &dyn Field, iso: f32) -> u8 {
    let mut bits = 0;
    for (f, face) in FACES.iter().enumerate() {
        if !face_is_ambiguous(case, f) {
            continue;
        }
        let [a, b, c, d] = face.map(|k| corner(k as usize));
        if a == c || b == d {
            continue;
        }
        if field.value(face_centre([a, b, c, d])) < iso {
            bits |= 1 << f;
        }
    }
    bits
}

/// The mean of a face's four corners, summed in the order of their coordinates, so that the two
/// cells sharing the face, which list its corners in the same order but may hold them as
/// different vertices of equal position, compute the same bits.
fn face_centre(mut corners: [Vec3; 4]) -> Vec3 {
    corners.sort_by(|p, q| p.x.total_cmp(&q.x).then(p.y.total_cmp(&q.y)).then(p.z.total_cmp(&q.z)));
    (corners[0] + corners[1] + corners[2] + corners[3]) * 0.25
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tables::CORNERS;

    /// A unit cube's corners, with corner 7 pulled to `seventh`.
    fn cube_with(seventh: Vec3) -> [Vec3; 8] {
        let mut corners = CORNERS.map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32));
        corners[7] = seventh;
        corners
    }

    /// Face 1 (x = 1) holds corners 1, 3, 7, 5 in its order; inside: 1 and 7, a diagonal.
    #[test]
    fn the_field_at_the_faces_centre_decides() {
        let case = (1u8 << 1) | (1 << 7);
        assert!(face_is_ambiguous(case, 1));
        let corners = cube_with(Vec3::ONE);
        let solid_at_centre = |p: Vec3| (p - Vec3::new(1.0, 0.5, 0.5)).length() - 0.1;
        let air_at_centre = |p: Vec3| 0.1 - (p - Vec3::new(1.0, 0.5, 0.5)).length();
        assert_eq!(joined_faces(case, |k| corners[k], &solid_at_centre, 0.0) & 0b10, 0b10);
        assert_eq!(joined_faces(case, |k| corners[k], &air_at_centre, 0.0) & 0b10, 0);
    }

    #[test]
    fn a_face_whose_diagonal_is_one_vertex_stays_separated() {
        let case = (1u8 << 1) | (1 << 7);
        let corners = cube_with(Vec3::new(1.0, 0.0, 0.0));
        let solid = |_: Vec3| -1.0;
        assert_eq!(joined_faces(case, |k| corners[k], &solid, 0.0) & 0b10, 0);
    }

    #[test]
    fn the_centre_does_not_depend_on_the_corners_order() {
        let corners =
            [Vec3::new(0.1, 0.7, 0.3), Vec3::new(0.9, 0.2, 0.4), Vec3::new(0.3, 0.3, 0.8), Vec3::ONE];
        let mut reversed = corners;
        reversed.reverse();
        assert_eq!(
            face_centre(corners).to_array().map(f32::to_bits),
            face_centre(reversed).to_array().map(f32::to_bits)
        );
    }
}

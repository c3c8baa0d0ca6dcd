//! The feature lines EMC hands out: the mesh edges between feature points that the flips made,
//! with their gaps bridged.
//!
//! Where a crease skims a cell (runs within a few hundredths of a cell of its face or corner), no
//! point on the crease gives that cell's fan a valid shape, and its centre is an approximate one
//! next to the crease. Edges between feature vertices alone then break the crease: the fandisk's
//! at 64 cells into 10 pieces, the rotated box's 12 edges into 2 to 5. An approximate centre
//! joined to feature vertices of two different pieces closes such a gap; only those are taken,
//! so a centre next to a line that is whole adds no side branch.
//!
//! A feature line follows its crease: an edge whose far end lies off the line of an edge centre's
//! crease (not a corner's) is not one. Where two creases bound a face a couple of cells wide (the
//! rocket's fins are 0.07 thick, the bottom of its body is a disc a few cells across), the flips
//! join feature points of both creases by edges across the face, which lie in the face and are
//! right as triangle edges, but as feature lines they drew lines across flat faces: 63 of 465
//! feature edges on the rocket at 48 cells. The test is the far end's distance from the line, not
//! the edge's angle to it: where the points of one crease zigzag (a crease in a grid plane, or
//! one a grid edge crosses twice) short edges leave the line at steep angles but stay near it.

use crate::mesh::analysis::topology::UnionFind;
use crate::mesh::Mesh;
use glam::Vec3;

/// How far (in cells) the far end of a feature edge may lie from the line of an edge centre's
/// crease: the next point of a crease curved to a radius of one cell lies half a cell off its
/// tangent, and the scenes' faces between two creases are a cell wide and more.
const OFF_LINE: f32 = 0.5;

/// Mesh edges joining two feature vertices, plus, for each approximate fan centre (a fan centre
/// that is not a feature vertex) whose feature-vertex neighbours lie on two or more pieces of
/// those lines, one edge to the nearest neighbour on each piece. Each edge once, `[low, high]`.
/// `crease` is, per vertex, the unit direction of its crease (zero for corners and for vertices
/// without one); an edge whose other end lies more than half a cell (`h`) off that line is no
/// feature edge.
pub fn feature_edges(
    mesh: &Mesh,
    fan_centre: &[bool],
    is_feature: &[bool],
    crease: &[Vec3],
    h: f32,
) -> Vec<[u32; 2]> {
    let approximate = |v: u32| fan_centre[v as usize] && !is_feature[v as usize];
    let follows = |a: u32, b: u32| {
        let across = mesh.positions[b as usize] - mesh.positions[a as usize];
        [a, b].iter().all(|&v| across.cross(crease[v as usize]).length() <= OFF_LINE * h)
    };
    // One pass over the mesh edges: those between feature vertices, and each approximate centre's
    // edges to feature vertices as `[centre, feature vertex]`.
    let (mut edges, mut bridges): (Vec<[u32; 2]>, Vec<[u32; 2]>) = (Vec::new(), Vec::new());
    for [a, b] in mesh.triangles.iter().flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]]) {
        if !follows(a, b) {
            continue;
        }
        let (fa, fb) = (is_feature[a as usize], is_feature[b as usize]);
        if fa && fb {
            edges.push([a.min(b), a.max(b)]);
        } else if fb && approximate(a) {
            bridges.push([a, b]);
        } else if fa && approximate(b) {
            bridges.push([b, a]);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    if bridges.is_empty() {
        return edges;
    }
    bridges.sort_unstable();
    bridges.dedup();
    let mut pieces = UnionFind::new(mesh.positions.len());
    for &[a, b] in &edges {
        pieces.union(a, b);
    }
    let distance = |a: u32, b: u32| mesh.positions[a as usize].distance_squared(mesh.positions[b as usize]);
    for group in bridges.chunk_by(|x, y| x[0] == y[0]) {
        let centre = group[0][0];
        // The nearest neighbour on each piece.
        let mut nearest: Vec<(u32, u32)> = group.iter().map(|&[_, f]| (pieces.find(f), f)).collect();
        nearest.sort_by(|x, y| x.0.cmp(&y.0).then(distance(centre, x.1).total_cmp(&distance(centre, y.1))));
        nearest.dedup_by_key(|x| x.0);
        if nearest.len() < 2 {
            continue;
        }
        for &(_, f) in &nearest {
            pieces.union(centre, f);
            edges.push([centre.min(f), centre.max(f)]);
        }
    }
    edges.sort_unstable();
    edges
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures;

    /// A strip of triangles along x: feature vertices 0, 1 and 3, 4 on the line y = 0, an
    /// approximate centre 2 between them, crossings 5.. above and below.
    fn strip() -> Mesh {
        let positions: Vec<[f32; 3]> =
            (0..5).map(|i| [i as f32, 0.0, 0.0]).chain((0..5).map(|i| [i as f32 + 0.5, 1.0, 0.0])).collect();
        // Upper row 5..10 over the line 0..5: triangles (i, i+1, 5+i) and (i+1, 6+i, 5+i).
        let mut triangles = Vec::new();
        for i in 0..4u32 {
            triangles.push([i, i + 1, 5 + i]);
            triangles.push([i + 1, 6 + i, 5 + i]);
        }
        fixtures::mesh(&positions, &triangles)
    }

    #[test]
    fn an_approximate_centre_between_two_pieces_bridges_them() {
        let mesh = strip();
        let mut feature = vec![false; 10];
        let mut centre = vec![false; 10];
        for v in [0, 1, 3, 4] {
            feature[v] = true;
            centre[v] = true;
        }
        centre[2] = true;
        assert_eq!(
            feature_edges(&mesh, &centre, &feature, &vec![Vec3::ZERO; mesh.positions.len()], 1.0),
            vec![[0, 1], [1, 2], [2, 3], [3, 4]]
        );
        // Without the approximate centre the line stays in two pieces.
        centre[2] = false;
        assert_eq!(
            feature_edges(&mesh, &centre, &feature, &vec![Vec3::ZERO; mesh.positions.len()], 1.0),
            vec![[0, 1], [3, 4]]
        );
    }

    #[test]
    fn an_approximate_centre_beside_a_whole_line_adds_nothing() {
        let mesh = strip();
        let feature: Vec<bool> = (0..10).map(|v| v < 5).collect();
        let mut centre = feature.clone();
        // Vertex 6 of the upper row, joined to 1 and 2 of a whole line.
        centre[6] = true;
        assert_eq!(
            feature_edges(&mesh, &centre, &feature, &vec![Vec3::ZERO; mesh.positions.len()], 1.0),
            vec![[0, 1], [1, 2], [2, 3], [3, 4]]
        );
    }

    /// Two creases along x a cell apart, every vertex on one of them: the flips' edges across the
    /// face between them are no feature lines; without crease directions they would all be.
    #[test]
    fn edges_across_a_face_between_two_creases_are_not_feature_edges() {
        let mesh = strip();
        let all = vec![true; 10];
        let along_x = vec![Vec3::X; 10];
        let rows = vec![[0, 1], [1, 2], [2, 3], [3, 4], [5, 6], [6, 7], [7, 8], [8, 9]];
        assert_eq!(feature_edges(&mesh, &all, &all, &along_x, 1.0), rows);
        assert_eq!(feature_edges(&mesh, &all, &all, &[Vec3::ZERO; 10], 1.0).len(), rows.len() + 9);
    }
}

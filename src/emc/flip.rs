//! The edge-flipping pass of EMC (§4.3): after the fans are in, flip every edge whose two opposite
//! vertices are feature points, so feature lines become explicit chains of mesh edges.
//!
//! A flip is a decision about a mesh that does not cross itself, and must keep it so: its two new
//! triangles reach from one fan centre across a cell face to the next, over triangles of both
//! cells and (where a centre sits outside its cell, or a neighbour's fan reaches in) of cells
//! around them, none of which the fans' own construction knew of. So a flip is made only when
//! neither new triangle crosses any triangle near it as the mesh stands (see
//! [`super::nearby`]); each accepted flip then leaves every pair it did not touch as it was.

use super::nearby::NearbyTriangles;
use crate::mesh::analysis::bvh::Aabb;
use crate::mesh::analysis::tri_tri::folded_within;
use crate::mesh::Mesh;
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// How close (degrees) the half-planes of two triangles across an edge may come before a flip
/// that makes them counts as folding them onto each other. A crease EMC joins opens wider than
/// this; a pair nearer is a fold (on the gear at 64 cells, two triangles in its top face, which
/// lies in a grid plane, came 1.5° apart and a later merge made them cross).
const FLIP_FOLD_DEG: f64 = 10.0;

/// One pass over all edges; returns how many were flipped. `is_feature` marks the fan centres,
/// `on_feature` those of them that lie on their feature: a flip must join two centres, at least
/// one of them on its feature (two approximate centres side by side make no feature line, and on
/// the gyroid at 72 cells such flips cut the triangles of a second sheet in the same cells).
/// A flip is also refused when the new edge
/// already exists (it would make the mesh non-manifold), when a new triangle would be degenerate, or
/// when a new triangle would face against the vertex normal (`mesh.normals`, from the field) of its
/// non-feature vertex (a fold-over), and when a new triangle would cross a triangle near it
/// (`spacing`: the grid's cell, the size of the neighbourhoods searched). Edges are visited in
/// the order of their vertex ids, so the same mesh always gets the same flips.
pub fn flip_toward_features(
    mesh: &mut Mesh,
    is_feature: &[bool],
    on_feature: &[bool],
    spacing: Vec3,
) -> usize {
    // Directed edge (from, to) → the triangle that has it. Closed manifold meshes have each edge
    // once in each direction.
    // Only triangles at a feature point can take part in a flip (both triangles of a flipped edge
    // have one), which keeps this map small: feature cells are few.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::default();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if !tri.iter().any(|&v| is_feature[v as usize]) {
            continue;
        }
        for k in 0..3 {
            directed.insert((tri[k], tri[(k + 1) % 3]), t as u32);
        }
    }
    let mut edges: Vec<(u32, u32)> = directed.keys().copied().filter(|&(a, b)| a < b).collect();
    edges.sort_unstable();
    // Each candidate edge (a, b) with its two triangles and their far corners (c, d): an edge
    // between two crossings, between two fan centres, one of them on its feature. Only edges
    // between two crossing vertices are flipped: turning an edge that already ends at a feature
    // point would join that point's two neighbours on the feature line past it. A flip only makes
    // triangles with a fan centre and no edge between two crossings, so it never changes another
    // candidate's triangles: these are the candidates throughout, and their quads hold every
    // triangle a flip can make.
    let candidates: Vec<Candidate> = edges
        .into_iter()
        .filter_map(|(a, b)| {
            let (&t1, &t2) = (directed.get(&(a, b))?, directed.get(&(b, a))?);
            let c = opposite(mesh.triangles[t1 as usize], a, b);
            let d = opposite(mesh.triangles[t2 as usize], b, a);
            let joins_centres = c != d && is_feature[c as usize] && is_feature[d as usize];
            let flippable = joins_centres
                && (on_feature[c as usize] || on_feature[d as usize])
                && !is_feature[a as usize]
                && !is_feature[b as usize];
            flippable.then_some(Candidate { a, b, t1, t2, c, d })
        })
        .collect();
    let region: Vec<Aabb> = candidates
        .iter()
        .map(|q| Aabb::of_points(&[q.a, q.b, q.c, q.d].map(|v| mesh.positions[v as usize])))
        .collect();
    // Built on the first flip that gets as far as the crossing test.
    let mut nearby: Option<NearbyTriangles> = None;
    let mut flips = 0;
    for Candidate { a, b, t1, t2, c, d } in candidates {
        if directed.contains_key(&(c, d)) || directed.contains_key(&(d, c)) {
            continue;
        }
        // Fold-over test against the field, not the old triangles: the two old triangles straddle
        // the crease and their normals are a poor reference. Each new triangle lies on one side of
        // the crease, the side of its one non-feature vertex, and must face the way the field's
        // normal at that vertex does.
        let p = |v: u32| mesh.positions[v as usize];
        let new1 = normal(p(c), p(a), p(d));
        let new2 = normal(p(d), p(b), p(c));
        if new1 == Vec3::ZERO || new2 == Vec3::ZERO {
            continue;
        }
        if new1.dot(mesh.normals[a as usize]) <= 0.0 || new2.dot(mesh.normals[b as usize]) <= 0.0 {
            continue;
        }
        // Where the non-feature vertices lie on the crease themselves (a rim in a grid plane),
        // their normals are perpendicular to a flat face's triangles and the test above cannot
        // see those turn over: refuse a flip whose new triangles fold onto each other or onto a
        // neighbour.
        let d64 = |v: u32| p(v).as_dvec3();
        let folds_onto_neighbour = |u: u32, v: u32, w: u32| {
            directed.get(&(v, u)).is_some_and(|&n| {
                let x = opposite(mesh.triangles[n as usize], u, v);
                folded_within(d64(v) - d64(u), d64(w) - d64(u), d64(x) - d64(u), FLIP_FOLD_DEG)
            })
        };
        if folded_within(d64(d) - d64(c), d64(a) - d64(c), d64(b) - d64(c), FLIP_FOLD_DEG)
            || [(c, a, d), (a, d, c), (d, b, c), (b, c, d)]
                .iter()
                .any(|&(u, v, w)| folds_onto_neighbour(u, v, w))
        {
            continue;
        }
        let (tri1, tri2) = ([c, a, d], [d, b, c]);
        let buckets = nearby.get_or_insert_with(|| NearbyTriangles::around(mesh, spacing, &region));
        if buckets.any_crosses(mesh, &[(tri1, tri1.map(p)), (tri2, tri2.map(p))], &[t1, t2]) {
            continue;
        }
        mesh.triangles[t1 as usize] = tri1;
        mesh.triangles[t2 as usize] = tri2;
        for t in [t1, t2] {
            buckets.insert(t, &mesh.corners(t as usize));
        }
        directed.remove(&(a, b));
        directed.remove(&(b, a));
        for (edge, t) in [((c, a), t1), ((a, d), t1), ((d, c), t1), ((d, b), t2), ((b, c), t2), ((c, d), t2)]
        {
            directed.insert(edge, t);
        }
        flips += 1;
    }
    flips
}

/// An edge (a, b) between two crossings, its triangles t1 (holding a → b) and t2, and their
/// far corners c and d, both fan centres.
struct Candidate {
    a: u32,
    b: u32,
    t1: u32,
    t2: u32,
    c: u32,
    d: u32,
}

fn opposite(tri: [u32; 3], a: u32, b: u32) -> u32 {
    tri.into_iter().find(|&v| v != a && v != b).expect("triangle holds the edge")
}

fn normal(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    (b - a).cross(c - a).normalize_or_zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flips_the_diagonal_between_two_feature_points_once() {
        // A square a=0 (0,0) b=1 (1,1) split along a-b; c=2 (1,0) and d=3 (0,1) are feature points.
        let mut mesh = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            triangles: vec![[0, 2, 1], [0, 1, 3]],
        };
        let feature = [false, false, true, true];
        assert_eq!(flip_toward_features(&mut mesh, &feature, &feature, Vec3::ONE), 1);
        let has_cd = mesh.triangles.iter().any(|t| t.contains(&2) && t.contains(&3));
        assert!(has_cd);
        for t in 0..2 {
            assert!(mesh.face_normal(t).z > 0.0, "orientation kept");
        }
        assert_eq!(flip_toward_features(&mut mesh, &feature, &feature, Vec3::ONE), 0, "nothing left to flip");
    }

    #[test]
    fn refuses_a_flip_that_would_face_against_the_field() {
        let mut mesh = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![-Vec3::Z; 4],
            triangles: vec![[0, 2, 1], [0, 1, 3]],
        };
        assert_eq!(
            flip_toward_features(
                &mut mesh,
                &[false, false, true, true],
                &[false, false, true, true],
                Vec3::ONE
            ),
            0
        );
    }
}

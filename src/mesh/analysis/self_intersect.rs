//! Does the surface cross itself? Candidate pairs come from a [`Bvh`] over the triangles' boxes;
//! each candidate is decided in `f64` by [`super::tri_tri`].
//!
//! Which pairs are tested depends on how many vertex indices they share:
//! - none: any common point (touching included) is an intersection;
//! - exactly one: an intersection when they overlap beyond that vertex (a fold, a fan wound twice,
//!   a spike through a neighbour), see [`overlap_beyond_shared_vertex`];
//! - two or three: never (neighbours across an edge, or duplicates, are the topology's business).
//!
//! Neighbours across an edge that lie on top of each other are counted apart, by [`folded_pairs`]:
//! a fold is the surface overlapping itself without crossing. DMC's pleats (a triangle turned over
//! among flat neighbours) are folds; so are Marching Cubes' zero-thickness sheets where samples
//! equal the iso-level and two cells' triangles lie in their shared face, which is why folds are not
//! self-intersections here.
//!
//! Vertices are identified by index, so an unwelded mesh (one copy of a vertex per triangle) reports
//! every pair of neighbours as touching: weld it first. Collapsed triangles (repeated index) are
//! skipped; zero-area triangles with distinct indices are tested as the segments they are.

use super::bvh::{Aabb, Bvh};
use super::tri_tri::{folded_across_edge, overlap_beyond_shared_vertex, triangles_intersect};
use crate::mesh::Mesh;
use glam::DVec3;

/// Number of intersecting triangle pairs, by the rules of this module: pairs sharing no vertex that
/// touch or cross, plus pairs sharing one vertex that overlap beyond it.
pub fn self_intersections(mesh: &Mesh) -> usize {
    self_intersecting_pairs(mesh).len()
}

/// The intersecting pairs `[i, j]` (triangle indices, `i < j`), sorted: for highlighting them.
pub fn self_intersecting_pairs(mesh: &Mesh) -> Vec<[u32; 2]> {
    let (ids, boxes) = candidates(mesh);
    let intersect =
        |i: u32, j: u32| triangle_pair_intersects(mesh, ids[i as usize] as usize, ids[j as usize] as usize);
    let mut pairs: Vec<[u32; 2]> = Bvh::build(&boxes)
        .overlapping_pairs_par(&boxes, intersect)
        .into_iter()
        .map(|(i, j)| {
            let (s, t) = (ids[i as usize], ids[j as usize]);
            [s.min(t), s.max(t)]
        })
        .collect();
    pairs.sort_unstable();
    pairs
}

/// The triangles that are not collapsed (no repeated index), and their boxes.
fn candidates(mesh: &Mesh) -> (Vec<u32>, Vec<Aabb>) {
    let ids: Vec<u32> = (0..mesh.triangles.len() as u32)
        .filter(|&t| {
            let [a, b, c] = mesh.triangles[t as usize];
            a != b && b != c && a != c
        })
        .collect();
    let boxes = ids.iter().map(|&t| Aabb::of_points(&mesh.corners(t as usize))).collect();
    (ids, boxes)
}

/// [`self_intersecting_pairs`] with a [`checkpoint`](crate::progress::checkpoint) every few
/// thousand box pairs: on the page it runs after every mesh, and a newer request must be able to
/// stop it within milliseconds, not wait for it.
pub fn self_intersecting_pairs_cancellable(mesh: &Mesh) -> Result<Vec<[u32; 2]>, crate::Error> {
    self_intersecting_pairs_within(mesh, "analysis", 0.0)
}

/// [`self_intersecting_pairs_cancellable`] as a step of another phase, whose checkpoints report
/// `phase` at `fraction` done.
pub fn self_intersecting_pairs_within(
    mesh: &Mesh,
    phase: &'static str,
    fraction: f32,
) -> Result<Vec<[u32; 2]>, crate::Error> {
    pairs_until(mesh, || crate::progress::checkpoint(phase, fraction))
}

fn pairs_until<E>(mesh: &Mesh, tick: impl FnMut() -> Result<(), E>) -> Result<Vec<[u32; 2]>, E> {
    let (ids, boxes) = candidates(mesh);
    let bvh = Bvh::build(&boxes);
    let mut pairs = Vec::new();
    bvh.overlapping_pairs_until(
        &boxes,
        |i, j| {
            let (s, t) = (ids[i as usize], ids[j as usize]);
            if triangle_pair_intersects(mesh, s as usize, t as usize) {
                pairs.push([s.min(t), s.max(t)]);
            }
        },
        tick,
    )?;
    pairs.sort_unstable();
    Ok(pairs)
}

/// Whether triangles `s` and `t` of `mesh` intersect, by the rules of this module.
pub fn triangle_pair_intersects(mesh: &Mesh, s: usize, t: usize) -> bool {
    let corners = |t: usize| mesh.corners(t).map(|p| p.as_dvec3());
    indexed_pair_intersects((mesh.triangles[s], corners(s)), (mesh.triangles[t], corners(t)))
}

/// [`triangle_pair_intersects`] for two triangles given by their vertex ids and corners, so that a
/// mesher can ask it of triangles it has not written yet.
pub fn indexed_pair_intersects(s: ([u32; 3], [DVec3; 3]), t: ([u32; 3], [DVec3; 3])) -> bool {
    let ((ts, a), (tt, b)) = (s, t);
    let mut shared = None;
    let mut count = 0;
    for (i, v) in ts.iter().enumerate() {
        if let Some(j) = tt.iter().position(|w| w == v) {
            shared = Some((i, j));
            count += 1;
        }
    }
    match (count, shared) {
        (0, _) => triangles_intersect(&a, &b),
        (1, Some((i, j))) => {
            let rest = |c: [DVec3; 3], k: usize| [c[(k + 1) % 3] - c[k], c[(k + 2) % 3] - c[k]];
            overlap_beyond_shared_vertex(&rest(a, i), &rest(b, j))
        }
        _ => false,
    }
}

/// Pairs `[i, j]` (`i < j`, sorted) of triangles sharing an edge that fold onto each other (see
/// [`folded_across_edge`]). Collapsed triangles are skipped.
pub fn folded_pairs(mesh: &Mesh) -> Vec<[u32; 2]> {
    let mut by_edge: rustc_hash::FxHashMap<(u32, u32), u32> = rustc_hash::FxHashMap::default();
    let mut pairs = Vec::new();
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        if a == b || b == c || a == c {
            continue;
        }
        for (u, v, w) in [(a, b, c), (b, c, a), (c, a, b)] {
            let Some(&n) = by_edge.get(&(u.min(v), u.max(v))) else {
                by_edge.insert((u.min(v), u.max(v)), t as u32);
                continue;
            };
            let other = mesh.triangles[n as usize];
            let Some(&x) = other.iter().find(|&&x| x != u && x != v) else { continue };
            let p = |i: u32| mesh.positions[i as usize].as_dvec3();
            if folded_across_edge(p(v) - p(u), p(w) - p(u), p(x) - p(u)) {
                pairs.push([n, t as u32]);
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures::*;
    use glam::Vec3;

    #[test]
    fn closed_solids_do_not_intersect_themselves() {
        for m in [tetrahedron(), octahedron(), cube()] {
            assert_eq!(self_intersections(&m), 0);
        }
    }

    #[test]
    fn overlapping_tetrahedra_intersect_and_distant_ones_do_not() {
        let tet = tetrahedron();
        let crossing = merged(&tet, &translated(&tet, Vec3::splat(0.2)));
        let pairs = self_intersecting_pairs(&crossing);
        assert!(!pairs.is_empty());
        // Every reported pair joins one face of each tetrahedron.
        assert!(pairs.iter().all(|&[i, j]| i < 4 && j >= 4), "{pairs:?}");
        let apart = merged(&tet, &translated(&tet, Vec3::new(1.5, 0.0, 0.0)));
        assert_eq!(self_intersections(&apart), 0);
        // Touching at a point without sharing the vertex index counts as intersecting.
        let touching = merged(&tet, &translated(&tet, Vec3::new(1.0, 0.0, 0.0)));
        assert!(self_intersections(&touching) > 0);
    }

    #[test]
    fn a_fold_at_a_shared_vertex_is_found() {
        // A fan of two triangles around vertex 0; the second is folded back over the first.
        let folded = mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.2, 0.0], [0.2, 1.0, 0.0]],
            &[[0, 1, 2], [0, 4, 3]],
        );
        assert_eq!(self_intersecting_pairs(&folded), vec![[0, 1]]);
        let spread = mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
            &[[0, 1, 2], [0, 3, 4]],
        );
        assert_eq!(self_intersections(&spread), 0);
    }

    /// The pleat DMC made on the rotated box: a triangle flipped in the plane of its neighbour,
    /// tilted out of it by rounding. Folded within a degree counts; a sharp but open edge does not.
    #[test]
    fn a_triangle_folded_onto_its_neighbour_across_an_edge_is_found() {
        let across = |d: [f32; 3]| {
            mesh(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, 1.0, 0.0], d], &[[0, 1, 2], [1, 0, 3]])
        };
        assert_eq!(folded_pairs(&across([0.6, 0.8, 1e-5])), vec![[0, 1]]);
        assert_eq!(folded_pairs(&across([0.6, 0.8, -1e-3])), vec![[0, 1]]);
        assert_eq!(self_intersections(&across([0.6, 0.8, 1e-5])), 0, "a fold crosses nothing");
        assert!(folded_pairs(&across([0.6, -0.8, 0.0])).is_empty(), "flat continuation");
        assert!(folded_pairs(&across([0.6, 0.8, 0.1])).is_empty(), "a 7° edge is sharp, not folded");
        assert!(folded_pairs(&across([0.6, 1e-4, 1e-6])).is_empty(), "a sliver has no reliable side");
        for m in [tetrahedron(), octahedron(), cube()] {
            assert!(folded_pairs(&m).is_empty());
        }
    }

    #[test]
    fn tetrahedra_sharing_a_vertex_touch_only_there() {
        let a = tetrahedron();
        let mut b = a.clone();
        for p in &mut b.positions {
            *p = -*p;
        }
        let m = merged(&a, &b);
        // Unwelded: the two apex copies touch, three faces each.
        assert_eq!(self_intersections(&m), 9);
        let mut welded = m.clone();
        for t in &mut welded.triangles {
            for v in t.iter_mut() {
                if *v == 4 {
                    *v = 0;
                }
            }
        }
        assert_eq!(self_intersections(&welded), 0);
    }

    #[test]
    fn edges_crossing_in_a_shared_cell_face_touch() {
        // Found in a Marching Cubes gyroid: each cell's fan triangulation put a diagonal in the cell
        // face x = 5, and the two diagonals cross there, so the sheets touch at one point.
        let touching = mesh(
            &[
                [5.0, 0.13, 0.0],
                [4.0, 0.53, 1.0],
                [5.0, 0.76, 1.0],
                [5.0, 1.0, 0.64],
                [6.0, 0.0, 0.57],
                [5.0, 0.0, 0.08],
            ],
            &[[0, 1, 2], [3, 4, 5]],
        );
        assert_eq!(self_intersections(&touching), 1);
        let mut apart = touching.clone();
        for p in &mut apart.positions[3..] {
            p.x += 0.01;
        }
        assert_eq!(self_intersections(&apart), 0);
    }

    #[test]
    fn mc_spheres_are_free_of_self_intersections() {
        for res in [16, 33] {
            let (m, _) = mc_sphere(res);
            assert_eq!(self_intersections(&m), 0, "res {res}");
        }
    }

    #[test]
    fn a_pushed_vertex_makes_the_sphere_cross_itself() {
        let (mut m, _) = mc_sphere(16);
        let n = m.positions.len();
        // Drive one vertex through the sphere to the far side.
        let v = (0..n).max_by(|&a, &b| m.positions[a].x.total_cmp(&m.positions[b].x)).unwrap();
        m.positions[v].x -= 1.7;
        assert!(self_intersections(&m) > 0);
    }
}

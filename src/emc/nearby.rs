//! Which triangles of a mesh lie near a region: buckets of one grid cell each, holding every
//! triangle whose bounding box reaches into them, kept up to date as triangles change.
//!
//! The passes after extraction (edge flips, pulling fan centres back into their cells) make
//! triangles that span two cells or leave their own, so the cell a triangle was emitted for no
//! longer says where it is. Each of those passes asks, before it changes the mesh, whether the
//! triangles it would make cross any triangle nearby; this answers "nearby" from where the
//! triangles actually are ([`crate::mesh::buckets`]), so the question covers every triangle that
//! can be hit. The callers build it on their first question: on smooth surfaces there is none.

use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use crate::mesh::buckets::{bounds, TriangleBuckets};
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};

/// A mesh's triangles by where they are, for crossing tests.
pub struct NearbyTriangles {
    buckets: TriangleBuckets,
}

fn corners64(corners: &[Vec3; 3]) -> [DVec3; 3] {
    corners.map(|p| p.as_dvec3())
}

impl NearbyTriangles {
    /// Every triangle of `mesh`, in buckets of a grid cell (`spacing`'s longest side).
    pub fn new(mesh: &Mesh, spacing: Vec3) -> NearbyTriangles {
        let boxes = (0..mesh.triangles.len()).map(|t| bounds(&corners64(&mesh.corners(t))));
        NearbyTriangles { buckets: TriangleBuckets::build(spacing.max_element() as f64, boxes) }
    }

    /// Records triangle `t` with these corners (in place of those it had).
    pub fn insert(&mut self, t: u32, corners: &[Vec3; 3]) {
        let (lo, hi) = bounds(&corners64(corners));
        self.buckets.insert(t, lo, hi);
    }

    /// Forgets triangle `t`.
    pub fn remove(&mut self, t: u32) {
        self.buckets.remove(t);
    }

    /// Every recorded triangle whose box overlaps the box of `corners`, each once.
    pub fn near(&mut self, corners: &[Vec3; 3]) -> Vec<u32> {
        let (lo, hi) = bounds(&corners64(corners));
        let mut out = Vec::new();
        self.buckets.query(lo, hi, &mut out);
        out
    }

    /// Whether the triangle `ids` at `corners` crosses any recorded triangle of `mesh` nearby other
    /// than those in `skip`, by the self-intersection checker's rules (sharing an edge never
    /// counts, sharing a vertex counts when they overlap beyond it).
    pub fn crosses(&mut self, mesh: &Mesh, ids: [u32; 3], corners: &[Vec3; 3], skip: &[u32]) -> bool {
        let new: ([u32; 3], [DVec3; 3]) = (ids, corners64(corners));
        self.near(corners).into_iter().filter(|t| !skip.contains(t)).any(|t| {
            let t = t as usize;
            indexed_pair_intersects(new, (mesh.triangles[t], corners64(&mesh.corners(t))))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh() -> Mesh {
        Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(5.0, 5.0, 5.0),
                Vec3::new(6.0, 5.0, 5.0),
                Vec3::new(5.0, 6.0, 5.0),
            ],
            normals: Vec::new(),
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        }
    }

    #[test]
    fn finds_the_triangles_near_a_box_and_forgets_removed_ones() {
        let m = mesh();
        let mut buckets = NearbyTriangles::new(&m, Vec3::ONE);
        let probe = [Vec3::new(0.2, 0.2, -0.5), Vec3::new(0.3, 0.2, 0.5), Vec3::new(0.2, 0.3, 0.5)];
        assert_eq!(buckets.near(&probe), vec![0]);
        assert!(buckets.crosses(&m, [10, 11, 12], &probe, &[]), "the probe pierces triangle 0");
        assert!(!buckets.crosses(&m, [10, 11, 12], &probe, &[0]), "unless it is skipped");
        buckets.remove(0);
        assert!(buckets.near(&probe).is_empty());
        let far = [Vec3::new(5.2, 5.2, 4.5), Vec3::new(5.3, 5.2, 5.5), Vec3::new(5.2, 5.3, 5.5)];
        assert_eq!(buckets.near(&far), vec![1]);
        assert!(buckets.crosses(&m, [10, 11, 12], &far, &[]));
    }
}

//! Which triangles of a mesh lie near a region: buckets of one grid cell each, holding every
//! triangle whose bounding box reaches into them, kept up to date as triangles change.
//!
//! The passes after extraction (edge flips, pulling fan centres back into their cells) make
//! triangles that span two cells or leave their own, so the cell a triangle was emitted for no
//! longer says where it is. Each of those passes asks, before it changes the mesh, whether the
//! triangles it would make cross any triangle nearby; this answers "nearby" from where the
//! triangles actually are, so the question covers every triangle that can be hit.

use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use crate::mesh::Mesh;
use glam::{DVec3, IVec3, Vec3};
use std::collections::HashMap;

/// Triangles by the buckets (cells of size `spacing`) their bounding boxes overlap.
pub struct TriangleBuckets {
    spacing: Vec3,
    buckets: HashMap<IVec3, Vec<u32>>,
}

impl TriangleBuckets {
    /// Buckets of size `spacing` (a grid's cell) over every triangle of `mesh`.
    pub fn new(mesh: &Mesh, spacing: Vec3) -> TriangleBuckets {
        let mut out = TriangleBuckets { spacing, buckets: HashMap::new() };
        for t in 0..mesh.triangles.len() {
            out.insert(t as u32, &mesh.corners(t));
        }
        out
    }

    /// The bucket keys a box overlaps (grown by a thousandth of a bucket, so that a triangle
    /// touching a bucket's side is found from both).
    fn keys(&self, lo: Vec3, hi: Vec3) -> impl Iterator<Item = IVec3> {
        let margin = self.spacing * 1e-3;
        let a = ((lo - margin) / self.spacing).floor().as_ivec3();
        let b = ((hi + margin) / self.spacing).floor().as_ivec3();
        (a.z..=b.z)
            .flat_map(move |z| (a.y..=b.y).flat_map(move |y| (a.x..=b.x).map(move |x| IVec3::new(x, y, z))))
    }

    fn bounds(corners: &[Vec3; 3]) -> (Vec3, Vec3) {
        (corners[0].min(corners[1]).min(corners[2]), corners[0].max(corners[1]).max(corners[2]))
    }

    /// Records triangle `t` with these corners.
    pub fn insert(&mut self, t: u32, corners: &[Vec3; 3]) {
        let (lo, hi) = Self::bounds(corners);
        let keys: Vec<IVec3> = self.keys(lo, hi).collect();
        for key in keys {
            self.buckets.entry(key).or_default().push(t);
        }
    }

    /// Forgets triangle `t`, recorded with these corners.
    pub fn remove(&mut self, t: u32, corners: &[Vec3; 3]) {
        let (lo, hi) = Self::bounds(corners);
        let keys: Vec<IVec3> = self.keys(lo, hi).collect();
        for key in keys {
            if let Some(list) = self.buckets.get_mut(&key) {
                list.retain(|&u| u != t);
            }
        }
    }

    /// Every recorded triangle whose buckets overlap the box of `corners` (each once, ascending).
    pub fn near(&self, corners: &[Vec3; 3]) -> Vec<u32> {
        let (lo, hi) = Self::bounds(corners);
        let mut out: Vec<u32> =
            self.keys(lo, hi).filter_map(|k| self.buckets.get(&k)).flatten().copied().collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Whether the triangle `ids` at `corners` crosses any recorded triangle of `mesh` nearby other
    /// than those in `skip`, by the self-intersection checker's rules (sharing an edge never
    /// counts, sharing a vertex counts when they overlap beyond it).
    pub fn crosses(&self, mesh: &Mesh, ids: [u32; 3], corners: &[Vec3; 3], skip: &[u32]) -> bool {
        let at = |c: &[Vec3; 3]| c.map(|p| p.as_dvec3());
        let new: ([u32; 3], [DVec3; 3]) = (ids, at(corners));
        self.near(corners).into_iter().filter(|t| !skip.contains(t)).any(|t| {
            let t = t as usize;
            indexed_pair_intersects(new, (mesh.triangles[t], at(&mesh.corners(t))))
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
        let mut buckets = TriangleBuckets::new(&m, Vec3::ONE);
        let probe = [Vec3::new(0.2, 0.2, -0.5), Vec3::new(0.3, 0.2, 0.5), Vec3::new(0.2, 0.3, 0.5)];
        assert_eq!(buckets.near(&probe), vec![0]);
        assert!(buckets.crosses(&m, [10, 11, 12], &probe, &[]), "the probe pierces triangle 0");
        assert!(!buckets.crosses(&m, [10, 11, 12], &probe, &[0]), "unless it is skipped");
        buckets.remove(0, &m.corners(0));
        assert!(buckets.near(&probe).is_empty());
        let far = [Vec3::new(5.2, 5.2, 4.5), Vec3::new(5.3, 5.2, 5.5), Vec3::new(5.2, 5.3, 5.5)];
        assert_eq!(buckets.near(&far), vec![1]);
        assert!(buckets.crosses(&m, [10, 11, 12], &far, &[]));
    }
}

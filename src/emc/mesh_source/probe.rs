//! Off-grid queries on a mesh: where any segment crosses it and how far a point lies from it. They
//! give remeshing what functions already have ([`EdgeSampler::crossing_on_segment`],
//! [`EdgeSampler::distance`]): resampling of curved creases, the fine-scale test that tells a
//! crease from a rounded edge tessellated in strips (each strip's turn is under θ, the cell sees
//! the outer strips' planes and would put a crease where they meet, off the surface), and the
//! check that a fan centre lies on the surface.
//!
//! [`EdgeSampler::crossing_on_segment`]: super::EdgeSampler::crossing_on_segment
//! [`EdgeSampler::distance`]: super::EdgeSampler::distance

use super::MeshBvh;
use crate::mesh::analysis::bvh::Aabb;
use glam::{DVec3, Vec3};

impl MeshBvh {
    /// Every triangle the segment `a → b` meets, as the fraction `t` of the way from `a` and the
    /// triangle's index, nearest first. A segment through an edge or a vertex shared by several
    /// triangles may count it more than once or not at all: callers use the hits' parity as a
    /// side test and give up where it is even.
    pub fn segment_hits(&self, a: Vec3, b: Vec3) -> Vec<(f32, u32)> {
        let mut hits: Vec<(f32, u32)> = Vec::new();
        let (from, dir) = (a.as_dvec3(), (b - a).as_dvec3());
        self.bvh.walk(
            &mut hits,
            |_, bx| segment_meets_box(a, b, bx).then_some(0.0),
            |hits, t| {
                if let Some(s) = segment_triangle(from, dir, &self.triangles[t as usize]) {
                    hits.push((s as f32, t));
                }
            },
        );
        hits.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        hits
    }
}

/// Whether the segment `a → b` meets the closed box (slabs).
fn segment_meets_box(a: Vec3, b: Vec3, bx: &Aabb) -> bool {
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    let d = b - a;
    for axis in 0..3 {
        if d[axis] == 0.0 {
            if a[axis] < bx.min[axis] || a[axis] > bx.max[axis] {
                return false;
            }
            continue;
        }
        let (t0, t1) = ((bx.min[axis] - a[axis]) / d[axis], (bx.max[axis] - a[axis]) / d[axis]);
        lo = lo.max(t0.min(t1));
        hi = hi.min(t0.max(t1));
        if lo > hi {
            return false;
        }
    }
    true
}

/// Where the segment `from + s·dir`, `s` in `[0, 1]`, meets the triangle (Möller and Trumbore),
/// in `f64`.
fn segment_triangle(from: DVec3, dir: DVec3, tri: &[Vec3; 3]) -> Option<f64> {
    let [p0, p1, p2] = tri.map(|p| p.as_dvec3());
    let (e1, e2) = (p1 - p0, p2 - p0);
    let h = dir.cross(e2);
    let det = e1.dot(h);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = from - p0;
    let u = s.dot(h) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (0.0..=1.0).contains(&t).then_some(t)
}

#[cfg(test)]
mod tests {
    use crate::emc::mesh_source::MeshBvh;
    use crate::mesh::Mesh;
    use glam::Vec3;

    /// The unit cube [0, 1]³ as twelve triangles wound outwards.
    fn cube() -> Mesh {
        let positions: Vec<Vec3> =
            (0..8).map(|c| Vec3::new((c & 1) as f32, (c >> 1 & 1) as f32, (c >> 2 & 1) as f32)).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let triangles =
            quads.iter().flat_map(|q: &[u32; 4]| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        Mesh { positions, triangles, ..Mesh::default() }
    }

    #[test]
    fn a_slanted_segment_meets_the_faces_it_passes_through() {
        let bvh = MeshBvh::new(&cube()).unwrap();
        // In at x = 0 (a quarter of the way), out at x = 1 (three quarters).
        let hits = bvh.segment_hits(Vec3::new(-0.5, 0.3, 0.4), Vec3::new(1.5, 0.7, 0.6));
        assert_eq!(hits.len(), 2, "{hits:?}");
        assert!((hits[0].0 - 0.25).abs() < 1e-6 && (hits[1].0 - 0.75).abs() < 1e-6, "{hits:?}");
        assert!(bvh.normal(hits[0].1).x < -0.99 && bvh.normal(hits[1].1).x > 0.99);
        // Inside to inside, and outside past the cube: nothing.
        assert!(bvh.segment_hits(Vec3::splat(0.2), Vec3::splat(0.8)).is_empty());
        assert!(bvh.segment_hits(Vec3::new(2.0, 0.5, -0.5), Vec3::new(0.5, 2.0, -0.1)).is_empty());
    }

    /// Seeded: on soups of triangles, a third of them lying in axis planes (a CAD part's faces,
    /// whose boxes are flat), the BVH walk finds for every segment the very hits a test of every
    /// triangle finds.
    #[test]
    fn segment_hits_are_those_of_every_triangle() {
        use crate::expr::testutil::Rng;
        let mut flat_hits = 0;
        for seed in 0..20u64 {
            let mut rng = Rng::new(seed);
            let mut positions = Vec::new();
            for _ in 0..150 {
                let corner = rng.vec3(-1.0, 1.0);
                let mut tri = [corner, corner + rng.vec3(-0.4, 0.4), corner + rng.vec3(-0.4, 0.4)];
                if rng.below(3) == 0 {
                    let axis = rng.below(3);
                    let level = (rng.range(-1.0, 1.0) * 8.0).round() / 8.0;
                    tri.iter_mut().for_each(|p| p[axis] = level);
                }
                positions.extend(tri);
            }
            let triangles = (0..150u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
            let bvh = MeshBvh::new(&Mesh { positions, triangles, ..Mesh::default() }).unwrap();
            for _ in 0..300 {
                let (a, b) = (rng.vec3(-1.5, 1.5), rng.vec3(-1.5, 1.5));
                let (from, dir) = (a.as_dvec3(), (b - a).as_dvec3());
                let every: Vec<u32> = (0..bvh.triangles.len() as u32)
                    .filter(|&t| super::segment_triangle(from, dir, &bvh.triangles[t as usize]).is_some())
                    .collect();
                let mut walked: Vec<u32> = bvh.segment_hits(a, b).iter().map(|h| h.1).collect();
                walked.sort();
                assert_eq!(walked, every, "seed {seed}: segment {a} -> {b}");
                flat_hits += every.iter().filter(|&&t| flat(&bvh.triangles[t as usize])).count();
            }
        }
        assert!(flat_hits > 500, "only {flat_hits} hits on flat triangles: the case is not tested");
    }

    fn flat(tri: &[Vec3; 3]) -> bool {
        (0..3).any(|axis| tri[0][axis] == tri[1][axis] && tri[1][axis] == tri[2][axis])
    }
}

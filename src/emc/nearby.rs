//! Which triangles of a mesh lie near a region: buckets of one grid cell each, holding every
//! triangle whose bounding box reaches into them, kept up to date as triangles change.
//!
//! The passes after extraction (edge flips, pulling fan centres back into their cells) make
//! triangles that span two cells or leave their own, so the cell a triangle was emitted for no
//! longer says where it is. Each of those passes asks, before it changes the mesh, whether the
//! triangles it would make cross any triangle nearby; this answers "nearby" from where the
//! triangles actually are ([`crate::mesh::buckets`]), so the question covers every triangle that
//! can be hit. The callers build it on their first question: on smooth surfaces there is none.
//!
//! Those passes only ever ask about a known region, the few cells around the fan centres, so
//! only the triangles that reach into it are recorded ([`NearbyTriangles::around`]): at 256
//! cells, recording all 400 000 triangles of the gear took 67 ms a pass, a third of the flips'
//! time, for questions about a small share of them. The buckets keep boxes for the recorded
//! triangles alone (a third of the gear's at 256 cells, a twentieth for the pull-backs): lists
//! per triangle of the whole mesh, touched for the first time in every pass, cost the
//! pull-backs a third of their time.

use crate::mesh::analysis::bvh::Aabb;
use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use crate::mesh::buckets::{bounds, TriangleBuckets};
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};

/// Triangles per piece of [`NearbyTriangles::around`]'s scan on several threads.
const SCAN_PIECE: usize = 16_384;

/// A mesh's triangles by where they are, for crossing tests.
pub struct NearbyTriangles {
    buckets: TriangleBuckets,
    /// Where questions may be asked, when not everywhere.
    region: Option<Region>,
}

fn corners64(corners: &[Vec3; 3]) -> [DVec3; 3] {
    corners.map(|p| p.as_dvec3())
}

impl NearbyTriangles {
    /// Every triangle of `mesh`, in buckets of a grid cell (`spacing`'s longest side).
    pub fn new(mesh: &Mesh, spacing: Vec3) -> NearbyTriangles {
        let boxes = (0..mesh.triangles.len()).map(|t| bounds(&corners64(&mesh.corners(t))));
        NearbyTriangles { buckets: TriangleBuckets::build(spacing.max_element() as f64, boxes), region: None }
    }

    /// The triangles of `mesh` that reach into `region` (boxes), for questions about triangles
    /// that lie in it: a triangle that meets such a one reaches into the region, so it is
    /// recorded. Asking about a triangle outside the region is a caller's error (checked in debug
    /// builds).
    pub fn around(mesh: &Mesh, spacing: Vec3, region: &[Aabb]) -> NearbyTriangles {
        let cell = spacing.max_element() as f64;
        let region = Region::new(cell, region);
        // The scan over every triangle is most of the cost, and each triangle's answer is its
        // own: pieces of the list go to threads ([`crate::par`]) and are joined in order.
        // A box's lowest and highest cubes are those of its corners' lowest and highest, so
        // each vertex's cube is found once.
        let mut cubes = vec![[0i64; 3]; mesh.positions.len()];
        crate::par::map_chunks_mut(&mut cubes, SCAN_PIECE, |c, piece| {
            for (k, cube) in piece.iter_mut().enumerate() {
                *cube = region.lattice.cube(mesh.positions[c * SCAN_PIECE + k].as_dvec3());
            }
        });
        let pieces = crate::par::map(mesh.triangles.len().div_ceil(SCAN_PIECE), |c| {
            let piece = c * SCAN_PIECE..((c + 1) * SCAN_PIECE).min(mesh.triangles.len());
            let mut recorded = Vec::new();
            for t in piece {
                let [p, q, r] = mesh.triangles[t].map(|v| cubes[v as usize]);
                let low = std::array::from_fn(|a| p[a].min(q[a]).min(r[a]));
                let high = std::array::from_fn(|a| p[a].max(q[a]).max(r[a]));
                if region.meets(low, high) {
                    let (lo, hi) = bounds(&corners64(&mesh.corners(t)));
                    recorded.push((t as u32, lo, hi));
                }
            }
            recorded
        });
        NearbyTriangles {
            buckets: TriangleBuckets::build_sparse(cell, mesh.triangles.len(), pieces.concat()),
            region: Some(region),
        }
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
    #[cfg(test)]
    fn near(&mut self, corners: &[Vec3; 3]) -> Vec<u32> {
        let (lo, hi) = bounds(&corners64(corners));
        debug_assert!(self.region.as_ref().is_none_or(|r| r.covers(lo, hi)), "asked outside the region");
        self.overlapping(lo, hi)
    }

    /// Every recorded triangle whose box overlaps `lo..hi`, each once.
    fn overlapping(&mut self, lo: DVec3, hi: DVec3) -> Vec<u32> {
        let mut out = Vec::new();
        self.buckets.query(lo, hi, &mut out);
        out
    }

    /// [`NearbyTriangles::any_crosses`] for one triangle.
    #[cfg(test)]
    fn crosses(&mut self, mesh: &Mesh, ids: [u32; 3], corners: &[Vec3; 3], skip: &[u32]) -> bool {
        self.any_crosses(mesh, &[(ids, *corners)], skip)
    }

    /// Whether any of the triangles `new` (ids and corners, side by side: a flip's two, a fan)
    /// crosses a recorded triangle of `mesh` nearby other than those in `skip`, by the
    /// self-intersection checker's rules (sharing an edge never counts, sharing a vertex counts
    /// when they overlap beyond it). One look-up over the box of them all: the triangles a change
    /// makes share most of their neighbourhood, and the look-up, not the crossing tests, is most
    /// of a question's cost (the gear's flips at 64 cells: 1.4 µs a look-up, 50 ns a test).
    pub fn any_crosses(&mut self, mesh: &Mesh, new: &[([u32; 3], [Vec3; 3])], skip: &[u32]) -> bool {
        let Some(((lo, hi), new)) = union_bounds(new) else { return false };
        // Each triangle's box must lie in the region (the box of them all need not): a triangle
        // that crosses one of them meets its box, so it was recorded.
        debug_assert!(
            new.iter().all(|(_, _, (lo, hi))| self.region.as_ref().is_none_or(|r| r.covers(*lo, *hi))),
            "asked outside the region"
        );
        self.overlapping(lo, hi).into_iter().filter(|t| !skip.contains(t)).any(|t| {
            let t = t as usize;
            let (ids, corners) = (mesh.triangles[t], corners64(&mesh.corners(t)));
            let (tlo, thi) = bounds(&corners);
            new.iter().any(|&(ids_new, corners_new, (nlo, nhi))| {
                nlo.cmple(thi).all()
                    && nhi.cmpge(tlo).all()
                    && indexed_pair_intersects((ids_new, corners_new), (ids, corners))
            })
        })
    }
}

/// The triangles' corners in `f64` with each one's box, and the box of them all (`None`: none).
#[allow(clippy::type_complexity)]
fn union_bounds(
    new: &[([u32; 3], [Vec3; 3])],
) -> Option<((DVec3, DVec3), Vec<([u32; 3], [DVec3; 3], (DVec3, DVec3))>)> {
    let boxed: Vec<_> = new
        .iter()
        .map(|(ids, corners)| {
            let c = corners64(corners);
            (*ids, c, bounds(&c))
        })
        .collect();
    let all = boxed.iter().map(|b| b.2).reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))?;
    Some((all, boxed))
}

/// The cubes of side `cell` that some boxes reach into (each grown by a hundredth of a cube, more
/// than the thousandth a question's box is grown by), as bits over the boxes' extent.
struct Region {
    lattice: Lattice,
    bits: Vec<u64>,
}

/// Cubes of side `cell`, numbered over a block of `size` of them from cube `low`.
#[derive(Clone, Copy)]
struct Lattice {
    cell: f64,
    low: [i64; 3],
    size: [i64; 3],
}

impl Lattice {
    fn cube(&self, p: DVec3) -> [i64; 3] {
        p.to_array().map(|x| (x / self.cell).floor() as i64)
    }

    /// Calls `f` with the number (`None`: outside the block) of every cube `[lo, hi]` overlaps,
    /// while it returns true; returns whether it always did.
    fn cubes(&self, lo: DVec3, hi: DVec3, f: impl FnMut(Option<usize>) -> bool) -> bool {
        self.cube_range(self.cube(lo), self.cube(hi), f)
    }

    /// [`Lattice::cubes`] over the cubes from `a` to `z` (inclusive).
    fn cube_range(&self, a: [i64; 3], z: [i64; 3], mut f: impl FnMut(Option<usize>) -> bool) -> bool {
        for cz in a[2]..=z[2] {
            for cy in a[1]..=z[1] {
                for cx in a[0]..=z[0] {
                    let at = [cx - self.low[0], cy - self.low[1], cz - self.low[2]];
                    let inside = (0..3).all(|k| (0..self.size[k]).contains(&at[k]));
                    let number =
                        inside.then(|| (at[0] + self.size[0] * (at[1] + self.size[1] * at[2])) as usize);
                    if !f(number) {
                        return false;
                    }
                }
            }
        }
        true
    }
}

impl Region {
    fn new(cell: f64, boxes: &[Aabb]) -> Region {
        let margin = 1e-2 * cell;
        let grown: Vec<(DVec3, DVec3)> =
            boxes.iter().map(|b| (b.min.as_dvec3() - margin, b.max.as_dvec3() + margin)).collect();
        let mut lattice = Lattice { cell, low: [0; 3], size: [0; 3] };
        if grown.is_empty() {
            return Region { lattice, bits: Vec::new() };
        }
        let (mut low, mut high) = ([i64::MAX; 3], [i64::MIN; 3]);
        for &(lo, hi) in &grown {
            let (a, z) = (lattice.cube(lo), lattice.cube(hi));
            for k in 0..3 {
                low[k] = low[k].min(a[k]);
                high[k] = high[k].max(z[k]);
            }
        }
        lattice.low = low;
        lattice.size = std::array::from_fn(|k| (high[k] - low[k] + 1).max(0));
        let count = lattice.size.iter().product::<i64>() as usize;
        let mut bits = vec![0u64; count.div_ceil(64)];
        for &(lo, hi) in &grown {
            lattice.cubes(lo, hi, |n| {
                if let Some(n) = n {
                    bits[n / 64] |= 1 << (n % 64);
                }
                true
            });
        }
        Region { lattice, bits }
    }

    fn has(&self, n: Option<usize>) -> bool {
        n.is_some_and(|n| self.bits[n / 64] >> (n % 64) & 1 == 1)
    }

    /// Whether any cube from `a` to `z` (inclusive) is in the region.
    fn meets(&self, a: [i64; 3], z: [i64; 3]) -> bool {
        !self.lattice.cube_range(a, z, |n| !self.has(n))
    }

    fn covers(&self, lo: DVec3, hi: DVec3) -> bool {
        self.lattice.cubes(lo, hi, |n| self.has(n))
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
    fn around_a_region_finds_what_reaches_into_it() {
        let m = mesh();
        // A region around the first triangle only: the far one is not recorded, and a question
        // about the near one sees what the whole-mesh buckets see.
        let region = [Aabb { min: Vec3::splat(-0.5), max: Vec3::splat(0.5) }];
        let mut around = NearbyTriangles::around(&m, Vec3::ONE, &region);
        let mut all = NearbyTriangles::new(&m, Vec3::ONE);
        let probe = [Vec3::new(0.2, 0.2, -0.4), Vec3::new(0.3, 0.2, 0.4), Vec3::new(0.2, 0.3, 0.4)];
        assert_eq!(around.near(&probe), all.near(&probe));
        assert!(around.crosses(&m, [10, 11, 12], &probe, &[]));
        assert_eq!(around.buckets.recorded(), 1, "the far triangle is left out");
    }

    /// Random soups of small triangles (the sizes of EMC's, up to two cells), random regions of
    /// a few boxes, random questions inside them: the region's buckets answer as the whole
    /// mesh's do, before and after triangles move within the region.
    #[test]
    fn around_a_region_answers_as_the_whole_mesh_does() {
        for seed in 0..40u64 {
            let mut rng = crate::expr::testutil::Rng::new(9100 + seed);
            let cell = rng.range(0.05, 0.3);
            let mut mesh = Mesh { positions: Vec::new(), normals: Vec::new(), triangles: Vec::new() };
            for t in 0..300u32 {
                let a = rng.vec3(-1.0, 1.0);
                for _ in 0..3 {
                    mesh.positions.push(a + rng.vec3(-cell, cell));
                }
                mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
            }
            let boxes: Vec<Aabb> = (0..1 + rng.below(4))
                .map(|_| {
                    let min = rng.vec3(-1.0, 0.8);
                    Aabb { min, max: min + rng.vec3(0.0, 3.0 * cell) }
                })
                .collect();
            let spacing = Vec3::splat(cell);
            let mut around = NearbyTriangles::around(&mesh, spacing, &boxes);
            let mut all = NearbyTriangles::new(&mesh, spacing);
            let sorted = |mut v: Vec<u32>| {
                v.sort_unstable();
                v
            };
            for round in 0..2 {
                for _ in 0..50 {
                    let b = boxes[rng.below(boxes.len())];
                    let question = [0; 3].map(|_: u8| b.min + (b.max - b.min) * rng.vec3(0.0, 1.0));
                    assert_eq!(
                        sorted(around.near(&question)),
                        sorted(all.near(&question)),
                        "seed {seed}, round {round}"
                    );
                }
                // Move a few triangles that lie in a region box to other places in it.
                for _ in 0..10 {
                    let b = boxes[rng.below(boxes.len())];
                    let t = rng.below(mesh.triangles.len());
                    let corners = [0; 3].map(|_: u8| b.min + (b.max - b.min) * rng.vec3(0.0, 1.0));
                    for (k, &p) in corners.iter().enumerate() {
                        mesh.positions[3 * t + k] = p;
                    }
                    around.insert(t as u32, &corners);
                    all.insert(t as u32, &corners);
                }
            }
        }
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "asked outside the region")]
    fn asking_outside_the_region_is_an_error() {
        let m = mesh();
        let mut around =
            NearbyTriangles::around(&m, Vec3::ONE, &[Aabb { min: Vec3::ZERO, max: Vec3::splat(0.5) }]);
        around.near(&[Vec3::splat(5.2), Vec3::splat(5.3), Vec3::new(5.2, 5.3, 5.2)]);
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

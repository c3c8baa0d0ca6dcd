//! A two-sided Hausdorff distance between triangle meshes by sampling, written for the tests alone
//! so that what they assert does not rest on the library's own distance code
//! (`mesh::analysis::surface_error`, `MeshBvh::nearest`).
//!
//! Each mesh is sampled at its vertices and over its faces and edges to a given spacing (see
//! [`hausdorff`]), and every sample's distance to the other mesh's nearest triangle is exact (in
//! f64). Vertices alone under-report: the largest distance of a remeshed part often lies on a
//! crease of the input between two output vertices, or inside a face of the input that the output
//! cuts across.

use glam::{DVec3, Vec3};

/// Triangles with a uniform grid of buckets over their bounding box: a triangle sits in every
/// bucket its bounding box overlaps, and a query searches rings of buckets outward until no
/// closer triangle can lie in the next ring.
pub struct NearestTriangles {
    tris: Vec<[DVec3; 3]>,
    lo: DVec3,
    size: f64,
    dims: [usize; 3],
    buckets: Vec<Vec<u32>>,
}

impl NearestTriangles {
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> NearestTriangles {
        let tris: Vec<[DVec3; 3]> =
            triangles.iter().map(|t| t.map(|v| positions[v as usize].as_dvec3())).collect();
        assert!(!tris.is_empty(), "no triangles to measure against");
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for t in &tris {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        let extent = (hi - lo).max(DVec3::splat(1e-9));
        // About two triangles per occupied bucket on a surface: buckets of the mean edge length.
        let mean_edge = tris.iter().map(|t| (t[1] - t[0]).length()).sum::<f64>() / tris.len() as f64;
        let size = mean_edge.max(extent.max_element() / 256.0).max(1e-12);
        let dims = [0, 1, 2].map(|a| ((extent[a] / size).ceil() as usize).max(1));
        let mut buckets = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        for (n, t) in tris.iter().enumerate() {
            let tlo = t[0].min(t[1]).min(t[2]);
            let thi = t[0].max(t[1]).max(t[2]);
            let a = Self::cell_of(lo, size, dims, tlo);
            let b = Self::cell_of(lo, size, dims, thi);
            for k in a[2]..=b[2] {
                for j in a[1]..=b[1] {
                    for i in a[0]..=b[0] {
                        buckets[i + dims[0] * (j + dims[1] * k)].push(n as u32);
                    }
                }
            }
        }
        NearestTriangles { tris, lo, size, dims, buckets }
    }

    fn cell_of(lo: DVec3, size: f64, dims: [usize; 3], p: DVec3) -> [usize; 3] {
        [0, 1, 2].map(|a| (((p[a] - lo[a]) / size).floor().max(0.0) as usize).min(dims[a] - 1))
    }

    /// The distance from `p` to the nearest triangle.
    pub fn distance(&self, p: DVec3) -> f64 {
        let c = Self::cell_of(self.lo, self.size, self.dims, p);
        // How far outside the buckets' box p lies: rings start counting from the clamped bucket.
        let outside = (self.lo - p).max(p - (self.lo + DVec3::from(self.dims.map(|d| d as f64)) * self.size));
        let outside = outside.max(DVec3::ZERO).length();
        let mut best = f64::INFINITY;
        let max_ring = self.dims.iter().copied().max().unwrap();
        for ring in 0..=max_ring {
            let r = ring as isize;
            // The ring's buckets that exist: its cube clipped to the grid, hollow inside.
            let span =
                |a: usize| (-r).max(-(c[a] as isize))..=r.min(self.dims[a] as isize - 1 - c[a] as isize);
            for dk in span(2) {
                for dj in span(1) {
                    let on_shell = dk.abs() == r || dj.abs() == r;
                    let row: Vec<isize> = if on_shell { span(0).collect() } else { vec![-r, r] };
                    for di in row {
                        if !span(0).contains(&di) {
                            continue;
                        }
                        let idx =
                            [c[0] as isize + di, c[1] as isize + dj, c[2] as isize + dk].map(|x| x as usize);
                        let b = idx[0] + self.dims[0] * (idx[1] + self.dims[1] * idx[2]);
                        for &t in &self.buckets[b] {
                            best = best.min(point_triangle_distance(p, &self.tris[t as usize]));
                        }
                    }
                }
            }
            // Every bucket of the next ring is at least `ring` bucket widths from p along some
            // axis, and no nearer than the buckets' box.
            if best <= (ring as f64 * self.size).max(outside) {
                break;
            }
        }
        best
    }
}

/// The exact distance from `p` to the triangle `t`: to its plane where p projects inside it,
/// otherwise to the nearest of its three sides.
pub fn point_triangle_distance(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let nn = n.length_squared();
    if nn > 0.0 {
        // p is over the triangle when it lies on the inner side of all three sides' planes.
        let inside = (0..3).all(|q| {
            let (a, b) = (t[q], t[(q + 1) % 3]);
            (b - a).cross(p - a).dot(n) >= 0.0
        });
        if inside {
            return (p - t[0]).dot(n).abs() / nn.sqrt();
        }
    }
    (0..3).map(|q| point_segment_distance(p, t[q], t[(q + 1) % 3])).fold(f64::INFINITY, f64::min)
}

fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    let s = if len2 > 0.0 { ((p - a).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + d * s - p).length()
}

/// The two one-sided distances between two meshes and the area-weighted root mean square.
#[derive(Debug, Clone, Copy)]
pub struct Hausdorff {
    /// The largest distance found from a point of `a` to `b`, and from one of `b` to `a`. The
    /// larger of the two is the Hausdorff distance (to the sampling's precision); the smaller is
    /// only a lower bound of its side, whose pieces were searched only as far as they could beat
    /// the larger.
    pub a_to_b: f64,
    pub b_to_a: f64,
    /// Over both surfaces, by area, from one point per face (its centroid).
    pub rms: f64,
    /// Where the larger side's farthest point lies.
    pub worst: DVec3,
    /// Points whose distance was taken, both sides.
    pub queries: usize,
}

impl Hausdorff {
    pub fn max(&self) -> f64 {
        self.a_to_b.max(self.b_to_a)
    }
}

/// The two-sided Hausdorff distance between meshes `a` and `b`, sampled to `spacing`.
///
/// Every vertex is measured first. Then faces are split in four, recursively, measuring the new
/// corners (the midpoints of their sides, so creases and borders are sampled along with the
/// faces), until the pieces are under `spacing` across. The distance to a mesh changes no faster
/// than the point moves, and every point of a triangle with sides under L lies within L / √3 of
/// a corner, so no point of a piece lies farther than its corners' largest distance plus L / √3:
/// pieces are taken largest bound first, and the search ends when no piece left can beat the
/// largest distance found. The result is what uniform samples `spacing` apart over every face and
/// edge would give (they could miss the true maximum by at most `spacing / √3`), at the cost of
/// sampling only near the maximum.
pub fn hausdorff(a: (&[Vec3], &[[u32; 3]]), b: (&[Vec3], &[[u32; 3]]), spacing: f64) -> Hausdorff {
    // Both sides' vertices first: the search of either side then only refines pieces that could
    // beat the larger of the two.
    let mut sides = [Side::new(a, b), Side::new(b, a)];
    let mut best = sides[0].best.max(sides[1].best);
    for side in &mut sides {
        side.search(spacing, &mut best);
    }
    let [sa, sb] = sides;
    Hausdorff {
        a_to_b: sa.best,
        b_to_a: sb.best,
        rms: ((sa.sum2 + sb.sum2) / (sa.area + sb.area)).sqrt(),
        worst: if sa.best >= sb.best { sa.worst } else { sb.worst },
        queries: sa.queries + sb.queries,
    }
}

/// One direction of [`hausdorff`]: the faces of one mesh measured against the other.
struct Side {
    index: NearestTriangles,
    heap: std::collections::BinaryHeap<Piece>,
    best: f64,
    worst: DVec3,
    sum2: f64,
    area: f64,
    queries: usize,
}

impl Side {
    /// Measures the vertices of `from` and one point per face (for the mean square), and lines
    /// up its faces for [`Side::search`].
    fn new(from: (&[Vec3], &[[u32; 3]]), to: (&[Vec3], &[[u32; 3]])) -> Side {
        let index = NearestTriangles::new(to.0, to.1);
        let at_vertex: Vec<f64> = from.0.iter().map(|p| index.distance(p.as_dvec3())).collect();
        let mut side = Side {
            heap: Default::default(),
            best: 0.0,
            worst: DVec3::ZERO,
            sum2: 0.0,
            area: 0.0,
            queries: from.0.len() + from.1.len(),
            index,
        };
        for (p, &d) in from.0.iter().zip(&at_vertex) {
            side.note(p.as_dvec3(), d);
        }
        for t in from.1 {
            let corners = t.map(|v| from.0[v as usize].as_dvec3());
            let a = 0.5 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).length();
            let d = side.index.distance((corners[0] + corners[1] + corners[2]) / 3.0);
            side.sum2 += a * d * d;
            side.area += a;
            side.heap.push(Piece::new(corners, t.map(|v| at_vertex[v as usize])));
        }
        side
    }

    fn note(&mut self, p: DVec3, d: f64) {
        if d > self.best {
            (self.best, self.worst) = (d, p);
        }
    }

    /// Refines the pieces that could hold a point farther than `best` (see [`hausdorff`]).
    fn search(&mut self, spacing: f64, best: &mut f64) {
        while let Some(piece) = self.heap.pop() {
            if piece.bound <= *best {
                break;
            }
            let t = piece.corners;
            if piece.longest <= spacing {
                let c = (t[0] + t[1] + t[2]) / 3.0;
                let d = self.index.distance(c);
                self.queries += 1;
                self.note(c, d);
                *best = best.max(d);
                continue;
            }
            let m = [0, 1, 2].map(|q| (t[q] + t[(q + 1) % 3]) * 0.5);
            let dm = m.map(|p| self.index.distance(p));
            self.queries += 3;
            for q in 0..3 {
                self.note(m[q], dm[q]);
            }
            *best = best.max(self.best);
            let dc = piece.distances;
            self.heap.push(Piece::new([t[0], m[0], m[2]], [dc[0], dm[0], dm[2]]));
            self.heap.push(Piece::new([m[0], t[1], m[1]], [dm[0], dc[1], dm[1]]));
            self.heap.push(Piece::new([m[2], m[1], t[2]], [dm[2], dm[1], dc[2]]));
            self.heap.push(Piece::new(m, dm));
        }
    }
}

/// A piece of a face still to be searched, ordered by the largest distance a point of it could
/// have.
struct Piece {
    bound: f64,
    longest: f64,
    corners: [DVec3; 3],
    distances: [f64; 3],
}

impl Piece {
    fn new(corners: [DVec3; 3], distances: [f64; 3]) -> Piece {
        let longest = (0..3).map(|q| (corners[q] - corners[(q + 1) % 3]).length()).fold(0.0, f64::max);
        let bound = distances[0].max(distances[1]).max(distances[2]) + longest / 3f64.sqrt();
        Piece { bound, longest, corners, distances }
    }
}

impl PartialEq for Piece {
    fn eq(&self, other: &Piece) -> bool {
        self.bound == other.bound
    }
}

impl Eq for Piece {}

impl PartialOrd for Piece {
    fn partial_cmp(&self, other: &Piece) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Piece {
    fn cmp(&self, other: &Piece) -> std::cmp::Ordering {
        self.bound.total_cmp(&other.bound)
    }
}

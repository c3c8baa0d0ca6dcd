//! Directed distances from an oriented point cloud (paper §3.1, "Point clouds", and §5.2): every
//! point with its normal is a small tangent plane element, and the signed distance of a query
//! point is its distance to the tangent plane of the nearest sample, `n·(p − q)`.
//!
//! A [`PointIndex`] (a kd-tree) answers the nearest-sample queries. Edge crossings are roots of the
//! tangent-plane distance along the edge: start from the linear interpolation of the end values,
//! take the plane of the sample nearest to that estimate, intersect the edge with it, and repeat
//! once from the new point ([`TangentPlanes`]). The crossing's normal is that sample's normal, so
//! a sharp edge sampled on both sides gives EMC the two planes it needs to place a feature point.

use super::edges::EdgeSampler;
use super::{mesh_with_sampler, EmcMesh, EmcOptions, EmcTimings};
use crate::error::Error;
use crate::grid::Grid;
use crate::input::PointCloud;
use crate::mc::ms_since;
use glam::Vec3;
use web_time::Instant;

/// Leaves of the kd-tree hold at most this many points.
const LEAF_SIZE: usize = 8;

/// A kd-tree over a point cloud: the points are reordered so that every subtree is a contiguous
/// range whose middle element splits it (on the axis stored for that element).
pub struct PointIndex {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    /// Per element: the split axis when it is the middle of an inner node's range.
    axes: Vec<u8>,
    /// Per element: its index in the cloud the index was built from.
    order: Vec<u32>,
}

impl PointIndex {
    /// Indexes `cloud`, which must pass [`PointCloud::validate`].
    pub fn new(cloud: &PointCloud) -> Result<PointIndex, Error> {
        cloud.validate()?;
        let mut order: Vec<u32> = (0..cloud.len() as u32).collect();
        let mut axes = vec![0u8; cloud.len()];
        build(&cloud.positions, &mut order, &mut axes, 0);
        Ok(PointIndex {
            positions: order.iter().map(|&i| cloud.positions[i as usize]).collect(),
            normals: order.iter().map(|&i| cloud.normals[i as usize]).collect(),
            axes,
            order,
        })
    }

    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The index in the indexed cloud of (reordered) sample `i`.
    pub fn original(&self, i: u32) -> usize {
        self.order[i as usize] as usize
    }

    /// Position and unit normal of (reordered) sample `i`.
    pub fn sample(&self, i: u32) -> (Vec3, Vec3) {
        (self.positions[i as usize], self.normals[i as usize])
    }

    /// The sample nearest to `p`. `guess`, any sample (typically the answer for a nearby point),
    /// seeds the search radius, which makes sweeps over a grid several times faster.
    pub fn nearest(&self, p: Vec3, guess: Option<u32>) -> u32 {
        self.search(p, guess, f32::INFINITY)
    }

    /// Like [`PointIndex::nearest`], exact when the nearest sample is within `exact_within` of `p`;
    /// farther away the answer may be up to half the excess over `exact_within` farther than the
    /// nearest. Far from all samples an exact nearest neighbour costs a lot (at the centre of a
    /// sampled sphere every sample is nearly the nearest) and buys nothing: only the side matters.
    pub fn nearest_approx(&self, p: Vec3, guess: Option<u32>, exact_within: f32) -> u32 {
        self.search(p, guess, exact_within)
    }

    fn search(&self, p: Vec3, guess: Option<u32>, exact_within: f32) -> u32 {
        let g = guess.filter(|&g| (g as usize) < self.len()).unwrap_or(0);
        let mut best = ((self.positions[g as usize] - p).length_squared(), g);
        let limit = |best: f32| {
            let d = best.sqrt();
            let r = d - 0.5 * (d - exact_within).max(0.0);
            r * r
        };
        let mut prune = limit(best.0);
        // (range start, range end, per-axis distance from p to the range's region)
        let mut stack: Vec<(usize, usize, Vec3)> = vec![(0, self.len(), Vec3::ZERO)];
        while let Some((lo, hi, gap)) = stack.pop() {
            if gap.length_squared() > prune {
                continue;
            }
            if hi - lo <= LEAF_SIZE {
                for i in lo..hi {
                    let d = (self.positions[i] - p).length_squared();
                    if d < best.0 {
                        best = (d, i as u32);
                        prune = limit(d);
                    }
                }
                continue;
            }
            let mid = (lo + hi) / 2;
            let d = (self.positions[mid] - p).length_squared();
            if d < best.0 {
                best = (d, mid as u32);
                prune = limit(d);
            }
            self.push_halves(&mut stack, p, (lo, mid, hi), gap);
        }
        best.1
    }

    /// Pushes the two halves of the range `lo..hi` split at `mid`, the one on `p`'s side on top; the
    /// far one lies beyond the splitting plane, so its gap to `p` grows to at least that distance.
    fn push_halves(
        &self,
        stack: &mut Vec<(usize, usize, Vec3)>,
        p: Vec3,
        (lo, mid, hi): (usize, usize, usize),
        gap: Vec3,
    ) {
        let axis = self.axes[mid] as usize;
        let offset = p[axis] - self.positions[mid][axis];
        let (near, far) = if offset < 0.0 { ((lo, mid), (mid + 1, hi)) } else { ((mid + 1, hi), (lo, mid)) };
        let mut far_gap = gap;
        far_gap[axis] = far_gap[axis].max(offset.abs());
        stack.push((far.0, far.1, far_gap));
        stack.push((near.0, near.1, gap));
    }

    /// The `k` samples nearest to `p`, nearest first, into `out` (cleared first).
    pub fn k_nearest(&self, p: Vec3, k: usize, out: &mut Vec<(f32, u32)>) {
        out.clear();
        if k == 0 {
            return;
        }
        // `out` stays sorted by squared distance; its last entry bounds the search once full.
        let offer = |out: &mut Vec<(f32, u32)>, i: usize| {
            let d = (self.positions[i] - p).length_squared();
            if out.len() == k && d >= out[k - 1].0 {
                return;
            }
            let at = out.partition_point(|e| e.0 <= d);
            if out.len() == k {
                out.pop();
            }
            out.insert(at, (d, i as u32));
        };
        let mut stack: Vec<(usize, usize, Vec3)> = vec![(0, self.len(), Vec3::ZERO)];
        while let Some((lo, hi, gap)) = stack.pop() {
            if out.len() == k && gap.length_squared() > out[k - 1].0 {
                continue;
            }
            if hi - lo <= LEAF_SIZE {
                for i in lo..hi {
                    offer(out, i);
                }
                continue;
            }
            let mid = (lo + hi) / 2;
            offer(out, mid);
            self.push_halves(&mut stack, p, (lo, mid, hi), gap);
        }
    }

    /// Signed distance from `p` to the tangent plane of sample `i`.
    pub fn plane_distance(&self, i: u32, p: Vec3) -> f32 {
        let (q, n) = self.sample(i);
        n.dot(p - q)
    }
}

/// Orders `order` (indices into `positions`) into a kd-tree: the middle element of every range of
/// more than [`LEAF_SIZE`] points is the median along the axis where the range spreads most.
fn build(positions: &[Vec3], order: &mut [u32], axes: &mut [u8], offset: usize) {
    if order.len() <= LEAF_SIZE {
        return;
    }
    let (lo, hi) = order.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
        let p = positions[i as usize];
        (lo.min(p), hi.max(p))
    });
    let spread = hi - lo;
    let axis = if spread.x >= spread.y && spread.x >= spread.z {
        0
    } else if spread.y >= spread.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        positions[a as usize][axis].total_cmp(&positions[b as usize][axis])
    });
    axes[offset + mid] = axis as u8;
    let (left, right) = order.split_at_mut(mid);
    build(positions, left, axes, offset);
    build(positions, &mut right[1..], axes, offset + mid + 1);
}

/// Neighbours consulted where the nearest sample's tangent plane is not trusted.
const NEIGHBOURS: usize = 8;

/// A tangent element decides the side of a point that lies in front of or behind it; one the point
/// lies beside (`|n·(p − q)| < BESIDE |p − q|`) is not trusted.
const BESIDE: f32 = 0.5;

/// Signed tangent-plane distance `n·(p − q)` at every grid point (negative inside), for the sample
/// `q` nearest to `p` (§3.1). Far from the samples these are distances to an extended plane, not
/// to the surface; only their signs matter there, so beyond two cells from every sample `q` may
/// be a near-nearest one ([`PointIndex::nearest_approx`]).
///
/// One exception keeps sharp edges from leaking: a sample near an edge extends its plane past the
/// edge, so a point outside the solid just beyond the other face can find that sample nearest and
/// land on the inside of its plane (and a stray inside point far from the surface becomes a
/// spurious bubble). So where `p` lies beside its nearest element rather than in front of or
/// behind it (`|n·(p − q)| < |p − q| / 2`), the element among the 8 nearest that `p` faces most
/// squarely (largest `|n·(p − q)| / |p − q|`) gives the value instead.
///
/// A surface the samples cover lies within their bounding box, so a grid point more than a cell
/// outside the box is outside whatever its nearest plane says: the value is at least the distance
/// to the box less a cell. Otherwise the tangent plane of a sample on a thin part, or at a sharp
/// edge seen from beyond it, can reach out to the grid's border and call points there inside,
/// and the surface would be cut open by the border. With the default grid (the box padded by two
/// cells) every border point is outside, so the output is closed.
pub fn grid_values(points: &PointIndex, grid: &Grid) -> Vec<f32> {
    let [nx, ny, nz] = grid.points();
    let mut values = vec![0.0f32; grid.point_count()];
    let mut guess = None;
    let mut neighbours = Vec::with_capacity(NEIGHBOURS);
    let band = 2.0 * grid.cell_size();
    let (lo, hi) = points
        .positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let outside_box = |p: Vec3| (lo - p).max(p - hi).max(Vec3::ZERO).length() - grid.cell_size();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let p = grid.position(i, j, k);
                let q = points.nearest_approx(p, guess, band);
                guess = Some(q);
                let mut value = points.plane_distance(q, p);
                let distance = (points.sample(q).0 - p).length();
                if value.abs() < BESIDE * distance {
                    points.k_nearest(p, NEIGHBOURS, &mut neighbours);
                    let facing = |&(d2, s): &(f32, u32)| {
                        points.plane_distance(s, p).abs() / d2.sqrt().max(f32::MIN_POSITIVE)
                    };
                    if let Some(best) = neighbours.iter().max_by(|a, b| facing(a).total_cmp(&facing(b))) {
                        value = points.plane_distance(best.1, p);
                    }
                }
                values[grid.index(i, j, k)] = value.max(outside_box(p));
            }
        }
    }
    values
}

/// EMC's edge crossings on a point cloud, in three steps:
/// 1. the linear interpolation of the end values (plain MC's estimate);
/// 2. the root of the tangent plane of the sample nearest to the estimate, refined once more from
///    the sample nearest to that root (§3.1's "nearest tangent element");
/// 3. among the 8 samples nearest to the result, the one whose tangent plane meets the edge
///    closest to the sample itself decides the crossing and its normal.
///
/// Step 3 matters at sharp edges: a sample next to an edge is often the nearest one for crossings
/// on the other face too, and its plane, extended past the edge, puts them up to a sample spacing
/// off the surface with the wrong normal. The plane of the most local element does not. Planes
/// (nearly) parallel to the edge or meeting it outside the segment are never used. With `directed`
/// off the crossing stays at the linear estimate, with the nearest sample's normal.
pub struct TangentPlanes<'a> {
    pub points: &'a PointIndex,
    pub directed: bool,
}

/// Tangent-plane refinements per crossing: the paper's "iterate once or twice".
const REFINEMENTS: usize = 2;

impl TangentPlanes<'_> {
    /// Where the tangent plane of sample `i` meets the line `a + s d`, if within the segment.
    fn root(&self, i: u32, a: Vec3, d: Vec3) -> Option<f32> {
        let (sample, n) = self.points.sample(i);
        let s = n.dot(sample - a) / n.dot(d);
        (s.is_finite() && (0.0..=1.0).contains(&s)).then_some(s)
    }
}

impl EdgeSampler for TangentPlanes<'_> {
    fn crossing(&self, a: Vec3, b: Vec3, da: f32, db: f32) -> (f32, Vec3) {
        let t = da / (da - db);
        let mut t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.5 };
        let d = b - a;
        let mut q = self.points.nearest(a + d * t, None);
        if !self.directed {
            return (t, self.points.sample(q).1);
        }
        for _ in 0..REFINEMENTS {
            let Some(s) = self.root(q, a, d) else { break };
            t = s;
            let next = self.points.nearest(a + d * t, Some(q));
            if next == q {
                break;
            }
            q = next;
        }
        let mut neighbours = Vec::with_capacity(NEIGHBOURS);
        self.points.k_nearest(a + d * t, NEIGHBOURS, &mut neighbours);
        let mut best = (f32::INFINITY, t, q);
        for &(_, i) in &neighbours {
            if let Some(s) = self.root(i, a, d) {
                let off = (a + d * s - self.points.sample(i).0).length();
                if off < best.0 {
                    best = (off, s, i);
                }
            }
        }
        (best.1, self.points.sample(best.2).1)
    }
}

/// EMC surface reconstruction from an oriented point cloud on `grid` (paper §5.2). The cloud
/// should cover the surface densely compared with the grid's cells, and its normals must point
/// out of the solid; `options.crust` does not apply and `options.iso` offsets the tangent-plane
/// distances would not be distances to the surface, so it must be 0.
pub fn reconstruct(
    points: &PointCloud,
    grid: &Grid,
    options: &EmcOptions,
) -> Result<(EmcMesh, EmcTimings), Error> {
    options.validate()?;
    if options.iso != 0.0 {
        return Err(Error::InvalidOption(format!(
            "iso must be 0 when reconstructing from points (the surface is the samples' tangent planes), got {}",
            options.iso
        )));
    }
    grid.check_size(options.max_cells)?;
    let t0 = Instant::now();
    let index = PointIndex::new(points)?;
    let values = grid_values(&index, grid);
    let sample_ms = ms_since(t0);
    let sampler = TangentPlanes { points: &index, directed: options.directed };
    let (mut out, mut timings) = mesh_with_sampler(&values, grid, options, &sampler)?;
    out.points_evaluated = grid.point_count();
    timings.sample_ms = sample_ms;
    Ok((out, timings))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(n: usize) -> PointCloud {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let positions: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next())).collect();
        let normals = positions.iter().map(|p| p.normalize_or(Vec3::X)).collect();
        PointCloud { positions, normals }
    }

    #[test]
    fn nearest_matches_brute_force() {
        for n in [1, 5, 9, 100, 1000] {
            let c = cloud(n);
            let index = PointIndex::new(&c).unwrap();
            for (k, &p) in cloud(50).positions.iter().enumerate() {
                let p = p * 1.5;
                let found = index.sample(index.nearest(p, Some(k as u32))).0;
                let brute =
                    c.positions.iter().map(|q| (*q - p).length_squared()).fold(f32::INFINITY, f32::min);
                assert_eq!((found - p).length_squared(), brute, "n = {n}, p = {p}");
                // Approximate beyond 0.1: never more than half the excess over 0.1 too far.
                let approx = (index.sample(index.nearest_approx(p, None, 0.1)).0 - p).length();
                let brute = brute.sqrt();
                assert!(approx - 0.5 * (approx - 0.1).max(0.0) <= brute + 1e-6, "n = {n}, p = {p}");
                if brute < 0.1 {
                    assert_eq!(approx, brute);
                }
            }
        }
    }

    #[test]
    fn k_nearest_matches_brute_force() {
        let c = cloud(500);
        let index = PointIndex::new(&c).unwrap();
        let mut out = Vec::new();
        for &p in &cloud(20).positions {
            index.k_nearest(p, 8, &mut out);
            let mut brute: Vec<f32> = c.positions.iter().map(|q| (*q - p).length_squared()).collect();
            brute.sort_by(f32::total_cmp);
            let found: Vec<f32> = out.iter().map(|e| e.0).collect();
            assert_eq!(found, brute[..8].to_vec());
        }
        index.k_nearest(Vec3::ZERO, 1000, &mut out);
        assert_eq!(out.len(), 500);
    }

    #[test]
    fn crossings_lie_on_the_tangent_plane() {
        // Samples of the plane z = 0.3 (normal +z), on a lattice.
        let mut c = PointCloud::default();
        for i in -10..=10 {
            for j in -10..=10 {
                c.positions.push(Vec3::new(i as f32 * 0.1, j as f32 * 0.1, 0.3));
                c.normals.push(Vec3::Z);
            }
        }
        let index = PointIndex::new(&c).unwrap();
        let sampler = TangentPlanes { points: &index, directed: true };
        let (a, b) = (Vec3::new(0.23, 0.41, 0.0), Vec3::new(0.23, 0.41, 0.5));
        let (da, db) = (index.plane_distance(index.nearest(a, None), a), 0.2);
        let (t, n) = sampler.crossing(a, b, da, db);
        assert!((t - 0.6).abs() < 1e-6, "{t}");
        assert_eq!(n, Vec3::Z);
    }

    #[test]
    fn invalid_clouds_are_refused() {
        let grid = Grid::new(Vec3::ZERO, Vec3::ONE, [4, 4, 4]).unwrap();
        let empty = PointCloud::default();
        assert!(reconstruct(&empty, &grid, &EmcOptions::default()).is_err());
        let mut c = cloud(10);
        c.normals.pop();
        assert!(reconstruct(&c, &grid, &EmcOptions::default()).is_err());
        let bad = EmcOptions { iso: 0.1, ..EmcOptions::default() };
        assert!(reconstruct(&cloud(10), &grid, &bad).is_err());
    }
}

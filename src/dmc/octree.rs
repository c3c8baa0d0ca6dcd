//! Top-down octree construction (§2.1): a cell is sampled on a `samples_per_cell³` grid, the QEF of
//! the samples' tangent planes is minimised, and the cell is split while the residual exceeds the
//! tolerance and the depth allows.
//!
//! **Only near the surface.** The residual splits a cell only if the surface may pass through it:
//! some sample's distance estimate `|f - iso| / |∇f|` is within half a sample spacing's diagonal
//! (every point of the cell is that close to a sample, so a surface point in the cell puts the
//! nearest sample at most that far from it; exact for distance fields, first order otherwise).
//! Elsewhere the function's curvature (a distance field is rounded outside every convex edge, out to
//! infinity) split cells to the maximum depth that no contour uses: their vertices only matter
//! through their sign, which is far from zero there, and crossings are found by root finding. The
//! refinement rules of `refine.rs` still split such a cell when the contour asks; its children
//! follow the same rule. Measured at depth 6 over the scenes: 10–50 % fewer leaves, the same
//! triangles within 5 % and the same maximum error.
//!
//! With pruning, a cell whose interval bounds (from [`Field::interval`]) exclude the iso-level is
//! not sampled at all: it becomes a *pruned* leaf with its vertex at its centre. Pruning is only
//! provisional: [`crate::dmc::refine`] un-prunes every pruned leaf that touches a leaf on the other
//! side of the iso-level, and an un-pruned cell is treated exactly as without pruning. That makes the
//! final output identical to the unpruned one (the argument is in `refine.rs`).
//!
//! Coordinates are integers in units of the finest cell, so the geometry of a cell never depends on
//! the order cells were built in.

use super::qef::Qef;
use crate::error::Error;
use crate::field::{gradients_or_differences, Field};
use glam::Vec3;

pub const NONE: u32 = u32::MAX;

/// Deepest octree the options accept: 2^16 finest cells per side is far below `f32` resolution
/// trouble and far beyond what fits in memory near a surface.
pub const MAX_DEPTH_LIMIT: u8 = 16;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Internal,
    /// A sampled leaf with a QEF.
    Leaf,
    /// A leaf skipped because the surface cannot reach it (interval bounds); its vertex is its centre.
    Pruned,
}

#[derive(Debug, Clone, Copy)]
pub struct Node {
    /// Lowest corner, in units of the finest cell.
    pub coord: [u32; 3],
    pub depth: u8,
    pub kind: Kind,
    /// First of the eight children (octant `c = x | y << 1 | z << 2`), for internal nodes.
    pub children: u32,
    /// Index into [`Octree::qefs`], for sampled leaves.
    pub qef: u32,
    /// [`Qef::rank`] of that QEF, computed once (feature isolation asks every round).
    pub rank: u8,
    /// Some samples lie inside and some outside: the surface passes through the cell.
    pub straddles: bool,
    /// Every sample lies inside (below the iso-level).
    pub inside: bool,
    /// Sliver elimination put the vertex on the surface (restricted QEF).
    pub on_surface: bool,
    /// Sliver elimination must not move this vertex: a neighbour holds a feature.
    pub keep_free: bool,
    /// The vertex stays at the cell's centre: feature placement folded the contour here.
    pub centred: bool,
    /// A centred vertex keeps the side of the iso-level its free vertex is on: at the centre that
    /// side would change the contour's topology (see [`crate::dmc::refine::keep_signs`]).
    pub keep_sign: bool,
    /// [`crate::dmc::refine::keep_signs`] has decided `keep_sign`.
    pub centre_checked: bool,
    /// The dual vertex (set by feature isolation) and `f - iso` there.
    pub vertex: Vec3,
    pub value: f32,
    pub has_vertex: bool,
    /// The vertex is kept in the leaf whatever [`Params::vertex_reach`] allows: out of it, it
    /// folded the contour or made it cross itself (refinement rules 4 and 5).
    pub confined: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    pub iso: f32,
    /// Largest accepted QEF residual (root-mean-square 4-D distance, world units).
    pub tolerance: f32,
    pub max_depth: u8,
    pub samples_per_cell: usize,
    pub prune: bool,
    pub max_leaves: u64,
    /// Refinement rule 3 (see [`crate::dmc::refine`]) is applied.
    pub accuracy_rule: bool,
    /// How far a leaf's free vertex may leave its leaf, as a fraction of its side
    /// ([`crate::dmc::DmcOptions::vertex_reach`]).
    pub vertex_reach: f32,
}

pub struct Octree {
    pub nodes: Vec<Node>,
    pub qefs: Vec<Qef>,
    /// The root cube: lowest corner and side.
    pub min: Vec3,
    pub size: f32,
    pub params: Params,
    leaves: u64,
    /// Working memory of [`Octree::sample`], kept across cells.
    points: Vec<Vec3>,
    values: Vec<f32>,
    exact: Vec<Option<Vec3>>,
    gradients: Vec<Vec3>,
}

impl Node {
    /// A new leaf at `coord` and `depth`, not sampled yet.
    fn unsampled(coord: [u32; 3], depth: u8) -> Node {
        Node {
            coord,
            depth,
            kind: Kind::Leaf,
            children: NONE,
            qef: NONE,
            rank: 0,
            straddles: false,
            inside: false,
            on_surface: false,
            keep_free: false,
            centred: false,
            keep_sign: false,
            centre_checked: false,
            vertex: Vec3::ZERO,
            value: 0.0,
            has_vertex: false,
            confined: false,
        }
    }
}

impl Octree {
    /// Builds the octree over the cube `[min, min + size]`.
    pub fn build(field: &dyn Field, min: Vec3, size: f32, params: Params) -> Result<Octree, Error> {
        let mut tree = Octree {
            nodes: vec![Node::unsampled([0; 3], 0)],
            qefs: Vec::new(),
            min,
            size,
            params,
            leaves: 1,
            points: Vec::new(),
            values: Vec::new(),
            exact: Vec::new(),
            gradients: Vec::new(),
        };
        tree.decide(field, 0, params.prune)?;
        Ok(tree)
    }

    /// Leaves, pruned ones included.
    pub fn leaf_count(&self) -> u64 {
        self.leaves
    }

    /// Side of a cell at `depth`.
    pub fn cell_size(&self, depth: u8) -> f32 {
        self.size / (1u64 << depth) as f32
    }

    /// The cell of node `n` as (lowest corner, highest corner).
    pub fn cell(&self, n: u32) -> (Vec3, Vec3) {
        let node = &self.nodes[n as usize];
        let unit = self.size / (1u64 << self.params.max_depth) as f32;
        let span = 1u32 << (self.params.max_depth - node.depth);
        let lo = node.coord.map(|c| c as f32 * unit);
        let hi = node.coord.map(|c| (c + span) as f32 * unit);
        (self.min + Vec3::from(lo), self.min + Vec3::from(hi))
    }

    /// Splits a sampled leaf regardless of its residual (refinement asked for by the surface).
    pub fn refine(&mut self, field: &dyn Field, n: u32) -> Result<(), Error> {
        debug_assert_eq!(self.nodes[n as usize].kind, Kind::Leaf);
        self.split(field, n, self.params.prune)
    }

    /// Treats a pruned leaf as the unpruned construction would: sample it, split it if needed. Its
    /// descendants are not pruned again: a cell next to the surface would mostly be un-pruned piece
    /// by piece, one pass of the dual grid each.
    pub fn unprune(&mut self, field: &dyn Field, n: u32) -> Result<(), Error> {
        debug_assert_eq!(self.nodes[n as usize].kind, Kind::Pruned);
        self.nodes[n as usize].kind = Kind::Leaf;
        self.nodes[n as usize].has_vertex = false;
        self.decide(field, n, false)
    }

    /// Decides a fresh leaf: pruned, kept, or split (recursively).
    fn decide(&mut self, field: &dyn Field, n: u32, allow_prune: bool) -> Result<(), Error> {
        let (lo, hi) = self.cell(n);
        let iso = self.params.iso;
        if allow_prune {
            if let Some((a, b)) = field.interval(lo, hi) {
                if a > iso || b < iso {
                    let centre = (lo + hi) * 0.5;
                    let node = &mut self.nodes[n as usize];
                    node.kind = Kind::Pruned;
                    node.vertex = centre;
                    node.value = field.value(centre) - iso;
                    node.has_vertex = true;
                    return Ok(());
                }
            }
        }
        let (qef, below, above, nearest) = self.sample(field, n, lo, hi)?;
        let depth = self.nodes[n as usize].depth;
        // Half the diagonal of the samples' spacing: every point of the cell is that close to a sample.
        let reach = 0.5 * (hi - lo).length() / (self.params.samples_per_cell - 1) as f32;
        let far = nearest > reach;
        let solution = qef.minimise_in_box(lo, hi, None);
        if !far && solution.rms > self.params.tolerance as f64 && depth < self.params.max_depth {
            return self.split(field, n, allow_prune);
        }
        let node = &mut self.nodes[n as usize];
        node.kind = Kind::Leaf;
        node.straddles = below && above;
        node.inside = below && !above;
        node.qef = self.qefs.len() as u32;
        node.rank = qef.rank() as u8;
        self.qefs.push(qef);
        Ok(())
    }

    fn split(&mut self, field: &dyn Field, n: u32, allow_prune: bool) -> Result<(), Error> {
        let parent = self.nodes[n as usize];
        if parent.depth >= self.params.max_depth {
            return Ok(());
        }
        self.leaves += 7;
        if self.leaves > self.params.max_leaves {
            return Err(Error::InvalidOption(format!(
                "the octree needs more than {} leaves of {} samples each, more work than maxCells \
                 allows; raise the tolerance, lower the maximum depth or raise maxCells",
                self.params.max_leaves,
                self.params.samples_per_cell.pow(3)
            )));
        }
        let first = self.nodes.len() as u32;
        let half = 1u32 << (self.params.max_depth - parent.depth - 1);
        for c in 0..8u32 {
            let offset = [c & 1, (c >> 1) & 1, (c >> 2) & 1];
            self.nodes.push(Node::unsampled(
                std::array::from_fn(|a| parent.coord[a] + offset[a] * half),
                parent.depth + 1,
            ));
        }
        let node = &mut self.nodes[n as usize];
        node.kind = Kind::Internal;
        node.children = first;
        node.has_vertex = false;
        for c in 0..8 {
            self.decide(field, first + c, allow_prune)?;
        }
        Ok(())
    }

    /// Samples the closed cell on a regular grid, first and last samples on its faces: the QEF of
    /// their tangent planes, whether some lie below and some at or above the iso-level, and the
    /// smallest distance estimate `|f - iso| / |∇f|` of a sample from the surface.
    ///
    /// Samples on the faces matter: with cell-centred samples a feature within an eighth of a cell of
    /// a face (a box edge at 0.0024 from it, in the measured case) lies outside every sample's
    /// region, the QEF sees one side of it, and the edge is chamfered down to the finest level.
    fn sample(
        &mut self,
        field: &dyn Field,
        n: u32,
        lo: Vec3,
        hi: Vec3,
    ) -> Result<(Qef, bool, bool, f32), Error> {
        let k = self.params.samples_per_cell;
        self.points.clear();
        for z in 0..k {
            for y in 0..k {
                for x in 0..k {
                    let t = Vec3::new(x as f32, y as f32, z as f32) / (k - 1) as f32;
                    self.points.push(lo + (hi - lo) * t);
                }
            }
        }
        self.values.resize(self.points.len(), 0.0);
        field.values(&self.points, &mut self.values);
        let mut qef = Qef::new((lo + hi) * 0.5);
        let (mut below, mut above) = (false, false);
        let mut nearest = f32::INFINITY;
        let h = (hi - lo).max_element() * 1e-3;
        gradients_or_differences(field, &self.points, h, &mut self.exact, &mut self.gradients);
        for ((&p, &v), &g) in self.points.iter().zip(&self.values).zip(&self.gradients) {
            if !v.is_finite() || !g.is_finite() {
                // The value, or else the first bad gradient component, names the problem.
                let bad = std::iter::once(v).chain(g.to_array()).find(|c| !c.is_finite());
                return Err(Error::NonFiniteSample {
                    index: self.nodes[n as usize].coord.map(|c| c as usize),
                    position: p.to_array(),
                    value: bad.unwrap_or(f32::NAN),
                });
            }
            let d = v - self.params.iso;
            below |= d < 0.0;
            above |= d >= 0.0;
            nearest = nearest.min(d.abs() / g.length());
            qef.add(p, d, g);
        }
        Ok((qef, below, above, nearest))
    }

    /// Leaves (sampled and pruned) in node order.
    pub fn leaves(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.nodes.len() as u32).filter(|&n| self.nodes[n as usize].kind != Kind::Internal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::compile;

    fn params(prune: bool) -> Params {
        Params {
            iso: 0.0,
            tolerance: 1e-3,
            max_depth: 5,
            samples_per_cell: 3,
            prune,
            max_leaves: 1 << 20,
            accuracy_rule: true,
            vertex_reach: 0.0,
        }
    }

    #[test]
    fn a_plane_needs_no_subdivision_and_a_curved_function_does() {
        let plane = compile("x + 0.3 * y - 0.1").unwrap();
        let tree = Octree::build(&plane, Vec3::splat(-1.0), 2.0, params(false)).unwrap();
        assert_eq!(tree.leaf_count(), 1);
        // A paraboloid's tangent planes meet nowhere (a distance field's would: at the centre).
        let bowl = compile("(x - 0.3)^2 + (y - 0.2)^2 + (z - 0.1)^2 - 0.25").unwrap();
        let tree = Octree::build(&bowl, Vec3::splat(-1.0), 2.0, params(false)).unwrap();
        assert!(tree.leaf_count() > 8, "{}", tree.leaf_count());
        // Every leaf the surface (the sphere of radius 0.5) passes through is either accepted or at
        // the maximum depth; some leaves away from it are neither (their residual is not looked at).
        let centre = Vec3::new(0.3, 0.2, 0.1);
        let mut coarse_far = 0;
        for n in tree.leaves() {
            let node = tree.nodes[n as usize];
            let (lo, hi) = tree.cell(n);
            let rms = tree.qefs[node.qef as usize].minimise_in_box(lo, hi, None).rms;
            let nearest = (centre.clamp(lo, hi) - centre).length();
            let farthest = (centre - (lo + hi) * 0.5).abs() + (hi - lo) * 0.5;
            let on_surface = nearest <= 0.5 && farthest.length() >= 0.5;
            assert!(rms <= 1e-3 || node.depth == 5 || !on_surface, "leaf {n} rms {rms}");
            coarse_far += (rms > 1e-3 && node.depth < 5) as usize;
        }
        assert!(coarse_far > 0);
    }

    #[test]
    fn pruning_skips_cells_away_from_the_surface() {
        let ball = compile("x^2 + y^2 + z^2 - 0.25").unwrap();
        let full = Octree::build(&ball, Vec3::splat(-1.0), 2.0, params(false)).unwrap();
        let pruned = Octree::build(&ball, Vec3::splat(-1.0), 2.0, params(true)).unwrap();
        assert!(pruned.leaf_count() <= full.leaf_count());
        assert!(pruned.nodes.iter().any(|n| n.kind == Kind::Pruned));
        for n in pruned.leaves().filter(|&n| pruned.nodes[n as usize].kind == Kind::Pruned) {
            let (lo, hi) = pruned.cell(n);
            let (a, b) = ball.eval_interval(lo, hi);
            assert!(a > 0.0 || b < 0.0);
        }
    }

    #[test]
    fn too_many_leaves_is_an_error() {
        let ball = compile("x^2 + y^2 + z^2 - 0.25").unwrap();
        let p = Params { max_leaves: 20, tolerance: 0.0, ..params(false) };
        let err = Octree::build(&ball, Vec3::splat(-1.0), 2.0, p).err().unwrap();
        assert!(err.to_string().contains("maxCells"), "{err}");
    }
}

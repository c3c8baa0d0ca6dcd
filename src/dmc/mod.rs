//! Dual Marching Cubes (Schaefer & Warren 2004): an octree adapted to the *function*, one vertex per
//! leaf on the function's features, and Marching Cubes on the dual grid those vertices span. Thin
//! walls and sharp edges come out of a coarse octree because the vertices sit on the creases and
//! ridges of the field, not on a lattice.
//!
//! The octree is built in one pass, bottom-up, so that what is right at the finest level stays
//! right (the phases, one file each):
//! - [`tree`]: the octree of cubic finest cells, clipped to the bounds.
//! - [`build`]: the crust (every finest cell the surface may reach, by interval bounds, never by
//!   samples) and its sampling: one 4-D QEF ([`qef`]) per crust cell.
//! - [`simplify`]: eight leaves become one where their summed QEF fits one vertex within the
//!   tolerance, [`safety`] proves the contour's topology unchanged and [`fidelity`] finds the
//!   merged triangles within the tolerance of the surface.
//! - [`dual`]: the dual cells, one per octree vertex, the grid's boundary included.
//! - [`contour`]: Marching Cubes on the dual cells, crossings by root finding per dual edge,
//!   ambiguous faces decided by the field at their centres ([`faces`]).
//! - [`slivers`]: crossings within a tenth of a cell of a dual vertex moved onto it, the slivers
//!   between them dropped; then the slivers, spikes and specks left removed by checked edge
//!   collapses and flips (no vertex moves off the surface, the topology is kept).
//! - [`untangle`]: vertices of folded or crossing triangles moved toward their leaves' centres,
//!   keeping their signs (so the topology), in a bounded number of rounds.
//!
//! **What is guaranteed.** The contour of the simplified octree is homeomorphic to the contour of
//! the unsimplified finest level (every merge passes [`safety`]), and closed. The finest level's
//! contour is Marching Cubes on the lattice of the finest cells' vertices: its topology is the
//! surface's wherever the surface's features are wider than a finest cell, and a wall thinner
//! than a cell is kept wherever a vertex falls inside it (the QEF puts the vertex on the wall's
//! medial ridge). Vertices stay inside their leaves; that does not keep every dual cell convex,
//! so the mesh may fold or cross itself near features, which [`untangle`] repairs without
//! changing any vertex's side (so without changing the topology), where it can.
//!
//! **Options.** `tolerance` is a fraction of the longest side of the bounds: the largest
//! root-mean-square 4-D distance of a leaf's sampled tangent planes from its vertex, and the
//! largest distance of a merged leaf's triangles from the surface. `max_depth`
//! sets the finest level (`2^max_depth` finest cells along the longest side, the `res` reported).

pub mod bounds;
pub mod build;
pub mod contour;
pub mod dual;
pub mod faces;
pub mod fidelity;
pub mod qef;
pub mod safety;
pub mod simplify;
pub mod slivers;
pub mod tree;
pub mod untangle;

use crate::error::Error;
use crate::field::Field;
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::ms_since;
use crate::mesh::Mesh;
use contour::DualVertices;
use tree::{Octree, MAX_DEPTH_LIMIT};
use web_time::Instant;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DmcOptions {
    pub iso: f32,
    /// Error tolerance as a fraction of the longest side of the bounds (see the module docs).
    pub tolerance: f32,
    /// Deepest octree level: the finest cells are `1 / 2^max_depth` of the bounds' longest side.
    pub max_depth: u8,
    /// Samples per finest cell along each axis, its corners included (shared with neighbours).
    pub samples_per_cell: usize,
    /// The work cap, in grid cells' worth of samples: a crust of more than
    /// `max_cells / samples_per_cell³` finest cells is refused.
    pub max_cells: u64,
    /// Bottom-up simplification; off, the finest level is contoured as it is (the reference the
    /// simplified contour's topology is proven equal to).
    pub simplify: bool,
}

impl Default for DmcOptions {
    /// `tolerance` 1e-3 of the bounds, `max_depth` 7 (128 finest cells along the longest side, the
    /// resolution where Marching Cubes is usually compared), 3 samples per cell edge (corners and
    /// midpoints: both sides of a thin wall in a cell are seen).
    fn default() -> Self {
        DmcOptions {
            iso: 0.0,
            tolerance: 1e-3,
            max_depth: 7,
            samples_per_cell: 3,
            max_cells: DEFAULT_MAX_CELLS,
            simplify: true,
        }
    }
}

impl DmcOptions {
    pub(crate) fn validate(&self) -> Result<(), Error> {
        let bad = |msg: String| Err(Error::InvalidOption(msg));
        if !self.iso.is_finite() {
            return bad(format!("iso must be finite, got {}", self.iso));
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return bad(format!(
                "tolerance is a fraction of the bounds and must be finite and ≥ 0, got {}",
                self.tolerance
            ));
        }
        if self.max_depth > MAX_DEPTH_LIMIT {
            return bad(format!("maxDepth must be at most {MAX_DEPTH_LIMIT}, got {}", self.max_depth));
        }
        if !(2..=16).contains(&self.samples_per_cell) {
            return bad(format!("samplesPerCell must lie in 2..=16, got {}", self.samples_per_cell));
        }
        if self.max_cells == 0 {
            return bad("maxCells must be at least 1".into());
        }
        Ok(())
    }
}

/// What a run built, and how long each phase took.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DmcStats {
    /// Leaves of the final octree, empty ones included.
    pub octree_leaves: usize,
    /// Leaves the interval bounds proved empty (wholly inside or outside).
    pub pruned_leaves: usize,
    /// Dual cells the surface crosses.
    pub dual_cells: usize,
    /// Finest cells the surface may reach, each sampled.
    pub crust_cells: usize,
    /// Field samples taken for the QEFs.
    pub samples: usize,
    /// Merges made, and merges the QEF allowed but the topological safety test refused.
    pub merges: usize,
    pub unsafe_merges: usize,
    /// Merges refused because their triangles would stray beyond the tolerance, and because the
    /// QEF's residual was above it.
    pub inaccurate_merges: usize,
    pub qef_refused_merges: usize,
    /// Triangles crossing another or folded onto a neighbour, before and after [`untangle`], and
    /// the vertices it moved.
    pub crossing_triangles_before: usize,
    pub crossing_triangles: usize,
    pub moved_vertices: usize,
    pub unmerged_leaves: usize,
    /// What [`slivers::improve`] did to the final contour: collapses, flips, bad triangles
    /// (slivers, spikes, specks) before and left.
    pub improved: slivers::Improved,
    pub crust_ms: f64,
    pub sampling_ms: f64,
    pub simplify_ms: f64,
    pub dual_ms: f64,
    pub contour_ms: f64,
    pub untangle_ms: f64,
}

impl DmcStats {
    /// The phases by name, in pipeline order, for [`crate::stats::Stats`]. The names are the ones
    /// DMC has always reported: `octree` is the crust and the simplification, `feature_isolation`
    /// the sampling and the vertices' placement, `topology` listing the dual cells; `untangling`
    /// is new.
    pub fn phases(&self) -> Vec<(String, f64)> {
        vec![
            ("octree".to_string(), self.crust_ms + self.simplify_ms),
            ("feature_isolation".to_string(), self.sampling_ms),
            ("topology".to_string(), self.dual_ms),
            ("contouring".to_string(), self.contour_ms),
            ("untangling".to_string(), self.untangle_ms),
        ]
    }
}

/// Marching Cubes on the dual cells given by their keys.
fn contour_cells(
    tree: &Octree,
    keys: &[[dual::VertexKey; 8]],
    field: &dyn Field,
    iso: f32,
    tolerance: f32,
    cache: &mut contour::RootCache,
    history: &mut slivers::History,
) -> (contour::Contour, slivers::Improved) {
    let mut vertices = DualVertices::default();
    let cells: Vec<[u32; 8]> = keys.iter().map(|cell| cell.map(|k| vertices.id(tree, k))).collect();
    vertices.evaluate(field, iso);
    let mut contour = contour::contour(&cells, &vertices, field, iso, cache);
    slivers::collapse(&mut contour, &vertices, tree.h);
    let improved = slivers::improve(&mut contour, field, iso, tolerance, tree.h, history);
    (contour, improved)
}

/// The finest grid of a DMC run over `[min, max]`: `2^max_depth` cubic cells along the longest
/// side, the grid Marching Cubes uses at that resolution.
pub fn finest_grid(min: glam::Vec3, max: glam::Vec3, max_depth: u8) -> Result<Grid, Error> {
    Grid::with_resolution(min, max, 1usize << max_depth)
}

/// Meshes the `iso` level of `field` inside the box `[min, max]`: the octree's finest cells are
/// cubes, `2^max_depth` of them along the longest side, and the bounds cut the last ones along the
/// shorter sides (nothing is sampled outside the bounds).
pub fn mesh_field(
    field: &dyn Field,
    min: glam::Vec3,
    max: glam::Vec3,
    options: &DmcOptions,
) -> Result<(Mesh, DmcStats), Error> {
    options.validate()?;
    // The bounds' checks (finite, ordered, not degenerate) and the finest cells' size.
    finest_grid(min, max, options.max_depth)?;
    let clipped = bounds::Clipped::new(field, options.iso, min, max);
    let field: &dyn Field = &clipped;
    // The clipped field is the distance from `options.iso`: its level is 0.
    let iso = 0.0;
    let mut stats = DmcStats::default();

    crate::progress::checkpoint("octree", 0.0)?;
    let t = Instant::now();
    let mut tree = Octree::new(min, max, options.max_depth);
    let mut built = build::crust(&mut tree, field, iso, options.samples_per_cell, options.max_cells)?;
    stats.crust_ms = ms_since(t);

    let longest = (max - min).max_element();
    let tolerance = options.tolerance * longest;
    crate::progress::checkpoint("octree", 0.5)?;
    let t = Instant::now();
    build::sample(&mut tree, &clipped, iso, options.samples_per_cell, &mut built);
    stats.sampling_ms = ms_since(t);
    stats.crust_cells = built.crust_cells;
    stats.samples = built.samples;

    crate::progress::checkpoint("feature_isolation", 0.0)?;
    let t = Instant::now();
    if options.simplify {
        let s = simplify::simplify(&mut tree, field, iso, tolerance)?;
        stats.merges = s.merged;
        stats.unsafe_merges = s.unsafe_merges;
        stats.inaccurate_merges = s.inaccurate_merges;
        stats.qef_refused_merges = s.qef_refused;
    }
    stats.simplify_ms = ms_since(t);

    let t = Instant::now();
    let mut keys = Vec::new();
    dual::for_each_mixed_cell(&tree, |cell| keys.push(*cell));
    stats.dual_cells = keys.len();
    stats.dual_ms = ms_since(t);
    crate::progress::checkpoint("contouring", 0.0)?;
    let t = Instant::now();
    let mut moves = vec![0u8; tree.nodes.len()];
    let mut origins = rustc_hash::FxHashMap::default();
    let mut roots = contour::RootCache::default();
    let mut history = slivers::History::default();
    let (mut contour, mut improved) =
        contour_cells(&tree, &keys, field, iso, tolerance, &mut roots, &mut history);
    stats.contour_ms = ms_since(t);
    let t = Instant::now();
    for round in 0..=untangle::ROUNDS {
        crate::progress::checkpoint("untangling", round as f32 / untangle::ROUNDS as f32)?;
        let offending = untangle::offending_triangles(&contour.mesh);
        stats.crossing_triangles = offending.len();
        if round == 0 {
            stats.crossing_triangles_before = offending.len();
        }
        if offending.is_empty() || round == untangle::ROUNDS {
            break;
        }
        let cells: Vec<&[dual::VertexKey; 8]> =
            offending.iter().map(|&t| &keys[contour.cell_of_triangle[t as usize] as usize]).collect();
        let (moved, unmerged) =
            untangle::move_toward_centres(&mut tree, field, iso, &cells, &mut moves, &mut origins);
        stats.moved_vertices += moved;
        stats.unmerged_leaves += unmerged;
        if unmerged > 0 {
            keys.clear();
            dual::for_each_mixed_cell(&tree, |cell| keys.push(*cell));
            stats.dual_cells = keys.len();
        }
        (contour, improved) = contour_cells(&tree, &keys, field, iso, tolerance, &mut roots, &mut history);
    }
    stats.improved = improved;
    let mut mesh = contour.mesh;
    contour::field_normals(&mut mesh, field, tree.h * 1e-2);
    stats.untangle_ms = ms_since(t);

    let leaves = tree.leaves();
    stats.octree_leaves = leaves.len();
    stats.pruned_leaves =
        leaves.iter().filter(|&&n| matches!(tree.nodes[n as usize].kind, tree::Kind::Empty { .. })).count();
    Ok((mesh, stats))
}

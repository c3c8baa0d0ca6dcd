//! Dual Marching Cubes (Schaefer & Warren 2004): an octree adapted to the *function*, one vertex per
//! leaf on the function's features, and Marching Cubes on the dual grid those vertices span. Thin
//! walls and sharp edges come out of a coarse octree because the vertices sit on the creases and
//! ridges of the field, not on a lattice.
//!
//! The phases, one file each:
//! - [`qef`]: the 4-D QEF of the graph's tangent planes and its minimiser inside a box.
//! - [`octree`]: top-down construction by QEF residual, with interval pruning.
//! - [`features`]: feature isolation — the vertex of every leaf and of the boundary cells.
//! - [`dual`]: the cellProc/faceProc/edgeProc/vertProc traversal listing the dual cells, the root's
//!   boundary included.
//! - [`contour`]: Marching Cubes on the dual cells, crossings shared per dual edge.
//! - [`memo`]: root finding, gradients and triangle errors remembered across refinement rounds.
//! - [`refine`]: the fixpoints run once the dual grid is known (un-pruning, representing every
//!   straddling leaf, splitting leaves under inaccurate triangles).
//! - [`slivers`]: collapsing the tiny triangles around vertices that lie on the surface (and
//!   [`crate::mesh::pleats`] triangulating again flat discs where a triangle is turned over).
//!
//! **Options.** `tolerance` is a fraction of the longest side of the bounds; it bounds both the QEF
//! residual of a leaf (root-mean-square 4-D distance of its sampled tangent planes from its vertex)
//! and the estimated distance of every triangle from the surface (refinement rule 3). `max_depth`
//! caps the octree (`2^max_depth` finest cells along the longest side, the `res` reported).

pub mod bounds;
pub mod contour;
pub mod dual;
pub mod features;
pub mod memo;
pub mod octree;
pub mod qef;
pub mod refine;
pub mod slivers;

use crate::error::Error;
use crate::field::Field;
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::ms_since;
use crate::mesh::pleats::unpleat;
use crate::mesh::Mesh;
use dual::CellRef;
use features::DualVertices;
use glam::Vec3;
use octree::{Octree, Params, MAX_DEPTH_LIMIT};
use web_time::Instant;

/// The root cube is the bounds' cube grown by this factor and placed slightly off-centre (a fraction
/// [`ROOT_BELOW_CENTRE`] of it below the bounds' centre), so that the round coordinates CSG models
/// are written in (0, ±0.5, ±0.25, …) do not fall on cell faces at any depth. A thin wall lying in a
/// cell face is seen from one side only by each of the two cells sharing it: both fit one plane,
/// both vertices land outside the wall, and the wall is lost until refinement resolves it.
pub const ROOT_GROWTH: f32 = 1.05;
pub const ROOT_BELOW_CENTRE: f32 = 0.49;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DmcOptions {
    pub iso: f32,
    /// Error tolerance as a fraction of the longest side of the bounds (see the module docs).
    pub tolerance: f32,
    /// Deepest octree level: the finest cells are `1 / 2^max_depth` of the bounds' longest side.
    pub max_depth: u8,
    /// Samples per cell along each axis for the QEF (`samples_per_cell³` per cell).
    pub samples_per_cell: usize,
    /// §4: put vertices on the surface where the QEF allows it, then collapse the slivers around
    /// them.
    pub sliver_elimination: bool,
    /// Skip cells whose interval bounds exclude the iso-level (fields that provide bounds only).
    /// The output is the same either way.
    pub prune: bool,
    /// The work cap, in grid cells' worth of samples: octrees whose leaves would take more than
    /// this many field samples (`samples_per_cell³` each) are refused.
    pub max_cells: u64,
    /// The paper's refinement only, for measurement: the octree is split by QEF residual alone
    /// (plus un-pruning and representing straddling leaves, `refine` rules 1 and 2); the accuracy,
    /// fold and self-intersection rules (3 to 5) and the centring fallback are off. The result may
    /// fold or self-intersect.
    pub paper_only: bool,
    /// Refinement rule 3 (split leaves under triangles farther from the surface than the
    /// tolerance). Off, only the QEF residual and the fold and intersection rules refine: on the
    /// planar room fewer triangles and, at depth 5, a smaller maximum distance (see the README,
    /// "Thin walls"), but curved surfaces lose the accuracy bound.
    pub accuracy_rule: bool,
    /// How far beyond its leaf a leaf's vertex may follow its QEF minimiser, as a fraction of the
    /// leaf's side (0: kept in the leaf, as the paper does). Where a leaf holds one wall next to
    /// the junction of two thin walls, the minimiser lies on the junction in the neighbouring leaf;
    /// clamped to the leaf's face, the vertex leaves the room's inner edge up to a leaf's width
    /// from every crossing, and the triangles cut the edge. With 0.25 and `tolerance` 0.01 the
    /// planar room is within 1 % in < 1 000 triangles at depth 5 (README, "Thin walls"). Where
    /// the dual grid still folds or crosses at the maximum depth, the vertices go back into their
    /// leaves before any centring (`refine`). Off by default: measured on five scenes at depths 5
    /// and 6 it lowered or kept the maximum distance, but it changes every mesh and coarsens some
    /// normals (README, "Thin walls").
    ///
    /// A vertex leaves its leaf only where it fits the leaf's tangent planes strictly better out
    /// there and keeps the side of the iso-level of the leaf's own minimiser
    /// (`features::reached_vertex`): on the rounded thin room, reached vertices beside the rounded
    /// outer edges crossed into the walls and folded the dual cells (4040 triangles instead of
    /// 1048). So a vertex's sign is still the field's at a point of its leaf, the premise of the
    /// pruning argument of `refine` (rule 1).
    pub vertex_reach: f32,
}

impl Default for DmcOptions {
    /// `tolerance` 1e-3 of the bounds, `max_depth` 7 (128 finest cells along the longest side, the
    /// resolution where Marching Cubes is usually compared), 4³ samples per cell (enough to see
    /// both sides of a thin wall in a cell), sliver elimination and pruning on.
    fn default() -> Self {
        DmcOptions {
            iso: 0.0,
            tolerance: 1e-3,
            max_depth: 7,
            samples_per_cell: 4,
            sliver_elimination: true,
            prune: true,
            max_cells: DEFAULT_MAX_CELLS,
            paper_only: false,
            accuracy_rule: true,
            vertex_reach: 0.0,
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
        if !(0.0..=1.0).contains(&self.vertex_reach) {
            return bad(format!("vertexReach must lie in 0..=1, got {}", self.vertex_reach));
        }
        if self.max_cells == 0 {
            return bad("maxCells must be at least 1".into());
        }
        Ok(())
    }
}

/// What a run built, and how long each phase took (summed over the refinement rounds).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DmcStats {
    /// Leaves of the final octree, pruned ones included.
    pub octree_leaves: usize,
    pub pruned_leaves: usize,
    /// Dual cells (= octree vertices, the root's boundary included) of the final dual grid.
    pub dual_cells: usize,
    /// Passes of the dual grid until no rule of `refine` asked for more.
    pub rounds: usize,
    /// Triangles removed by sliver elimination.
    pub slivers_removed: usize,
    pub octree_ms: f64,
    pub features_ms: f64,
    pub topology_ms: f64,
    pub contour_ms: f64,
}

impl DmcStats {
    /// The phases by name, in pipeline order, for [`crate::stats::Stats`].
    pub fn phases(&self) -> Vec<(String, f64)> {
        vec![
            ("octree".to_string(), self.octree_ms),
            ("feature_isolation".to_string(), self.features_ms),
            ("topology".to_string(), self.topology_ms),
            ("contouring".to_string(), self.contour_ms),
        ]
    }
}

/// The octree's root cube (lowest corner and side) for the box `[min, max]`, and the build
/// parameters in world units.
pub fn octree_root(min: Vec3, max: Vec3, options: &DmcOptions) -> (Vec3, f32, Params) {
    let longest = (max - min).max_element();
    let size = longest * ROOT_GROWTH;
    let params = Params {
        iso: options.iso,
        tolerance: options.tolerance * longest,
        max_depth: options.max_depth,
        samples_per_cell: options.samples_per_cell,
        prune: options.prune,
        // Each leaf is sampled `samples_per_cell³` times: the cap bounds the samples, as
        // `max_cells` bounds the samples of a grid.
        max_leaves: (options.max_cells / (options.samples_per_cell as u64).pow(3)).max(8),
        accuracy_rule: options.accuracy_rule,
        vertex_reach: options.vertex_reach,
    };
    ((min + max) * 0.5 - Vec3::splat(size * ROOT_BELOW_CENTRE), size, params)
}

/// Meshes the `iso` level of `field` inside the box `[min, max]` (the octree's root is the cube
/// around its centre with the box's longest side).
pub fn mesh_field(
    field: &dyn Field,
    min: Vec3,
    max: Vec3,
    options: &DmcOptions,
) -> Result<(Mesh, DmcStats), Error> {
    options.validate()?;
    Grid::new(min, max, [1, 1, 1])?;
    let clipped = bounds::Clipped { field, iso: options.iso, min, max };
    let field: &dyn Field = &clipped;
    let (root_min, size, params) = octree_root(min, max, options);
    let mut stats = DmcStats::default();
    let t = Instant::now();
    let mut tree = Octree::build(field, root_min, size, params)?;
    stats.octree_ms += ms_since(t);
    let mut memo = memo::Memo::default();
    let mut contour = loop {
        stats.rounds += 1;
        let t = Instant::now();
        features::isolate(&mut tree, field, options.sliver_elimination);
        stats.features_ms += ms_since(t);

        let t = Instant::now();
        let mut vertices = DualVertices::new(&tree);
        let (mut refs, mut ids): (Vec<[CellRef; 8]>, Vec<[u32; 8]>) = (Vec::new(), Vec::new());
        // The dual cells around centred leaves not checked yet by `refine::keep_signs`.
        let unchecked: Vec<bool> =
            (0..tree.nodes.len() as u32).map(|n| refine::unchecked_centre(&tree, n)).collect();
        let check = unchecked.contains(&true);
        let (mut around, mut around_ids): (Vec<[CellRef; 8]>, Vec<[u32; 8]>) = (Vec::new(), Vec::new());
        stats.dual_cells = 0;
        dual::for_each_dual_cell(&tree, |cell| {
            stats.dual_cells += 1;
            let cell_ids = cell.map(|r| vertices.id(&tree, field, r));
            if check && cell.iter().any(|r| unchecked[r.node as usize]) {
                around.push(*cell);
                around_ids.push(cell_ids);
            }
            let first = vertices.values[cell_ids[0] as usize] < 0.0;
            if cell_ids.iter().any(|&v| (vertices.values[v as usize] < 0.0) != first) {
                refs.push(*cell);
                ids.push(cell_ids);
            }
        });
        stats.topology_ms += ms_since(t);

        let t = Instant::now();
        let unprune = refine::to_unprune(&tree, &refs, &ids, &vertices.values);
        for &n in &unprune {
            tree.unprune(field, n)?;
        }
        stats.octree_ms += ms_since(t);
        if !unprune.is_empty() {
            continue;
        }
        let t = Instant::now();
        let kept =
            check && refine::keep_signs(&mut tree, field, &vertices.values, &ids, &around, &around_ids);
        stats.topology_ms += ms_since(t);
        if kept {
            continue;
        }
        let revert = features::near_features(&tree, &refs);

        let t = Instant::now();
        let contour = contour::contour(&ids, &vertices, field, options.iso, &mut memo);
        stats.contour_ms += ms_since(t);

        let t = Instant::now();
        let plan = match options.paper_only {
            true => refine::represent(&tree, &refs, &ids, &vertices.values),
            false => refine::plan(&tree, field, &refs, &ids, &vertices.values, &contour, &mut memo),
        };
        for &n in &revert {
            let node = &mut tree.nodes[n as usize];
            node.keep_free = true;
            node.has_vertex = false;
        }
        let changed = apply(&mut tree, field, &plan)? || !revert.is_empty();
        stats.octree_ms += ms_since(t);
        if changed {
            continue;
        }

        let t = Instant::now();
        let (contour, pairs) = finish(contour, &vertices, field, options, params.tolerance, &mut stats);
        stats.contour_ms += ms_since(t);
        let plan = match options.paper_only {
            true => refine::Plan::default(),
            false => refine::untangle(&tree, &refs, &contour, &pairs),
        };
        if !apply(&mut tree, field, &plan)? {
            break contour;
        }
    };
    let t = Instant::now();
    let mut mesh = std::mem::take(&mut contour.mesh);
    contour::field_normals(&mut mesh, field, tree.cell_size(options.max_depth) * 1e-2);
    stats.contour_ms += ms_since(t);
    stats.octree_leaves = tree.leaf_count() as usize;
    stats.pruned_leaves =
        tree.leaves().filter(|&n| tree.nodes[n as usize].kind == octree::Kind::Pruned).count();
    Ok((mesh, stats))
}

/// Applies a refinement plan; whether it changed anything.
fn apply(tree: &mut Octree, field: &dyn Field, plan: &refine::Plan) -> Result<bool, Error> {
    for &n in &plan.split {
        tree.refine(field, n)?;
    }
    for &n in &plan.confine {
        let node = &mut tree.nodes[n as usize];
        node.confined = true;
        node.has_vertex = false;
    }
    for &n in &plan.centre {
        let node = &mut tree.nodes[n as usize];
        node.centred = true;
        node.has_vertex = false;
    }
    Ok(!plan.is_empty())
}

/// Sliver collapse, pleats triangulated again, and the final self-intersection check. A merge that makes two sheets cross (thin
/// walls bring sheets within the tolerance of each other) is undone by collapsing again without the
/// dual vertices involved; intersections that remain are the dual grid's (rule 5).
fn finish(
    contour: contour::Contour,
    vertices: &DualVertices,
    field: &dyn Field,
    options: &DmcOptions,
    tolerance: f32,
    stats: &mut DmcStats,
) -> (contour::Contour, Vec<[u32; 2]>) {
    let mut contour = contour;
    slivers::collapse_zero_edges(&mut contour);
    slivers::flip_caps(&mut contour);
    unpleat(&mut contour.mesh, Some(&mut contour.cell_of_triangle));
    // Folds (triangles lying on each other across an edge) are treated as crossings: both are
    // the surface overlapping itself.
    let intersections = |c: &contour::Contour| {
        let mut pairs = crate::mesh::analysis::self_intersecting_pairs(&c.mesh);
        pairs.extend(crate::mesh::analysis::folded_pairs(&c.mesh));
        pairs
    };
    if !options.sliver_elimination {
        let pairs = intersections(&contour);
        return (contour, pairs);
    }
    let mut skip = std::collections::BTreeSet::new();
    for _ in 0..3 {
        let mut collapsed = contour.clone();
        let (removed, merged) =
            slivers::collapse(&mut collapsed, vertices, field, options.iso, tolerance, &skip);
        slivers::collapse_zero_edges(&mut collapsed);
        slivers::flip_caps(&mut collapsed);
        unpleat(&mut collapsed.mesh, Some(&mut collapsed.cell_of_triangle));
        let pairs = intersections(&collapsed);
        let culprits: Vec<u32> = pairs
            .iter()
            .flatten()
            .flat_map(|&t| collapsed.mesh.triangles[t as usize])
            .map(|v| merged[v as usize])
            .filter(|&d| d != u32::MAX)
            .collect();
        if pairs.is_empty() || culprits.is_empty() {
            stats.slivers_removed = removed;
            return (collapsed, pairs);
        }
        skip.extend(culprits);
    }
    let pairs = intersections(&contour);
    stats.slivers_removed = 0;
    (contour, pairs)
}

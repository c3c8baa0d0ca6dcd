//! The one summary of a meshing run, shared by the CLI's `--stats`, the wasm API and the benches.
//! Field names are a contract (scripts parse them): add freely, never rename.

use crate::error::Error;
use crate::field::Field;
use crate::mesh::analysis;
use crate::mesh::Mesh;
use serde::Serialize;
use web_time::Instant;

/// Which of the costlier checks to run; the cheap ones always run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AnalysisOptions {
    /// Pairwise triangle intersection test (spatial index, but still the costliest check).
    pub self_intersections: bool,
    /// Distance to the true surface and normal deviation (needs field evaluations).
    pub surface_error: bool,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        AnalysisOptions { self_intersections: true, surface_error: true }
    }
}

#[derive(Debug, Clone, Serialize, PartialEq, Default)]
pub struct Stats {
    pub method: String,
    /// Cells along the longest side of the bounds (or of the finest octree level).
    pub res: usize,
    pub vertices: usize,
    pub triangles: usize,
    pub closed_manifold: bool,
    pub euler: i64,
    pub genus: Option<i64>,
    pub components: usize,
    pub boundary_edges: usize,
    pub non_manifold_edges: usize,
    pub non_manifold_vertices: usize,
    pub misoriented_edges: usize,
    pub degenerate_triangles: usize,
    /// `None` when the check was skipped.
    pub self_intersections: Option<usize>,
    /// Pairs of triangles lying on each other across an edge (the surface overlapping itself
    /// without crossing; see [`analysis::folded_pairs`]).
    pub folded_pairs: usize,
    pub min_angle_deg: f64,
    pub max_angle_deg: f64,
    /// Triangle angles in 5° bins, 0–5°, 5–10°, …, 175–180°.
    pub angle_histogram_5deg: Vec<u32>,
    pub aspect_ratio_mean: f64,
    pub aspect_ratio_max: f64,
    pub area: f64,
    pub volume: f64,
    pub dist_max: Option<f64>,
    pub dist_rms: Option<f64>,
    pub normal_dev_deg_p50: Option<f64>,
    pub normal_dev_deg_p95: Option<f64>,
    pub normal_dev_deg_max: Option<f64>,
    /// Faces at a sharp edge, and their normal deviation p95 (see
    /// [`analysis::SurfaceError::crease_faces`]): where "crinkly" edges show.
    pub crease_faces: Option<usize>,
    pub crease_normal_dev_deg_p95: Option<f64>,
    /// Per face against the nearest true normal near it (see
    /// [`analysis::SurfaceError::face_normal_dev_deg_max`]): crease faces lying flat count as
    /// right, spikes and faces turned over do not.
    pub face_normal_dev_deg_p95: Option<f64>,
    pub face_normal_dev_deg_max: Option<f64>,
    /// Wall-clock time of the meshing itself (all phases, analysis excluded).
    pub ms_total: f64,
    /// Time per phase of the method, in the order they ran (a JSON object, insertion ordered).
    #[serde(serialize_with = "phases_as_object")]
    pub phases_ms: Vec<(String, f64)>,
    pub ms_analysis: f64,
    /// Mesh edges on reconstructed feature lines (EMC), 0 for methods without feature detection.
    pub feature_edges: usize,
    /// Cells whose component was classified as an edge / a corner feature and got a point on it
    /// (EMC).
    pub edge_features: usize,
    pub corner_features: usize,
    /// Sharp components fanned around a point near, not on, their feature (EMC): no point of the
    /// feature gave a fan that does not fold.
    pub approximate_features: usize,
    /// Edges flipped to make feature lines explicit (EMC).
    pub flips: usize,
    /// Crossings collapsed into feature points on flat faces (EMC).
    pub flat_merges: usize,
    /// Grid points where the field was evaluated (EMC's crust skips the rest), and the grid's size.
    pub points_evaluated: Option<usize>,
    pub grid_points: Option<usize>,
    /// Leaves of the final octree, and dual cells traversed (DMC).
    pub octree_leaves: Option<usize>,
    pub dual_cells: Option<usize>,
    /// Quad faces of the quad method (0 otherwise; `triangles` is then their triangulation).
    pub quads: usize,
    /// The quad method's record per stage: valence-four share, aspect ratios, distance.
    pub quad_stages: Vec<crate::quad::QuadStage>,
    /// How far the program's tape was specialised per brick (programs only, `None` otherwise).
    pub tape: Option<TapeStats>,
}

/// The distribution of specialised tape lengths (instructions) over the leaf bricks that were
/// queried (see [`crate::expr::regions`]).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq, Default)]
pub struct TapeStats {
    /// The whole program's length.
    pub full: usize,
    /// Leaf bricks built (the rest of space was never queried at leaf level).
    pub bricks: usize,
    pub min: usize,
    pub p50: usize,
    pub p90: usize,
    pub max: usize,
}

impl From<&crate::expr::TapeLengths> for TapeStats {
    fn from(lengths: &crate::expr::TapeLengths) -> TapeStats {
        TapeStats {
            full: lengths.full,
            bricks: lengths.leaves.len(),
            min: lengths.quantile(0.0),
            p50: lengths.quantile(0.5),
            p90: lengths.quantile(0.9),
            max: lengths.quantile(1.0),
        }
    }
}

impl Stats {
    pub(crate) fn set_feature_counts(
        &mut self,
        feature_edges: usize,
        [edges, corners, approximate, flips, flat_merges]: [usize; 5],
    ) {
        self.feature_edges = feature_edges;
        self.edge_features = edges;
        self.corner_features = corners;
        self.approximate_features = approximate;
        self.flips = flips;
        self.flat_merges = flat_merges;
    }
}

/// Analyses `mesh` against `field` (its true surface) and bundles the numbers with the timings;
/// fails only with [`Error::Cancelled`], where a progress hook stops the crossing check or the
/// surface measurement.
pub fn compute(
    method: &str,
    res: usize,
    mesh: &Mesh,
    field: &dyn Field,
    phases_ms: Vec<(String, f64)>,
    options: AnalysisOptions,
) -> Result<Stats, Error> {
    let t0 = Instant::now();
    let topo = analysis::topology(mesh);
    let angles = analysis::angle_stats(mesh);
    let (aspect_mean, aspect_max) = analysis::aspect_ratios(mesh);
    let intersections = options
        .self_intersections
        .then(|| analysis::self_intersecting_pairs_cancellable(mesh).map(|pairs| pairs.len()))
        .transpose()?;
    let error = (options.surface_error && mesh.triangle_count() > 0)
        .then(|| analysis::surface_error_cancellable(mesh, field))
        .transpose()?;
    let ms_total = phases_ms.iter().map(|(_, ms)| ms).sum();
    Ok(Stats {
        method: method.to_string(),
        res,
        vertices: mesh.vertex_count(),
        triangles: mesh.triangle_count(),
        closed_manifold: topo.is_closed_manifold(),
        euler: topo.euler,
        genus: topo.genus,
        components: topo.components,
        boundary_edges: topo.boundary_edges,
        non_manifold_edges: topo.non_manifold_edges,
        non_manifold_vertices: topo.non_manifold_vertices,
        misoriented_edges: topo.misoriented_edges,
        degenerate_triangles: topo.degenerate_triangles,
        self_intersections: intersections,
        folded_pairs: analysis::folded_pairs(mesh).len(),
        min_angle_deg: angles.min_deg,
        max_angle_deg: angles.max_deg,
        angle_histogram_5deg: angles.histogram_5deg.to_vec(),
        aspect_ratio_mean: aspect_mean,
        aspect_ratio_max: aspect_max,
        area: analysis::surface_area(mesh),
        volume: analysis::signed_volume(mesh),
        dist_max: error.as_ref().map(|e| e.dist_max),
        dist_rms: error.as_ref().map(|e| e.dist_rms),
        normal_dev_deg_p50: error.as_ref().map(|e| e.normal_dev_deg_p50),
        normal_dev_deg_p95: error.as_ref().map(|e| e.normal_dev_deg_p95),
        normal_dev_deg_max: error.as_ref().map(|e| e.normal_dev_deg_max),
        crease_faces: error.as_ref().map(|e| e.crease_faces),
        crease_normal_dev_deg_p95: error.as_ref().map(|e| e.crease_normal_dev_deg_p95),
        face_normal_dev_deg_p95: error.as_ref().map(|e| e.face_normal_dev_deg_p95),
        face_normal_dev_deg_max: error.as_ref().map(|e| e.face_normal_dev_deg_max),
        ms_total,
        phases_ms,
        ms_analysis: crate::mc::ms_since(t0),
        ..Stats::default()
    })
}

fn phases_as_object<S: serde::Serializer>(phases: &[(String, f64)], s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(phases.iter().map(|(k, v)| (k, v)))
}

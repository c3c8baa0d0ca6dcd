//! Semi-regular quad meshes from distance fields (seed paper 003): a quad mesh of the surface's
//! topology is extracted from the grid ([`extract`]: the dual of Marching Cubes' polygon mesh, so the
//! topology is MC's on the same grid by construction); projected onto f = 0, relaxed, and thinned by
//! three collapse operators, it becomes a mesh with few non-valence-four vertices.
//!
//! Stages, each measured (valence-four share, aspect ratios, distance to the surface):
//! [`extract`] → [`project`] + relax → up to two passes of [`semilocal`] + [`ring`] collapses →
//! [`local`] collapses → [`subdivide`] steps, re-projecting after every stage.
//!
//! What holds after every stage: the collapses keep the topology (each is validated in
//! [`collapse::merge`]); the geometry is guarded here. Moving vertices onto a wild surface (random
//! samples, thin parts) can make quads cross or fold, so every stage that moves vertices ends with
//! [`hold_back`]: vertices of crossing, folded or degenerate quads go back to where the stage found
//! them until none is left, which terminates because the stage started from a valid mesh. A collapse
//! stage whose merged mesh is itself not valid is undone whole. So the output is always as valid as
//! the extraction, which is valid by construction.

pub mod collapse;
pub mod extract;
pub mod local;
pub mod mesh;
pub mod obj;
pub mod project;
pub mod ring;
pub mod semilocal;
pub mod subdivide;

use crate::error::Error;
use crate::field::{check_finite, sample_level, Field};
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::ms_since;
pub use extract::ExtractCounts;
use glam::Vec3;
pub use mesh::QuadMesh;
use serde::Serialize;
use web_time::Instant;

/// Knobs of the quad method; the defaults are the paper's sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QuadOptions {
    /// Smoothing rounds after projection and after every collapse stage.
    pub relax_iterations: usize,
    /// Passes of Semi-local + Ring Collapse (the paper finds two enough).
    pub passes: usize,
    /// Apply the Local Collapse after the passes.
    pub local: bool,
    /// Bilinear subdivision steps at the end, new vertices projected onto the surface.
    pub subdivisions: usize,
    /// Refuse grids with more cells than this, before anything is allocated.
    pub max_cells: u64,
}

impl Default for QuadOptions {
    fn default() -> Self {
        QuadOptions {
            relax_iterations: 5,
            passes: 2,
            local: true,
            subdivisions: 1,
            max_cells: DEFAULT_MAX_CELLS,
        }
    }
}

/// The numbers of one stage: what the paper's figures show, counted.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct QuadStage {
    pub stage: String,
    pub vertices: usize,
    pub quads: usize,
    pub euler: i64,
    /// Share of vertices with valence four.
    pub valence4_share: f64,
    /// Vertices of valence other than four.
    pub irregular: usize,
    /// Collapses (or subdivision steps) this stage applied.
    pub operations: usize,
    pub aspect_mean: f64,
    pub aspect_max: f64,
    /// Vertex distance to f = 0 estimated as |f| / |∇f| (exact for signed distance fields).
    pub dist_max: f64,
    pub dist_rms: f64,
    /// Vertices this stage had to leave where it found them (or, for a collapse stage undone whole,
    /// its quads before) so that no quads cross or fold.
    pub held_back: usize,
}

/// The quad mesh, the stage-by-stage record, and what extraction found.
#[derive(Debug, Clone, Default)]
pub struct QuadResult {
    pub mesh: QuadMesh,
    pub stages: Vec<QuadStage>,
    pub extract: ExtractCounts,
}

/// Refuses a grid of more than `max_cells` cells (or whose cell or point count does not fit a
/// `u64`), with checked arithmetic so that no product can wrap past the check.
pub fn check_size(grid: &Grid, max_cells: u64) -> Result<(), Error> {
    grid.check_size(max_cells)
}

/// Runs the whole method on `field` (inside where it is negative) sampled on `grid`.
pub fn mesh_field(
    field: &dyn Field,
    grid: &Grid,
    options: &QuadOptions,
) -> Result<(QuadResult, Vec<(String, f64)>), Error> {
    check_size(grid, options.max_cells)?;
    let t = Instant::now();
    let (values, _) = sample_level(field, grid, 0.0, false)?;
    let phases = vec![("sample".to_string(), ms_since(t))];
    mesh_values(&values, field, grid, options, phases)
}

/// Runs the method on samples already taken (`values` minus the iso-level, x fastest over `grid`'s
/// points, inside where negative), projecting onto `field`'s zero set. The extraction reads the
/// samples themselves, never `field` at the grid points, so its signs are exactly MC's.
pub fn mesh_samples(
    values: &[f32],
    field: &dyn Field,
    grid: &Grid,
    options: &QuadOptions,
) -> Result<(QuadResult, Vec<(String, f64)>), Error> {
    check_size(grid, options.max_cells)?;
    check_finite(values, grid)?;
    mesh_values(values, field, grid, options, Vec::new())
}

fn mesh_values(
    values: &[f32],
    field: &dyn Field,
    grid: &Grid,
    options: &QuadOptions,
    mut phases: Vec<(String, f64)>,
) -> Result<(QuadResult, Vec<(String, f64)>), Error> {
    let step = grid.spacing.max_element();
    let t = Instant::now();
    let (mut mesh, counts) = extract::extract(values, grid);
    phases.push(("extract".to_string(), ms_since(t)));
    let mut stages = vec![measure("extracted", &mesh, field, step, 0, 0)];

    let t = Instant::now();
    let before = mesh.positions.clone();
    project::project(&mut mesh, field, step, None);
    project::relax(&mut mesh, field, options.relax_iterations, step);
    let held = hold_back(&mut mesh, &before);
    phases.push(("project".to_string(), ms_since(t)));
    stages.push(measure("projected", &mesh, field, step, 0, held));

    let t = Instant::now();
    // One collapse stage: apply, settle (re-project and relax), keep only what stays valid.
    let collapse_stage = |mesh: &mut QuadMesh, op: fn(&mut QuadMesh) -> usize| -> (usize, usize) {
        let original = mesh.clone();
        let n = op(mesh);
        if n == 0 {
            return (0, 0);
        }
        mesh.compact();
        let merged = mesh.positions.clone();
        if !extract::geometry_ok(mesh) {
            *mesh = original;
            return (0, 1);
        }
        project::project(mesh, field, step, None);
        project::relax(mesh, field, options.relax_iterations, step);
        (n, hold_back(mesh, &merged))
    };
    for pass in 1..=options.passes {
        let (n, held) = collapse_stage(&mut mesh, semilocal::semilocal_collapse);
        stages.push(measure(&format!("semilocal{pass}"), &mesh, field, step, n, held));
        let (m, held) = collapse_stage(&mut mesh, ring::ring_collapse);
        stages.push(measure(&format!("ring{pass}"), &mesh, field, step, m, held));
        if n + m == 0 {
            break;
        }
    }
    if options.local {
        let (n, held) = collapse_stage(&mut mesh, local::local_collapse);
        stages.push(measure("local", &mesh, field, step, n, held));
    }
    phases.push(("collapse".to_string(), ms_since(t)));

    let t = Instant::now();
    for s in 1..=options.subdivisions {
        let (mut next, new) = subdivide::subdivide(&mesh);
        if !extract::geometry_ok(&next) {
            stages.push(measure(&format!("subdivided{s}"), &mesh, field, step, 0, 1));
            break;
        }
        let before = next.positions.clone();
        project::project(&mut next, field, step, Some(&new));
        let held = hold_back(&mut next, &before);
        mesh = next;
        stages.push(measure(&format!("subdivided{s}"), &mesh, field, step, 1, held));
    }
    phases.push(("subdivide".to_string(), ms_since(t)));
    Ok((QuadResult { mesh, stages, extract: counts }, phases))
}

/// Puts back, at `before`, the vertices of every quad that crosses or folds onto another (or has a
/// degenerate or non-finite triangle), until none is left; returns how many were put back. Ends
/// because each round puts back at least one vertex, and the mesh at `before` is valid.
pub fn hold_back(mesh: &mut QuadMesh, before: &[Vec3]) -> usize {
    let mut held = vec![false; mesh.positions.len()];
    let mut count = 0;
    loop {
        let bad = bad_quads(mesh);
        if bad.is_empty() {
            return count;
        }
        let mut changed = false;
        for f in bad {
            for v in mesh.quads[f] {
                if !std::mem::replace(&mut held[v as usize], true) {
                    mesh.positions[v as usize] = before[v as usize];
                    count += 1;
                    changed = true;
                }
            }
        }
        if !changed {
            return count;
        }
    }
}

/// The quads whose triangles (two per quad, as [`QuadMesh::triangulate`] makes them) cross, fold
/// or are degenerate.
fn bad_quads(mesh: &QuadMesh) -> Vec<usize> {
    use crate::mesh::analysis;
    let t = mesh.triangulate();
    let mut bad: Vec<usize> = analysis::self_intersecting_pairs(&t)
        .into_iter()
        .chain(analysis::folded_pairs(&t))
        .flat_map(|[a, b]| [a as usize / 2, b as usize / 2])
        .collect();
    for (n, tri) in t.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| t.positions[v as usize].as_dvec3());
        if !(a.is_finite() && b.is_finite() && c.is_finite()) || (b - a).cross(c - a) == glam::DVec3::ZERO {
            bad.push(n / 2);
        }
    }
    bad.sort_unstable();
    bad.dedup();
    bad
}

fn measure(
    stage: &str,
    mesh: &QuadMesh,
    field: &dyn Field,
    step: f32,
    operations: usize,
    held_back: usize,
) -> QuadStage {
    let (aspect_mean, aspect_max) = mesh.aspect_ratios();
    let (dist_max, dist_rms) = project::vertex_distance(mesh, field, step * 1e-3);
    QuadStage {
        stage: stage.to_string(),
        vertices: mesh.vertex_count(),
        quads: mesh.quad_count(),
        euler: mesh.euler(),
        valence4_share: mesh.valence4_share(),
        irregular: mesh.irregular_count(),
        operations,
        aspect_mean,
        aspect_max,
        dist_max,
        dist_rms,
        held_back,
    }
}

//! Semi-regular quad meshes from distance fields (seed paper 003): the outside faces of the cells
//! the surface cuts form a quad mesh of the surface's topology; projected onto f = 0, relaxed, and
//! thinned by three collapse operators, it becomes a mesh with few non-valence-four vertices.
//!
//! Stages, each measured (valence-four share, aspect ratios, distance to the surface):
//! [`extract`] → [`project`] + relax → up to two passes of [`semilocal`] + [`ring`] collapses →
//! [`local`] collapses → [`subdivide`] steps, re-projecting after every stage.

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
use crate::field::{sample_grid, Field};
use crate::grid::Grid;
use crate::mc::ms_since;
pub use extract::ExtractCounts;
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
}

impl Default for QuadOptions {
    fn default() -> Self {
        QuadOptions { relax_iterations: 5, passes: 2, local: true, subdivisions: 1 }
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
}

/// The quad mesh, the stage-by-stage record, and what extraction found.
#[derive(Debug, Clone, Default)]
pub struct QuadResult {
    pub mesh: QuadMesh,
    pub stages: Vec<QuadStage>,
    pub extract: ExtractCounts,
}

/// Runs the whole method on `field` (inside where it is negative) sampled on `grid`.
pub fn mesh_field(
    field: &dyn Field,
    grid: &Grid,
    options: &QuadOptions,
) -> Result<(QuadResult, Vec<(String, f64)>), Error> {
    let mut phases = Vec::new();
    let step = grid.spacing.max_element();
    let t = Instant::now();
    let values = sample_grid(field, grid)?;
    phases.push(("sample".to_string(), ms_since(t)));

    let t = Instant::now();
    let (mut mesh, counts) = extract::extract(&values, grid);
    phases.push(("extract".to_string(), ms_since(t)));
    let mut stages = vec![measure("extracted", &mesh, field, step, 0)];

    let t = Instant::now();
    project::project(&mut mesh, field, step, None);
    project::relax(&mut mesh, field, options.relax_iterations, step);
    phases.push(("project".to_string(), ms_since(t)));
    stages.push(measure("projected", &mesh, field, step, 0));

    let t = Instant::now();
    let settle = |mesh: &mut QuadMesh| {
        mesh.compact();
        project::project(mesh, field, step, None);
        project::relax(mesh, field, options.relax_iterations, step);
    };
    for pass in 1..=options.passes {
        let n = semilocal::semilocal_collapse(&mut mesh);
        settle(&mut mesh);
        stages.push(measure(&format!("semilocal{pass}"), &mesh, field, step, n));
        let m = ring::ring_collapse(&mut mesh);
        settle(&mut mesh);
        stages.push(measure(&format!("ring{pass}"), &mesh, field, step, m));
        if n + m == 0 {
            break;
        }
    }
    if options.local {
        let n = local::local_collapse(&mut mesh);
        settle(&mut mesh);
        stages.push(measure("local", &mesh, field, step, n));
    }
    phases.push(("collapse".to_string(), ms_since(t)));

    let t = Instant::now();
    for s in 1..=options.subdivisions {
        let (next, new) = subdivide::subdivide(&mesh);
        mesh = next;
        project::project(&mut mesh, field, step, Some(&new));
        stages.push(measure(&format!("subdivided{s}"), &mesh, field, step, 1));
    }
    phases.push(("subdivide".to_string(), ms_since(t)));
    Ok((QuadResult { mesh, stages, extract: counts }, phases))
}

fn measure(stage: &str, mesh: &QuadMesh, field: &dyn Field, step: f32, operations: usize) -> QuadStage {
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
    }
}

//! From a request (method, resolution, options) to a mesh and its stats: the one path the CLI, the
//! wasm bindings and the benches share, so the three can never disagree about what a request means.

use crate::error::Error;
use crate::field::{Field, SampledField};
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::{self, McOptions, Topology};
use crate::mesh::Mesh;
use crate::stats::{self, AnalysisOptions, Stats};
use glam::Vec3;

/// The meshing methods. Names are the CLI's `--method` and the wasm API's `method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    #[default]
    Mc,
}

impl Method {
    pub const NAMES: [&'static str; 1] = ["mc"];

    pub fn parse(name: &str) -> Result<Method, Error> {
        match name {
            "mc" => Ok(Method::Mc),
            _ => Err(Error::UnknownName {
                kind: "method",
                name: name.to_string(),
                known: Self::NAMES.iter().map(|s| s.to_string()).collect(),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Method::Mc => "mc",
        }
    }
}

/// Everything a caller can ask of a meshing run.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    pub method: Method,
    /// Cells along the longest side of the bounds.
    pub res: usize,
    pub iso: f32,
    pub topology: Topology,
    pub max_cells: u64,
    /// Overrides the input's own bounds.
    pub bounds: Option<(Vec3, Vec3)>,
    pub analysis: AnalysisOptions,
}

impl Default for Request {
    fn default() -> Self {
        Request {
            method: Method::Mc,
            res: 64,
            iso: 0.0,
            topology: Topology::Fixed,
            max_cells: DEFAULT_MAX_CELLS,
            bounds: None,
            analysis: AnalysisOptions::default(),
        }
    }
}

impl Request {
    fn mc_options(&self) -> McOptions {
        McOptions { iso: self.iso, topology: self.topology, max_cells: self.max_cells }
    }
}

/// Meshes a field over `bounds` (unless the request overrides them).
pub fn mesh_field(
    field: &dyn Field,
    bounds: (Vec3, Vec3),
    request: &Request,
) -> Result<(Mesh, Stats), Error> {
    let (min, max) = request.bounds.unwrap_or(bounds);
    let grid = Grid::with_resolution(min, max, request.res)?;
    grid.check_size(request.max_cells)?;
    let (mesh, timings) = match request.method {
        Method::Mc => mc::mesh_field(field, &grid, &request.mc_options())?,
    };
    let shifted = Shifted { field, iso: request.iso };
    let stats = stats::compute(
        request.method.name(),
        request.res,
        &mesh,
        &shifted,
        timings.phases(),
        request.analysis,
    );
    Ok((mesh, stats))
}

/// Meshes a sampled volume (`values` x fastest over `grid`'s points). The trilinear interpolant of
/// the samples stands in for the true surface in the error statistics.
pub fn mesh_samples(values: &[f32], grid: &Grid, request: &Request) -> Result<(Mesh, Stats), Error> {
    let (mesh, timings) = match request.method {
        Method::Mc => mc::mesh_samples(values, grid, &request.mc_options())?,
    };
    let field = SampledField { grid: *grid, values };
    let shifted = Shifted { field: &field, iso: request.iso };
    let res = grid.cells.iter().copied().max().unwrap_or(0);
    let stats =
        stats::compute(request.method.name(), res, &mesh, &shifted, timings.phases(), request.analysis);
    Ok((mesh, stats))
}

/// The field minus the iso-level, so "the surface" is always the zero set for the analysis.
struct Shifted<'a> {
    field: &'a dyn Field,
    iso: f32,
}

impl Field for Shifted<'_> {
    fn value(&self, p: Vec3) -> f32 {
        self.field.value(p) - self.iso
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        self.field.gradient(p)
    }
}

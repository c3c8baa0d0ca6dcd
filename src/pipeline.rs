//! From a request (method, resolution, options) to a mesh and its stats: the one path the CLI, the
//! wasm bindings and the benches share, so the three can never disagree about what a request means.
//! Fields (scenes, programs, functions) and sampled volumes are meshed here; triangle meshes and
//! point clouds in `pipeline/inputs.rs`.

use crate::dmc::{self, DmcOptions, DmcStats};
use crate::emc::{self, EmcMesh, EmcOptions};
use crate::error::Error;
use crate::expr::{self, Program, RegionalProgram};
use crate::field::{BatchFn, Field, SampleGradient, SampledField};
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::{self, McOptions, Topology};
use crate::mcq::{self, McqOptions, PolygonRules};
use crate::mesh::decimate::{decimate, DecimateOptions};
use crate::mesh::smooth::smooth;
use crate::mesh::Mesh;
use crate::quad::{self, QuadOptions};
use crate::scenes;
use crate::stats::{self, AnalysisOptions, Stats, TapeStats};
use glam::Vec3;

mod inputs;
mod validate;
pub use inputs::{mesh_points, mesh_triangles, MeshDistance, PlaneDistance};

/// The meshing methods. Names are the CLI's `--method` and the wasm API's `method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    #[default]
    Mc,
    Emc,
    Dmc,
    /// Marching Cubes with the per-cell triangle-quality rules of issue 7 (see [`crate::mcq`]).
    Mcq,
    /// Semi-regular quad mesh: the dual of MC's polygon mesh, collapsed and subdivided.
    Quad,
}

impl Method {
    pub const NAMES: [&'static str; 5] = ["mc", "emc", "dmc", "mcq", "quad"];

    pub fn parse(name: &str) -> Result<Method, Error> {
        match name {
            "mc" => Ok(Method::Mc),
            "emc" => Ok(Method::Emc),
            "dmc" => Ok(Method::Dmc),
            "mcq" => Ok(Method::Mcq),
            "quad" => Ok(Method::Quad),
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
            Method::Emc => "emc",
            Method::Dmc => "dmc",
            Method::Mcq => "mcq",
            Method::Quad => "quad",
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
    /// EMC: sharp when the normal cone's min nᵢ·nⱼ is below this.
    pub theta_sharp: f32,
    /// EMC: corner when max |nᵢ·n*| exceeds this.
    pub phi_corner: f32,
    /// EMC: exact edge crossings by root finding (directed distances) rather than interpolation.
    pub directed: bool,
    /// EMC: triangulate components without a feature point by MCQ's per-cell rules
    /// (`mcq_rules`) instead of MC's table.
    pub better_triangles: bool,
    /// EMC: move feature points onto curved creases by resampling their sheets (functions only);
    /// `false` keeps the paper's tangent-plane points.
    pub resample_creases: bool,
    /// EMC: collapse one flat crossing into each fan centre (see [`crate::emc::merge`]).
    pub merge_flat: bool,
    /// MCQ: the per-cell rules, the snapping distance in cells (`None`: no snapping) and whether
    /// inserted vertices are projected onto the surface.
    pub mcq_rules: PolygonRules,
    pub mcq_snap: Option<f32>,
    pub mcq_project: bool,
    /// Quad method: relaxation, collapse passes, subdivision steps.
    pub quad: QuadOptions,
    /// Sampled volumes only: which gradient stands in for the true surface's normals in the
    /// error statistics (see [`SampleGradient`]).
    pub gradient: SampleGradient,
    /// DMC: error tolerance as a fraction of the bounds' longest side (see [`DmcOptions`]).
    pub tolerance: f32,
    /// DMC: deepest octree level; `None` takes the shallowest whose finest cells are no larger than
    /// `res` cells along the longest side would be, so `res` means the same finest cell for all
    /// methods.
    pub max_depth: Option<u8>,
    /// DMC: QEF samples per cell along each axis.
    pub samples_per_cell: usize,
    /// After meshing, decimate to at most this many triangles (see [`crate::mesh::decimate`]):
    /// feature lines stay where they are, the mesh stays a closed manifold without crossings.
    pub decimate: Option<usize>,
    /// Decimation never moves the surface farther than this many cells from the true one (where
    /// the input has a field to measure against); `None`: the target alone decides.
    pub decimate_error: Option<f32>,
    /// After meshing (and decimating), this many passes of feature-preserving smoothing
    /// (see [`crate::mesh::smooth`]).
    pub smooth: usize,
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
            theta_sharp: 0.9,
            phi_corner: 0.7,
            directed: true,
            better_triangles: false,
            resample_creases: true,
            merge_flat: true,
            mcq_rules: PolygonRules::default(),
            mcq_snap: Some(mcq::DEFAULT_SNAP),
            mcq_project: true,
            quad: QuadOptions::default(),
            gradient: SampleGradient::default(),
            tolerance: DmcOptions::default().tolerance,
            max_depth: None,
            samples_per_cell: DmcOptions::default().samples_per_cell,
            decimate: None,
            decimate_error: None,
            smooth: 0,
        }
    }
}

impl Request {
    fn mc_options(&self) -> McOptions {
        McOptions { iso: self.iso, topology: self.topology, max_cells: self.max_cells }
    }

    fn quad_options(&self) -> QuadOptions {
        QuadOptions { max_cells: self.max_cells, ..self.quad }
    }

    fn dmc_options(&self) -> DmcOptions {
        DmcOptions {
            iso: self.iso,
            tolerance: self.tolerance,
            max_depth: self.depth(),
            samples_per_cell: self.samples_per_cell,
            max_cells: self.max_cells,
            ..DmcOptions::default()
        }
    }

    /// The octree depth DMC runs at (see [`Request::max_depth`]), saturating past any valid depth so
    /// that validation reports it.
    fn depth(&self) -> u8 {
        self.max_depth.unwrap_or_else(|| self.res.max(1).next_power_of_two().trailing_zeros().min(255) as u8)
    }

    /// The `res` reported: cells along the longest side at the finest level (DMC: `2^depth`).
    fn reported_res(&self) -> usize {
        match self.method {
            Method::Dmc => 1usize.checked_shl(self.depth() as u32).unwrap_or(usize::MAX),
            _ => self.res,
        }
    }

    fn mcq_options(&self) -> McqOptions {
        McqOptions {
            iso: self.iso,
            max_cells: self.max_cells,
            rules: self.mcq_rules,
            snap: self.mcq_snap,
            project: self.mcq_project,
        }
    }

    fn emc_options(&self) -> EmcOptions {
        EmcOptions {
            iso: self.iso,
            theta_sharp: self.theta_sharp,
            phi_corner: self.phi_corner,
            directed: self.directed,
            flip_edges: true,
            crust: true,
            better_triangles: self.better_triangles.then_some(self.mcq_rules),
            resample_creases: self.resample_creases,
            merge_flat: self.merge_flat,
            topology: self.topology,
            max_cells: self.max_cells,
        }
    }
}

/// A mesh plus what the method knows about its features (empty for methods that know none).
#[derive(Debug, Clone, Default)]
pub struct Output {
    pub mesh: Mesh,
    /// Feature lines as vertex index pairs.
    pub feature_edges: Vec<[u32; 2]>,
    /// The quad method's faces (4 vertex indices each, counter-clockwise from outside, indexing
    /// `mesh.positions`); `mesh.triangles` is their triangulation. Empty for triangle methods.
    pub quads: Vec<[u32; 4]>,
    pub stats: Stats,
}

/// What a method hands back before analysis.
struct Meshed {
    mesh: Mesh,
    feature_edges: Vec<[u32; 2]>,
    phases: Vec<(String, f64)>,
    /// Edge features, corner features, approximate features, flips, flat merges (EMC).
    feature_counts: [usize; 5],
    /// Points evaluated and grid points (EMC).
    evaluations: Option<(usize, usize)>,
    /// Octree leaves and dual cells (DMC).
    octree: Option<(usize, usize)>,
    quads: Vec<[u32; 4]>,
    quad_stages: Vec<quad::QuadStage>,
}

impl Meshed {
    fn plain(mesh: Mesh, phases: Vec<(String, f64)>) -> Meshed {
        Meshed {
            mesh,
            feature_edges: vec![],
            phases,
            feature_counts: [0; 5],
            evaluations: None,
            quads: vec![],
            quad_stages: vec![],
            octree: None,
        }
    }

    fn from_dmc(mesh: Mesh, stats: DmcStats) -> Meshed {
        Meshed {
            octree: Some((stats.octree_leaves, stats.dual_cells)),
            ..Meshed::plain(mesh, stats.phases())
        }
    }

    fn from_emc(out: EmcMesh, timings: crate::emc::EmcTimings) -> Meshed {
        Meshed {
            feature_counts: [
                out.edge_features,
                out.corner_features,
                out.approximate_features,
                out.flips,
                out.flat_merges,
            ],
            evaluations: Some((out.points_evaluated, out.grid_points)),
            octree: None,
            phases: timings.phases(),
            mesh: out.mesh,
            feature_edges: out.feature_edges,
            quads: vec![],
            quad_stages: vec![],
        }
    }

    fn from_quad(out: quad::QuadResult, phases: Vec<(String, f64)>) -> Meshed {
        let mesh = out.mesh.triangulate();
        Meshed { quads: out.mesh.quads, quad_stages: out.stages, ..Meshed::plain(mesh, phases) }
    }

    /// Decimation and smoothing, where asked for, on the method's mesh: `truth` bounds the error and
    /// projects smoothed vertices, `cell` sets the scale of the tolerances.
    fn refine(mut self, request: &Request, truth: &dyn Field, cell: f32) -> Result<Meshed, Error> {
        if let Some(target) = request.decimate {
            let t0 = web_time::Instant::now();
            let options = DecimateOptions {
                target_triangles: target,
                max_error: request.decimate_error.map(|e| (e * cell) as f64),
                // Just under the 1 % of a cell promised, leaving room for f32 rounding.
                feature_tolerance: 0.008 * cell as f64,
                ..DecimateOptions::default()
            };
            let out = decimate(&self.mesh, &self.feature_edges, Some(truth), &options)?;
            self.mesh = out.mesh;
            self.feature_edges = out.feature_edges;
            self.phases.push(("decimate".into(), mc::ms_since(t0)));
        }
        if request.smooth > 0 {
            let t0 = web_time::Instant::now();
            smooth(&mut self.mesh, &self.feature_edges, Some(truth), request.smooth)?;
            self.phases.push(("smooth".into(), mc::ms_since(t0)));
        }
        Ok(self)
    }

    /// The stats of the mesh, after the last check every output passes: coordinates that reached
    /// infinity or NaN in the method's arithmetic (samples near `f32::MAX`, say) are an error, never
    /// a mesh whose stats call it closed.
    fn analyse(
        self,
        method: Method,
        res: usize,
        truth: &dyn Field,
        options: AnalysisOptions,
    ) -> Result<Output, Error> {
        let bad_vertex = self.mesh.positions.iter().position(|p| !p.is_finite());
        let bad_normal = self.mesh.normals.iter().position(|n| !n.is_finite());
        if let Some(index) = bad_vertex.or(bad_normal) {
            let position = self.mesh.positions[index].to_array();
            return Err(Error::NonFiniteOutput { method: method.name(), index, position });
        }
        crate::progress::checkpoint("analysis", 0.0)?;
        let mut stats = stats::compute(method.name(), res, &self.mesh, truth, self.phases, options)?;
        stats.set_feature_counts(self.feature_edges.len(), self.feature_counts);
        stats.points_evaluated = self.evaluations.map(|e| e.0);
        stats.grid_points = self.evaluations.map(|e| e.1);
        stats.octree_leaves = self.octree.map(|o| o.0);
        stats.dual_cells = self.octree.map(|o| o.1);
        stats.quads = self.quads.len();
        stats.quad_stages = self.quad_stages;
        Ok(Output { mesh: self.mesh, feature_edges: self.feature_edges, quads: self.quads, stats })
    }
}

/// Meshes a field over `bounds` (unless the request overrides them).
pub fn mesh_field(field: &dyn Field, bounds: (Vec3, Vec3), request: &Request) -> Result<Output, Error> {
    request.validate()?;
    let (min, max) = request.bounds.unwrap_or(bounds);
    // DMC's finest level is a grid too: the same precision and count checks hold for it.
    let grid = Grid::with_resolution(min, max, request.reported_res())?;
    if request.method != Method::Dmc {
        grid.check_size(request.max_cells)?;
    }
    let meshed = match request.method {
        Method::Mc => {
            let (mesh, timings) = mc::mesh_field(field, &grid, &request.mc_options())?;
            Meshed::plain(mesh, timings.phases())
        }
        Method::Emc => {
            let (out, timings) = emc::mesh_field(field, &grid, &request.emc_options())?;
            Meshed::from_emc(out, timings)
        }
        // The octree bounds its own work (see `DmcOptions::max_cells`); `res` only picks the
        // default depth.
        Method::Dmc => {
            let (mesh, stats) = dmc::mesh_field(field, min, max, &request.dmc_options())?;
            Meshed::from_dmc(mesh, stats)
        }
        Method::Mcq => {
            let (mesh, report) = mcq::mesh_field(field, &grid, &request.mcq_options())?;
            Meshed::plain(mesh, report.phases())
        }
        Method::Quad => {
            let shifted = Shifted { field, iso: request.iso };
            let (out, phases) = quad::mesh_field(&shifted, &grid, &request.quad_options())?;
            Meshed::from_quad(out, phases)
        }
    };
    let shifted = Shifted { field, iso: request.iso };
    let meshed = meshed.refine(request, &shifted, grid.cell_size())?;
    meshed.analyse(request.method, request.reported_res(), &shifted, request.analysis)
}

/// Where programs (typed or CSG) are meshed unless the request names bounds: [-1, 1]³.
pub const DEFAULT_BOUNDS: (Vec3, Vec3) = (Vec3::splat(-1.0), Vec3::splat(1.0));

/// Meshes a built-in scene (see [`scenes::SCENE_NAMES`]) in its own bounds.
pub fn mesh_scene(name: &str, request: &Request) -> Result<Output, Error> {
    let scene = scenes::scene(name)?;
    mesh_program_in(&scene.field, (scene.min, scene.max), request)
}

/// Meshes a compiled program over the request's bounds, or [`DEFAULT_BOUNDS`].
pub fn mesh_program(program: &Program, request: &Request) -> Result<Output, Error> {
    mesh_program_in(program, DEFAULT_BOUNDS, request)
}

/// Leaf bricks of the tape octree are about this many cells of the finest grid on a side.
const CELLS_PER_BRICK: usize = 4;

/// DMC's and EMC's leaf bricks are smaller. DMC bounds every finest cell of its crust and
/// evaluates points all through them (samples, roots, distances of candidate triangles), so a
/// brick's tape is asked more per cell than by a grid mesher that bounds boxes of four cells.
/// Measured on the gear at depth 6 (callgrind): 4.63 → 3.36 G instructions, the fandisk and the
/// rocket within 2 %. EMC walks between crossings point by point along every crease, where a
/// brick of four cells holds several of a part's features and keeps most of its tape (the gear
/// at 64 cells: median 142 of 900 instructions, 41 on two-cell bricks); callgrind on the gear
/// at 32 and 64 cells 1 099 → 889 and 1 409 → 1 255 M instructions, the same at 128, the cube
/// minus a ball, the rotated box, the fandisk, the milling and the thin room within 2 % (the
/// same meshes). Marching Cubes evaluates only columns of grid points, where a long tape costs
/// less per point than building more tapes (the gear at 64: +3 %), and keeps four.
const FINE_CELLS_PER_BRICK: usize = 2;

/// [`mesh_field`] through a [`RegionalProgram`]: every query, from the crust's intervals to the
/// analysis's distances, runs on a tape specialised to the brick it falls in.
pub fn mesh_program_in(program: &Program, bounds: (Vec3, Vec3), request: &Request) -> Result<Output, Error> {
    let (min, max) = request.bounds.unwrap_or(bounds);
    let cells_per_brick = if matches!(request.method, Method::Dmc | Method::Emc) {
        FINE_CELLS_PER_BRICK
    } else {
        CELLS_PER_BRICK
    };
    let depth = RegionalProgram::depth_for(request.reported_res(), cells_per_brick);
    let regional = RegionalProgram::new(program, min, max, depth);
    let mut output = mesh_field(&regional, bounds, request)?;
    output.stats.tape = Some(TapeStats::from(&regional.tape_lengths()));
    Ok(output)
}

/// Compiles a program in the expression language and meshes it like [`mesh_program`]. A
/// malformed program fails with [`Error::Parse`] (line, column and a caret under the spot).
pub fn mesh_expr(text: &str, request: &Request) -> Result<Output, Error> {
    mesh_program(&expr::compile(text)?, request)
}

/// Compiles a CSG tree in JSON (see [`crate::expr::csg`]) and meshes it like [`mesh_program`].
pub fn mesh_csg_json(json: &str, request: &Request) -> Result<Output, Error> {
    mesh_program(&Program::from_csg_json(json)?, request)
}

/// DMC over the trilinear interpolant of sampled values, sampled like any other field (the QEF
/// needs values between the samples); the octree's finest level is the grid's.
fn dmc_on_samples(values: &[f32], grid: &Grid, request: &Request) -> Result<Meshed, Error> {
    crate::field::check_finite(values, grid)?;
    let field = SampledField { grid: *grid, values, gradient: SampleGradient::Trilinear };
    let (mesh, stats) =
        dmc::mesh_field(&field, grid.origin, grid.max(), &dmc_request_on(grid, request).dmc_options())?;
    Ok(Meshed::from_dmc(mesh, stats))
}

/// The request DMC runs on samples over `grid`: its default depth is the grid's own resolution.
fn dmc_request_on(grid: &Grid, request: &Request) -> Request {
    Request { res: grid.cells.iter().copied().max().unwrap_or(1), ..request.clone() }
}

/// The `res` reported for samples over `grid`: its cells along the longest side, or for DMC its
/// finest octree level.
fn sampled_res(grid: &Grid, request: &Request) -> usize {
    match request.method {
        Method::Dmc => dmc_request_on(grid, request).reported_res(),
        _ => grid.cells.iter().copied().max().unwrap_or(0),
    }
}

/// Meshes a sampled volume (`values` x fastest over `grid`'s points). The trilinear interpolant of
/// the samples stands in for the true surface in the error statistics, its normals given by
/// `request.gradient` (trilinear or interpolated central differences, see [`SampleGradient`]).
pub fn mesh_samples(values: &[f32], grid: &Grid, request: &Request) -> Result<Output, Error> {
    request.validate()?;
    // Before any method interpolates them: differences of samples near f32::MAX overflow.
    crate::field::check_finite(values, grid)?;
    let meshed = match request.method {
        Method::Mc => {
            let (mesh, timings) = mc::mesh_samples(values, grid, &request.mc_options())?;
            Meshed::plain(mesh, timings.phases())
        }
        Method::Emc => {
            let (out, timings) = emc::mesh_samples(values, grid, &request.emc_options())?;
            Meshed::from_emc(out, timings)
        }
        Method::Dmc => dmc_on_samples(values, grid, request)?,
        Method::Mcq => {
            let (mesh, report) = mcq::mesh_samples(values, grid, &request.mcq_options())?;
            Meshed::plain(mesh, report.phases())
        }
        Method::Quad => {
            // The samples minus the iso-level, as MC computes them, so the signs are MC's exactly.
            crate::field::check_finite(values, grid)?;
            let field = SampledField { grid: *grid, values, gradient: request.gradient };
            let shifted: Vec<f32> = values.iter().map(|v| v - request.iso).collect();
            let (out, phases) = quad::mesh_samples(
                &shifted,
                &Shifted { field: &field, iso: request.iso },
                grid,
                &request.quad_options(),
            )?;
            Meshed::from_quad(out, phases)
        }
    };
    let field = SampledField { grid: *grid, values, gradient: request.gradient };
    let shifted = Shifted { field: &field, iso: request.iso };
    let meshed = meshed.refine(request, &shifted, grid.cell_size())?;
    meshed.analyse(request.method, sampled_res(grid, request), &shifted, request.analysis)
}

/// Meshes a batch field function (the slow path for functions that are costly to call, such as
/// JavaScript ones): the closure samples the grid over `bounds` (or the request's) one z-slab per
/// call, then the samples are meshed like [`mesh_samples`], gradients by central differences.
pub fn mesh_function<F>(field: &BatchFn<F>, bounds: (Vec3, Vec3), request: &Request) -> Result<Output, Error>
where
    F: Fn(&[Vec3], &mut [f32]) -> Result<(), String>,
{
    request.validate()?;
    let (min, max) = request.bounds.unwrap_or(bounds);
    let grid = Grid::with_resolution(min, max, request.res)?;
    grid.check_size(request.max_cells)?;
    let values = field.sample(&grid)?;
    let request = Request { gradient: SampleGradient::CentralDifferences, ..request.clone() };
    mesh_samples(&values, &grid, &request)
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
    fn value_and_gradient(&self, p: Vec3) -> (f32, Option<Vec3>) {
        let (v, g) = self.field.value_and_gradient(p);
        (v - self.iso, g)
    }
    fn steepness(&self) -> f32 {
        self.field.steepness()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quick() -> Request {
        Request {
            res: 16,
            analysis: AnalysisOptions { self_intersections: false, surface_error: true },
            ..Request::default()
        }
    }

    #[test]
    fn text_csg_and_scene_paths_mesh_the_same_sphere() {
        let from_text = mesh_expr("sphere(0.8)", &quick()).unwrap();
        let from_csg = mesh_csg_json(r#"{"op": "sphere", "radius": 0.8}"#, &quick()).unwrap();
        let from_scene = mesh_scene("sphere", &quick()).unwrap();
        assert_eq!(
            from_text.mesh.positions, from_scene.mesh.positions,
            "default bounds are the scene's [-1, 1]³"
        );
        assert_eq!(from_csg.mesh.triangles, from_scene.mesh.triangles);
        assert_eq!(from_text.stats.euler, 2);
        assert!(from_text.stats.dist_max.unwrap() < 0.01);
    }

    #[test]
    fn requested_bounds_replace_the_default_ones() {
        let request = Request { bounds: Some((Vec3::splat(-3.0), Vec3::splat(3.0))), ..quick() };
        let out = mesh_expr("sphere(2.5)", &request).unwrap();
        assert!(out.stats.closed_manifold && out.stats.euler == 2);
        let clipped = mesh_expr("sphere(2.5)", &quick()).unwrap();
        assert_eq!(
            clipped.stats.triangles, 0,
            "a sphere containing the default bounds has no surface in them"
        );
    }

    #[test]
    fn parse_errors_come_back_with_their_position() {
        let err = mesh_expr("union(sphere(1),\n  box(1, 2)", &quick()).unwrap_err();
        assert!(matches!(err, Error::Parse { line: 2, .. }), "{err}");
        assert!(err.to_string().contains('^'));
    }
}

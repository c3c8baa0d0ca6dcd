//! `isoforge`: mesh a built-in scene, a program in the expression language, a raw volume, a
//! triangle mesh or an oriented point cloud from the command line, write OBJ/STL/PLY, print stats as JSON.

use clap::{ArgGroup, Parser, Subcommand, ValueEnum};
use isoforge::field::SampleGradient;
use isoforge::grid::{self, Dtype, Grid};
use isoforge::mc::Topology;
use isoforge::mcq::PolygonRules;
use isoforge::mesh::export;
use isoforge::pipeline::{self, Method, Output, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::{expr, input, scenes, Error, Vec3};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "isoforge", version, about = "Feature-preserving isosurface extraction")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Mesh a scene, an expression, a raw volume, a triangle mesh or a point cloud; optionally write the mesh and print its stats.
    Mesh(Box<MeshArgs>),
    /// List the built-in scenes, or print one scene's program.
    Scenes {
        /// Print this scene's program in the expression language.
        name: Option<String>,
    },
}

/// The inputs other than --grid, which the volume's layout options make no sense with. (A plain
/// `requires = "grid"` is not enforced by clap for a member of the input group.)
const NOT_GRID: [&str; 5] = ["scene", "expr", "expr_file", "mesh", "points"];

#[derive(clap::Args)]
#[command(group(ArgGroup::new("input").required(true).args(["scene", "expr", "expr_file", "grid", "mesh", "points"])))]
struct MeshArgs {
    /// A built-in scene (see `isoforge scenes`), meshed in its own bounds.
    #[arg(long)]
    scene: Option<String>,
    /// A program in the expression language, meshed in --bounds (default [-1, 1]³).
    #[arg(long, allow_hyphen_values = true, value_name = "TEXT")]
    expr: Option<String>,
    /// A file holding a program in the expression language (like --expr).
    #[arg(long, value_name = "FILE")]
    expr_file: Option<PathBuf>,
    /// A triangle mesh to remesh (.obj, .stl, .ply, .off); holes are spanned (generalised winding
    /// number). Without --bounds the grid covers its bounding box padded by two cells, --res cells
    /// along the longest side.
    #[arg(long, value_name = "FILE")]
    mesh: Option<PathBuf>,
    /// An oriented point cloud to reconstruct a surface from (.ply with nx ny nz, .xyz text
    /// `x y z nx ny nz`, or CGAL's .pwn); normals that disagree with their neighbours are turned
    /// first; bounds as for --mesh.
    #[arg(long, value_name = "FILE")]
    points: Option<PathBuf>,
    /// A raw volume: samples without a header, little-endian, x fastest (needs --dims).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["bounds", "res"])]
    grid: Option<PathBuf>,
    /// Sample points per axis of the --grid volume.
    #[arg(long, value_parser = list::<usize, 3>, value_name = "X,Y,Z", conflicts_with_all = NOT_GRID)]
    dims: Option<[usize; 3]>,
    /// Sample type of the --grid volume [default: f32].
    #[arg(long, value_enum, conflicts_with_all = NOT_GRID)]
    dtype: Option<DtypeArg>,
    /// Distance between --grid samples per axis [default: 1,1,1].
    #[arg(long, value_parser = list::<f32, 3>, value_name = "SX,SY,SZ", conflicts_with_all = NOT_GRID)]
    spacing: Option<[f32; 3]>,
    /// Position of the first --grid sample [default: 0,0,0].
    #[arg(long, value_parser = list::<f32, 3>, value_name = "X,Y,Z", allow_hyphen_values = true, conflicts_with_all = NOT_GRID)]
    origin: Option<[f32; 3]>,
    /// Meshing method: mc (Marching Cubes), emc (Extended Marching Cubes), dmc (Dual Marching
    /// Cubes), mcq (Marching Cubes with per-cell triangle-quality rules) or quad (semi-regular
    /// quads; an .obj output keeps the quads).
    #[arg(long, default_value = "mc")]
    method: String,
    /// Cells along the longest side of the bounds (a --grid has its own).
    #[arg(long, default_value_t = 64)]
    res: usize,
    /// Mesh this box instead of the scene's own ([-1, 1]³ for expressions).
    #[arg(long, value_parser = list::<f32, 6>, value_name = "X0,Y0,Z0,X1,Y1,Z1", allow_hyphen_values = true)]
    bounds: Option<[f32; 6]>,
    /// Fit the bounds to an --expr or --expr-file program: the box its inside fits in, found
    /// from interval bounds, grown by 5 % of its longest side. Fails on an unbounded inside.
    #[arg(long, conflicts_with_all = ["bounds", "scene", "grid", "mesh", "points"])]
    fit: bool,
    /// Iso-level: points with value < iso are inside.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    iso: f32,
    /// How ambiguous cell faces are resolved.
    #[arg(long, value_enum, default_value_t = TopologyArg::Fixed)]
    topology: TopologyArg,
    /// Refuse grids with more cells than this.
    #[arg(long, default_value_t = isoforge::grid::DEFAULT_MAX_CELLS)]
    max_cells: u64,
    /// Threads for sampling and Marching Cubes' slabs (default: one per core); the mesh is the
    /// same for every count.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Output file; the format follows the extension (.obj, .stl, .ply, .glb).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Print one JSON object of statistics on stdout.
    #[arg(long)]
    stats: bool,
    /// Skip the pairwise self-intersection check in --stats (the costliest one).
    #[arg(long)]
    no_intersections: bool,
    /// EMC: a cell is sharp when the min dot product of its normals is below this.
    #[arg(long, default_value_t = 0.9, allow_hyphen_values = true)]
    theta_sharp: f32,
    /// EMC: a sharp cell holds a corner when max |n·n*| exceeds this.
    #[arg(long, default_value_t = 0.7, allow_hyphen_values = true)]
    phi_corner: f32,
    /// EMC: place edge crossings by linear interpolation instead of exact root finding.
    #[arg(long)]
    no_directed: bool,
    /// EMC: triangulate cells without a sharp feature by MCQ's per-cell polygon rules (--cut-angle,
    /// --quad-ratio) instead of Marching Cubes' table; feature fans stay as they are.
    #[arg(long)]
    better_triangles: bool,
    /// EMC: keep the paper's tangent-plane feature points on curved creases instead of resampling
    /// each sheet next to the crease (expressions, CSG and scenes only).
    #[arg(long)]
    tangent_planes: bool,
    /// EMC: keep every fan's two extra triangles instead of collapsing, into each feature point,
    /// one neighbouring crossing whose triangles lie in one plane.
    #[arg(long)]
    no_flat_merge: bool,
    /// DMC: error tolerance as a fraction of the bounds' longest side (the QEF residual a merged
    /// leaf may have).
    #[arg(long, default_value_t = isoforge::dmc::DmcOptions::default().tolerance)]
    tol: f32,
    /// DMC: deepest octree level [default: the depth whose finest cells match --res].
    #[arg(long)]
    max_depth: Option<u8>,
    /// DMC: QEF samples per finest cell along each axis, its corners included.
    #[arg(long, default_value_t = isoforge::dmc::DmcOptions::default().samples_per_cell)]
    samples_per_cell: usize,
    /// MCQ: merge vertices closer than this many cells to a grid point onto it (0: no snapping).
    #[arg(long, default_value_t = isoforge::mcq::DEFAULT_SNAP)]
    snap: f32,
    /// MCQ: cut off polygon corners whose angle is below this many degrees as their own triangle.
    #[arg(long)]
    cut_angle: Option<f32>,
    /// MCQ: give a four-sided polygon an inner vertex when its longest/shortest edge exceeds this.
    #[arg(long)]
    quad_ratio: Option<f32>,
    /// MCQ: leave inserted vertices in their polygon (the paper) instead of projecting them onto the surface.
    #[arg(long)]
    no_project: bool,
    /// After meshing, decimate to at most this many triangles, keeping feature lines in place and
    /// the mesh closed, manifold and free of crossings (not for --method quad).
    #[arg(long)]
    decimate: Option<usize>,
    /// With --decimate: never move the surface farther than this many cells from the true one.
    #[arg(long, requires = "decimate")]
    decimate_error: Option<f32>,
    /// After meshing (and decimating), this many passes of smoothing that leaves feature lines put.
    #[arg(long, default_value_t = 0)]
    smooth: usize,
    /// --grid only: the volume's gradient in the error stats, that of the trilinear interpolant or
    /// central differences at the samples interpolated (continuous across cells) [default: central].
    #[arg(long, value_enum, conflicts_with_all = NOT_GRID)]
    gradient: Option<GradientArg>,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum GradientArg {
    Trilinear,
    Central,
}

#[derive(Clone, Copy, ValueEnum)]
enum TopologyArg {
    Fixed,
    Trilinear,
}

#[derive(Clone, Copy, ValueEnum)]
enum DtypeArg {
    F32,
    U8,
    U16,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Scenes { name: None } => {
            print_out(&scenes::SCENE_NAMES.map(|name| format!("{name}\n")).concat())
        }
        Command::Scenes { name: Some(name) } => scenes::source(&name).and_then(print_out),
        Command::Mesh(args) => mesh(*args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("isoforge: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Writes `text` to stdout. A reader that has stopped reading (`isoforge ... --stats | head -c
/// 100`) is not an error, as for any Unix filter: the rest is dropped quietly (`println!` panicked
/// there, with a backtrace).
fn print_out(text: &str) -> Result<(), Error> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::Io(format!("writing to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

fn mesh(args: MeshArgs) -> Result<(), Error> {
    if let Some(n) = args.threads {
        isoforge::par::set_threads(n)?;
    }
    let defaults = PolygonRules::default();
    let request = Request {
        method: Method::parse(&args.method)?,
        res: args.res,
        iso: args.iso,
        topology: match args.topology {
            TopologyArg::Fixed => Topology::Fixed,
            TopologyArg::Trilinear => Topology::Trilinear,
        },
        max_cells: args.max_cells,
        bounds: args.bounds.as_ref().map(|b| (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]))),
        // Without --stats nobody reads the error measures, and they can cost more than the meshing.
        analysis: AnalysisOptions {
            self_intersections: args.stats && !args.no_intersections,
            surface_error: args.stats,
        },
        theta_sharp: args.theta_sharp,
        phi_corner: args.phi_corner,
        directed: !args.no_directed,
        better_triangles: args.better_triangles,
        resample_creases: !args.tangent_planes,
        merge_flat: !args.no_flat_merge,
        mcq_rules: PolygonRules {
            cut_angle_deg: args.cut_angle.unwrap_or(defaults.cut_angle_deg),
            quad_ratio: args.quad_ratio.unwrap_or(defaults.quad_ratio),
        },
        mcq_snap: (args.snap != 0.0).then_some(args.snap),
        mcq_project: !args.no_project,
        gradient: match args.gradient {
            Some(GradientArg::Trilinear) => SampleGradient::Trilinear,
            Some(GradientArg::Central) | None => SampleGradient::CentralDifferences,
        },
        tolerance: args.tol,
        max_depth: args.max_depth,
        samples_per_cell: args.samples_per_cell,
        decimate: args.decimate,
        decimate_error: args.decimate_error,
        smooth: args.smooth,
        ..Request::default()
    };
    let out = mesh_input(&args, &request)?;
    if let Some(path) = &args.output {
        let is_obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if is_obj && request.method == Method::Quad {
            isoforge::quad::obj::write_obj_file(&out.mesh.positions, &out.quads, path)?;
        } else {
            export::write_by_extension(&out.mesh, path)?;
        }
    }
    if args.stats {
        print_out(&(serde_json::to_string(&out.stats).map_err(|e| Error::Io(e.to_string()))? + "\n"))?;
    }
    Ok(())
}

/// Meshes a program in --bounds, or with --fit in bounds fitted to its inside.
fn mesh_program(program: &expr::Program, args: &MeshArgs, request: &Request) -> Result<Output, Error> {
    if !args.fit {
        return pipeline::mesh_program(program, request);
    }
    let bounds = expr::extent::auto_bounds(program, 0.05)?;
    pipeline::mesh_program(program, &Request { bounds: Some(bounds), ..request.clone() })
}

/// Meshes whichever input was given (clap makes sure it is exactly one).
fn mesh_input(args: &MeshArgs, request: &Request) -> Result<Output, Error> {
    if let Some(name) = &args.scene {
        pipeline::mesh_scene(name, request)
    } else if let Some(text) = &args.expr {
        mesh_program(&expr::compile(text)?, args, request)
    } else if let Some(path) = &args.expr_file {
        let text = std::fs::read_to_string(path).map_err(|e| io_error(path, e))?;
        // Compiler style: file:line:column: message.
        let program = expr::compile(&text).map_err(|e| match e {
            Error::Parse { .. } => Error::Io(format!("{}:{e}", path.display())),
            e => e,
        })?;
        mesh_program(&program, args, request)
    } else if let Some(path) = &args.grid {
        let dims = args.dims.ok_or_else(|| Error::InvalidOption("--grid needs --dims X,Y,Z".into()))?;
        let origin = args.origin.map_or(Vec3::ZERO, Vec3::from);
        let spacing = args.spacing.map_or(Vec3::ONE, Vec3::from);
        let grid = Grid::from_points(dims, origin, spacing)?;
        grid.check_size(request.max_cells)?;
        let dtype = match args.dtype.unwrap_or(DtypeArg::F32) {
            DtypeArg::F32 => Dtype::F32,
            DtypeArg::U8 => Dtype::U8,
            DtypeArg::U16 => Dtype::U16,
        };
        let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
        let values = grid::samples_from_bytes(&bytes, dtype, &grid)?;
        pipeline::mesh_samples(&values, &grid, request)
    } else if let Some(path) = &args.mesh {
        let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
        let mesh = input::read_mesh(&bytes, path.to_str()).map_err(|e| in_file(path, e))?;
        pipeline::mesh_triangles(&mesh, request)
    } else if let Some(path) = &args.points {
        let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
        let cloud = input::read_points(&bytes, path.to_str()).map_err(|e| in_file(path, e))?;
        pipeline::mesh_points(&cloud, request)
    } else {
        Err(Error::InvalidOption("give one of --scene, --expr, --expr-file, --grid, --mesh, --points".into()))
    }
}

/// `N` comma-separated numbers, e.g. `--dims 64,64,32` or `--bounds -1,-1,-1,1,1,1`.
fn list<T: std::str::FromStr, const N: usize>(text: &str) -> Result<[T; N], String>
where
    T::Err: std::fmt::Display,
{
    let values = text
        .split(',')
        .map(|t| t.trim().parse::<T>().map_err(|e| format!("'{}': {e}", t.trim())))
        .collect::<Result<Vec<T>, String>>()?;
    let n = values.len();
    values.try_into().map_err(|_| format!("expected {N} comma-separated numbers, got {n}"))
}

/// A reader's error, prefixed with the file it is about.
fn in_file(path: &Path, e: Error) -> Error {
    match e {
        Error::Io(msg) => Error::Io(format!("{}: {msg}", path.display())),
        e => e,
    }
}

fn io_error(path: &Path, e: std::io::Error) -> Error {
    Error::Io(format!("cannot read {}: {e}", path.display()))
}

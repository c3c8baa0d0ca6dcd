//! `isoforge`: mesh a scene from the command line, write OBJ/STL/PLY, print stats as JSON.

use clap::{Parser, Subcommand, ValueEnum};
use isoforge::mc::Topology;
use isoforge::mesh::export;
use isoforge::pipeline::{self, Method, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::{scenes, Error, Vec3};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "isoforge", version, about = "Feature-preserving isosurface extraction")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Mesh a scene and optionally write the mesh and print its stats.
    Mesh(MeshArgs),
    /// List the built-in scenes.
    Scenes,
}

#[derive(clap::Args)]
struct MeshArgs {
    /// A built-in scene (see `isoforge scenes`).
    #[arg(long)]
    scene: String,
    /// Meshing method: mc (Marching Cubes) or emc (Extended Marching Cubes).
    #[arg(long, default_value = "mc")]
    method: String,
    /// Cells along the longest side of the bounds.
    #[arg(long, default_value_t = 64)]
    res: usize,
    /// x0,y0,z0,x1,y1,z1: mesh this box instead of the scene's own.
    #[arg(long, value_delimiter = ',', num_args = 6, allow_hyphen_values = true)]
    bounds: Option<Vec<f32>>,
    /// Iso-level: points with value < iso are inside.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    iso: f32,
    /// How ambiguous cell faces are resolved.
    #[arg(long, value_enum, default_value_t = TopologyArg::Fixed)]
    topology: TopologyArg,
    /// Refuse grids with more cells than this.
    #[arg(long, default_value_t = isoforge::grid::DEFAULT_MAX_CELLS)]
    max_cells: u64,
    /// Output file; the format follows the extension (.obj, .stl, .ply).
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
}

#[derive(Clone, Copy, ValueEnum)]
enum TopologyArg {
    Fixed,
    Trilinear,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Scenes => {
            for name in scenes::SCENE_NAMES {
                println!("{name}");
            }
            Ok(())
        }
        Command::Mesh(args) => mesh(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("isoforge: {e}");
            ExitCode::FAILURE
        }
    }
}

fn mesh(args: MeshArgs) -> Result<(), Error> {
    let request = Request {
        method: Method::parse(&args.method)?,
        res: args.res,
        iso: args.iso,
        topology: match args.topology {
            TopologyArg::Fixed => Topology::Fixed,
            TopologyArg::Trilinear => Topology::Trilinear,
        },
        max_cells: args.max_cells,
        bounds: args.bounds.map(|b| (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]))),
        analysis: AnalysisOptions { self_intersections: !args.no_intersections, surface_error: true },
        theta_sharp: args.theta_sharp,
        phi_corner: args.phi_corner,
        directed: !args.no_directed,
    };
    let scene = scenes::scene(&args.scene)?;
    let out = pipeline::mesh_field(scene.field.as_ref(), (scene.min, scene.max), &request)?;
    if let Some(path) = &args.output {
        export::write_by_extension(&out.mesh, path)?;
    }
    if args.stats {
        println!("{}", serde_json::to_string(&out.stats).map_err(|e| Error::Io(e.to_string()))?);
    }
    Ok(())
}

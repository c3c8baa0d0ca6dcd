//! isoforge: feature-preserving isosurface extraction for Rust and the browser.
//!
//! # Start here
//! [`pipeline`] turns an input (a program in the [`expr`] language, a CSG tree, a sampled grid, a
//! triangle mesh, a point cloud) and a [`pipeline::Request`] (method, resolution, bounds, options)
//! into a mesh and its [`stats`]. The README's quick start, tested here:
//!
//! ```
//! # fn main() -> Result<(), isoforge::Error> {
//! use isoforge::pipeline::{mesh_expr, Method, Request};
//! let request = Request { method: Method::Emc, res: 48, ..Request::default() };
//! let out = mesh_expr("subtract(box(0.6, 0.6, 0.6), sphere(0.75))", &request)?;
//! assert!(out.stats.closed_manifold && out.stats.euler == -8);
//! isoforge::mesh::export::write_by_extension(&out.mesh, &std::env::temp_dir().join("frame.glb"))?;
//! # Ok(()) }
//! ```
//!
//! The crate is organised in rooms, each owning one idea:
//! - [`grid`]: where samples live (bounds, dimensions, index → world mapping, size caps).
//! - [`field`]: what is sampled (the [`field::Field`] trait, closures, sampled volumes).
//! - [`expr`]: fields typed as text or built as CSG JSON, compiled to a flat tape (values, exact
//!   gradients, interval bounds, batches).
//! - [`tables`]: the Marching Cubes cube topology and case tables, generated once from first principles.
//! - [`mc`]: plain Marching Cubes, the baseline every other method is compared against.
//! - [`emc`]: Extended Marching Cubes (sharp features on the MC grid).
//! - [`dmc`]: Dual Marching Cubes (an octree adapted to the field, contoured on its dual grid).
//! - [`mcq`]: Marching Cubes with better triangles (per-cell polygon rules and vertex snapping).
//! - [`mesh`]: the triangle mesh, its analysis (topology, quality, error) and export.
//! - [`input`]: reading triangle meshes (OBJ, STL, PLY, OFF) and oriented point clouds (PLY, XYZ)
//!   for EMC's remeshing and surface reconstruction ([`emc::mesh_source`], [`emc::point_source`]).
//! - [`quad`]: semi-regular quad meshes from the outside faces of cut cells, with collapses.
//! - [`scenes`]: named test objects shared by the CLI, tests, benches and the demo.
//! - [`stats`]: the one JSON-able summary of a meshing run.
//! - [`par`]: threads natively (rayon), the same loops in order in wasm; same output either way.
//!
//! The algorithm core knows nothing of JavaScript; `wasm` (only on wasm32) is a thin binding layer.

pub mod crust;
pub mod dmc;
pub mod emc;
pub mod error;
pub mod expr;
pub mod field;
pub mod grid;
pub mod input;
pub mod mc;
pub mod mcq;
pub mod mesh;
pub mod par;
pub mod pipeline;
pub mod progress;
pub mod quad;
pub mod scenes;
pub mod stats;
pub mod tables;

#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use error::Error;
pub use field::Field;
pub use glam::Vec3;
pub use grid::Grid;
pub use mesh::Mesh;

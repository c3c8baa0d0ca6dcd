//! Mesh analysis: everything a test, benchmark or demo needs to judge a mesh without trusting the
//! mesher that made it.
//!
//! Each submodule owns one question:
//! - [`topology`](mod@topology): is it a closed, oriented 2-manifold, and of which Euler
//!   characteristic and genus?
//! - [`self_intersect`]: does the surface cross itself? (driver over [`bvh`] and [`tri_tri`])
//! - [`quality`]: how well shaped are the triangles, and what area and volume do they enclose?
//! - [`surface_error`](mod@surface_error): how far is the mesh from the true zero set, in position
//!   and in normal?
//! - [`digital`]: the Euler characteristic of the sampled inside region, an independent count to
//!   check a mesher's topology against.
//!
//! All functions are pure and work in `f64` internally, because the quantities they sum (volumes,
//! Euler characteristics, millions of distances) or compare (orientation signs) lose too much in
//! `f32`.

pub mod bvh;
pub mod digital;
pub mod quality;
pub mod self_intersect;
pub mod surface_error;
pub mod topology;
pub mod tri_tri;

#[cfg(test)]
pub(crate) mod fixtures;

pub use digital::digital_euler;
pub use quality::{angle_stats, aspect_ratios, signed_volume, surface_area, AngleStats};
pub use self_intersect::{self_intersecting_pairs, self_intersections};
pub use surface_error::{surface_error, SurfaceError};
pub use topology::{degenerate_triangles, topology, Topology};

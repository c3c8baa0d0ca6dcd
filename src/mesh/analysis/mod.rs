//! Mesh analysis: everything a test, benchmark or demo needs to judge a mesh without trusting the
//! mesher that made it.
//!
//! Each submodule owns one question:
//! - [`topology`](mod@topology): is it a closed, oriented 2-manifold, and of which Euler
//!   characteristic and genus?
//! - [`digital`]: the Euler characteristic of the sampled inside region, an independent count to
//!   check a mesher's topology against.
//!
//! All functions are pure and work in `f64` internally, because the quantities they sum (volumes,
//! Euler characteristics, millions of distances) or compare (orientation signs) lose too much in
//! `f32`.

pub mod digital;
pub mod topology;

#[cfg(test)]
pub(crate) mod fixtures;

pub use digital::digital_euler;
pub use topology::{degenerate_triangles, topology, Topology};

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
pub use self_intersect::{
    folded_pairs, self_intersecting_pairs, self_intersecting_pairs_cancellable, self_intersections,
};
pub use surface_error::{surface_error, surface_error_cancellable, SurfaceError};
pub use topology::{degenerate_triangles, topology, Topology};

#[cfg(test)]
mod scale_tests {
    use super::*;
    use crate::mc::{mesh_field, McOptions};
    use crate::{scenes, Grid};
    use web_time::Instant;

    /// The brief's scale target: about half a million triangles in a few seconds natively. Ignored
    /// because a debug build is ten times slower; run with
    /// `cargo test --release --lib scale -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn half_a_million_triangles() {
        let scene = scenes::scene("sphere").unwrap();
        let grid = Grid::with_resolution(scene.min, scene.max, 290).unwrap();
        let (mesh, _) = mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
        eprintln!("{} triangles", mesh.triangle_count());
        assert!(mesh.triangle_count() > 400_000);
        let t = Instant::now();
        let topo = topology(&mesh);
        eprintln!("topology {:?} in {:?}", topo.euler, t.elapsed());
        assert!(topo.is_closed_manifold(), "{topo:?}");
        let t = Instant::now();
        let crossings = self_intersections(&mesh);
        eprintln!("self_intersections {crossings} in {:?}", t.elapsed());
        assert_eq!(crossings, 0);
        let t = Instant::now();
        let angles = angle_stats(&mesh);
        let (mean, max) = aspect_ratios(&mesh);
        eprintln!(
            "quality: angles {:.2}..{:.2}, aspect mean {mean:.3} max {max:.1}, in {:?}",
            angles.min_deg,
            angles.max_deg,
            t.elapsed()
        );
        let t = Instant::now();
        let error = surface_error(&mesh, scene.field.as_ref());
        eprintln!("surface_error {error:?} in {:?}", t.elapsed());
        assert!(error.dist_max < grid.cell_size() as f64);
    }
}

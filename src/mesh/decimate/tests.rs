use super::*;
use crate::mesh::analysis::{self_intersections, topology};
use crate::pipeline::{mesh_expr, Method, Request};

fn emc(text: &str, res: usize) -> crate::pipeline::Output {
    mesh_expr(text, &Request { method: Method::Emc, res, ..Request::default() }).unwrap()
}

#[test]
fn a_box_comes_down_to_its_corners_with_its_edges_in_place() {
    let out = emc("box(0.5, 0.6, 0.7)", 16);
    let before = topology(&out.mesh);
    let options = DecimateOptions { feature_tolerance: 1e-4, ..DecimateOptions::default() };
    let d = decimate(&out.mesh, &out.feature_edges, None, &options).unwrap();
    let after = topology(&d.mesh);
    assert!(after.is_closed_manifold() && after.euler == before.euler, "{after:?}");
    assert_eq!(self_intersections(&d.mesh), 0);
    assert!(
        d.mesh.triangle_count() * 20 < out.mesh.triangle_count(),
        "{} triangles",
        d.mesh.triangle_count()
    );
    // Every feature vertex still lies on one of the box's twelve edges.
    for &[a, b] in &d.feature_edges {
        for p in [d.mesh.positions[a as usize], d.mesh.positions[b as usize]] {
            let on_faces = (p.abs() - Vec3::new(0.5, 0.6, 0.7)).abs().cmplt(Vec3::splat(1e-4));
            assert!(on_faces.bitmask().count_ones() >= 2, "{p} is off the box's edges");
        }
    }
    assert!(d.feature_edges.len() >= 12);
}

#[test]
fn the_error_bound_stops_a_sphere_before_it_turns_polyhedral() {
    let out = emc("sphere(0.8)", 24);
    let field = crate::expr::compile("sphere(0.8)").unwrap();
    let undecimated = crate::mesh::analysis::surface_error(&out.mesh, &field).dist_max;
    let bound = 2.0 * undecimated;
    let options = DecimateOptions { max_error: Some(bound), ..DecimateOptions::default() };
    let d = decimate(&out.mesh, &out.feature_edges, Some(&field), &options).unwrap();
    let error = crate::mesh::analysis::surface_error(&d.mesh, &field);
    assert!(error.dist_max <= bound * 1.01, "{error:?} against {undecimated}");
    assert!(d.mesh.triangle_count() * 2 < out.mesh.triangle_count());
    assert!(topology(&d.mesh).is_closed_manifold());
}

#[test]
fn segment_distance_measures_to_the_nearest_point_of_the_segment() {
    let (a, b) = (DVec3::ZERO, DVec3::X);
    assert!((segment_distance(DVec3::new(0.5, 1.0, 0.0), a, b) - 1.0).abs() < 1e-12);
    assert!((segment_distance(DVec3::new(2.0, 0.0, 0.0), a, b) - 1.0).abs() < 1e-12);
}

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

/// Seeded fans of triangles with every vertex on a ball, the field the ball's distance or its
/// negation: the balanced centre lies outside the ball (the faces sag inwards, whichever way the
/// field's sign runs) and the fan's largest distance, vertex and face samples, drops by a quarter
/// (with the ring fixed, the samples halfway to it move by a sixth of the offset only). Fails if
/// the offset's sign or the samples' shares are wrong.
#[test]
fn the_balanced_vertex_of_a_fan_on_a_ball_sits_outside_and_cuts_the_error_by_a_quarter() {
    use crate::expr::testutil::Rng;
    for seed in 0..30u64 {
        let mut rng = Rng::new(0xBA1A_0000 + seed);
        let radius = rng.range(0.3, 1.0);
        let axis = rng.vec3(-1.0, 1.0).try_normalize().unwrap_or(Vec3::Z);
        let (u, w) = axis.any_orthonormal_pair();
        let spread = rng.range(0.03, 0.2);
        let k = 5 + rng.below(4);
        let mut positions = vec![radius * axis];
        for i in 0..k {
            let turn = std::f32::consts::TAU * (i as f32 + rng.range(-0.2, 0.2)) / k as f32;
            let angle = spread * rng.range(0.8, 1.2);
            let dir = axis * angle.cos() + (u * turn.cos() + w * turn.sin()) * angle.sin();
            positions.push(radius * dir);
        }
        let triangles = (0..k as u32).map(|i| [0, 1 + i, 1 + (i + 1) % k as u32]).collect();
        let mesh = Mesh { positions, normals: vec![], triangles };
        for text in [format!("sphere({radius})"), format!("-sphere({radius})")] {
            let field = crate::expr::compile(&text).unwrap();
            let state = State::new(&mesh, &[], Some(&field), &DecimateOptions::default());
            let p = state.pos[0];
            let fan = |centre: DVec3| -> Vec<[DVec3; 3]> {
                mesh.triangles
                    .iter()
                    .map(|t| t.map(|i| if i == 0 { centre } else { state.pos[i as usize] }))
                    .collect()
            };
            let off_ball = |x: DVec3| (x.length() - radius as f64).abs();
            let worst = |centre: DVec3| {
                let mut worst = off_ball(centre);
                for c in fan(centre) {
                    let middle = (c[0] + c[1] + c[2]) / 3.0;
                    worst = c
                        .iter()
                        .map(|&x| off_ball(0.5 * (middle + x)))
                        .fold(worst.max(off_ball(middle)), f64::max);
                }
                worst
            };
            let balanced = state.balanced(p, &fan(p));
            let what = format!("seed {seed}, {text}, spread {spread}, {k} neighbours");
            assert!(balanced.length() > radius as f64, "{what}: moved inwards to {balanced}");
            assert!(worst(balanced) <= 0.76 * worst(p), "{what}: {} -> {}", worst(p), worst(balanced));
        }
    }
}

/// A split moves nothing: the mesh stays closed with its Euler characteristic, area and volume,
/// two triangles more, the new vertex at the edge's midpoint and free.
#[test]
fn splitting_an_edge_keeps_the_surface_and_its_topology() {
    let out = emc("subtract(box(0.6, 0.6, 0.6), sphere(0.75))", 16);
    let before = topology(&out.mesh);
    let mut state = State::new(&out.mesh, &out.feature_edges, None, &DecimateOptions::default());
    let count = state.alive_count;
    let mut split = 0;
    for f in (0..state.tris.len() as u32).step_by(7) {
        let t = state.tris[f as usize];
        if state.alive[f as usize] && !state.lines.contains_key(&key(t[0], t[1])) {
            let midpoint = 0.5 * (state.pos[t[0] as usize] + state.pos[t[1] as usize]);
            assert!(state.split_edge(f, t[0], t[1]));
            assert_eq!(*state.pos.last().unwrap(), midpoint);
            assert_eq!(*state.kind.last().unwrap(), Kind::Free);
            split += 1;
        }
    }
    assert!(split > 20, "{split} edges split");
    assert_eq!(state.alive_count, count + 2 * split);
    let d = state.finish(&out.mesh);
    let after = topology(&d.mesh);
    assert!(after.is_closed_manifold() && after.euler == before.euler, "{after:?}");
    assert_eq!(d.mesh.triangle_count(), out.mesh.triangle_count() + 2 * split);
    use crate::mesh::analysis::quality::{signed_volume as volume, surface_area as area};
    assert!((area(&d.mesh) - area(&out.mesh)).abs() < 1e-6 * area(&out.mesh));
    assert!((volume(&d.mesh) - volume(&out.mesh)).abs() < 1e-6 * volume(&out.mesh).abs());
    assert_eq!(self_intersections(&d.mesh), 0);
}

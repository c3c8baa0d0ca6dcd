//! Remeshing real CAD parts (issue 18): CGAL's fandisk and three small closed parts from the same
//! data set (`tests/data/`, provenance and licence in its README). Each is remeshed by EMC and by
//! MC on the same grid, held closed with the input's genus, and measured by the tests' own
//! sampled two-sided Hausdorff distance (`common::hausdorff`), as a fraction of the input's
//! bounding-box diagonal, the measure the paper reports.

mod common;

use common::assert_watertight;
use common::hausdorff::{hausdorff, point_triangle_distance, Hausdorff, NearestTriangles};
use glam::{DVec3, Vec3};
use isoforge::emc::mesh_source::mesh_bounds;
use isoforge::input::read_mesh;
use isoforge::pipeline::{mesh_triangles, Method};
use isoforge::Mesh;

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

fn model(name: &str) -> Mesh {
    let bytes: &[u8] = match name {
        "fandisk" => include_bytes!("data/fandisk.off"),
        "anchor" => include_bytes!("data/anchor.off"),
        "couplingdown" => include_bytes!("data/couplingdown.off"),
        "joint" => include_bytes!("data/joint.off"),
        _ => panic!("no test model {name}"),
    };
    read_mesh(bytes, Some("off")).unwrap()
}

fn diagonal(mesh: &Mesh) -> f64 {
    let (lo, hi) = mesh_bounds(mesh);
    (hi - lo).as_dvec3().length()
}

/// Samples this fraction of the diagonal apart where the distance could be largest: the maximum
/// is found to 3e-4 of the diagonal (0.03 cells at 64 cells).
const SPACING: f64 = 1.0 / 2000.0;

/// The sampled Hausdorff distance between `input` and `output`, as a fraction of the input's
/// bounding-box diagonal.
fn relative_hausdorff(input: &Mesh, output: &Mesh) -> (Hausdorff, f64) {
    let diag = diagonal(input);
    let h = hausdorff(
        (&input.positions, &input.triangles),
        (&output.positions, &output.triangles),
        SPACING * diag,
    );
    (h, h.max() / diag)
}

struct Remeshed {
    mesh: Mesh,
    euler: i64,
    /// Hausdorff over the diagonal.
    relative: f64,
    /// Hausdorff in cells.
    cells: f64,
    rms: f64,
}

fn remesh(input: &Mesh, method: Method, res: usize) -> Remeshed {
    let out = mesh_triangles(input, &common::bare_request(method, res)).unwrap();
    let what = format!("{} at {res} cells", method.name());
    let topo = assert_watertight(&out.mesh, &what);
    let (h, relative) = relative_hausdorff(input, &out.mesh);
    let (lo, hi) = mesh_bounds(input);
    // The padded grid's cell: the longest side over res - 4 (two cells of padding each side).
    let cell = (hi - lo).max_element() as f64 / (res - 4) as f64;
    Remeshed {
        euler: topo.euler,
        relative,
        cells: h.max() / cell,
        rms: h.rms / diagonal(input),
        mesh: out.mesh,
    }
}

fn report(name: &str, res: usize, mc: &Remeshed, emc: &Remeshed) {
    eprintln!(
        "{name} at {res}: MC {} triangles, Hausdorff {:.3} % ({:.3} cells), rms {:.4} %; \
         EMC {} triangles, Hausdorff {:.3} % ({:.3} cells), rms {:.4} %",
        mc.mesh.triangle_count(),
        100.0 * mc.relative,
        mc.cells,
        100.0 * mc.rms,
        emc.mesh.triangle_count(),
        100.0 * emc.relative,
        emc.cells,
        100.0 * emc.rms,
    );
}

/// The distance code against brute force, on shapes whose distances are known.
#[test]
fn the_sampled_hausdorff_distance_is_exact_where_it_can_be_checked() {
    let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
    // Over the face, beyond each side, beyond each corner.
    assert!((point_triangle_distance(DVec3::new(0.2, 0.2, 0.5), &t) - 0.5).abs() < 1e-12);
    assert!((point_triangle_distance(DVec3::new(0.5, -0.3, 0.4), &t) - 0.5).abs() < 1e-12);
    assert!((point_triangle_distance(DVec3::new(1.0, 1.0, 0.0), &t) - 0.5f64.sqrt()).abs() < 1e-12);
    assert!((point_triangle_distance(DVec3::new(-3.0, -4.0, 0.0), &t) - 5.0).abs() < 1e-12);
    assert!((point_triangle_distance(DVec3::new(2.0, 0.0, 0.0), &t) - 1.0).abs() < 1e-12);

    // The bucket search agrees with brute force, inside and far outside the model.
    let fandisk = model("fandisk");
    let index = NearestTriangles::new(&fandisk.positions, &fandisk.triangles);
    let tris: Vec<[DVec3; 3]> =
        fandisk.triangles.iter().map(|t| t.map(|v| fandisk.positions[v as usize].as_dvec3())).collect();
    let mut rng = common::Rng::new(18);
    for n in 0..300 {
        let reach = if n % 3 == 0 { 3.0 } else { 0.7 };
        let p = DVec3::new(
            rng.range(-reach, reach) as f64,
            rng.range(-reach, reach) as f64,
            rng.range(-reach, reach) as f64,
        );
        let brute = tris.iter().map(|t| point_triangle_distance(p, t)).fold(f64::INFINITY, f64::min);
        assert!((index.distance(p) - brute).abs() < 1e-12, "{p}: {} vs {brute}", index.distance(p));
    }

    // A unit cube against the same cube pushed out by 0.01 along +z (its top moved): 0.01 from
    // both sides, found on the faces and edges, not only at the vertices.
    let cube = |top: f32| {
        let positions: Vec<Vec3> = (0..8)
            .map(|c| Vec3::new((c & 1) as f32, (c >> 1 & 1) as f32, if c & 4 != 0 { top } else { 0.0 }))
            .collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let triangles: Vec<[u32; 3]> =
            quads.iter().flat_map(|q: &[u32; 4]| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        Mesh { positions, triangles, ..Mesh::default() }
    };
    let (a, b) = (cube(1.0), cube(1.01));
    let h = hausdorff((&a.positions, &a.triangles), (&b.positions, &b.triangles), 0.01);
    assert!((h.a_to_b - 0.01).abs() < 1e-6 && (h.b_to_a - 0.01).abs() < 1e-6, "{h:?}");

    // A square against a square with its centre raised by 0.1 (a pyramid of four triangles): the
    // vertices of the flat square lie on the pyramid, so only face samples see the 0.1.
    let square = Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        ..Mesh::default()
    };
    let mut pyramid = square.clone();
    pyramid.positions.push(Vec3::new(0.5, 0.5, 0.1));
    pyramid.triangles = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
    let h = hausdorff((&square.positions, &square.triangles), (&pyramid.positions, &pyramid.triangles), 0.01);
    assert!(h.b_to_a > 0.099 && h.a_to_b > 0.09, "{h:?}");
}

/// The fandisk (12 946 triangles, one closed genus-0 part with flat, cylindrical and rounded
/// faces) at 64 and 72 cells. Its largest error is where a face half a cell wide runs between
/// two creases and tapers out; two fan centres there (`emc::strip`) took 72 cells from 0.425 %
/// to 0.252 % (64: 0.345 % to 0.337 %).
#[test]
fn the_fandisk_remeshes_closed_genus_0_within_the_bound() {
    let input = model("fandisk");
    for (res, bound) in [(64, 0.0036), (72, 0.0030)] {
        let mc = remesh(&input, Method::Mc, res);
        let emc = remesh(&input, Method::Emc, res);
        report("fandisk", res, &mc, &emc);
        assert_eq!(emc.euler, 2, "genus 0");
        assert_eq!(mc.euler, 2);
        assert!(
            emc.relative <= bound,
            "EMC Hausdorff {:.3} % of the diagonal at {res}",
            100.0 * emc.relative
        );
        assert!(emc.relative * 2.5 < mc.relative, "EMC {} against MC {} at {res}", emc.relative, mc.relative);
    }
}

/// Three smaller CAD parts of higher genus: closed, with their genus, nearer than MC.
#[test]
fn small_cad_parts_remesh_closed_with_their_genus() {
    for (name, res, euler, bound) in
        [("joint", 48, -2, 0.01), ("anchor", 64, -6, 0.01), ("couplingdown", 80, -16, 0.01)]
    {
        let input = model(name);
        let mc = remesh(&input, Method::Mc, res);
        let emc = remesh(&input, Method::Emc, res);
        report(name, res, &mc, &emc);
        assert_eq!(emc.euler, euler, "{name}");
        assert_eq!(mc.euler, euler, "{name}");
        assert!(emc.relative <= bound, "{name}: EMC Hausdorff {:.3} %", 100.0 * emc.relative);
        assert!(emc.relative < mc.relative, "{name}: EMC {} against MC {}", emc.relative, mc.relative);
    }
}

/// Not run by default: `ISOFORGE_MODEL=fandisk ISOFORGE_RES=48,64,80 cargo test --test cad_models
/// -- --ignored --nocapture` prints the table in docs/inputs.md (triangles, Hausdorff, time).
#[test]
#[ignore]
fn measure() {
    let var = |name: &str, default: &str| std::env::var(name).unwrap_or_else(|_| default.to_string());
    for name in var("ISOFORGE_MODEL", "fandisk").split(',') {
        let input = model(name);
        for res in var("ISOFORGE_RES", "48,64,80").split(',').map(|r| r.trim().parse::<usize>().unwrap()) {
            let mut row = Vec::new();
            for method in [Method::Mc, Method::Emc] {
                let mut best = f64::INFINITY;
                let mut out = None;
                for _ in 0..3 {
                    let t = std::time::Instant::now();
                    let o = mesh_triangles(&input, &common::bare_request(method, res)).unwrap();
                    best = best.min(t.elapsed().as_secs_f64() * 1e3);
                    out = Some(o);
                }
                let out = out.unwrap();
                let euler = assert_watertight(&out.mesh, name).euler;
                let (h, rel) = relative_hausdorff(&input, &out.mesh);
                row.push(format!(
                    "{} {} tris Euler {euler} {:.3} % rms {:.4} % (worst at {:.4}, {} queries) {:.1} ms",
                    method.name(),
                    out.mesh.triangle_count(),
                    100.0 * rel,
                    100.0 * h.rms / diagonal(&input),
                    h.worst,
                    h.queries,
                    best
                ));
            }
            eprintln!("{name} {} tris in, res {res}: {}", input.triangle_count(), row.join("; "));
        }
    }
}

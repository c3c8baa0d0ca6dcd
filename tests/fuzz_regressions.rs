//! Every input the cargo-fuzz targets in `fuzz/` found failing, minimised and written out inline,
//! one test each, so that the fix stays fixed on every `cargo test` (natively and as
//! wasm-bindgen-test in headless Chromium) without libFuzzer. docs/fuzzing.md lists the runs.

use isoforge::expr;
use isoforge::input;
use isoforge::mesh::analysis;
use isoforge::pipeline::{self, Method, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::Vec3;

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

/// `expr_parse`, minimised by `cargo fuzz tmin` from a mutated milling scene: the bounds of
/// `eval_interval` left out the points where `z^-0.3` is undefined (z < 0), but `max` and `min`
/// return their other operand there (`f32::max(x, NaN)` is `x`), so the box's bounds excluded
/// the program's own values: -5 at a corner of a box claimed to hold only [3, inf].
#[test]
fn expr_parse_interval_of_max_with_an_operand_undefined_in_the_box() {
    let text =
        "r =15;\nh=+-2-z ^-.3;block= box(8,6, h);\npath =(capsule(6,5,h,1, 0,h, r));\nsubtract(block,path)\n";
    let program = expr::compile(text).unwrap();
    let (lo, hi) = (Vec3::splat(-1.0), Vec3::ONE);
    let (a, b) = program.eval_interval(lo, hi);
    for p in [lo, hi, Vec3::new(-0.5, 0.5, -0.8), Vec3::new(1.0, -1.0, -0.25)] {
        let v = program.eval(p);
        assert!(v.is_nan() || (a <= v && v <= b), "{v} at {p} outside its interval [{a}, {b}]");
    }
    // The same box's min/max choices must keep the values too.
    let (_, choices) = program.eval_interval_with_choices(lo, hi);
    let lean = program.simplify(&choices);
    for p in [lo, hi, Vec3::new(-0.5, 0.5, -0.8)] {
        let (v, w) = (program.eval(p), lean.eval(p));
        assert!(v == w || (v.is_nan() && w.is_nan()), "{v} at {p}, simplified {w}");
    }
}

/// What that bug did to a mesh: DMC's octree culls boxes whose interval has no zero, so
/// `max(x, sqrt(z) + 1)`, which is `x` where z < 0 (there `sqrt(z) + 1` is NaN and `max` gives
/// `x`), was one culled root box and an empty mesh while MC meshed the surface.
#[test]
fn expr_parse_dmc_meshes_a_surface_where_a_max_operand_is_undefined() {
    let request = |method| Request {
        method,
        res: 16,
        analysis: AnalysisOptions { self_intersections: false, surface_error: false },
        ..Request::default()
    };
    let text = "max(x, sqrt(z) + 1)";
    let mc = pipeline::mesh_expr(text, &request(Method::Mc)).unwrap();
    let dmc = pipeline::mesh_expr(text, &request(Method::Dmc)).unwrap();
    assert!(mc.mesh.triangle_count() > 0);
    assert!(dmc.mesh.triangle_count() > 0, "DMC meshed nothing where MC meshed {}", mc.mesh.triangle_count());
    // The solid is x < 0, z < 0 (for z >= 0 the field is at least 1), which DMC closes by the
    // bounds: one closed piece of volume 1 * 2 * 1.
    let topo = analysis::topology(&dmc.mesh);
    assert!(topo.is_closed_manifold() && topo.components == 1, "{topo:?}");
    assert!((dmc.stats.volume - 2.0).abs() < 0.1, "volume {}", dmc.stats.volume);
}

/// `read_mesh`, minimised by `cargo fuzz tmin` (its first byte picked the OBJ hint): the relative
/// index i64::MIN was checked as `-i > count`, and negating it overflows (a panic in debug
/// builds, a wrapped comparison in release ones). Now an error naming the index.
#[test]
fn read_mesh_obj_relative_index_i64_min() {
    for bytes in [&b"f -9223372036854775808"[..], b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -9223372036854775808 1 2\n"]
    {
        let err = input::read_mesh(bytes, Some("obj")).unwrap_err().to_string();
        assert!(err.contains("-9223372036854775808") && err.contains("before the first vertex"), "{err}");
    }
}

/// `expr_parse`, minimised by `cargo fuzz tmin` from a mutated seed (`0.e0/ -0` inside a torus's
/// radius): a constant folded to NaN was bounded by everything but not marked undefined, so
/// `abs` narrowed it to [0, inf] and `max` with it claimed at least 0 where it is `-y`.
#[test]
fn expr_parse_interval_of_max_with_a_nan_constant() {
    let text = "s = smooth_union(sphere(0.4), rounded_box(0.3, 0.2, 0.25, 0.05), 0.1);\
                t = smooth_intersect(cone(0.3, 0.6), capsule(0, 0, -0.5, 0, 4, 0.5, 0.4), 0.05);\n\
                u = smooth_subtract(torus(0.e0/ -0 * x- 2.15, 0.1), plane(0, 0, 1, 0.2), .02);\n\
                v = shell(offset(s, 01), 0.02);\nw = s;\n\
                union(v, intersect(w, box(0.5, 0.5, 0.5)), subtract(u, cylinder(0.1, 1)), rotate(v, 1, 1, 0, 30))\n";
    let (lo, hi) = (Vec3::new(0.1, -0.3, 0.2), Vec3::new(0.35, -0.05, 0.6));
    for text in [text, "max(abs(0/-0*y), x)"] {
        let program = expr::compile(text).unwrap();
        let (a, b) = program.eval_interval(lo, hi);
        for p in [lo, hi, Vec3::new(0.35, -0.3, 0.4), Vec3::new(0.1, -0.05, 0.6)] {
            let v = program.eval(p);
            assert!(v.is_nan() || (a <= v && v <= b), "{text}: {v} at {p} outside its interval [{a}, {b}]");
        }
    }
}

/// `expr_parse`, minimised by `cargo fuzz tmin`: `pow`'s bounds took a base of -0 for a
/// non-negative one and bounded `(-0)^x` by [0, inf], but `(-0)^-1` is -inf.
#[test]
fn expr_parse_interval_of_negative_zero_to_a_power() {
    let program = expr::compile("(-0)^x").unwrap();
    let (a, b) = program.eval_interval(Vec3::splat(-1.0), Vec3::ONE);
    for x in [-1.0, -0.5, 0.0, 0.5, 1.0] {
        let v = program.eval(Vec3::new(x, 0.0, 0.0));
        assert!(v.is_nan() || (a <= v && v <= b), "{v} at x = {x} outside its interval [{a}, {b}]");
    }
}

/// `expr_parse`, minimised by `cargo fuzz tmin`: `0^x` reaches +inf at x = -1, so the plane's
/// value and the union reach -inf, and `pow`'s bounds treated every negative base to the
/// fractional power 1/3 as undefined, but `(-inf)^(1/3)` is +inf: the interval ended at 1.
#[test]
fn expr_parse_interval_of_minus_infinity_to_a_fractional_power() {
    let text = "body= -x ;fin=(plane(0,0,1,0^x )); union(body,rotate(fin, 0,0,3, 8))^ 3^-1";
    let program = expr::compile(text).unwrap();
    let (lo, hi) = (Vec3::splat(-1.0), Vec3::ONE);
    let (a, b) = program.eval_interval(lo, hi);
    for p in [lo, hi, Vec3::new(-1.0, 0.5, 0.5), Vec3::new(0.5, -1.0, -0.5)] {
        let v = program.eval(p);
        assert!(v.is_nan() || (a <= v && v <= b), "{v} at {p} outside its interval [{a}, {b}]");
    }
}

/// `read_points` (libFuzzer could not shrink it further): a binary little-endian PLY whose first
/// normal is (1.4e-45, -2.7e-23, 0). Its squared length underflows, so `normalize` divided by a
/// wrong length and returned a normal 0.71 long. Now scaled by its largest component first: the
/// unit vector -y. A normal past 1e19, whose square overflowed and was refused as having "no
/// direction", is a direction too.
#[test]
fn read_points_ply_tiny_normal_is_a_unit_vector() {
    let mut bytes = b"ply\nformat binary_little_endian .0\nelement vertex 2\nproperty float x\n\
        property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
        property uchar d\nend_header\n"
        .to_vec();
    for (v, d) in [
        ([1.0, 0.0, 0.0, f32::from_bits(1), -2.667_657_5e-23, 0.0], 7u8),
        ([-1.0, 0.0, 0.0, -1.0, 0.0, 0.0], 9),
    ] {
        for c in v {
            bytes.extend_from_slice(&f32::to_le_bytes(c));
        }
        bytes.push(d);
    }
    let near = |normals: &[Vec3], expected: &[Vec3]| {
        normals.len() == expected.len()
            && normals
                .iter()
                .zip(expected)
                .all(|(n, e)| (*n - *e).length() < 1e-6 && (n.length() - 1.0).abs() < 1e-6)
    };
    let cloud = input::read_points(&bytes, Some("ply")).unwrap();
    assert!(near(&cloud.normals, &[Vec3::NEG_Y, Vec3::NEG_X]), "{:?}", cloud.normals);
    let cloud = input::read_points(b"0 0 0 1e-30 0 0\n1 1 1 0 3e30 -3e30\n", Some("xyz")).unwrap();
    let s = std::f32::consts::FRAC_1_SQRT_2;
    assert!(near(&cloud.normals, &[Vec3::X, Vec3::new(0.0, s, -s)]), "{:?}", cloud.normals);
}

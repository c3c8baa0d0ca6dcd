//! The command-line tool, run as a real process: each input kind, the stats JSON, errors, outputs.
#![cfg(not(target_arch = "wasm32"))]

use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Output};

fn isoforge(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_isoforge")).args(args).output().expect("run isoforge")
}

/// Runs a command that must succeed and returns its stdout.
fn ok(args: &[&str]) -> String {
    let out = isoforge(args);
    assert!(out.status.success(), "isoforge {args:?} failed:\n{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// Runs a command that must fail and returns its stderr.
fn fails(args: &[&str]) -> String {
    let out = isoforge(args);
    assert!(!out.status.success(), "isoforge {args:?} should have failed");
    assert!(out.stdout.is_empty(), "nothing on stdout when failing");
    String::from_utf8(out.stderr).unwrap()
}

fn stats(args: &[&str]) -> Value {
    let mut all = args.to_vec();
    all.push("--stats");
    serde_json::from_str(&ok(&all)).expect("--stats prints one JSON object")
}

/// A path in cargo's per-target scratch directory, unique per test.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn scene_stats_have_every_key() {
    let s = stats(&["mesh", "--scene", "torus", "--res", "24"]);
    for key in [
        "method",
        "res",
        "vertices",
        "triangles",
        "closed_manifold",
        "euler",
        "genus",
        "components",
        "min_angle_deg",
        "max_angle_deg",
        "dist_max",
        "dist_rms",
        "normal_dev_deg_p50",
        "normal_dev_deg_p95",
        "ms_total",
    ] {
        assert!(s.get(key).is_some_and(|v| !v.is_null()), "missing or null '{key}' in {s}");
    }
    assert_eq!(s["method"], "mc");
    assert_eq!(s["res"], 24);
    assert_eq!(s["closed_manifold"], true);
    assert_eq!(s["euler"], 0);
    assert_eq!(s["genus"], 1);
}

/// A reader that stops before the output comes (`isoforge ... --stats | true`) is no panic: the
/// output is dropped quietly, exit status 0 (`println!` panicked with a backtrace).
#[test]
fn a_reader_closing_stdout_early_is_not_a_panic() {
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_isoforge"))
        .args(["mesh", "--scene", "gear", "--res", "32", "--stats"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run isoforge");
    // Closed long before the mesh and its stats are done.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(out.status.success(), "{stderr}");
}

#[test]
fn scenes_are_listed_and_their_programs_printed() {
    let names = ok(&["scenes"]);
    for name in isoforge::scenes::SCENE_NAMES {
        assert!(names.lines().any(|l| l == name), "{name} not listed");
    }
    assert_eq!(ok(&["scenes", "rocket"]), isoforge::scenes::source("rocket").unwrap());
    assert!(fails(&["scenes", "rockett"]).contains("unknown scene 'rockett'"));
}

#[test]
fn an_expression_is_meshed_in_the_default_or_given_bounds() {
    let s = stats(&["mesh", "--expr", "sphere(0.7)", "--res", "20"]);
    assert_eq!(s["euler"], 2);
    assert!(s["dist_max"].as_f64().unwrap() < 0.02, "{s}");
    // Default bounds are [-1, 1]³: a radius-1.5 ball only fits in larger ones.
    let s = stats(&["mesh", "--expr", "r = 1.5; sphere(r)", "--res", "20", "--bounds", "-2,-2,-2,2,2,2"]);
    assert_eq!(s["euler"], 2);
    assert!((s["volume"].as_f64().unwrap() - 4.0 / 3.0 * std::f64::consts::PI * 3.375).abs() < 0.3, "{s}");
    // A leading minus is the expression's, not an option.
    let s = stats(&["mesh", "--expr", "-(0.5 - length(x, y, z))", "--res", "12"]);
    assert_eq!(s["euler"], 2);
}

#[test]
fn fit_meshes_a_program_where_it_is_and_refuses_an_unbounded_one() {
    // A torus far outside the default [-1, 1]³: fitted, it is whole (genus 1, closed).
    let s = stats(&[
        "mesh",
        "--expr",
        "translate(torus(2, 0.5), 5, -3, 1)",
        "--fit",
        "--method",
        "emc",
        "--res",
        "48",
    ]);
    assert_eq!((s["euler"].as_i64(), s["closed_manifold"].as_bool()), (Some(0), Some(true)), "{s}");
    assert!(s["dist_max"].as_f64().unwrap() < 0.05, "{s}");
    let err = fails(&["mesh", "--expr", "z - 0.2", "--fit"]);
    assert!(err.contains("unbounded along -x, -y, -z, +x, +y"), "{err}");
    assert!(fails(&["mesh", "--expr", "sphere(1)", "--fit", "--bounds", "0,0,0,1,1,1"]).contains("--bounds"));
}

#[test]
fn an_expression_file_is_meshed_and_its_errors_name_the_file() {
    let path = scratch("frame.isf");
    std::fs::write(&path, "// a frame\nsubtract(box(0.6, 0.6, 0.6), sphere(0.75))\n").unwrap();
    let s = stats(&["mesh", "--expr-file", path.to_str().unwrap(), "--res", "24"]);
    assert_eq!(s["euler"], -8);
    std::fs::write(&path, "a = sphere(0.5);\nunion(a, bx(1, 1, 1))\n").unwrap();
    let err = fails(&["mesh", "--expr-file", path.to_str().unwrap()]);
    assert!(err.contains(&format!("{}:2:10: unknown function 'bx'", path.display())), "{err}");
    let err = fails(&["mesh", "--expr-file", scratch("missing.isf").to_str().unwrap()]);
    assert!(err.contains("cannot read"), "{err}");
}

#[test]
fn a_malformed_expression_fails_with_line_column_and_caret() {
    let err = fails(&["mesh", "--expr", "union(sphere(0.5),\n      box(1, 2)"]);
    // Exactly where: line 2, and a caret under the column on the quoted line.
    let at = err.find("2:").expect("line:column");
    assert!(err[at..].starts_with("2:7: "), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines[1], "      box(1, 2)", "{err}");
    assert_eq!(lines[2], "      ^", "{err}");
    let err = fails(&["mesh", "--expr", "sphere(0.5) +"]);
    assert!(err.contains("1:"), "{err}");
}

#[test]
fn exactly_one_input_is_required() {
    let err = fails(&["mesh", "--scene", "sphere", "--expr", "sphere(1)"]);
    assert!(err.contains("cannot be used with"), "{err}");
    assert!(fails(&["mesh", "--res", "8"]).contains("required"));
    assert!(fails(&["mesh", "--grid", "x.raw"]).contains("--dims"));
    assert!(fails(&["mesh", "--scene", "sphere", "--dims", "2,2,2"]).contains("cannot be used with"));
    assert!(fails(&["mesh", "--grid", "x.raw", "--dims", "2,2"]).contains("expected 3"));
}

/// A dark ball (low values) of radius 0.6 in brighter surroundings, sampled on 21³ points over
/// [-1, 1]³: `value = 200 |p|`, so iso 120 is the sphere of radius 0.6.
fn ball_volume() -> Vec<f32> {
    let mut out = Vec::new();
    for k in 0..21 {
        for j in 0..21 {
            for i in 0..21 {
                let p = [i, j, k].map(|c| -1.0 + 0.1 * c as f32);
                out.push((200.0 * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()).min(255.0));
            }
        }
    }
    out
}

#[test]
fn raw_volumes_of_each_sample_type_are_meshed() {
    let values = ball_volume();
    let u8s: Vec<u8> = values.iter().map(|&v| v.round() as u8).collect();
    let u16s: Vec<u8> = values.iter().flat_map(|&v| ((v * 100.0).round() as u16).to_le_bytes()).collect();
    let f32s: Vec<u8> = values.iter().flat_map(|&v| v.to_le_bytes()).collect();
    let expected = 4.0 / 3.0 * std::f64::consts::PI * 0.6f64.powi(3);
    for (dtype, bytes, iso) in [("u8", u8s, "120"), ("u16", u16s, "12000"), ("f32", f32s, "120")] {
        let path = scratch(&format!("ball_{dtype}.raw"));
        std::fs::write(&path, &bytes).unwrap();
        let path = path.to_str().unwrap();
        let args = [
            "mesh", "--grid", path, "--dims", "21,21,21", "--dtype", dtype, "--iso", iso, "--origin",
            "-1,-1,-1",
        ];
        let s = stats(&[&args[..], &["--spacing", "0.1,0.1,0.1"]].concat());
        assert_eq!(s["closed_manifold"], true, "{dtype}: {s}");
        assert_eq!(s["euler"], 2, "{dtype}");
        assert_eq!(s["res"], 20, "{dtype}: a grid's resolution is its cells on the longest side");
        let volume = s["volume"].as_f64().unwrap();
        assert!((volume - expected).abs() < 0.05 * expected, "{dtype}: volume {volume} vs {expected}");
    }
    // Without --origin and --spacing the samples sit at integer positions from 0.
    let path = scratch("ball_u8.raw");
    let s = stats(&[
        "mesh",
        "--grid",
        path.to_str().unwrap(),
        "--dims",
        "21,21,21",
        "--dtype",
        "u8",
        "--iso",
        "120",
    ]);
    let volume = s["volume"].as_f64().unwrap();
    assert!((volume - expected * 1000.0).abs() < 0.05 * expected * 1000.0, "{volume}");
    // The byte count must match the dimensions and type.
    let err = fails(&["mesh", "--grid", path.to_str().unwrap(), "--dims", "21,21,21", "--dtype", "u16"]);
    assert!(err.contains("21 x 21 x 21 u16 samples take 18522 bytes, got 9261"), "{err}");
    assert!(fails(&["mesh", "--grid", path.to_str().unwrap(), "--dims", "21,21,21", "--res", "8"])
        .contains("cannot be used with"));
}

#[test]
fn output_files_follow_their_extension() {
    let mut sizes = Vec::new();
    for ext in ["obj", "stl", "ply", "glb"] {
        let path = scratch(&format!("torus.{ext}"));
        let _ = std::fs::remove_file(&path);
        let s = stats(&["mesh", "--scene", "torus", "--res", "16", "-o", path.to_str().unwrap()]);
        let bytes = std::fs::read(&path).expect("the mesh file was written");
        let triangles = s["triangles"].as_u64().unwrap() as usize;
        match ext {
            "obj" => {
                let text = String::from_utf8(bytes.clone()).unwrap();
                assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), triangles);
            }
            "stl" => assert_eq!(bytes.len(), 84 + 50 * triangles),
            "glb" => {
                // Header says glTF 2 and the file's length; the JSON's index accessor counts the triangles.
                assert_eq!(&bytes[..8], b"glTF\x02\0\0\0");
                assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, bytes.len());
                let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
                let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
                let indices = json["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
                assert_eq!(json["accessors"][indices]["count"].as_u64().unwrap() as usize, 3 * triangles);
            }
            _ => assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n")),
        }
        sizes.push(bytes.len());
    }
    assert!(sizes.iter().all(|&n| n > 1000), "{sizes:?}");
    let err =
        fails(&["mesh", "--scene", "torus", "--res", "8", "-o", scratch("torus.xyz").to_str().unwrap()]);
    assert!(!err.is_empty());
}

#[test]
fn dmc_reports_its_octree_and_phases() {
    let s = stats(&["mesh", "--scene", "torus", "--method", "dmc", "--tol", "0.002", "--max-depth", "5"]);
    assert_eq!(s["method"], "dmc");
    assert_eq!(s["res"], 32, "2^max_depth finest cells");
    assert_eq!(s["closed_manifold"], true);
    assert_eq!(s["euler"], 0);
    assert_eq!(s["self_intersections"], 0);
    assert!(s["octree_leaves"].as_u64().unwrap() > 0 && s["dual_cells"].as_u64().unwrap() > 0, "{s}");
    // serde_json's map sorts keys here; the order the phases ran in is the JSON text's.
    let phases: Vec<&String> = s["phases_ms"].as_object().unwrap().keys().collect();
    assert_eq!(phases, ["contouring", "feature_isolation", "octree", "topology", "untangling"]);
    assert!(s["points_evaluated"].is_null(), "an EMC key, kept and null");
    let loose = stats(&["mesh", "--scene", "torus", "--method", "dmc", "--tol", "0.02", "--max-depth", "5"]);
    assert!(loose["triangles"].as_u64() < s["triangles"].as_u64(), "a looser tolerance simplifies more");
    let err = fails(&["mesh", "--scene", "torus", "--method", "dmc", "--samples-per-cell", "1"]);
    assert!(err.contains("samplesPerCell"), "{err}");
}

#[test]
fn tangent_planes_keep_the_papers_feature_points_on_curved_creases() {
    let args = ["mesh", "--scene", "fandisk", "--method", "emc", "--res", "32", "--no-intersections"];
    let resampled = stats(&args);
    let paper = stats(&[&args[..], &["--tangent-planes"]].concat());
    assert!(resampled["closed_manifold"] == true && paper["closed_manifold"] == true, "{resampled} {paper}");
    let dist = |s: &Value| s["dist_max"].as_f64().unwrap();
    assert!(dist(&resampled) < dist(&paper), "{} against {}", dist(&resampled), dist(&paper));
}

#[test]
fn no_flat_merge_keeps_every_fans_extra_triangles() {
    let args = ["mesh", "--scene", "rotated_box", "--method", "emc", "--res", "24", "--no-intersections"];
    let merged = stats(&args);
    let kept = stats(&[&args[..], &["--no-flat-merge"]].concat());
    let count = |s: &Value, key: &str| s[key].as_u64().unwrap();
    assert_eq!(count(&kept, "flat_merges"), 0);
    assert!(count(&merged, "flat_merges") > 0, "{merged}");
    assert_eq!(count(&merged, "triangles") + 2 * count(&merged, "flat_merges"), count(&kept, "triangles"));
    assert_eq!(merged["euler"], kept["euler"]);
    assert_eq!(merged["feature_edges"], kept["feature_edges"]);
}

#[test]
fn triangle_meshes_of_every_format_are_remeshed() {
    for ext in ["obj", "stl", "ply"] {
        let input = scratch(&format!("box_in.{ext}"));
        ok(&[
            "mesh",
            "--scene",
            "rotated_box",
            "--method",
            "emc",
            "--res",
            "16",
            "-o",
            input.to_str().unwrap(),
        ]);
        let s = stats(&["mesh", "--mesh", input.to_str().unwrap(), "--method", "emc", "--res", "24"]);
        assert_eq!(s["closed_manifold"], true, "{ext}");
        assert_eq!(s["euler"], 2, "{ext}");
        assert_eq!(s["res"], 24, "{ext}: --res cells along the input's longest side");
        assert_eq!(s["self_intersections"], 0, "{ext}");
        // The box's eight corners, and a few more where the coarse input's own fans are corners.
        assert!(s["corner_features"].as_u64().unwrap() >= 8, "{ext}: {}", s["corner_features"]);
        assert!(s["dist_max"].as_f64().unwrap() < 0.05, "{ext}: {}", s["dist_max"]);
    }
    let off = scratch("tetra.off");
    std::fs::write(&off, "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
        .unwrap();
    let s = stats(&["mesh", "--mesh", off.to_str().unwrap(), "--method", "emc", "--res", "20"]);
    assert_eq!((s["closed_manifold"].clone(), s["euler"].clone()), (true.into(), 2.into()));
    assert!(s["corner_features"].as_u64().unwrap() >= 4, "{}", s["corner_features"]);
}

#[test]
fn point_clouds_are_reconstructed() {
    let path = scratch("sphere.xyz");
    let mut text = String::from("# x y z nx ny nz\n");
    let n = 4000;
    for i in 0..n {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let (rho, a) = ((1.0 - z * z).sqrt(), i as f32 * 2.399_963);
        let (x, y) = (rho * a.cos(), rho * a.sin());
        text += &format!("{} {} {} {x} {y} {z}\n", 0.6 * x, 0.6 * y, 0.6 * z);
    }
    std::fs::write(&path, &text).unwrap();
    let s = stats(&["mesh", "--points", path.to_str().unwrap(), "--method", "emc", "--res", "20"]);
    assert_eq!((s["closed_manifold"].clone(), s["euler"].clone()), (true.into(), 2.into()));
    // The same points as CGAL's .pwn, with its count line: the same mesh.
    let pwn = scratch("sphere.pwn");
    std::fs::write(&pwn, format!("{n}\n{}", text.trim_start_matches("# x y z nx ny nz\n"))).unwrap();
    let p = stats(&["mesh", "--points", pwn.to_str().unwrap(), "--method", "emc", "--res", "20"]);
    assert_eq!((p["triangles"].clone(), p["euler"].clone()), (s["triangles"].clone(), s["euler"].clone()));
    // The grid covers the input's bounds padded by two cells: a box wider than that would make
    // the cells (and so the triangles) larger.
    let wide =
        stats(&["mesh", "--points", path.to_str().unwrap(), "--res", "20", "--bounds", "-2,-2,-2,2,2,2"]);
    assert!(wide["triangles"].as_u64().unwrap() * 3 < s["triangles"].as_u64().unwrap(), "{wide} vs {s}");
}

#[test]
fn dmc_remeshes_a_triangle_mesh_into_a_closed_surface_near_it() {
    let input = scratch("box_for_dmc.obj");
    ok(&["mesh", "--scene", "rotated_box", "--method", "emc", "--res", "16", "-o", input.to_str().unwrap()]);
    let s = stats(&["mesh", "--mesh", input.to_str().unwrap(), "--method", "dmc", "--res", "24"]);
    assert_eq!((s["closed_manifold"].clone(), s["euler"].clone()), (true.into(), 2.into()), "{s}");
    assert!(s["dist_max"].as_f64().unwrap() < 0.05, "{}", s["dist_max"]);
    assert!(s["octree_leaves"].as_u64().unwrap() > 0);
}

#[test]
fn malformed_mesh_and_point_files_name_the_file_and_line() {
    let bad = scratch("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n").unwrap();
    let err = fails(&["mesh", "--mesh", bad.to_str().unwrap()]);
    assert!(err.contains("bad.obj") && err.contains("line 4"), "{err}");
    let bad = scratch("bad.xyz");
    std::fs::write(&bad, "0 0 0 0 0 1\n1 2 3\n").unwrap();
    let err = fails(&["mesh", "--points", bad.to_str().unwrap()]);
    assert!(err.contains("bad.xyz") && err.contains("line 2"), "{err}");
    let bad = scratch("bad.pwn");
    std::fs::write(&bad, "3\n0 0 0 0 0 1\n1 2 3 0 1 0\n").unwrap();
    let err = fails(&["mesh", "--points", bad.to_str().unwrap()]);
    assert!(err.contains("bad.pwn") && err.contains("PWN line 1") && err.contains("declares 3"), "{err}");
    let err = fails(&["mesh", "--mesh", scratch("missing.stl").to_str().unwrap()]);
    assert!(err.contains("missing.stl"), "{err}");
    let err = fails(&["mesh", "--mesh", bad.to_str().unwrap(), "--scene", "sphere"]);
    assert!(err.contains("cannot be used with"), "{err}");
}

#[test]
fn mcq_method_its_options_and_the_angle_histogram_reach_the_json() {
    let sphere = ["mesh", "--expr", "sphere(0.8)", "--res", "9"];
    let mc = stats(&[&sphere[..], &["--method", "mc"]].concat());
    let mcq = stats(&[&sphere[..], &["--method", "mcq"]].concat());
    let per_cell = stats(&[&sphere[..], &["--method", "mcq", "--snap", "0", "--no-project"]].concat());
    assert_eq!(mcq["method"], "mcq");
    assert_eq!(mc["triangles"], 524);
    assert!(mcq["min_angle_deg"].as_f64().unwrap() >= 20.0, "{mcq}");
    assert_ne!(per_cell["triangles"], mcq["triangles"], "--snap 0 turns snapping off");
    let histogram = mcq["angle_histogram_5deg"].as_array().unwrap();
    assert_eq!(histogram.len(), 36);
    let angles: u64 = histogram.iter().map(|n| n.as_u64().unwrap()).sum();
    assert_eq!(angles, 3 * mcq["triangles"].as_u64().unwrap(), "every angle in one bin");
    assert!(fails(&[&sphere[..], &["--method", "mcq", "--snap", "0.7"]].concat()).contains("snap"));
}

#[test]
fn quad_method_writes_an_obj_of_quads_matching_its_stats() {
    let path = scratch("sphere_quads.obj");
    let s = stats(&[
        "mesh",
        "--scene",
        "sphere",
        "--method",
        "quad",
        "--res",
        "16",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert_eq!(s["method"], "quad");
    let text = std::fs::read_to_string(&path).unwrap();
    let faces: Vec<usize> =
        text.lines().filter_map(|l| l.strip_prefix("f ")).map(|l| l.split_whitespace().count()).collect();
    assert!(faces.iter().all(|&n| n == 4), "every face a quad");
    assert_eq!(faces.len() as u64, s["quads"].as_u64().unwrap());
    assert_eq!(s["triangles"].as_u64().unwrap(), 2 * s["quads"].as_u64().unwrap());
    assert_eq!(s["euler"], 2);
    assert!(s["quad_stages"].as_array().unwrap().len() >= 4);
}

#[test]
fn decimate_and_smooth_run_after_the_method_and_show_in_the_phases() {
    let s = stats(&[
        "mesh",
        "--scene",
        "fandisk",
        "--method",
        "emc",
        "--res",
        "32",
        "--decimate",
        "600",
        "--smooth",
        "2",
    ]);
    let triangles = s["triangles"].as_u64().unwrap();
    assert!(triangles <= 600 && triangles > 0, "{triangles} triangles");
    assert_eq!(s["closed_manifold"], true);
    assert_eq!(s["self_intersections"], 0);
    assert!(
        s["phases_ms"]["decimate"].is_number() && s["phases_ms"]["smooth"].is_number(),
        "{}",
        s["phases_ms"]
    );
    assert!(s["feature_edges"].as_u64().unwrap() > 0);
    assert!(fails(&["mesh", "--scene", "sphere", "--decimate", "0"]).contains("decimate must be"));
    assert!(fails(&["mesh", "--scene", "sphere", "--method", "quad", "--smooth", "1"]).contains("quad"));
}

use isoforge::dmc::{self, DmcOptions};
use isoforge::mesh::analysis;
use isoforge::{expr, Vec3};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = &args[1];
    let depth: u8 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(7);
    let tol: f32 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(1e-3);
    let sliver = args.get(4).map(|s| s != "0").unwrap_or(true);
    let half: f32 = args.get(5).map(|s| s.parse().unwrap()).unwrap_or(1.0);
    let field = expr::compile(text).unwrap();
    let opts =
        DmcOptions { max_depth: depth, tolerance: tol, sliver_elimination: sliver, ..DmcOptions::default() };
    let t = std::time::Instant::now();
    let (mesh, stats) = dmc::mesh_field(&field, Vec3::splat(-half), Vec3::splat(half), &opts).unwrap();
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let topo = analysis::topology(&mesh);
    let si = analysis::self_intersections(&mesh);
    let err = analysis::surface_error(&mesh, &field);
    let angles = analysis::angle_stats(&mesh);
    println!("{stats:?}");
    if std::env::var("WORST").is_ok() {
        worst(&mesh, &field);
    }
    if std::env::var("PAIRS").is_ok() {
        pairs(&mesh);
    }
    println!(
        "ms {ms:.0} tris {} closed {} bnd {} nme {} nmv {} mis {} degen {} euler {} si {} vol {:.4} dist_max {:.5} rms {:.5} ndev95 {:.2} ndevmax {:.1} minangle {:.2}",
        mesh.triangle_count(), topo.is_closed_manifold(), topo.boundary_edges, topo.non_manifold_edges, topo.non_manifold_vertices,
        topo.misoriented_edges, topo.degenerate_triangles, topo.euler, si, analysis::signed_volume(&mesh), err.dist_max, err.dist_rms,
        err.normal_dev_deg_p95, err.normal_dev_deg_max, angles.min_deg
    );
}

#[allow(dead_code)]
pub fn worst(mesh: &isoforge::Mesh, field: &dyn isoforge::Field) {
    let mut v: Vec<(f32, usize)> = (0..mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let mut p = (a + b + c) / 3.0;
            for _ in 0..4 {
                let g = field.gradient(p).unwrap();
                p -= g * field.value(p) / g.length_squared();
            }
            let g = field.gradient(p).unwrap().normalize();
            (n.dot(g).clamp(-1.0, 1.0).acos().to_degrees(), t)
        })
        .collect();
    v.sort_by(|a, b| b.0.total_cmp(&a.0));
    let bad = v.iter().filter(|x| x.0 > 20.0).count();
    println!("{bad} triangles over 20 deg");
    let (mut edge, mut circle, mut other) = (0, 0, 0);
    for &(d, t) in &v {
        if d < 20.0 {
            continue;
        }
        let [a, b, c] = mesh.corners(t);
        let p = (a + b + c) / 3.0;
        let near = p.abs().to_array().iter().filter(|&&q| (q - 0.6).abs() < 0.04).count();
        if near >= 2 {
            edge += 1
        } else if (p.length() - 0.75).abs() < 0.04 {
            circle += 1
        } else {
            other += 1
        }
    }
    println!("near cube edges {edge}, near circles {circle}, other {other}");
    let mut dv: Vec<(f32, usize)> = (0..mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let p = (a + b + c) / 3.0;
            (field.value(p).abs(), t)
        })
        .collect();
    dv.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(d, t) in dv.iter().take(8) {
        let [a, b, c] = mesh.corners(t);
        println!("dist {d:.4} {a:.4} {b:.4} {c:.4}");
    }
    let mut shown = 0;
    for &(d, t) in &v {
        let [a, b, c] = mesh.corners(t);
        let area = (b - a).cross(c - a).length() / 2.0;
        if d > 20.0 && area > 1e-5 && shown < 12 {
            shown += 1;
            println!("big {d:6.1} {a:.4} {b:.4} {c:.4} area {area:.2e}");
        }
    }
    let total: f32 = (0..mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum();
    let bad_area: f32 = v
        .iter()
        .filter(|x| x.0 > 20.0)
        .map(|&(_, t)| {
            let [a, b, c] = mesh.corners(t);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum();
    println!("bad area fraction {:.5}", bad_area / total);
    for &(d, t) in v.iter().take(12) {
        let [a, b, c] = mesh.corners(t);
        println!("{d:6.1} {a:.4} {b:.4} {c:.4} area {:.2e}", (b - a).cross(c - a).length() / 2.0);
    }
}
#[allow(dead_code)]
pub fn pairs(mesh: &isoforge::Mesh) {
    for [a, b] in analysis::self_intersecting_pairs(mesh).iter().take(6) {
        let ta = mesh.corners(*a as usize);
        let tb = mesh.corners(*b as usize);
        println!(
            "SI {a} {:?} {:.4?}\n   {b} {:?} {:.4?}",
            mesh.triangles[*a as usize], ta, mesh.triangles[*b as usize], tb
        );
    }
}

use isoforge::dmc::{self, DmcOptions};
use isoforge::mc::{self, McOptions};
use isoforge::mesh::analysis;
use isoforge::{expr, Grid, Vec3};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * ((self.next() >> 40) as f32 / (1u64 << 24) as f32)
    }
}

fn shape(rng: &mut Rng, depth: u32) -> String {
    if depth == 0 || rng.next() % 3 == 0 {
        let (x, y, z) = (rng.range(-0.4, 0.4), rng.range(-0.4, 0.4), rng.range(-0.4, 0.4));
        if rng.next() % 2 == 0 {
            format!("translate(sphere({:.3}), {x:.3}, {y:.3}, {z:.3})", rng.range(0.15, 0.45))
        } else {
            let b = format!(
                "box({:.3}, {:.3}, {:.3})",
                rng.range(0.1, 0.4),
                rng.range(0.1, 0.4),
                rng.range(0.1, 0.4)
            );
            let b = if rng.next() % 2 == 0 {
                format!(
                    "rotate({b}, {:.2}, {:.2}, {:.2}, {:.1})",
                    rng.range(-1., 1.),
                    rng.range(-1., 1.),
                    rng.range(0.1, 1.),
                    rng.range(0., 90.)
                )
            } else {
                b
            };
            format!("translate({b}, {x:.3}, {y:.3}, {z:.3})")
        }
    } else {
        let op = ["union", "intersect", "subtract"][(rng.next() % 3) as usize];
        format!("{op}({}, {})", shape(rng, depth - 1), shape(rng, depth - 1))
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: u64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(10);
    let depth: u8 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(6);
    let start: u64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(0);
    for seed in start..start + n {
        let mut rng = Rng(seed);
        let text = shape(&mut rng, 3);
        let field = expr::compile(&text).unwrap();
        if std::env::var("MCRES").is_ok() {
            for res in [64, 96, 128, 192, 256] {
                let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
                let (m, _) = mc::mesh_field(&field, &grid, &McOptions::default()).unwrap();
                let t = analysis::topology(&m);
                println!("seed {seed} mc {res}: euler {} components {}", t.euler, t.components);
            }
            continue;
        }
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 160).unwrap();
        let (mcm, _) = mc::mesh_field(&field, &grid, &McOptions::default()).unwrap();
        let mt = analysis::topology(&mcm);
        let t = std::time::Instant::now();
        let opts = DmcOptions { max_depth: depth, ..DmcOptions::default() };
        let (mesh, stats) = dmc::mesh_field(&field, Vec3::splat(-1.0), Vec3::splat(1.0), &opts).unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let topo = analysis::topology(&mesh);
        let si = analysis::self_intersections(&mesh);
        let vol = analysis::signed_volume(&mesh);
        let err = analysis::surface_error(&mesh, &field);
        let ok = topo.is_closed_manifold()
            && si == 0
            && topo.euler == mt.euler
            && topo.degenerate_triangles == 0
            && (mesh.triangle_count() == 0 || vol > 0.0);
        println!(
            "{} seed {seed} ms {ms:.0} rounds {} tris {} (mc {}) euler {} (mc {}) closed {} si {si} degen {} vol {vol:.3} dist {:.4} ndevmax {:.0}",
            if ok { "ok " } else { "BAD" }, stats.rounds, mesh.triangle_count(), mcm.triangle_count(), topo.euler, mt.euler, topo.is_closed_manifold(), topo.degenerate_triangles, err.dist_max, err.normal_dev_deg_max
        );
        if !ok {
            println!("    {text}");
        }
    }
}

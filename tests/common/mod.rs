//! Helpers shared by the integration suites, which run both natively and as wasm-bindgen-test in
//! headless Chromium (each suite imports `wasm_bindgen_test as test` on wasm32).
#![allow(dead_code)]

pub mod csg;
pub mod hausdorff;
pub mod normals;
pub mod quality;

use isoforge::mesh::analysis;
use isoforge::{Grid, Mesh, Vec3};

/// Does `p` lie on a line of `grid` (two of its coordinates on grid planes)? EMC's edge crossings
/// do; its fan centres and MC's centre vertices do not.
pub fn on_grid_line(grid: &Grid, p: Vec3) -> bool {
    let local = (p - grid.origin) / grid.spacing;
    (0..3).filter(|&a| (local[a] - local[a].round()).abs() < 1e-3).count() >= 2
}

/// A small seeded generator (splitmix64): reproducible random inputs without a dependency.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * ((self.next_u64() >> 40) as f32 / (1u64 << 24) as f32)
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
}

/// How many seeded cases a property suite runs: `ci` in `cargo test` (sized for CI on a 2-core
/// machine), or `ISOFORGE_SOAK` of them in a soak (`make soak`). Cases are numbered from 0; the
/// seed of case `n` is `seed_base + n`, printed on failure, and `ISOFORGE_SEED=S` runs that one
/// case alone.
pub fn case_seeds(seed_base: u64, ci: usize) -> Vec<u64> {
    let var = |name: &str| std::env::var(name).ok().and_then(|v| v.trim().parse::<u64>().ok());
    if cfg!(target_arch = "wasm32") {
        return (0..ci as u64).map(|n| seed_base + n).collect();
    }
    if let Some(seed) = var("ISOFORGE_SEED") {
        return vec![seed];
    }
    let count = var("ISOFORGE_SOAK").map_or(ci as u64, |n| n.max(1));
    (0..count).map(|n| seed_base + n).collect()
}

/// A request for `method` at `res` cells with the stats' costly analyses off (the suites check
/// what they need themselves).
pub fn bare_request(method: isoforge::pipeline::Method, res: usize) -> isoforge::pipeline::Request {
    isoforge::pipeline::Request {
        method,
        res,
        analysis: isoforge::stats::AnalysisOptions { self_intersections: false, surface_error: false },
        ..isoforge::pipeline::Request::default()
    }
}

/// The edges that only one triangle uses (a mesh's border), as vertex pairs.
pub fn boundary_edges(mesh: &Mesh) -> Vec<[u32; 2]> {
    let mut count = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for q in 0..3 {
            let (a, b) = (t[q], t[(q + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut edges: Vec<[u32; 2]> =
        count.into_iter().filter(|&(_, n)| n == 1).map(|((a, b), _)| [a, b]).collect();
    edges.sort_unstable();
    edges
}

/// Asserts the properties every closed output must have, with a message naming what broke.
pub fn assert_watertight(mesh: &Mesh, what: &str) -> analysis::Topology {
    let topo = analysis::topology(mesh);
    assert!(
        topo.is_closed_manifold(),
        "{what}: not a closed manifold: {} boundary, {} non-manifold edges, {} misoriented edges, {} non-manifold vertices",
        topo.boundary_edges,
        topo.non_manifold_edges,
        topo.misoriented_edges,
        topo.non_manifold_vertices
    );
    assert_eq!(topo.degenerate_triangles, 0, "{what}: degenerate triangles");
    assert_eq!(analysis::self_intersections(mesh), 0, "{what}: self-intersections");
    if mesh.triangle_count() > 0 {
        assert!(analysis::signed_volume(mesh) > 0.0, "{what}: not oriented outward");
    }
    topo
}

/// The thin room written with planar primitives, as the paper builds it: walls 0.016 thick (1 % of
/// the room), a door through the wall at y = -0.8 whose sill lies 0.042 above the floor.
pub const PLANAR_ROOM: &str = "b = max(abs(x) - 0.8, abs(y) - 0.8, abs(z) - 0.5); room = abs(b) - 0.008; \
     door = translate(max(abs(x) - 0.2, abs(y) - 0.1, abs(z) - 0.325), 0, -0.8, -0.125); max(room, -door)";

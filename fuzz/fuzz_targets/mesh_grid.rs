//! Bytes → a small sampled grid → `pipeline::mesh_samples` with every grid method. Layout:
//!
//! | byte | meaning |
//! |------|---------|
//! | 0..3 | points per axis, `2 + b % 7` (2..=8) |
//! | 3    | method `(b & 7) % 5` (mc, emc, dmc, mcq, quad); bit 3: trilinear topology; bit 4: samples are u8 (`b - 128`) rather than raw little-endian f32; bit 5: pad the border outside; bit 6: iso from the next 4 bytes (else 0) |
//! | 4    | spacing and origin: bits 0..6 pick a spacing per axis from [`SPACINGS`], bit 6..8 an origin from [`ORIGINS`] |
//! | ...  | iso (f32, or u8 `(b - 128) / 4` in u8 mode) when bit 6 is set, then the samples, x fastest, repeated cyclically when short (all 1 when absent) |
//!
//! Any request may be refused (non-finite or huge samples, far grids); none may panic, hang or
//! allocate without bound. A mesh that comes back must have finite coordinates and indices in
//! range, and MC's must be a closed manifold when every border sample is outside (>= iso), the
//! promise every user of a padded volume relies on.
#![no_main]

use isoforge::mc::Topology;
use isoforge::mesh::analysis;
use isoforge::pipeline::{self, Method, Request};
use isoforge::stats::AnalysisOptions;
use isoforge::{Grid, Vec3};
use libfuzzer_sys::fuzz_target;

const METHODS: [Method; 5] = [Method::Mc, Method::Emc, Method::Dmc, Method::Mcq, Method::Quad];
const SPACINGS: [f32; 4] = [1.0, 0.25, 3.0, 0.01];
const ORIGINS: [f32; 4] = [0.0, -5.0, 1000.0, 0.3];

/// Cap on cells: above the 7³ = 343 of the largest grid here, so every grid is meshed, while
/// DMC's octree (whose work `max_cells` bounds) stays small.
const MAX_CELLS: u64 = 512;

fuzz_target!(|data: &[u8]| {
    if data.len() < 5 {
        return;
    }
    let points: [usize; 3] = std::array::from_fn(|a| 2 + data[a] as usize % 7);
    let flags = data[3];
    let method = METHODS[(flags & 7) as usize % 5];
    let topology = if flags & 8 != 0 { Topology::Trilinear } else { Topology::Fixed };
    let bytes_mode = flags & 16 != 0;
    let pad = flags & 32 != 0;
    let has_iso = flags & 64 != 0;
    let layout = data[4];
    let spacing =
        Vec3::from(std::array::from_fn::<f32, 3, _>(|a| SPACINGS[(layout >> (2 * a)) as usize & 3]));
    let origin = Vec3::splat(ORIGINS[(layout >> 6) as usize & 3]);
    let mut rest = &data[5..];

    let take_value = |rest: &mut &[u8]| -> Option<f32> {
        if bytes_mode {
            let (&b, tail) = rest.split_first()?;
            *rest = tail;
            Some(b as f32 - 128.0)
        } else {
            let (head, tail) = rest.split_first_chunk::<4>()?;
            *rest = tail;
            Some(f32::from_le_bytes(*head))
        }
    };
    let iso = if has_iso {
        match take_value(&mut rest) {
            Some(v) if bytes_mode => v / 4.0,
            Some(v) => v,
            None => 0.0,
        }
    } else {
        0.0
    };
    let mut given = Vec::new();
    while let Some(v) = take_value(&mut rest) {
        given.push(v);
    }
    let Ok(grid) = Grid::from_points(points, origin, spacing) else { return };
    let mut values: Vec<f32> = (0..grid.point_count())
        .map(|n| if given.is_empty() { 1.0 } else { given[n % given.len()] })
        .collect();
    let on_border = |n: usize| {
        let ijk = grid.unindex(n);
        (0..3).any(|a| ijk[a] == 0 || ijk[a] == grid.cells[a])
    };
    if pad {
        // Outside means >= iso; exactly iso is outside too. Past ±1e30 the request is refused anyway.
        let outside = if iso.is_finite() { iso.max(iso + 1.0) } else { 1.0 };
        for (n, v) in values.iter_mut().enumerate() {
            if on_border(n) {
                *v = outside;
            }
        }
    }
    // NaN is neither inside nor outside; such grids are refused before meshing.
    let closed_expected = (0..values.len()).filter(|&n| on_border(n)).all(|n| values[n] >= iso);

    let request = Request {
        method,
        res: points.iter().max().unwrap() - 1,
        iso,
        topology,
        analysis: AnalysisOptions { self_intersections: false, surface_error: false },
        max_cells: MAX_CELLS,
        ..Default::default()
    };
    let Ok(out) = pipeline::mesh_samples(&values, &grid, &request) else { return };
    let mesh = &out.mesh;
    let n = mesh.positions.len();
    assert!(mesh.positions.iter().all(|p| p.is_finite()), "non-finite vertex");
    assert!(
        mesh.normals.is_empty() || mesh.normals.len() == n,
        "{} normals for {n} vertices",
        mesh.normals.len()
    );
    assert!(mesh.normals.iter().all(|v| v.is_finite()), "non-finite normal");
    for t in &mesh.triangles {
        assert!(t.iter().all(|&v| (v as usize) < n), "triangle {t:?} indexes past {n} vertices");
    }
    for q in &out.quads {
        assert!(q.iter().all(|&v| (v as usize) < n), "quad {q:?} indexes past {n} vertices");
    }
    if method == Method::Mc && closed_expected {
        let topo = analysis::topology(mesh);
        assert!(
            topo.is_closed_manifold(),
            "MC ({topology:?}) open on a grid whose border is outside: {topo:?}"
        );
    }
});

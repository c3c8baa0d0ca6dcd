//! Marching Cubes must be watertight on every input: every sign configuration, random grids, values
//! exactly at the iso-level, and the analytic scenes with their known topology.

mod common;

use common::{assert_watertight, Rng};
use isoforge::field::{sample_grid, sample_level, sample_level_probed};
use isoforge::mc::{self, McOptions, Topology};
use isoforge::mesh::analysis;
use isoforge::{scenes, Error, Grid, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

const TOPOLOGIES: [Topology; 2] = [Topology::Fixed, Topology::Trilinear];

fn options(topology: Topology) -> McOptions {
    McOptions { topology, ..McOptions::default() }
}

/// Connected components of the inside corners of one cell under 6-adjacency (cube edges).
fn edge_connected_components(case: u8) -> usize {
    let mut parent: [usize; 8] = std::array::from_fn(|c| c);
    fn find(p: &mut [usize; 8], c: usize) -> usize {
        if p[c] != c {
            p[c] = find(p, p[c]);
        }
        p[c]
    }
    for [a, b] in isoforge::tables::EDGES {
        if case >> a & 1 == 1 && case >> b & 1 == 1 {
            let (ra, rb) = (find(&mut parent, a as usize), find(&mut parent, b as usize));
            parent[ra] = rb;
        }
    }
    (0..8).filter(|&c| case >> c & 1 == 1 && find(&mut parent, c) == c).count()
}

/// The cell of a 3×3×3-cell grid whose corners carry `case` (inside = negative), everything else
/// outside, so the surface stays away from the grid boundary.
fn single_cell_grid(case: u8, rng: &mut Rng) -> (Grid, Vec<f32>) {
    single_cell_grid_in(case, rng, (-1.0, -0.05), (0.05, 1.0))
}

/// [`single_cell_grid`] with the inside and outside values drawn from the given ranges: a strong
/// inside and a weak outside make inside tunnels likely, and the other way round.
fn single_cell_grid_in(case: u8, rng: &mut Rng, inside: (f32, f32), outside: (f32, f32)) -> (Grid, Vec<f32>) {
    let grid = Grid::new(Vec3::ZERO, Vec3::splat(3.0), [3, 3, 3]).unwrap();
    let mut values = vec![0.0; grid.point_count()];
    for (n, v) in values.iter_mut().enumerate() {
        let [i, j, k] = grid.unindex(n);
        let corner = [i, j, k].iter().all(|&c| c == 1 || c == 2);
        let bit = (i == 2) as u8 | ((j == 2) as u8) << 1 | ((k == 2) as u8) << 2;
        *v = if corner && case >> bit & 1 == 1 {
            rng.range(inside.0, inside.1)
        } else {
            rng.range(outside.0, outside.1)
        };
    }
    (grid, values)
}

#[test]
fn all_256_configurations_give_closed_oriented_meshes() {
    let mut rng = Rng::new(256);
    for case in 0..=255u8 {
        for topology in TOPOLOGIES {
            for _ in 0..3 {
                let (grid, values) = single_cell_grid(case, &mut rng);
                let (mesh, _) = mc::mesh_samples(&values, &grid, &options(topology)).unwrap();
                let what = format!("case {case:#010b} {topology:?}");
                let topo = assert_watertight(&mesh, &what);
                if topology == Topology::Fixed {
                    // Every piece is a topological sphere around one edge-connected group of corners.
                    assert_eq!(topo.euler, 2 * topo.components as i64, "{what}");
                    assert_eq!(topo.components, edge_connected_components(case), "{what}");
                }
            }
        }
    }
}

/// The Euler characteristic of the surface of the trilinear interpolant of `values`, counted on a
/// grid `sub` times finer (twice the Euler characteristic of the inside, a closed solid).
fn interpolant_euler(grid: &Grid, values: &[f32], sub: usize, iso: f32) -> i64 {
    let fine = Grid::new(grid.origin, grid.max(), grid.cells.map(|c| c * sub)).unwrap();
    let samples: Vec<f32> = (0..fine.point_count())
        .map(|n| {
            let fine_ijk = fine.unindex(n);
            // The coarse cell (the last one for points on the far side) and the place in it.
            let cell = std::array::from_fn::<usize, 3, _>(|a| (fine_ijk[a] / sub).min(grid.cells[a] - 1));
            let t: [f32; 3] = std::array::from_fn(|a| (fine_ijk[a] - cell[a] * sub) as f32 / sub as f32);
            (0..8)
                .map(|c| {
                    let [x, y, z] = isoforge::tables::CORNERS[c];
                    let w = |bit: usize, t: f32| if bit == 1 { t } else { 1.0 - t };
                    values[grid.index(cell[0] + x, cell[1] + y, cell[2] + z)]
                        * w(x, t[0])
                        * w(y, t[1])
                        * w(z, t[2])
                })
                .sum()
        })
        .collect();
    2 * analysis::digital_euler(&samples, &fine, iso)
}

/// The trilinear option gives the topology of the trilinear interpolant itself (Marching Cubes 33
/// with its interior tests, tunnels included) on every sign configuration, where the fixed table
/// gets the tunnels and the face-joined cases wrong. The interpolant's own topology is counted on a
/// much finer grid; a configuration whose count changes with the resolution or with a small change
/// of the level is too close to critical to count and is skipped.
#[test]
fn trilinear_topology_matches_the_interpolant_in_every_configuration() {
    let mut rng = Rng::new(33);
    let (mut fixed_wrong, mut tunnels, mut checked) = (0, 0, 0);
    for case in 0..=255u8 {
        for (inside, outside) in
            [((-1.0, -0.05), (0.05, 1.0)), ((-1.0, -0.5), (0.05, 0.3)), ((-0.3, -0.05), (0.5, 1.0))]
        {
            let (grid, values) = single_cell_grid_in(case, &mut rng, inside, outside);
            // Stable: the same at two resolutions and at iso-levels a little either side, so no
            // critical point of the interpolant lies so close to the level that sampling misses it.
            let truth = interpolant_euler(&grid, &values, 8, 0.0);
            if [(8, -0.01), (8, 0.01), (12, 0.0)]
                .iter()
                .any(|&(sub, iso)| interpolant_euler(&grid, &values, sub, iso) != truth)
            {
                continue;
            }
            checked += 1;
            let topology_of = |topology| {
                analysis::topology(&mc::mesh_samples(&values, &grid, &options(topology)).unwrap().0)
            };
            let trilinear = topology_of(Topology::Trilinear);
            assert_eq!(trilinear.euler, truth, "case {case:#010b}: {values:?}");
            fixed_wrong += (topology_of(Topology::Fixed).euler != truth) as usize;
            // A tunnel: a piece with a handle, less Euler characteristic than its spheres would have.
            tunnels += (trilinear.euler < 2 * trilinear.components as i64) as usize;
        }
    }
    eprintln!("{checked} stable configurations, fixed table wrong on {fixed_wrong}, {tunnels} tunnels");
    assert!(checked > 720, "only {checked} stable configurations");
    assert!(fixed_wrong > 20, "the fixed table should miss some: {fixed_wrong}");
    assert!(tunnels > 0, "no tunnel was exercised");
}

/// Random grids, their border forced outside; `levels` > 0 quantises values so that many samples sit
/// exactly on the iso-level (the documented rule: equal counts as outside).
fn random_grid(rng: &mut Rng, n: usize, levels: u32) -> (Grid, Vec<f32>) {
    let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [n, n, n]).unwrap();
    let values = (0..grid.point_count())
        .map(|idx| {
            let ijk = grid.unindex(idx);
            if ijk.iter().any(|&c| c == 0 || c == n) {
                return 1.0;
            }
            let v = rng.range(-1.0, 1.0);
            if levels > 0 {
                (v * levels as f32).round() / levels as f32
            } else {
                v
            }
        })
        .collect();
    (grid, values)
}

#[test]
fn random_grids_are_watertight() {
    let mut rng = Rng::new(7);
    for trial in 0..24 {
        let levels = [0, 1, 2][trial % 3];
        let (grid, values) = random_grid(&mut rng, 6 + trial % 5, levels);
        for topology in TOPOLOGIES {
            let (mesh, _) = mc::mesh_samples(&values, &grid, &options(topology)).unwrap();
            assert!(mesh.triangle_count() > 0);
            assert_watertight(&mesh, &format!("trial {trial} levels {levels} {topology:?}"));
        }
    }
}

#[test]
fn iso_level_shifts_the_surface_and_equal_values_make_no_degenerate_triangles() {
    // Integer-valued distance to the centre along each axis (Chebyshev): many samples equal each iso.
    let grid = Grid::new(Vec3::splat(-4.0), Vec3::splat(4.0), [8, 8, 8]).unwrap();
    let f = |p: Vec3| p.abs().max_element();
    let values = sample_grid(&f, &grid).unwrap();
    let mut previous_volume = 0.0;
    for iso in [1.0f32, 2.0, 3.0] {
        let opts = McOptions { iso, ..McOptions::default() };
        let (mesh, _) = mc::mesh_samples(&values, &grid, &opts).unwrap();
        let topo = assert_watertight(&mesh, &format!("iso {iso}"));
        assert_eq!(topo.euler, 2);
        let volume = analysis::signed_volume(&mesh);
        assert!(volume > previous_volume, "volume must grow with the iso-level");
        previous_volume = volume;
    }
}

#[test]
fn sphere_torus_and_clipped_gyroid_have_the_right_euler_characteristic() {
    for (name, res) in
        [("sphere", 16), ("sphere", 40), ("torus", 24), ("torus", 48), ("cube_minus_sphere", 24)]
    {
        let scene = scenes::scene(name).unwrap();
        let grid = Grid::with_resolution(scene.min, scene.max, res).unwrap();
        for topology in TOPOLOGIES {
            let (mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &options(topology)).unwrap();
            let topo = assert_watertight(&mesh, &format!("{name} at {res}"));
            assert_eq!(Some(topo.euler), scene.euler, "{name} at {res} {topology:?}");
        }
    }
    // The clipped gyroid has no closed-form Euler characteristic: compare with an independent count
    // from the cubical complex of inside samples (twice the solid's χ for a closed surface).
    let gyroid = scenes::scene("gyroid").unwrap();
    let grid = Grid::with_resolution(gyroid.min, gyroid.max, 64).unwrap();
    let values = sample_grid(gyroid.field.as_ref(), &grid).unwrap();
    let (mesh, _) = mc::mesh_samples(&values, &grid, &McOptions::default()).unwrap();
    let topo = assert_watertight(&mesh, "gyroid");
    assert_eq!(topo.euler, 2 * analysis::digital_euler(&values, &grid, 0.0));
    assert!(topo.euler < 0, "a clipped gyroid has handles, got χ = {}", topo.euler);
}

#[test]
fn touching_spheres_share_no_non_manifold_vertex() {
    let scene = scenes::scene("two_spheres_touching").unwrap();
    // Odd and even resolutions: the touching point lands on a grid point, an edge or inside a cell.
    for res in [8, 9, 16, 17, 32, 33] {
        let grid = Grid::with_resolution(scene.min, scene.max, res).unwrap();
        for topology in TOPOLOGIES {
            let (mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &options(topology)).unwrap();
            let topo = assert_watertight(&mesh, &format!("touching spheres at {res} {topology:?}"));
            assert_eq!(topo.non_manifold_vertices, 0);
            assert!(topo.components == 1 || topo.components == 2);
            assert_eq!(topo.euler, 2 * topo.components as i64);
        }
    }
}

#[test]
fn sphere_vertices_converge_to_the_true_surface() {
    let scene = scenes::scene("sphere").unwrap();
    let mut previous = f64::INFINITY;
    for res in [8, 16, 32, 64] {
        let grid = Grid::with_resolution(scene.min, scene.max, res).unwrap();
        let (mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
        let worst_vertex = mesh.positions.iter().map(|p| (p.length() as f64 - 0.8).abs()).fold(0.0, f64::max);
        let h = grid.cell_size() as f64;
        // Linear interpolation of a distance function along an edge errs by O(h²/r).
        assert!(worst_vertex < 0.25 * h * h / 0.8 + 1e-5, "res {res}: {worst_vertex} vs h {h}");
        assert!(worst_vertex < previous / 2.5, "res {res}: error must shrink ~4x per halving");
        previous = worst_vertex;
        let err = analysis::surface_error(&mesh, scene.field.as_ref());
        // Flat triangles between exact vertices: the chord error is also O(h²/r).
        assert!(err.dist_max < 0.5 * h * h / 0.8, "res {res}: dist_max {} vs h {h}", err.dist_max);
    }
}

#[test]
fn sampled_and_functional_paths_agree() {
    let scene = scenes::scene("torus").unwrap();
    let grid = Grid::with_resolution(scene.min, scene.max, 20).unwrap();
    let (from_field, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
    let values = sample_grid(scene.field.as_ref(), &grid).unwrap();
    let (from_samples, _) = mc::mesh_samples(&values, &grid, &McOptions::default()).unwrap();
    assert_eq!(from_field.positions, from_samples.positions);
    assert_eq!(from_field.triangles, from_samples.triangles);
    // Normals: exact gradient vs interpolated central differences agree to a few degrees.
    for (a, b) in from_field.normals.iter().zip(&from_samples.normals) {
        assert!(a.dot(*b) > 0.97, "{a} vs {b}");
    }
}

#[test]
fn bad_input_is_reported_not_meshed() {
    let grid = Grid::new(Vec3::ZERO, Vec3::ONE, [2, 2, 2]).unwrap();
    let mut values = vec![1.0f32; 27];
    values[grid.index(1, 2, 0)] = f32::INFINITY;
    match mc::mesh_samples(&values, &grid, &McOptions::default()) {
        Err(Error::NonFiniteSample { index, .. }) => assert_eq!(index, [1, 2, 0]),
        other => panic!("expected a non-finite sample error, got {other:?}"),
    }
    assert!(matches!(
        mc::mesh_samples(&values[..26], &grid, &McOptions::default()),
        Err(Error::InvalidGrid(_))
    ));
    let opts = McOptions { max_cells: 7, ..McOptions::default() };
    assert!(matches!(mc::mesh_samples(&[1.0; 27], &grid, &opts), Err(Error::GridTooLarge { cells: 8, .. })));
    assert!(scenes::scene("no_such_scene").is_err());
}

/// A box of grid points: `lo..=hi` in grid indices along each axis.
type PointBox = ([i64; 3], [i64; 3]);

/// Random unions of one to three boxes whose faces lie on grid planes (written as decimals, so
/// their samples on those planes are zero only up to rounding), some sharing a face: every sample
/// takes its side by the rule of `field::snap_to_level`, whatever the rounding, through the crust
/// and without. Strictly inside a box: inside; in no box: outside; on a face, inside only where
/// no grid line through it has air at both its neighbours, and one has the inside of a box at
/// both, or, for EMC's samples (`sample_level_probed`: the function asked a thousandth of a cell
/// away), one has the inside of boxes just beside it on both sides and none air on both (a face
/// shared with a box one cell thick); otherwise exactly on the level (outside). Rounding made
/// such unions' faces step between grid planes in teeth (`tests/emc_quality.rs`) and split parts
/// sharing a face along it.
#[test]
fn samples_on_the_level_take_their_side_by_rule_not_by_rounding() {
    for seed in common::case_seeds(19_000, 24) {
        let mut rng = Rng::new(seed);
        let res = 16 + 2 * rng.below(17) as i64;
        let h = 2.0 / res as f64;
        let mut boxes: Vec<PointBox> = Vec::new();
        for n in 0..1 + rng.below(3) {
            let mut lo = [0i64; 3];
            let mut hi = [0i64; 3];
            for a in 0..3 {
                lo[a] = 2 + rng.below(res as u64 / 2) as i64;
                hi[a] = (lo[a] + 2 + rng.below(res as u64 / 3) as i64).min(res - 2);
            }
            if n > 0 && rng.below(2) == 0 {
                // Flush against the previous box's face along one axis, overlapping it across.
                let (plo, phi) = *boxes.last().unwrap();
                let a = rng.below(3) as usize;
                let width = hi[a] - lo[a];
                (lo[a], hi[a]) = (phi[a], (phi[a] + width).min(res - 2));
                for b in (0..3).filter(|&b| b != a) {
                    (lo[b], hi[b]) = (plo[b], phi[b]);
                }
            }
            if (0..3).all(|a| hi[a] > lo[a]) {
                boxes.push((lo, hi));
            }
        }
        let coord = |g: f64| -1.0 + g * h;
        let parts: Vec<String> = boxes
            .iter()
            .map(|(lo, hi)| {
                let half = [0, 1, 2].map(|a| (hi[a] - lo[a]) as f64 * h / 2.0);
                let centre = [0, 1, 2].map(|a| coord((lo[a] + hi[a]) as f64 / 2.0));
                format!(
                    "translate(box({}, {}, {}), {}, {}, {})",
                    half[0] as f32,
                    half[1] as f32,
                    half[2] as f32,
                    centre[0] as f32,
                    centre[1] as f32,
                    centre[2] as f32
                )
            })
            .collect();
        let text = parts.iter().skip(1).fold(parts[0].clone(), |acc, p| format!("union({acc}, {p})"));
        let field = isoforge::expr::compile(&text).unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res as usize).unwrap();
        // Points of the continuous lattice (grid points and points just beside them) in the
        // boxes' interiors, and in the closed boxes.
        let strictly = |q: [f64; 3]| {
            boxes.iter().any(|(lo, hi)| (0..3).all(|a| (lo[a] as f64) < q[a] && q[a] < hi[a] as f64))
        };
        let closed = |q: [f64; 3]| {
            boxes.iter().any(|(lo, hi)| (0..3).all(|a| (lo[a] as f64) <= q[a] && q[a] <= hi[a] as f64))
        };
        for (crust, probed) in [(true, false), (false, false), (true, true), (false, true)] {
            let sample = if probed { sample_level_probed } else { sample_level };
            let (values, _) = sample(&field, &grid, 0.0, crust).unwrap();
            let mut on_faces = 0;
            for (n, &v) in values.iter().enumerate() {
                let [i, j, k] = grid.unindex(n);
                let g = [i as i64, j as i64, k as i64];
                let what = || {
                    format!("seed {seed}: {text} at {res}, point {g:?}, crust {crust}, probed {probed}: {v}")
                };
                let at = g.map(|c| c as f64);
                if strictly(at) {
                    assert!(v < 0.0, "{}: inside", what());
                } else if !closed(at) {
                    assert!(v > 0.0, "{}: outside", what());
                } else {
                    on_faces += 1;
                    // `d` along axis `a` from the point, in cells: its grid neighbours at 1, the
                    // function's probes at a thousandth.
                    let step = |a: usize, d: f64| {
                        let mut q = at;
                        q[a] += d;
                        q
                    };
                    let both = |a: usize, d: f64, test: &dyn Fn([f64; 3]) -> bool| {
                        test(step(a, -d)) && test(step(a, d))
                    };
                    let inside_grid = |a: usize| g[a] > 0 && g[a] < res && both(a, 1.0, &strictly);
                    let air = |a: usize| g[a] > 0 && g[a] < res && both(a, 1.0, &|q| !closed(q));
                    let near_inner = |a: usize| both(a, 1e-3, &strictly);
                    let near_air = |a: usize| both(a, 1e-3, &|q| !closed(q));
                    let beside_inside = probed && (0..3).any(near_inner) && !(0..3).any(near_air);
                    if ((0..3).any(inside_grid) || beside_inside) && !(0..3).any(air) {
                        assert!(v < 0.0, "{}: between two parts", what());
                    } else {
                        assert_eq!(v, 0.0, "{}: on the surface", what());
                    }
                }
            }
            assert!(on_faces > 0, "seed {seed}: no face on a grid plane");
        }
    }
}

//! Marching Cubes throughput: isoforge against two peer crates on the very same sampled grids.
//!
//! For each scene (`sphere`, `gyroid`) and resolution (64³, 128³, 256³ cells over the scene's
//! `[-1, 1]³` bounds) the field is sampled once, outside any timing, and then:
//!
//! - `sample/<scene>/<res>`: [`sample_grid`] alone (throughput in sample points, `(res + 1)³`).
//! - `extract/<scene>/<res>/isoforge_mc`: [`mc::extract`] on the pre-sampled values with
//!   [`McOptions::default`] (fixed topology, iso 0). Throughput in cells, `res³`.
//! - `extract/<scene>/<res>/fast_surface_nets`: `fast_surface_nets::surface_nets` over the same
//!   array through an `ndshape::RuntimeShape` of the same point dimensions (x fastest, as
//!   [`Grid::index`]). Naive Surface Nets, not Marching Cubes: one vertex per surface cell, quads
//!   output as two triangles each. Its output is in array-index coordinates.
//! - `extract/<scene>/<res>/isosurface_mc`: the `isosurface` crate's `MarchingCubes`. It pulls its
//!   samples itself through its `ScalarSource` trait over the unit cube, so the source given to it
//!   is a lookup of the nearest sample of our pre-sampled array (both see identical values; the
//!   lookup is inside its timing, a rounding and an index per point). Its output is in unit-cube
//!   coordinates, its vertices are welded through hash maps.
//!
//! Every measured call builds its own output (no buffer reuse), as `mc::extract` does; each mesh
//! is dropped inside the timing.
//!
//! Grid size conventions: a grid of `res` cells per axis has `res + 1` points per axis. That is
//! the `RuntimeShape` given to `surface_nets` (with `min = [0; 3]`, `max = [res; 3]`, i.e. all
//! `res³` cells) and the `size` given to `isosurface::MarchingCubes::new` (its "size" counts grid
//! points, spaced `1 / (size - 1)`). `isosurface` 0.1.0-alpha.0 walks `size` cell layers along z
//! rather than `size - 1`, sampling one plane past z = 1; the lookup clamps that plane to the last
//! one, where both scenes are entirely outside, so the extra layer visits `res²` cells more and adds
//! no triangle. Inside is `value < 0` for isoforge and fast-surface-nets, `value <= 0` for
//! `isosurface`; the only exact 0 among these samples is the gyroid's at the origin, and both MC
//! implementations still give the same vertex and triangle counts on every grid here. The triangle
//! counts of every method are printed to stderr once per scene and size, so triangles per second
//! follow from the times.
//!
//! Run time (2 cores): `cargo bench --no-default-features --bench marching_cubes -- --quick` takes
//! about a minute after the build. In `--quick` mode criterion doubles the iteration count until
//! the estimate is stable or the group's measurement time has passed (one `isosurface` call at
//! 256³ takes 2–3 s, so its two samples alone take up to ~10 s). The 256³ groups use
//! `sample_size(10)`, flat sampling, a 1 s warm-up and a 4 s measurement time so that a full
//! (non-quick) run stays at several minutes; criterion then warns that 10 samples do not fit in
//! 4 s for `isosurface` and simply takes longer.

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, SamplingMode, Throughput};
use fast_surface_nets::ndshape::RuntimeShape;
use fast_surface_nets::{surface_nets, SurfaceNetsBuffer};
use isoforge::field::sample_grid;
use isoforge::grid::Grid;
use isoforge::mc::{self, McOptions};
use isoforge::scenes::{self, Scene};
use isosurface::distance::Signed;
use isosurface::extractor::IndexedVertices;
use isosurface::math::Vec3 as UnitVec3;
use isosurface::sampler::Sampler;
use isosurface::source::ScalarSource;
use isosurface::MarchingCubes;
use std::time::Duration;

const SCENES: [&str; 2] = ["sphere", "gyroid"];
const RESOLUTIONS: [usize; 3] = [64, 128, 256];
/// From this resolution on, groups get the small, flat-sampled configuration described above.
const LARGE: usize = 256;

/// The pre-sampled values seen by `isosurface` as a field over the unit cube: each query point is
/// answered with the nearest grid sample (the queries fall exactly on grid points, see above).
struct NearestSample<'a> {
    values: &'a [f32],
    grid: Grid,
}

impl ScalarSource for NearestSample<'_> {
    fn sample_scalar(&self, p: UnitVec3) -> Signed {
        let c = self.grid.cells;
        let nearest = |u: f32, a: usize| ((u * c[a] as f32).round().max(0.0) as usize).min(c[a]);
        Signed(self.values[self.grid.index(nearest(p.x, 0), nearest(p.y, 1), nearest(p.z, 2))])
    }
}

fn isoforge_mc(values: &[f32], grid: &Grid) -> isoforge::Mesh {
    mc::extract(values, grid, &McOptions::default()).expect("isoforge extraction")
}

fn fast_surface_nets(values: &[f32], shape: &RuntimeShape<u32, 3>, grid: &Grid) -> SurfaceNetsBuffer {
    let max = grid.cells.map(|c| c as u32);
    let mut buffer = SurfaceNetsBuffer::default();
    surface_nets(values, shape, [0; 3], max, &mut buffer);
    buffer
}

/// Returns (flat vertex coordinates, triangle indices).
fn isosurface_mc(source: &NearestSample) -> (Vec<f32>, Vec<u32>) {
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    let sampler = Sampler::new(source);
    let mut mc = MarchingCubes::<Signed>::new(source.grid.cells[0] + 1);
    mc.extract(&sampler, &mut IndexedVertices::new(&mut vertices, &mut indices));
    (vertices, indices)
}

fn configure(group: &mut BenchmarkGroup<WallTime>, res: usize) {
    if res >= LARGE {
        group
            .sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(4));
    }
}

fn bench_scene(c: &mut Criterion, scene: &Scene, res: usize) {
    let grid = Grid::with_resolution(scene.min, scene.max, res).expect("grid");
    assert_eq!(grid.cells, [res; 3], "the peers need a cubic grid; scene bounds must be a cube");
    let field = scene.field.as_ref();
    let values = sample_grid(field, &grid).expect("sampling");
    let cells = grid.cell_count();
    let shape = RuntimeShape::<u32, 3>::new(grid.points().map(|p| p as u32));
    let source = NearestSample { values: &values, grid };

    // Output sizes, once per scene and size, so triangles/s can be derived from the times.
    let ours = isoforge_mc(&values, &grid);
    let nets = fast_surface_nets(&values, &shape, &grid);
    let (iso_vertices, iso_indices) = isosurface_mc(&source);
    eprintln!(
        "triangles {}/{res}: isoforge_mc {} ({} vertices), fast_surface_nets {} ({} vertices), \
         isosurface_mc {} ({} vertices)",
        scene.name,
        ours.triangle_count(),
        ours.vertex_count(),
        nets.indices.len() / 3,
        nets.positions.len(),
        iso_indices.len() / 3,
        iso_vertices.len() / 3,
    );
    assert!(ours.triangle_count() > 0 && !nets.indices.is_empty() && !iso_indices.is_empty());
    drop((ours, nets, iso_vertices, iso_indices));

    let mut group = c.benchmark_group("sample");
    configure(&mut group, res);
    group.throughput(Throughput::Elements(grid.point_count() as u64));
    group.bench_function(format!("{}/{res}", scene.name), |b| {
        b.iter(|| sample_grid(field, &grid).expect("sampling"))
    });
    group.finish();

    let mut group = c.benchmark_group(format!("extract/{}/{res}", scene.name));
    configure(&mut group, res);
    group.throughput(Throughput::Elements(cells));
    group.bench_function("isoforge_mc", |b| b.iter(|| isoforge_mc(&values, &grid)));
    group.bench_function("fast_surface_nets", |b| b.iter(|| fast_surface_nets(&values, &shape, &grid)));
    group.bench_function("isosurface_mc", |b| b.iter(|| isosurface_mc(&source)));
    group.finish();
}

fn marching_cubes(c: &mut Criterion) {
    for name in SCENES {
        let scene = scenes::scene(name).expect("scene");
        for res in RESOLUTIONS {
            bench_scene(c, &scene, res);
        }
    }
}

criterion_group!(benches, marching_cubes);
criterion_main!(benches);

use isoforge::emc::{mesh_source, point_source, EmcOptions};
use isoforge::input::PointCloud;
use isoforge::mc::{self, McOptions};
use isoforge::{Grid, Vec3};
#[test]
fn perf() {
    let sphere = |p: Vec3| (p - Vec3::new(0.013, -0.007, 0.021)).length() - 0.8;
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 160).unwrap();
    let (input, _) = mc::mesh_field(&sphere, &grid, &McOptions::default()).unwrap();
    for res in [64, 128, 256] {
        let (lo, hi) = mesh_source::mesh_bounds(&input);
        let g = mesh_source::padded_grid(lo, hi, res).unwrap();
        let t = std::time::Instant::now();
        let (emc, tm) = mesh_source::remesh(&input, &g, &EmcOptions::default()).unwrap();
        eprintln!("remesh {} tris at res {res}: {:?} total, sample {:.0} ms extract {:.0} ms flip {:.0} ms → {} tris", input.triangle_count(), t.elapsed(), tm.sample_ms, tm.extract_ms, tm.flip_ms, emc.mesh.triangle_count());
    }
    let cloud = PointCloud { positions: input.positions.clone(), normals: input.normals.clone() };
    for res in [64, 128] {
        let (lo, hi) = cloud.bounds();
        let g = mesh_source::padded_grid(lo, hi, res).unwrap();
        let t = std::time::Instant::now();
        let (emc, tm) = point_source::reconstruct(&cloud, &g, &EmcOptions::default()).unwrap();
        eprintln!("points {} at res {res}: {:?} total, sample {:.0} ms extract {:.0} ms → {} tris", cloud.len(), t.elapsed(), tm.sample_ms, tm.extract_ms, emc.mesh.triangle_count());
    }
}

use isoforge::emc::{mesh_source, point_source::PointIndex};
use isoforge::input::PointCloud;
use isoforge::mc::{self, McOptions};
use isoforge::{Grid, Vec3};
#[test]
fn perf2() {
    let sphere = |p: Vec3| (p - Vec3::new(0.013, -0.007, 0.021)).length() - 0.8;
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 160).unwrap();
    let (input, _) = mc::mesh_field(&sphere, &grid, &McOptions::default()).unwrap();
    let cloud = PointCloud { positions: input.positions.clone(), normals: input.normals.clone() };
    let index = PointIndex::new(&cloud).unwrap();
    let (lo, hi) = cloud.bounds();
    let g = mesh_source::padded_grid(lo, hi, 64).unwrap();
    let band = 2.0 * g.cell_size();
    let pts: Vec<Vec3> = (0..g.point_count()).map(|n| { let [i, j, k] = g.unindex(n); g.position(i, j, k) }).collect();
    let t = std::time::Instant::now();
    let mut guess = None;
    let mut qs = Vec::new();
    for &p in &pts { let q = index.nearest_approx(p, guess, band); guess = Some(q); qs.push(q); }
    eprintln!("approx nearest: {:?}", t.elapsed());
    let t = std::time::Instant::now();
    let mut beside = 0;
    let mut nb = Vec::new();
    for (&p, &q) in pts.iter().zip(&qs) {
        let v = index.plane_distance(q, p);
        if v.abs() < 0.5 * (index.sample(q).0 - p).length() { beside += 1; index.k_nearest(p, 8, &mut nb); }
    }
    eprintln!("beside {beside} of {}: {:?}", pts.len(), t.elapsed());
}

use glam::Vec3;
use isoforge::input::PointCloud;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for l in text.lines() {
        let v: Vec<f32> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
        positions.push(Vec3::new(v[0], v[1], v[2]));
        normals.push(Vec3::new(v[3], v[4], v[5]));
    }
    let cloud = PointCloud { positions, normals };
    let mut o = cloud.clone();
    let turned = isoforge::emc::orient::orient_normals(&mut o).unwrap();
    println!("turned {turned} of {}", cloud.positions.len());
    let (lo, hi) = cloud.bounds();
    println!("bounds {lo} {hi}");
    let idx: Vec<usize> =
        (0..cloud.positions.len()).filter(|&i| o.normals[i].dot(cloud.normals[i]) < 0.0).collect();
    let mut lo2 = Vec3::splat(9.0);
    let mut hi2 = Vec3::splat(-9.0);
    for &i in &idx {
        lo2 = lo2.min(cloud.positions[i]);
        hi2 = hi2.max(cloud.positions[i]);
    }
    println!("turned box {lo2} {hi2}");
    // nearest-neighbour spacing and opposite-normal distance for turned ones
    let n = cloud.positions.len();
    let mut thick = Vec::new();
    let mut spacing = Vec::new();
    for &i in idx.iter().step_by(10) {
        let p = cloud.positions[i];
        let ni = cloud.normals[i];
        let mut best = f32::MAX;
        let mut bopp = f32::MAX;
        let mut offs = 0.0;
        for j in 0..n {
            if j == i {
                continue;
            }
            let d = cloud.positions[j].distance(p);
            best = best.min(d);
            if cloud.normals[j].dot(ni) < -0.5 && d < bopp {
                bopp = d;
                offs = (cloud.positions[j] - p).dot(ni);
            }
        }
        spacing.push(best);
        thick.push((bopp, offs));
    }
    println!("spacing {:?}", &spacing[..spacing.len().min(15)]);
    println!("opp {:?}", &thick[..thick.len().min(15)]);
}

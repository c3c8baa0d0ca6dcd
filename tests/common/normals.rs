//! How far a face turns from the surface it stands for, measured so that a face lying flat against
//! one side of a crease counts as right: the EMC quality suite holds every scene to it.
//!
//! The stats' normal deviation takes the field's gradient at the projection of a face's centroid.
//! Next to a crease that projection can land on the other sheet, and a face lying exactly in its
//! own sheet reads as the crease's dihedral angle. Here a face is compared with the true normals
//! at the projections of seven points of it (its corners, its centroid and the midpoints between
//! the two) and keeps the smallest angle: a face that lies in one of the sheets meeting near it
//! has a sample on that sheet and reads near 0°, while a tooth, a step across a crease, a chord
//! across a thin wedge or a flipped face is off every sheet near it.

use isoforge::field::gradient_or_differences;
use isoforge::{Field, Mesh, Vec3};

/// Newton steps onto the zero set; steps are capped at half a cell so that a point near a
/// vanishing gradient cannot jump to a far sheet.
pub fn project(field: &dyn Field, p: Vec3, cell: f32) -> Vec3 {
    let mut q = p;
    for _ in 0..8 {
        let g = gradient_or_differences(field, q, 1e-4 * cell);
        let slope = g.length_squared();
        if slope == 0.0 || !slope.is_finite() {
            break;
        }
        let mut step = g * (field.value(q) / slope);
        let len = step.length();
        if len > 0.5 * cell {
            step *= 0.5 * cell / len;
        }
        q -= step;
        if len < 1e-6 * cell {
            break;
        }
    }
    q
}

/// The unit normal of the surface at the projection of `p`.
pub fn true_normal(field: &dyn Field, p: Vec3, cell: f32) -> Vec3 {
    let q = project(field, p, cell);
    gradient_or_differences(field, q, 1e-4 * cell).normalize_or_zero()
}

fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    (a.as_dvec3().dot(b.as_dvec3())).clamp(-1.0, 1.0).acos().to_degrees()
}

/// Faces thinner than this (their smallest altitude, in cells) have no normal worth measuring:
/// crossings are kept 1e-3 of an edge off its ends (`mc::MIN_EDGE_FRACTION`), and that alone
/// turns a face of altitude a by up to 1e-3 / a radians, 3° at this bound. MC's own slivers,
/// where the surface passes through a grid point, read up to 53° on the torus at 24 cells; they
/// are under 0.02 cells² and invisible. The teeth and steps this suite is for are 0.1 cells²
/// and more.
pub const MIN_ALTITUDE: f32 = 0.02;

/// The deviation of one face (see the module's comment), in degrees; `None` for a face thinner
/// than [`MIN_ALTITUDE`] cells.
pub fn face_deviation(field: &dyn Field, corners: [Vec3; 3], cell: f32) -> Option<f64> {
    let [a, b, c] = corners;
    let normal = (b - a).cross(c - a);
    let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
    if longest == 0.0 || normal.length() / longest < MIN_ALTITUDE * cell {
        return None;
    }
    let normal = normal.normalize();
    let centroid = (a + b + c) / 3.0;
    let samples = [a, b, c, centroid, (centroid + a) * 0.5, (centroid + b) * 0.5, (centroid + c) * 0.5];
    samples
        .iter()
        .map(|&s| true_normal(field, s, cell))
        .filter(|n| *n != Vec3::ZERO)
        .map(|n| angle_deg(normal, n))
        .min_by(f64::total_cmp)
}

/// Every face's deviation (`None` for faces without a normal), in the mesh's order.
pub fn face_deviations(mesh: &Mesh, field: &dyn Field, cell: f32) -> Vec<Option<f64>> {
    mesh.triangles
        .iter()
        .map(|t| face_deviation(field, t.map(|v| mesh.positions[v as usize]), cell))
        .collect()
}

/// The largest angle between true normals at the projections of `p` and of points a quarter
/// cell from it (along the axes and the diagonals): a crease's dihedral where `p` is on one, and
/// on a smooth surface of radius R about half a cell over R (9° on the torus's tube at 24 cells,
/// the tightest curvature the suite's smooth scenes have).
pub fn normal_spread_near(field: &dyn Field, p: Vec3, cell: f32) -> f64 {
    let r = 0.25 * cell;
    let mut offsets = vec![Vec3::ZERO];
    for a in 0..3 {
        for s in [-1.0, 1.0] {
            let mut d = Vec3::ZERO;
            d[a] = s * r;
            offsets.push(d);
        }
    }
    for q in 0..8 {
        let d = Vec3::new(
            if q & 1 == 0 { -1.0 } else { 1.0 },
            if q & 2 == 0 { -1.0 } else { 1.0 },
            if q & 4 == 0 { -1.0 } else { 1.0 },
        );
        offsets.push(d * (r / 3f32.sqrt()));
    }
    let normals: Vec<Vec3> =
        offsets.iter().map(|&d| true_normal(field, p + d, cell)).filter(|n| *n != Vec3::ZERO).collect();
    let mut widest = 0.0f64;
    for (i, &a) in normals.iter().enumerate() {
        for &b in &normals[i + 1..] {
            widest = widest.max(angle_deg(a, b));
        }
    }
    widest
}

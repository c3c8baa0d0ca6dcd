//! How far a mesh is from the surface it approximates: the distance from points of the mesh to the
//! field's zero set, and the angle between face normals and the true surface normal.
//!
//! Distances are measured by walking to the zero set with Newton steps along the gradient instead
//! of trusting `|value|`: only signed distance fields have `|value| = distance`, and the library
//! meshes many fields that are not (gyroids, sampled volumes, CSG blends).

use crate::error::Error;
use crate::field::{finite_difference_gradient, Field};
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use serde::Serialize;

/// Position and normal error of a mesh against a field's zero set.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SurfaceError {
    /// Largest distance from a sample point of the mesh to the zero set.
    pub dist_max: f64,
    /// Root mean square of those distances.
    pub dist_rms: f64,
    /// Percentiles (nearest rank) and maximum of the angle between each face normal and the field
    /// gradient at the face centroid's projection onto the surface, in degrees.
    pub normal_dev_deg_p50: f64,
    pub normal_dev_deg_p95: f64,
    pub normal_dev_deg_max: f64,
    /// Faces at a crease: the true normals at their corners' projections onto the surface differ
    /// by more than [`CREASE_DEG`]. On a mesh that keeps its sharp edges these faces border the
    /// crease and lie flat against one side of it; where the crease is cut or zigzags ("crinkly"
    /// edges) they tilt across it. The whole-mesh percentiles above hide them among flat faces.
    /// Meaningful only where the mesh resolves the curvature: on a coarse sphere (an octahedron)
    /// every face counts.
    pub crease_faces: usize,
    /// The 95th percentile of the normal deviation over the crease faces alone, by area.
    pub crease_normal_dev_deg_p95: f64,
    /// Per face, the angle to the *nearest* of the true normals at the projections of its
    /// corners, its centroid and the points halfway between the two; the 95th percentile and the
    /// maximum over the faces. A face lying flat against one side of a crease, whose centroid's
    /// projection can land on the other side (and then reads as the whole dihedral angle in
    /// `normal_dev_deg_*`), reads near 0 here; a face cutting across a crease reads about half
    /// its dihedral angle, a spike or a face turned over stays large. Slivers count as they are.
    pub face_normal_dev_deg_p95: f64,
    pub face_normal_dev_deg_max: f64,
    /// Distance samples taken: every referenced vertex plus four points per triangle.
    pub samples: usize,
    /// Samples whose projection did not settle (vanishing gradient, or still moving after the last
    /// step): their distance is not trustworthy, so a non-zero count means "look closer".
    pub unconverged: usize,
}

/// Newton iterations per projection: signed distance fields need one, smooth fields two or three
/// from a mesh that is already close; more than this means the estimate is not trustworthy.
const MAX_STEPS: usize = 8;

/// Corner normals further apart than this mark a face as sitting at a crease: far above the turn
/// of a curved surface across one face of a mesh that resolves it (a few degrees), far below the
/// dihedral angles of the creases we mesh.
pub const CREASE_DEG: f64 = 30.0;

/// Measures `mesh` against the zero set of `field`.
///
/// Samples are the referenced vertices and, per non-collapsed triangle, its centroid and the
/// midpoints between the centroid and each corner (interior points catch the error of the flat
/// triangle between accurate vertices). Each is projected by Newton steps
/// `p -= f(p) grad f(p) / |grad f(p)|^2` and its distance is `|p - p0|` (an estimate of the
/// distance to the nearest surface point, exact for signed distance fields).
///
/// Gradients are the field's own where it knows them, else central differences with a step of
/// 1e-4 of the mesh's bounding-box diagonal. Faces with zero area have no normal and are left out
/// of the normal statistics, as are faces where the gradient vanishes. An outward-facing mesh of a
/// field that grows outward has deviations near 0; a flipped face shows up near 180 degrees.
pub fn surface_error(mesh: &Mesh, field: &dyn Field) -> SurfaceError {
    let Ok(error) = measure(mesh, field, |_| Ok::<(), std::convert::Infallible>(()));
    error
}

/// [`surface_error`] with a [`checkpoint`](crate::progress::checkpoint) every few thousand faces:
/// on a large mesh the measurement costs as much as meshing, and a page that abandons a request
/// must be able to stop it there too.
pub fn surface_error_cancellable(mesh: &Mesh, field: &dyn Field) -> Result<SurfaceError, Error> {
    measure(mesh, field, |fraction| crate::progress::checkpoint("analysis", fraction))
}

/// Faces measured between two calls of the `tick` of [`measure`].
const FACES_PER_TICK: usize = 1024;

fn measure<E>(
    mesh: &Mesh,
    field: &dyn Field,
    mut tick: impl FnMut(f32) -> Result<(), E>,
) -> Result<SurfaceError, E> {
    let faces: Vec<[u32; 3]> =
        mesh.triangles.iter().copied().filter(|&[a, b, c]| a != b && b != c && a != c).collect();
    let mut referenced = vec![false; mesh.positions.len()];
    for &v in faces.iter().flatten() {
        referenced[v as usize] = true;
    }
    let (lo, hi) = mesh
        .positions
        .iter()
        .zip(&referenced)
        .filter(|(_, &r)| r)
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), (&p, _)| (lo.min(p), hi.max(p)));
    if faces.is_empty() {
        return Ok(SurfaceError::default());
    }
    let diagonal = (hi - lo).length() as f64;
    let largest_coordinate = lo.abs().max(hi.abs()).max_element() as f64;
    let projector = Projector {
        field,
        fd_step: (1e-4 * diagonal).max(1e-6) as f32,
        // Stop once steps are below what f32 evaluation can resolve at these coordinates.
        tolerance: (1e-7 * diagonal).max(4.0 * f32::EPSILON as f64 * largest_coordinate),
        ridge_floor: 1e-3 * diagonal,
    };

    let mut sum_sq = 0.0;
    let mut result = SurfaceError::default();
    let mut record = |projection: &Projection| {
        result.samples += 1;
        result.unconverged += !projection.converged as usize;
        result.dist_max = result.dist_max.max(projection.distance);
        sum_sq += projection.distance * projection.distance;
    };
    // The true normal at each referenced vertex's projection, for finding the crease faces.
    let mut corner_normals = vec![DVec3::ZERO; mesh.positions.len()];
    for ((p, _), normal) in
        mesh.positions.iter().zip(&referenced).zip(&mut corner_normals).filter(|((_, &r), _)| r)
    {
        let projection = projector.project(p.as_dvec3());
        record(&projection);
        *normal = projector.gradient(projection.point).normalize_or_zero();
    }
    let crease_cos = CREASE_DEG.to_radians().cos();
    let mut deviations = Vec::with_capacity(faces.len());
    let mut crease_deviations = Vec::new();
    let mut face_deviations = Vec::with_capacity(faces.len());
    for (i, &[a, b, c]) in faces.iter().enumerate() {
        if i % FACES_PER_TICK == 0 {
            tick(i as f32 / faces.len() as f32)?;
        }
        let corners = [a, b, c].map(|v| mesh.positions[v as usize].as_dvec3());
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        let on_surface = projector.project(centroid);
        record(&on_surface);
        let halfway = corners.map(|corner| projector.project((centroid + corner) * 0.5));
        halfway.iter().for_each(&mut record);
        let twice_area = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let normal = twice_area.normalize_or_zero();
        let gradient = projector.gradient(on_surface.point).normalize_or_zero();
        let angle_to = |g: DVec3| normal.cross(g).length().atan2(normal.dot(g)).to_degrees();
        if normal != DVec3::ZERO && gradient != DVec3::ZERO {
            let angle = angle_to(gradient);
            deviations.push(angle);
            let n = [a, b, c].map(|v| corner_normals[v as usize]);
            let nearest = halfway
                .iter()
                .map(|h| projector.gradient(h.point).normalize_or_zero())
                .chain(n)
                .filter(|&g| g != DVec3::ZERO)
                .map(angle_to)
                .fold(angle, f64::min);
            face_deviations.push(nearest);
            let at_crease = [(0, 1), (1, 2), (2, 0)]
                .iter()
                .any(|&(i, j)| n[i] != DVec3::ZERO && n[j] != DVec3::ZERO && n[i].dot(n[j]) < crease_cos);
            if at_crease {
                crease_deviations.push((angle, twice_area.length() * 0.5));
            }
        }
    }
    result.dist_rms = (sum_sq / result.samples as f64).sqrt();
    deviations.sort_unstable_by(f64::total_cmp);
    result.normal_dev_deg_p50 = nearest_rank(&deviations, 0.50);
    result.normal_dev_deg_p95 = nearest_rank(&deviations, 0.95);
    result.normal_dev_deg_max = deviations.last().copied().unwrap_or(0.0);
    face_deviations.sort_unstable_by(f64::total_cmp);
    result.face_normal_dev_deg_p95 = nearest_rank(&face_deviations, 0.95);
    result.face_normal_dev_deg_max = face_deviations.last().copied().unwrap_or(0.0);
    crease_deviations.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    result.crease_faces = crease_deviations.len();
    result.crease_normal_dev_deg_p95 = area_weighted_rank(&crease_deviations, 0.95);
    Ok(result)
}

/// The smallest value with at least `fraction` of the total weight at or below it, over
/// `(value, weight)` pairs sorted by value; 0 for none. Weighted by area, slivers along a crease
/// (heights of 1e-5 of the bounds, normals set by rounding) count as little as they show.
fn area_weighted_rank(sorted: &[(f64, f64)], fraction: f64) -> f64 {
    let total: f64 = sorted.iter().map(|&(_, w)| w).sum();
    let mut below = 0.0;
    for &(value, weight) in sorted {
        below += weight;
        if below >= fraction * total {
            return value;
        }
    }
    sorted.last().map_or(0.0, |&(value, _)| value)
}

/// The smallest value with at least `fraction` of `sorted` at or below it; 0 for no values.
fn nearest_rank(sorted: &[f64], fraction: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (fraction * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

struct Projection {
    point: DVec3,
    distance: f64,
    converged: bool,
}

struct Projector<'a> {
    field: &'a dyn Field,
    fd_step: f32,
    tolerance: f64,
    /// Walks shorter than this are taken as they are (see [`Projector::project`]).
    ridge_floor: f64,
}

impl Projector<'_> {
    fn gradient(&self, p: DVec3) -> DVec3 {
        let q = p.as_vec3();
        let g = self
            .field
            .gradient(q)
            .filter(|g| g.is_finite())
            .unwrap_or_else(|| finite_difference_gradient(self.field, q, self.fd_step));
        g.as_dvec3()
    }

    /// The distance from `start` to the zero set, as the length of a Newton walk to it: an upper
    /// bound, tight where the walk goes straight to the nearest point. On a ridge of a distance
    /// field (the axis of a cone, the bisector inside a convex edge), where the gradient is the
    /// mean of two sides', the walk can land far off the nearest point (on the apex from a point
    /// on a cone's axis, three times the distance); there walks from points a little off `start`
    /// along each axis, each plus that offset (still upper bounds), are tried too, and the
    /// shortest kept, for walks longer than a thousandth of the mesh's diagonal.
    fn project(&self, start: DVec3) -> Projection {
        let (straight, first) = self.walk(start);
        let Some((f0, g0)) = first else { return straight };
        // Near the surface the walk's overshoot is too small to matter (and ridges, at creases,
        // are everywhere on CAD parts): only far samples are checked.
        if !straight.converged || straight.distance < self.ridge_floor {
            return straight;
        }
        let offset = (1e-2 * straight.distance).max(4.0 * self.fd_step as f64);
        // One value a little aside tells a ridge: there the field departs from its tangent plane
        // at first order (the gradient at `start` is the mean of the sides'), elsewhere at second.
        let aside = DVec3::new(0.802, 0.496, 0.333) * offset;
        let departure = self.field.value((start + aside).as_vec3()) as f64 - (f0 + g0.dot(aside));
        if departure.abs() < 0.05 * g0.length() * offset {
            return straight;
        }
        let mut best = straight;
        for axis in 0..6 {
            let mut step = DVec3::ZERO;
            step[axis % 3] = if axis < 3 { offset } else { -offset };
            let (mut walked, _) = self.walk(start + step);
            walked.distance = (walked.point - start).length();
            if walked.converged && walked.distance < best.distance {
                best = walked;
            }
        }
        best
    }

    /// Walks from `start` to the zero set with Newton steps along the gradient; also returns the
    /// value and gradient at `start`, where the walk took a step.
    fn walk(&self, start: DVec3) -> (Projection, Option<(f64, DVec3)>) {
        let mut p = start;
        let mut converged = false;
        let mut last_step = f64::INFINITY;
        let mut first = None;
        for _ in 0..MAX_STEPS {
            let f = self.field.value(p.as_vec3()) as f64;
            if f == 0.0 {
                converged = true;
                break;
            }
            let g = self.gradient(p);
            let g2 = g.length_squared();
            if !(g2 > 0.0 && g2.is_finite() && f.is_finite()) {
                break;
            }
            first.get_or_insert((f, g));
            let step = g * (f / g2);
            p -= step;
            last_step = step.length();
            if last_step <= self.tolerance {
                converged = true;
                break;
            }
        }
        // A walk that is still taking small steps at the end has found the surface all the same.
        converged |= last_step <= 10.0 * self.tolerance;
        (Projection { point: p, distance: (p - start).length(), converged }, first)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures::*;
    use crate::scenes::Sphere;

    /// Seeded random cones, placed anywhere, measured from points on their axes: on the axis the
    /// gradient is the mean of the side normals all around, shorter than unit, and a walk along it
    /// ends on the apex, up to three times as far as the side. The distance reported must be the
    /// side's (analytic: the radius there times the cosine of the half angle), within 2 %.
    #[test]
    fn prop_points_on_a_cones_axis_are_as_far_as_the_side_not_the_apex() {
        let mut rng = crate::expr::testutil::Rng::new(17);
        for case in 0..40 {
            let (r, h) = (rng.range(0.05, 0.5), rng.range(0.2, 1.0));
            let shift = rng.vec3(-1.0, 1.0);
            // Far enough below the apex that the walk is checked (over 1/1000 of the diagonal of
            // the tiny triangle plus its distance), above the base.
            let z = h * rng.range(0.5, 0.97);
            let text = format!("translate(cone({r}, {h}), {}, {}, {})", shift.x, shift.y, shift.z);
            let cone = crate::expr::compile(&text).unwrap();
            let tiny = 1e-5;
            let on_axis = shift + Vec3::new(0.0, 0.0, z);
            let mesh = Mesh {
                positions: vec![
                    on_axis,
                    on_axis + Vec3::new(tiny, 0.0, 0.0),
                    on_axis + Vec3::new(0.0, tiny, 0.0),
                ],
                normals: Vec::new(),
                triangles: vec![[0, 1, 2]],
            };
            let e = surface_error(&mesh, &cone);
            let half_angle = (r as f64).atan2(h as f64);
            let side = r as f64 * (h - z) as f64 / h as f64 * half_angle.cos();
            assert!(
                (e.dist_max - side).abs() < 0.02 * side,
                "case {case}: {text} at z {z}: {} against {side}",
                e.dist_max
            );
        }
    }

    #[test]
    fn an_octahedron_inscribed_in_the_unit_sphere() {
        let sphere = Sphere { center: Vec3::ZERO, radius: 1.0 };
        let e = surface_error(&octahedron(), &sphere);
        assert_eq!(e.samples, 6 + 4 * 8);
        assert_eq!(e.unconverged, 0);
        // Vertices are on the sphere; the face centroids are deepest, at 1/sqrt(3) from the centre.
        let deepest = 1.0 - 1.0 / 3f64.sqrt();
        assert!((e.dist_max - deepest).abs() < 1e-6, "{}", e.dist_max);
        assert!(e.dist_rms > 0.0 && e.dist_rms < e.dist_max);
        // Face normals point through the centroids, exactly along the sphere's gradient there.
        assert!(e.normal_dev_deg_max < 1e-3, "{e:?}");
    }

    /// MC cuts a box's edges with chamfer faces (normals ~45° off), EMC puts vertices on them; the
    /// crease statistic sees exactly that, the whole-mesh p95 of MC much less.
    #[test]
    fn crease_faces_show_mcs_chamfers_and_emcs_sharp_edges() {
        let field = crate::expr::compile("box(0.5, 0.4, 0.3)").unwrap();
        let grid = crate::grid::Grid::with_resolution(Vec3::splat(-0.7), Vec3::splat(0.7), 20).unwrap();
        let (mc, _) = crate::mc::mesh_field(&field, &grid, &crate::mc::McOptions::default()).unwrap();
        let (emc, _) = crate::emc::mesh_field(&field, &grid, &crate::emc::EmcOptions::default()).unwrap();
        let (mc, emc) = (surface_error(&mc, &field), surface_error(&emc.mesh, &field));
        assert!(mc.crease_faces > 50 && emc.crease_faces > 50, "{mc:?} {emc:?}");
        assert!(mc.crease_normal_dev_deg_p95 > 30.0, "{mc:?}");
        assert!(mc.normal_dev_deg_p95 < mc.crease_normal_dev_deg_p95, "{mc:?}");
        assert!(emc.crease_normal_dev_deg_p95 < 1.0, "{emc:?}");
    }

    /// A face lying in a box's top plane a little inside the solid, along an edge: its centroid
    /// is nearer the side face, so the centroid's gradient is the side's (90° off), while its far
    /// corner's nearest face is the top, the face's own plane. Turned over, it is off every
    /// normal near it.
    #[test]
    fn a_face_flat_beside_a_crease_is_right_by_the_nearest_normal() {
        let field = crate::expr::compile("box(0.5, 0.5, 0.5)").unwrap();
        let z = 0.4999;
        let mut mesh = Mesh {
            positions: vec![
                Vec3::new(0.499998, -0.1, z),
                Vec3::new(0.499998, 0.1, z),
                Vec3::new(0.49985, 0.0, z),
            ],
            normals: Vec::new(),
            triangles: vec![[0, 1, 2]],
        };
        let e = surface_error(&mesh, &field);
        assert!((e.normal_dev_deg_max - 90.0).abs() < 1e-3, "{e:?}");
        assert!(e.face_normal_dev_deg_max < 1e-3, "{e:?}");
        mesh.triangles[0].swap(1, 2);
        let e = surface_error(&mesh, &field);
        assert!(e.face_normal_dev_deg_max > 90.0 - 1e-3, "{e:?}");
    }

    #[test]
    fn weighted_ranks_count_area_not_faces() {
        let slivers_and_one_face = [(1.0, 10.0), (80.0, 1e-6), (90.0, 1e-6)];
        assert_eq!(area_weighted_rank(&slivers_and_one_face, 0.95), 1.0);
        assert_eq!(area_weighted_rank(&[(1.0, 1.0), (50.0, 1.0)], 0.95), 50.0);
        assert_eq!(area_weighted_rank(&[], 0.95), 0.0);
    }

    #[test]
    fn flipped_faces_deviate_by_half_a_turn() {
        let sphere = Sphere { center: Vec3::ZERO, radius: 1.0 };
        let mut m = octahedron();
        for t in &mut m.triangles[..4] {
            t.swap(1, 2);
        }
        let e = surface_error(&m, &sphere);
        assert!((e.normal_dev_deg_max - 180.0).abs() < 1e-3);
        // Against the nearest normal, its corners' (54.7° from the face's on this coarse mesh).
        assert!((e.face_normal_dev_deg_max - 125.26).abs() < 0.01, "{e:?}");
        assert!(e.normal_dev_deg_p50 < 1e-3, "half the faces are still right");
    }

    #[test]
    fn newton_finds_the_distance_for_fields_that_are_not_distances() {
        // 4 (|p|^2 - r^2) has the sphere as zero set but |value| is far from the distance.
        let r = 0.8f32;
        let squashed = |p: Vec3| 4.0 * (p.length_squared() - r * r);
        let (m, _) = mc_sphere(24);
        let exact = surface_error(&m, &sphere_field());
        let shifted = |p: Vec3| squashed(p - sphere_field().center);
        let estimated = surface_error(&m, &shifted);
        assert_eq!(estimated.unconverged, 0);
        assert!(
            (estimated.dist_max - exact.dist_max).abs() < 0.02 * exact.dist_max,
            "{estimated:?} vs {exact:?}"
        );
        assert!((estimated.normal_dev_deg_p95 - exact.normal_dev_deg_p95).abs() < 0.1);
    }

    #[test]
    fn mc_sphere_error_is_small_and_shrinks_with_resolution() {
        let mut previous: Option<SurfaceError> = None;
        for res in [16, 32, 64] {
            let (m, grid) = mc_sphere(res);
            let e = surface_error(&m, &sphere_field());
            let h = grid.cell_size() as f64;
            assert_eq!(e.unconverged, 0);
            assert!(e.dist_max < 0.1 * h, "res {res}: {e:?}");
            assert!(e.dist_rms <= e.dist_max);
            assert!(e.normal_dev_deg_p50 <= e.normal_dev_deg_p95);
            assert!(e.normal_dev_deg_p95 <= e.normal_dev_deg_max);
            // MC's slivers (a corner cut a hair from a sample) keep the worst face normal tens of
            // degrees off at every resolution; only a flipped or folded face would pass 90.
            assert!(e.normal_dev_deg_max < 60.0, "res {res}: {e:?}");
            assert!(e.normal_dev_deg_p95 < 6.0, "res {res}: {e:?}");
            if let Some(p) = previous {
                assert!(e.dist_max < 0.6 * p.dist_max, "res {res}: {e:?} vs {p:?}");
                assert!(e.dist_rms < 0.6 * p.dist_rms);
                assert!(e.normal_dev_deg_p95 < 0.6 * p.normal_dev_deg_p95);
            }
            previous = Some(e);
        }
    }

    #[test]
    fn empty_meshes_have_no_error() {
        let e = surface_error(&Mesh::default(), &sphere_field());
        assert_eq!(e, SurfaceError::default());
    }
}

//! Putting vertices on the surface: Newton steps along the gradient onto f = 0, and the
//! relaxation (tangential smoothing, then re-projection) that evens out the octree's staircase.

use super::mesh::QuadMesh;
use crate::field::{gradient_or_differences as gradient, Field};
use glam::Vec3;

/// Moves `p` onto f = 0 by Newton steps along the gradient. Each step is capped at `max_step`
/// (a cell) so a vertex near a saddle or a crease cannot be thrown across the model; the
/// original point is kept when the field gives no usable gradient.
///
/// Axes set in `pins` are held fixed: a vertex on the grid's outer face moves only within it
/// (Newton along the gradient's component in the face), one on an outer edge only along it.
pub fn project_point(field: &dyn Field, p: Vec3, max_step: f32, pins: u8) -> Vec3 {
    let mut q = p;
    let h = max_step * 1e-3;
    let free = Vec3::from_array(std::array::from_fn(|a| if pins >> a & 1 == 1 { 0.0 } else { 1.0 }));
    for _ in 0..20 {
        let f = field.value(q);
        if f.abs() <= max_step * 1e-5 {
            break;
        }
        let g = gradient(field, q, h) * free;
        let gg = g.length_squared();
        if gg.is_nan() || gg <= 1e-20 || !gg.is_finite() {
            break;
        }
        let mut step = g * (f / gg);
        let len = step.length();
        if len > max_step {
            step *= max_step / len;
        }
        q -= step;
    }
    if q.is_finite() {
        q
    } else {
        p
    }
}

/// Projects every vertex (or those `only` selects) onto the surface.
pub fn project(mesh: &mut QuadMesh, field: &dyn Field, max_step: f32, only: Option<&[bool]>) {
    let pins = mesh.pins.clone();
    for (v, p) in mesh.positions.iter_mut().enumerate() {
        if only.is_none_or(|o| o[v]) {
            *p = project_point(field, *p, max_step, pins.get(v).copied().unwrap_or(0));
        }
    }
}

/// `iterations` rounds of: move each vertex part way to the centroid of its neighbours, within
/// the tangent plane (the normal component would only be undone by the projection), then
/// project back onto f = 0. Vertex order does not matter: each round reads the previous one.
/// Border (pinned) vertices are only projected, within their outer face: smoothing them would
/// pull the border off it.
pub fn relax(mesh: &mut QuadMesh, field: &dyn Field, iterations: usize, max_step: f32) {
    let nb = mesh.neighbours();
    let h = max_step * 1e-3;
    for _ in 0..iterations {
        let old = mesh.positions.clone();
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            if nb[v].is_empty() || mesh.pins.get(v).is_some_and(|&pin| pin != 0) {
                continue;
            }
            let centroid = nb[v].iter().map(|&u| old[u as usize]).sum::<Vec3>() / nb[v].len() as f32;
            let d = centroid - old[v];
            let n = gradient(field, old[v], h).normalize_or_zero();
            let tangential = d - n * d.dot(n);
            *p = project_point(field, old[v] + tangential * 0.5, max_step, 0);
        }
    }
}

/// Largest distance from a vertex to the surface, estimated as |f| / |∇f| (exact for a signed
/// distance field), and the root mean square of the same.
pub fn vertex_distance(mesh: &QuadMesh, field: &dyn Field, h: f32) -> (f64, f64) {
    let mut max: f64 = 0.0;
    let mut sum = 0.0;
    for &p in &mesh.positions {
        let g = gradient(field, p, h).length().max(1e-12);
        let d = (field.value(p) / g).abs() as f64;
        max = max.max(d);
        sum += d * d;
    }
    (max, (sum / mesh.positions.len().max(1) as f64).sqrt())
}

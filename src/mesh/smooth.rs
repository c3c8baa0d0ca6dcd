//! Feature-preserving smoothing (the EMC paper's §5): Taubin λ|μ passes over the vertices off the
//! feature lines, each pass followed, where the true field is known, by a Newton step back onto the
//! surface.
//!
//! Smoothing alone shrinks a surface and rounds its creases; here the feature vertices (EMC's
//! crease and corner points, and every vertex on an open or non-manifold edge) do not move at all,
//! and Taubin's inflating μ step cancels the shrinking. With a field the relaxation becomes a
//! tangential one: each moved vertex is pulled back onto the zero set, so the triangles even out
//! while the distance error does not grow. A vertex stays where it was if its move would turn one
//! of its faces by more than 60°, give it a new sliver (see `turned`), make it cross a face it did
//! not cross before, or (with a field) put a sample of one of its faces (centroid, and halfway to
//! each corner) farther from the surface than the farthest was before smoothing: next to a crease,
//! a relaxed and projected vertex can land on the other sheet. Where undoing such moves does not
//! settle in a few rounds, the whole step is undone.

use crate::error::Error;
use crate::field::{finite_difference_gradient, Field};
use crate::mesh::analysis::self_intersect::self_intersecting_pairs_within;
use crate::mesh::Mesh;
use crate::progress::checkpoint;
use glam::Vec3;
use std::collections::{BTreeSet, HashMap, HashSet};

/// Taubin's weights: a shrinking step of λ, then an inflating one of μ (|μ| slightly above λ).
const LAMBDA: f32 = 0.5;
const MU: f32 = -0.53;

/// Smooths `mesh` in place by `passes` passes, leaving the endpoints of `feature_edges` and the
/// vertices on open or non-manifold edges where they are.
/// Fails only with [`Error::Cancelled`], from a [`checkpoint`] ("smooth") before each pass.
pub fn smooth(
    mesh: &mut Mesh,
    feature_edges: &[[u32; 2]],
    field: Option<&dyn Field>,
    passes: usize,
) -> Result<(), Error> {
    let n = mesh.positions.len();
    let mut fixed = vec![false; n];
    for &[a, b] in feature_edges {
        fixed[a as usize] = true;
        fixed[b as usize] = true;
    }
    let mut edge_count: HashMap<(u32, u32), u32> = HashMap::new();
    let mut neighbours: Vec<BTreeSet<u32>> = vec![BTreeSet::new(); n];
    let mut faces_of: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *edge_count.entry((a.min(b), a.max(b))).or_default() += 1;
            neighbours[a as usize].insert(b);
            neighbours[b as usize].insert(a);
            faces_of[a as usize].push(f);
        }
    }
    for (&(a, b), &count) in &edge_count {
        if count != 2 {
            fixed[a as usize] = true;
            fixed[b as usize] = true;
        }
    }
    let neighbours: Vec<Vec<u32>> = neighbours.into_iter().map(|s| s.into_iter().collect()).collect();
    let diagonal = {
        let (lo, hi) = mesh
            .positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| (l.min(p), h.max(p)));
        if n > 0 {
            (hi - lo).length()
        } else {
            1.0
        }
    };
    let step = (1e-4 * diagonal).max(1e-6);
    let bound = field.map(|field| {
        (0..mesh.triangles.len()).map(|f| face_distance(field, mesh, f, step)).fold(0.0, f32::max)
    });
    let too_far = |mesh: &Mesh, f: usize| match (field, bound) {
        (Some(field), Some(bound)) => face_distance(field, mesh, f, step) > bound,
        _ => false,
    };
    let crossing_before: HashSet<[u32; 2]> =
        self_intersecting_pairs_within(mesh, "smooth", 0.0)?.into_iter().collect();
    let mut moved = vec![false; n];
    for pass in 0..passes {
        checkpoint("smooth", pass as f32 / passes as f32)?;
        for weight in [LAMBDA, MU] {
            let before = mesh.positions.clone();
            for v in 0..n {
                if fixed[v] || neighbours[v].is_empty() {
                    continue;
                }
                let mean = neighbours[v].iter().map(|&w| before[w as usize]).sum::<Vec3>()
                    / neighbours[v].len() as f32;
                mesh.positions[v] = before[v] + weight * (mean - before[v]);
            }
            if weight == MU {
                if let Some(field) = field {
                    for v in (0..n).filter(|&v| !fixed[v]) {
                        mesh.positions[v] = project(field, mesh.positions[v], step);
                    }
                }
            }
            // Undo the moves that turn a face over, squeeze it, take it too far from the surface
            // or make it cross another; undoing one can spoil a neighbour, so repeat, and where
            // that does not settle, undo the whole step: the mesh before it passed all four.
            let mut settled = false;
            for _ in 0..UNDO_ROUNDS {
                let mut undone = false;
                let mut bad = vec![None; mesh.triangles.len()];
                for v in 0..n {
                    if fixed[v] || mesh.positions[v] == before[v] {
                        continue;
                    }
                    let mut is_bad = |f: usize| {
                        *bad[f].get_or_insert_with(|| turned(mesh, &before, f) || too_far(mesh, f))
                    };
                    if faces_of[v].iter().any(|&f| is_bad(f)) {
                        mesh.positions[v] = before[v];
                        undone = true;
                    }
                }
                if undone {
                    continue;
                }
                let crossing = new_crossings(mesh, &crossing_before, pass as f32 / passes as f32)?;
                if crossing.is_empty() {
                    settled = true;
                    break;
                }
                for f in crossing.into_iter().flatten() {
                    for v in mesh.triangles[f as usize] {
                        mesh.positions[v as usize] = before[v as usize];
                    }
                }
            }
            if !settled {
                mesh.positions.copy_from_slice(&before);
            }
            for v in 0..n {
                moved[v] |= mesh.positions[v] != before[v];
            }
        }
    }
    if mesh.normals.len() == n {
        let mut faces = mesh.clone();
        faces.compute_normals_from_faces();
        for v in (0..n).filter(|&v| moved[v]) {
            let from_field =
                field.and_then(|f| f.gradient(mesh.positions[v])).and_then(|g| g.try_normalize());
            mesh.normals[v] = from_field.unwrap_or(faces.normals[v]);
        }
    }
    Ok(())
}

/// Rounds of undoing moves before a step is undone whole.
const UNDO_ROUNDS: usize = 6;

/// The pairs of faces that cross now and not in `crossing_before` (the input's own).
fn new_crossings(
    mesh: &Mesh,
    crossing_before: &HashSet<[u32; 2]>,
    done: f32,
) -> Result<Vec<[u32; 2]>, Error> {
    Ok(self_intersecting_pairs_within(mesh, "smooth", done)?
        .into_iter()
        .filter(|pair| !crossing_before.contains(pair))
        .collect())
}

/// Whether face `f` now points more than 60° away from where it pointed at `before`, lost its
/// area, or became a sliver: a corner under [`SLIVER_DEG`] and under its smallest before. Moving
/// vertices among fixed feature vertices can squeeze a face that decimation had kept wide.
fn turned(mesh: &Mesh, before: &[Vec3], f: usize) -> bool {
    let [a, b, c] = mesh.triangles[f].map(|v| v as usize);
    let old = (before[b] - before[a]).cross(before[c] - before[a]);
    let new = mesh.face_normal(f);
    let squeezed = || {
        let angle = min_angle(&mesh.corners(f));
        angle < SLIVER_DEG.to_radians() && angle < min_angle(&[before[a], before[b], before[c]])
    };
    match (old.try_normalize(), new.try_normalize()) {
        (Some(o), Some(n)) => o.dot(n) < 0.5 || squeezed(),
        (Some(_), None) => true,
        _ => false,
    }
}

/// A face may not get a corner under this unless it had a smaller one already.
const SLIVER_DEG: f32 = 10.0;

/// Smallest interior angle, in radians.
fn min_angle(c: &[Vec3; 3]) -> f32 {
    (0..3).map(|i| (c[(i + 1) % 3] - c[i]).angle_between(c[(i + 2) % 3] - c[i])).fold(f32::INFINITY, f32::min)
}

/// The largest one-step distance estimate `|f| / |∇f|` over face `f`'s centroid and the points
/// halfway from it to each corner (the interior samples of the surface-error analysis).
fn face_distance(field: &dyn Field, mesh: &Mesh, f: usize, step: f32) -> f32 {
    let c = mesh.corners(f);
    let centre = (c[0] + c[1] + c[2]) / 3.0;
    let samples = [centre, 0.5 * (centre + c[0]), 0.5 * (centre + c[1]), 0.5 * (centre + c[2])];
    samples
        .iter()
        .map(|&p| {
            let g = field.gradient(p).unwrap_or_else(|| finite_difference_gradient(field, p, step));
            let g = g.length();
            if g > 1e-12 {
                (field.value(p) / g).abs()
            } else {
                f32::INFINITY
            }
        })
        .fold(0.0, f32::max)
}

/// Two Newton steps towards the zero set along the gradient; a point where the gradient vanishes
/// stays.
fn project(field: &dyn Field, mut p: Vec3, step: f32) -> Vec3 {
    for _ in 0..2 {
        let g = field.gradient(p).unwrap_or_else(|| finite_difference_gradient(field, p, step));
        let g2 = g.length_squared();
        if g2.is_nan() || g2 <= 1e-12 {
            break;
        }
        let q = p - field.value(p) * g / g2;
        if !q.is_finite() {
            break;
        }
        p = q;
    }
    p
}

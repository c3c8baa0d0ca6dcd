//! Pleats: a triangle turned over inside a flat part of the surface, lying on the neighbours it
//! shares its edges with. Where DMC's dual vertices lie on one plane of a primitive (a box's face),
//! Marching Cubes on a flat dual cell can fold a triangle back over its neighbours. The mesh stays
//! closed and consistently oriented and crosses nothing, but a face points into the solid: a dark
//! triangle on the rotated box's face at depth 6, 0.08 long (found by
//! [`crate::mesh::analysis::folded_pairs`]).
//!
//! The turned-over triangle and the neighbours folded onto it make one flat disc whose boundary,
//! walked along the neighbours' orientation, is a simple polygon; triangulating that polygon again
//! removes the fold without moving the surface or changing its topology. Where the boundary is not
//! simple (a lone folded pair is a bow tie) the pleat is left alone, to be counted (DMC's
//! refinement then treats it as an intersection).

use crate::mesh::analysis::tri_tri::folded_across_edge;
use crate::mesh::Mesh;
use glam::{DVec2, DVec3};
use std::collections::{HashMap, HashSet};

/// Re-triangulates every pleat it can; returns how many. `per_triangle` (one entry per triangle,
/// such as the dual cell each came from) is kept in step: a new triangle takes the entry of the
/// slot it fills.
pub fn unpleat(mesh: &mut Mesh, mut per_triangle: Option<&mut Vec<u32>>) -> usize {
    let mut fixed = 0;
    // A fix can expose the next pleat of a row; a few rounds are plenty.
    for _ in 0..4 {
        let found = unpleat_once(mesh, per_triangle.as_deref_mut());
        fixed += found;
        if found == 0 {
            break;
        }
    }
    fixed
}

/// Triangles a pleat's disc may grow to while looking for a simple boundary.
const MAX_REGION: usize = 24;
/// Triangles taken into the disc must lie this close to its plane (degrees), so that dropping
/// the vertices inside it does not move the surface.
const FLAT_DEG: f64 = 0.1;

fn unpleat_once(mesh_mut: &mut Mesh, per_triangle: Option<&mut Vec<u32>>) -> usize {
    let mesh = &*mesh_mut;
    let position = |v: u32| mesh.positions[v as usize].as_dvec3();
    let mut by_edge: HashMap<(u32, u32), usize> = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for i in 0..3 {
            by_edge.insert((tri[i], tri[(i + 1) % 3]), t);
        }
    }
    let by_edge = &by_edge;
    let neighbours = |t: usize| {
        let tri = mesh.triangles[t];
        (0..3).filter_map(move |i| by_edge.get(&(tri[(i + 1) % 3], tri[i])).copied())
    };
    let mut touched = vec![false; mesh.triangles.len()];
    let mut replacements: Vec<(Vec<usize>, Vec<[u32; 3]>)> = Vec::new();
    for (t, &tri) in mesh.triangles.iter().enumerate() {
        if touched[t] {
            continue;
        }
        let folded: Vec<usize> = (0..3)
            .filter_map(|i| {
                let (u, v, w) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
                let &n = by_edge.get(&(v, u))?;
                let across = mesh.triangles[n].into_iter().find(|&x| x != u && x != v)?;
                let (pu, e) = (position(u), position(v) - position(u));
                folded_across_edge(e, position(w) - pu, position(across) - pu).then_some(n)
            })
            .collect();
        if folded.len() < 2 || folded.iter().any(|&n| touched[n] || n == t) {
            continue;
        }
        let up =
            folded.iter().map(|&n| normal(mesh.triangles[n], &position)).sum::<DVec3>().normalize_or_zero();
        let flat = |n: usize| {
            let normal = normal(mesh.triangles[n], &position);
            normal.dot(up).abs() >= FLAT_DEG.to_radians().cos() * normal.length()
        };
        let mut region = vec![t];
        region.extend(&folded);
        region.sort_unstable();
        region.dedup();
        // The pleat and its folded neighbours first; where their boundary is not simple, the
        // flat triangles around them too, ring by ring.
        while region.len() <= MAX_REGION {
            let triangles: Vec<[u32; 3]> = region.iter().map(|&r| mesh.triangles[r]).collect();
            if let Some(new) = retriangulate(&triangles, up, &position, by_edge, &region) {
                // Every triangle at one of the disc's corners waits for the next pass, so that no
                // other disc of this pass can add a diagonal between the same two corners.
                let corners: HashSet<u32> = triangles.iter().flatten().copied().collect();
                for (other, tri) in mesh.triangles.iter().enumerate() {
                    if tri.iter().any(|v| corners.contains(v)) {
                        touched[other] = true;
                    }
                }
                replacements.push((region, new));
                break;
            }
            let mut grown: Vec<usize> = region
                .iter()
                .flat_map(|&r| neighbours(r))
                .filter(|&n| region.binary_search(&n).is_err() && !touched[n] && flat(n))
                .collect();
            if grown.is_empty() {
                break;
            }
            region.append(&mut grown);
            region.sort_unstable();
            region.dedup();
        }
    }
    let fixed = replacements.len();
    let mesh = mesh_mut;
    let mut removed = vec![false; mesh.triangles.len()];
    for (region, new) in replacements {
        for (k, slot) in region.into_iter().enumerate() {
            match new.get(k) {
                Some(&tri) => mesh.triangles[slot] = tri,
                None => removed[slot] = true,
            }
        }
    }
    if removed.contains(&true) {
        // Vertices inside a disc are left unreferenced, as sliver collapse leaves its merged ones.
        let mut t = 0;
        mesh.triangles.retain(|_| (!removed[t], t += 1).0);
        if let Some(entries) = per_triangle {
            let mut t = 0;
            entries.retain(|_| (!removed[t], t += 1).0);
        }
    }
    fixed
}

fn normal(tri: [u32; 3], position: &impl Fn(u32) -> DVec3) -> DVec3 {
    let [a, b, c] = tri.map(position);
    (b - a).cross(c - a)
}

/// The triangles of the polygon bounding `triangles` (one loop, walked with them), all facing
/// `up`, with no vertex inside; `None` if the boundary is not one simple loop around a disc, or
/// a new edge already exists outside the region.
fn retriangulate(
    triangles: &[[u32; 3]],
    up: DVec3,
    position: &impl Fn(u32) -> DVec3,
    by_edge: &HashMap<(u32, u32), usize>,
    region: &[usize],
) -> Option<Vec<[u32; 3]>> {
    let directed: HashSet<(u32, u32)> =
        triangles.iter().flat_map(|t| (0..3).map(move |i| (t[i], t[(i + 1) % 3]))).collect();
    if directed.len() != 3 * triangles.len() {
        return None; // two triangles run along an edge the same way: not one oriented disc
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(u, v) in &directed {
        if !directed.contains(&(v, u)) && next.insert(u, v).is_some() {
            return None;
        }
    }
    let start = *next.keys().min()?;
    let mut boundary = vec![start];
    while let Some(&v) = next.get(boundary.last()?) {
        if v == start {
            break;
        }
        if boundary.len() > next.len() {
            return None;
        }
        boundary.push(v);
    }
    let corners: HashSet<u32> = triangles.iter().flatten().copied().collect();
    let inner = corners.len() - boundary.len();
    if boundary.len() != next.len() || triangles.len() + 2 != boundary.len() + 2 * inner {
        return None; // not one loop around a disc
    }
    let up = up.normalize_or_zero();
    let e1 = up.any_orthonormal_vector();
    let e2 = up.cross(e1);
    let flat = |v: u32| {
        let p = position(v);
        DVec2::new(p.dot(e1), p.dot(e2))
    };
    let mut polygon: Vec<(u32, DVec2)> = boundary.iter().map(|&v| (v, flat(v))).collect();
    if !is_simple(&polygon) {
        return None;
    }
    let exists_outside =
        |u: u32, v: u32| [(u, v), (v, u)].iter().any(|e| by_edge.get(e).is_some_and(|t| !region.contains(t)));
    let mut result = Vec::new();
    while polygon.len() > 3 {
        let n = polygon.len();
        let corners = |i: usize| (polygon[(i + n - 1) % n], polygon[i], polygon[(i + 1) % n]);
        // Of the ears, the one whose smallest angle is largest: the first one found can be a
        // sliver (the pleat's corners are close to its neighbours' edges).
        let ear = (0..n)
            .filter(|&i| {
                let (a, b, c) = corners(i);
                cross(a.1, b.1, c.1) > 0.0
                    && !exists_outside(a.0, c.0)
                    && polygon
                        .iter()
                        .all(|p| [a.0, b.0, c.0].contains(&p.0) || !in_closed_triangle(p.1, a.1, b.1, c.1))
            })
            .max_by(|&i, &j| {
                let smallest = |k: usize| {
                    let (a, b, c) = corners(k);
                    smallest_angle(a.1, b.1, c.1)
                };
                smallest(i).total_cmp(&smallest(j))
            });
        let ear = ear?;
        let (a, b, c) = (polygon[(ear + n - 1) % n], polygon[ear], polygon[(ear + 1) % n]);
        result.push([a.0, b.0, c.0]);
        polygon.remove(ear);
    }
    let (a, b, c) = (polygon[0], polygon[1], polygon[2]);
    if cross(a.1, b.1, c.1) <= 0.0 {
        return None;
    }
    result.push([a.0, b.0, c.0]);
    Some(result)
}

fn smallest_angle(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let angle = |p: DVec2, q: DVec2, r: DVec2| (q - p).angle_to(r - p).abs();
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

fn cross(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

fn in_closed_triangle(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0
}

/// Distinct corners, counter-clockwise, and no two edges meeting except neighbours at their
/// shared corner.
fn is_simple(polygon: &[(u32, DVec2)]) -> bool {
    let n = polygon.len();
    let area: f64 = (0..n).map(|i| polygon[i].1.perp_dot(polygon[(i + 1) % n].1)).sum();
    if area <= 0.0 {
        return false;
    }
    let segment = |i: usize| (polygon[i].1, polygon[(i + 1) % n].1);
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            let (p, q) = (segment(i), segment(j));
            if adjacent {
                // Neighbours may only meet at their shared corner: not fold back along each other.
                let (shared, a, b) = if j == i + 1 { (p.1, p.0, q.1) } else { (p.0, p.1, q.0) };
                if cross(shared, a, b) == 0.0 && (a - shared).dot(b - shared) > 0.0 {
                    return false;
                }
            } else if segments_meet(p, q) {
                return false;
            }
        }
    }
    true
}

fn segments_meet((a, b): (DVec2, DVec2), (c, d): (DVec2, DVec2)) -> bool {
    let (d1, d2) = (cross(a, b, c), cross(a, b, d));
    let (d3, d4) = (cross(c, d, a), cross(c, d, b));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    let on = |p: DVec2, q: DVec2, x: DVec2| {
        cross(p, q, x) == 0.0
            && x.x >= p.x.min(q.x)
            && x.x <= p.x.max(q.x)
            && x.y >= p.y.min(q.y)
            && x.y <= p.y.max(q.y)
    };
    on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::{self_intersections, topology};
    use glam::Vec3;

    /// The pleat on the rotated box's face at depth 6, flattened (coordinates in hundredths of
    /// the face's plane): triangle (0, 1, 2) faces down, its three neighbours up, each folded
    /// across a shared edge onto it.
    fn pleated() -> Mesh {
        let positions =
            [(7.287, -4.324), (2.135, -2.729), (0.0, 0.0), (3.623, 2.425), (2.996, 2.383), (1.548, -5.837)]
                .map(|(x, y)| Vec3::new(x, y, 0.0))
                .to_vec();
        let triangles = vec![[0, 1, 2], [1, 0, 3], [2, 1, 4], [0, 2, 5]];
        Mesh { positions, triangles, normals: Vec::new() }
    }

    #[test]
    fn a_turned_over_triangle_among_its_neighbours_is_triangulated_again() {
        let mut mesh = pleated();
        assert!(self_intersections(&mesh) > 0, "the fixture folds");
        let before = topology(&mesh);
        let mut cells = vec![0, 1, 2, 3];
        assert_eq!(unpleat(&mut mesh, Some(&mut cells)), 1);
        assert_eq!(self_intersections(&mesh), 0);
        assert_eq!((mesh.triangles.len(), cells.len()), (4, 4));
        let after = topology(&mesh);
        assert_eq!((after.euler, after.boundary_edges), (before.euler, before.boundary_edges));
        for &tri in &mesh.triangles {
            let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "{tri:?} faces up");
        }
    }

    #[test]
    fn a_lone_folded_pair_is_left_alone() {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.3, 1.0, 0.0),
            Vec3::new(0.6, 0.8, 0.0),
        ];
        let mut mesh = Mesh { positions, triangles: vec![[0, 1, 2], [1, 0, 3]], normals: Vec::new() };
        let before = mesh.triangles.clone();
        assert_eq!(unpleat(&mut mesh, None), 0);
        assert_eq!(mesh.triangles, before);
    }
}

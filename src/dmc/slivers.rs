//! The second half of sliver elimination (§4). A dual vertex on (or very near) the surface makes
//! every crossing on its dual edges land next to it, and Marching Cubes then fans tiny, thin
//! triangles around it. The paper lets them collapse onto the vertex; here the crossings within the
//! tolerance of a dual vertex (and within a quarter of the edge) are merged into one mesh vertex
//! there, and the triangles that collapse are removed.
//!
//! A merge is an identification of several mesh vertices, which can pinch the surface (two sheets
//! meeting at the dual vertex). It is applied only when the merged vertex's link — the edges
//! opposite it in its remaining triangles — is one simple cycle of at least three vertices, which is
//! exactly the condition for the result to stay a manifold around it (and every other vertex's link
//! stays a cycle too: a vertex seeing the group twice would appear twice in that link). It is also
//! refused when a remaining triangle would turn over or lose its area.

use super::contour::Contour;
use super::features::DualVertices;
use crate::field::Field;
use glam::{DVec3, Vec3};
use std::collections::{BTreeMap, BTreeSet};

/// Merges crossings clustered around dual vertices, except around those in `skip`. Returns the
/// number of triangles removed and, per vertex of the result, the dual vertex it was merged into
/// (`u32::MAX` for vertices left alone).
pub fn collapse(
    contour: &mut Contour,
    vertices: &DualVertices,
    field: &dyn Field,
    iso: f32,
    tolerance: f32,
    skip: &BTreeSet<u32>,
) -> (usize, Vec<u32>) {
    let mesh = &mut contour.mesh;
    let mut groups: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for (v, c) in contour.crossings.iter().enumerate() {
        let length = vertices.positions[c.inside as usize].distance(vertices.positions[c.outside as usize]);
        if c.t <= 0.25 && c.t * length <= tolerance {
            groups.entry(c.inside).or_default().push(v as u32);
        } else if c.t >= 0.75 && (1.0 - c.t) * length <= tolerance {
            groups.entry(c.outside).or_default().push(v as u32);
        }
    }
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            incident[v as usize].push(t as u32);
        }
    }
    let mut alive = vec![true; mesh.triangles.len()];
    let mut removed = 0;
    let mut merged_into = vec![u32::MAX; mesh.positions.len()];
    for (dual, members) in groups {
        if members.len() < 2 || skip.contains(&dual) {
            continue;
        }
        let target = project(field, iso, vertices.positions[dual as usize], tolerance);
        let merged = members[0];
        let is_member = |v: u32| members.contains(&v);
        let mut touched: Vec<u32> =
            members.iter().flat_map(|&m| incident[m as usize].iter().copied()).collect();
        touched.sort_unstable();
        touched.dedup();
        touched.retain(|&t| alive[t as usize]);
        let mut kept = Vec::new();
        let mut dropped = Vec::new();
        let mut ok = true;
        for &t in &touched {
            let old = mesh.triangles[t as usize];
            let new = old.map(|v| if is_member(v) { merged } else { v });
            if new[0] == new[1] || new[1] == new[2] || new[0] == new[2] {
                dropped.push(t);
                continue;
            }
            let at = |tri: [u32; 3], moved: bool| -> [DVec3; 3] {
                tri.map(|v| {
                    if moved && v == merged {
                        target.as_dvec3()
                    } else {
                        mesh.positions[v as usize].as_dvec3()
                    }
                })
            };
            let normal = |p: [DVec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
            let (before, after) = (normal(at(old, false)), normal(at(new, true)));
            if after == DVec3::ZERO || before.dot(after) <= 0.0 {
                ok = false;
                break;
            }
            kept.push((t, new));
        }
        if !ok || !link_is_a_cycle(merged, &kept) {
            continue;
        }
        for &t in &dropped {
            alive[t as usize] = false;
        }
        removed += dropped.len();
        for &(t, new) in &kept {
            mesh.triangles[t as usize] = new;
        }
        mesh.positions[merged as usize] = target;
        merged_into[merged as usize] = dual;
        let all: Vec<u32> = kept.iter().map(|&(t, _)| t).collect();
        for &m in &members {
            incident[m as usize].clear();
        }
        incident[merged as usize] = all;
    }
    // Compact: live triangles, referenced vertices.
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangles.len() - removed);
    let mut cells = Vec::with_capacity(triangles.capacity());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if alive[t] {
            triangles.push(*tri);
            cells.push(contour.cell_of_triangle[t]);
        }
    }
    let mut new_id = vec![u32::MAX; mesh.positions.len()];
    let (mut positions, mut crossings, mut merged) = (Vec::new(), Vec::new(), Vec::new());
    for tri in &mut triangles {
        for v in tri.iter_mut() {
            if new_id[*v as usize] == u32::MAX {
                new_id[*v as usize] = positions.len() as u32;
                positions.push(mesh.positions[*v as usize]);
                crossings.push(contour.crossings[*v as usize]);
                merged.push(merged_into[*v as usize]);
            }
            *v = new_id[*v as usize];
        }
    }
    mesh.triangles = triangles;
    mesh.positions = positions;
    contour.crossings = crossings;
    contour.cell_of_triangle = cells;
    (removed, merged)
}

/// Whether the triangles around `center` (each containing it once) form one closed fan: their
/// opposite edges chain into a single cycle of at least three vertices.
fn link_is_a_cycle(center: u32, triangles: &[(u32, [u32; 3])]) -> bool {
    if triangles.len() < 3 {
        return false;
    }
    let mut next: BTreeMap<u32, u32> = BTreeMap::new();
    let mut targets = std::collections::BTreeSet::new();
    for &(_, tri) in triangles {
        let k = tri.iter().position(|&v| v == center).expect("triangle around the centre");
        let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
        if next.insert(a, b).is_some() || !targets.insert(b) {
            return false;
        }
    }
    let start = *next.keys().next().expect("non-empty");
    let (mut v, mut steps) = (start, 0);
    loop {
        let Some(&w) = next.get(&v) else { return false };
        steps += 1;
        v = w;
        if v == start {
            break;
        }
        if steps > triangles.len() {
            return false;
        }
    }
    steps == triangles.len()
}

/// A few Newton steps from `p` toward the zero set, each at most `limit` long.
fn project(field: &dyn Field, iso: f32, mut p: Vec3, limit: f32) -> Vec3 {
    for _ in 0..3 {
        let Some(g) = field.gradient(p) else { return p };
        let d = field.value(p) - iso;
        let g2 = g.length_squared();
        if d == 0.0 || g2 < 1e-20 {
            break;
        }
        let step = g * (d / g2);
        p -= step.clamp_length_max(limit);
    }
    p
}

/// Removes *caps*: triangles whose three corners are collinear, the middle one strictly between
/// the other two (on the planar room many crossings land exactly on a concave edge of the wall,
/// and Marching Cubes joins three of them). A cap's long edge is flipped with the neighbour across
/// it: `(a, b, c)` with `b` on `a..c` and the neighbour `(c, a, d)` become `(a, b, d)` and
/// `(b, c, d)`, which cover the neighbour exactly, so neither the surface nor its topology
/// changes, but the zero-area triangle (which overlaps its neighbours along the line, counted as
/// a self-intersection) is gone. A flip that would create an edge the mesh already has is skipped.
/// Returns the number of flips.
pub fn flip_caps(contour: &mut Contour) -> usize {
    use std::collections::{HashMap, HashSet};
    let mut flips = 0;
    for _ in 0..16 {
        let mesh = &contour.mesh;
        // Caps are rare: the edge maps below are built only when there is one.
        if !mesh.triangles.iter().any(|&tri| cap(mesh, tri).is_some()) {
            break;
        }
        let mut by_edge: HashMap<(u32, u32), usize> = HashMap::new();
        let mut edges: HashSet<(u32, u32)> = HashSet::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for i in 0..3 {
                let (u, v) = (tri[i], tri[(i + 1) % 3]);
                by_edge.insert((u, v), t);
                edges.insert((u.min(v), u.max(v)));
            }
        }
        let mut touched = vec![false; mesh.triangles.len()];
        let mut todo: Vec<(usize, usize, [u32; 4])> = Vec::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let Some((a, b, c)) = cap(mesh, *tri) else { continue };
            let Some(&n) = by_edge.get(&(a, c)) else { continue };
            let d = mesh.triangles[n].into_iter().find(|&v| v != a && v != c).unwrap_or(a);
            if n == t || touched[t] || touched[n] || d == a || d == b || edges.contains(&(b.min(d), b.max(d)))
            {
                continue;
            }
            touched[t] = true;
            touched[n] = true;
            edges.insert((b.min(d), b.max(d)));
            todo.push((t, n, [a, b, c, d]));
        }
        if todo.is_empty() {
            break;
        }
        for (t, n, [a, b, c, d]) in todo {
            contour.mesh.triangles[t] = [a, b, d];
            contour.mesh.triangles[n] = [b, c, d];
            flips += 1;
        }
    }
    flips
}

/// The corners of a cap triangle as `(a, b, c)` in the triangle's winding order with `b` the
/// middle one (strictly between `a` and `c`, within 1e-5 of `|c - a|` of the line), or `None`.
fn cap(mesh: &crate::mesh::Mesh, tri: [u32; 3]) -> Option<(u32, u32, u32)> {
    for i in 0..3 {
        let (a, b, c) = (tri[(i + 2) % 3], tri[i], tri[(i + 1) % 3]);
        let (pa, pb, pc) =
            (mesh.positions[a as usize], mesh.positions[b as usize], mesh.positions[c as usize]);
        let ac = pc - pa;
        let len2 = ac.length_squared();
        if len2 == 0.0 {
            return None;
        }
        let s = (pb - pa).dot(ac) / len2;
        let off = (pb - pa - ac * s).length();
        if s > 1e-3 && s < 1.0 - 1e-3 && off <= 1e-5 * len2.sqrt() {
            return Some((a, b, c));
        }
    }
    None
}

/// Collapses edges of zero length (both ends at the same position: several crossings landing
/// exactly on a corner of the surface) where the link condition allows it (the ends share exactly
/// the two neighbours opposite the edge), dropping the two zero-area triangles beside the edge.
/// Two triangles touching at such a point through different vertices counted as a
/// self-intersection. Neither the surface nor its topology changes. Returns the number collapsed.
pub fn collapse_zero_edges(contour: &mut Contour) -> usize {
    use std::collections::HashSet;
    let mut collapsed = 0;
    loop {
        let mesh = &contour.mesh;
        let is_zero = |u: u32, v: u32| u != v && mesh.positions[u as usize] == mesh.positions[v as usize];
        let zero_edges: Vec<(u32, u32)> = mesh
            .triangles
            .iter()
            .flat_map(|tri| (0..3).map(move |i| (tri[i], tri[(i + 1) % 3])))
            .filter(|&(u, v)| is_zero(u, v))
            .collect();
        // Zero-length edges are rare: the neighbour sets below are built only when there is one.
        if zero_edges.is_empty() {
            break;
        }
        let mut neighbours: Vec<HashSet<u32>> = vec![HashSet::new(); mesh.positions.len()];
        for tri in &mesh.triangles {
            for i in 0..3 {
                let (u, v) = (tri[i], tri[(i + 1) % 3]);
                neighbours[u as usize].insert(v);
                neighbours[v as usize].insert(u);
            }
        }
        let found = zero_edges.into_iter().find(|&(u, v)| {
            let beside: Vec<u32> = mesh
                .triangles
                .iter()
                .filter(|t| t.contains(&u) && t.contains(&v))
                .map(|t| t.iter().copied().find(|&w| w != u && w != v).unwrap_or(u))
                .collect();
            let common = neighbours[u as usize].intersection(&neighbours[v as usize]).count();
            beside.len() == 2 && beside[0] != beside[1] && common == 2
        });
        let Some((u, v)) = found else { break };
        let mut t = 0;
        while t < contour.mesh.triangles.len() {
            let tri = &mut contour.mesh.triangles[t];
            if tri.contains(&u) && tri.contains(&v) {
                contour.mesh.triangles.swap_remove(t);
                contour.cell_of_triangle.swap_remove(t);
                continue;
            }
            for w in tri.iter_mut() {
                if *w == v {
                    *w = u;
                }
            }
            t += 1;
        }
        collapsed += 1;
    }
    collapsed
}

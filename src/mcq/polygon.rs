//! The paper's per-cell triangulation of one polygon border (Sections 3.2–3.4): cut off vertices
//! with a bad angle as their own triangle, insert one vertex in long or uneven polygons with the
//! attraction factor √(1 + SLME/LSE), otherwise split the largest angle.
//!
//! A diagonal is only drawn between two vertices that lie on no common cube face and that no other
//! triangle or polygon already joins: the first keeps it off the face the neighbour's triangles lie
//! in (as [`crate::tables::triangulate_polygon`] does), the second keeps every mesh edge on exactly
//! two triangles once snapping has merged vertices. When no allowed diagonal is left, the polygon
//! gets an inner vertex, which needs none.

use crate::tables::edge_faces;
use glam::Vec3;
use std::collections::HashSet;

/// One corner of a polygon border: its vertex id, position and the cell faces it lies on (bit `f`
/// for face `f` of [`crate::tables::FACES`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Corner {
    pub id: u32,
    pub pos: Vec3,
    pub faces: u8,
}

impl Corner {
    /// A corner on cell edge `e` (it lies on that edge's two cell faces).
    pub(crate) fn on_edge(id: u32, pos: Vec3, e: usize) -> Corner {
        Corner { id, pos, faces: edge_faces(e).iter().fold(0, |m, &f| m | 1 << f) }
    }
}

/// The thresholds of the paper's three decisions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolygonRules {
    /// A polygon vertex whose angle is below this (degrees) is cut off as its own triangle.
    pub cut_angle_deg: f32,
    /// A four-sided polygon gets an inner vertex when its longest edge over its shortest exceeds this.
    pub quad_ratio: f32,
}

impl Default for PolygonRules {
    fn default() -> Self {
        PolygonRules { cut_angle_deg: 30.0, quad_ratio: 2.0 }
    }
}

/// An undirected edge key.
pub(crate) fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Triangles of one polygon (outward orientation kept: every triangle follows the border's order).
/// `inner` is the id an inserted vertex gets; the inserted vertex's position comes back with them.
pub(crate) fn triangulate(
    border: &[Corner],
    rules: &PolygonRules,
    edges: &mut HashSet<(u32, u32)>,
    inner: u32,
    out: &mut Vec<[u32; 3]>,
) -> Option<Vec3> {
    let mut poly: Vec<Corner> = border.to_vec();
    if poly.len() == 3 {
        out.push([poly[0].id, poly[1].id, poly[2].id]);
        return None;
    }
    let cut = rules.cut_angle_deg.to_radians();
    // 3.2: cut off the worst bad-angled vertex while one is left, so no triangle splits it.
    while poly.len() > 3 {
        let n = poly.len();
        let angles = corner_angles(&poly);
        let worst = (0..n)
            .filter(|&i| angles[i] < cut && allowed(&poly[(i + n - 1) % n], &poly[(i + 1) % n], edges))
            .min_by(|&a, &b| angles[a].total_cmp(&angles[b]));
        let Some(i) = worst else { break };
        let (p, q) = (poly[(i + n - 1) % n], poly[(i + 1) % n]);
        out.push([p.id, poly[i].id, q.id]);
        edges.insert(key(p.id, q.id));
        poly.remove(i);
    }
    let n = poly.len();
    if n == 3 {
        out.push([poly[0].id, poly[1].id, poly[2].id]);
        return None;
    }
    // 3.3: five or more sides, or four uneven ones, get an inner vertex.
    let lengths: Vec<f32> = (0..n).map(|i| poly[i].pos.distance(poly[(i + 1) % n].pos)).collect();
    let (shortest, longest) = lengths.iter().fold((f32::MAX, 0f32), |(s, l), &x| (s.min(x), l.max(x)));
    if n == 4 && longest <= rules.quad_ratio * shortest {
        // 3.4: from the largest angle to the vertex two steps away.
        let angles = corner_angles(&poly);
        let mut order = [0, 1, 2, 3];
        order.sort_by(|&a, &b| angles[b].total_cmp(&angles[a]));
        for &i in &order {
            let j = (i + 2) % 4;
            if allowed(&poly[i], &poly[j], edges) {
                let [a, b, c, d] = [i, i + 1, i + 2, i + 3].map(|k| poly[k % 4].id);
                out.push([a, b, c]);
                out.push([c, d, a]);
                edges.insert(key(a, c));
                return None;
            }
        }
    }
    for i in 0..n {
        out.push([inner, poly[i].id, poly[(i + 1) % n].id]);
    }
    Some(attracted_center(&poly))
}

/// One cell polygon of plain (unsnapped) Marching Cubes vertices, triangulated by the rules on its
/// own: `ids`, `pts` and the cell edges `cell_edges` they sit on, in border order. Returns the
/// triangles (`inner` standing for the inserted vertex) and the inserted vertex's position.
///
/// No edge set shared across polygons is needed here: a diagonal only joins two vertices on no
/// common face of the cell, that is on two opposite edges of it, and no other cell holds both, so
/// only the polygon's own border and diagonals can be in the way. (With snapping, merged vertices
/// break this, which is why [`super::extract`] shares one set over all polygons.)
pub(crate) fn triangulate_cell_polygon(
    ids: &[u32],
    pts: &[Vec3],
    cell_edges: &[u8],
    rules: &PolygonRules,
    inner: u32,
) -> (Vec<[u32; 3]>, Option<Vec3>) {
    let border: Vec<Corner> =
        (0..ids.len()).map(|k| Corner::on_edge(ids[k], pts[k], cell_edges[k] as usize)).collect();
    let mut edges: HashSet<(u32, u32)> =
        (0..ids.len()).map(|k| key(ids[k], ids[(k + 1) % ids.len()])).collect();
    let mut out = Vec::with_capacity(ids.len());
    let inserted = triangulate(&border, rules, &mut edges, inner, &mut out);
    (out, inserted)
}

/// The inner vertex: every border vertex weighted by √(1 + SLME/LSE), where LSE is the shorter of
/// its two edges and SLME the sum of all LSEs, so the vertex is drawn towards short edges.
fn attracted_center(poly: &[Corner]) -> Vec3 {
    let n = poly.len();
    let lse: Vec<f32> = (0..n)
        .map(|i| {
            let p = poly[i].pos;
            p.distance(poly[(i + n - 1) % n].pos).min(p.distance(poly[(i + 1) % n].pos)).max(1e-12)
        })
        .collect();
    let slme: f32 = lse.iter().sum();
    let (mut sum, mut total) = (Vec3::ZERO, 0.0);
    for (c, l) in poly.iter().zip(&lse) {
        let w = (1.0 + slme / l).sqrt();
        sum += c.pos * w;
        total += w;
    }
    sum / total
}

/// The angle (radians) of the border at each vertex, between its two border edges.
fn corner_angles(poly: &[Corner]) -> Vec<f32> {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let p = poly[i].pos;
            let a = poly[(i + n - 1) % n].pos - p;
            let b = poly[(i + 1) % n].pos - p;
            a.angle_between(b)
        })
        .collect()
}

fn allowed(a: &Corner, b: &Corner, edges: &HashSet<(u32, u32)>) -> bool {
    a.faces & b.faces == 0 && a.id != b.id && !edges.contains(&key(a.id, b.id))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corners(points: &[[f32; 3]]) -> Vec<Corner> {
        // Distinct single faces per vertex, so every diagonal is allowed.
        let faces = [1u8, 2, 4, 8, 16, 32];
        points
            .iter()
            .enumerate()
            .map(|(i, p)| Corner { id: i as u32, pos: Vec3::from(*p), faces: faces[i % 6] })
            .collect()
    }

    #[test]
    fn a_square_is_split_along_a_diagonal_and_a_pentagon_gets_an_inner_vertex() {
        let square = corners(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        let mut out = vec![];
        let mut edges = HashSet::new();
        assert!(triangulate(&square, &PolygonRules::default(), &mut edges, 9, &mut out).is_none());
        assert_eq!(out.len(), 2);
        assert_eq!(edges.len(), 1);
        let pentagon: Vec<[f32; 3]> = (0..5)
            .map(|k| {
                let t = k as f32 * std::f32::consts::TAU / 5.0;
                [t.cos(), t.sin(), 0.0]
            })
            .collect();
        out.clear();
        let c = triangulate(&corners(&pentagon), &PolygonRules::default(), &mut edges, 9, &mut out).unwrap();
        assert_eq!(out.len(), 5);
        assert!(c.length() < 1e-5, "a regular polygon's attracted centre is its centre");
    }

    #[test]
    fn the_inner_vertex_moves_towards_the_short_edge() {
        // A long rectangle: the short edges pull the centre towards them equally.
        let uneven =
            corners(&[[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 1.0, 0.0], [0.2, 1.0, 0.0], [0.0, 0.8, 0.0]]);
        let plain: Vec3 = uneven.iter().map(|c| c.pos).sum::<Vec3>() / 5.0;
        let c = attracted_center(&uneven);
        assert!(c.x < plain.x, "pulled towards the short edge near x = 0: {c} vs {plain}");
    }

    #[test]
    fn a_sharp_vertex_is_cut_off_whole() {
        // A kite whose vertex 0 has a 10° angle (and vertex 2 one of 19°).
        let quad = corners(&[[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [6.0, 0.525, 0.0], [3.939, 0.695, 0.0]]);
        let mut out = vec![];
        let mut edges = HashSet::new();
        let rules = PolygonRules { cut_angle_deg: 20.0, quad_ratio: 100.0 };
        triangulate(&quad, &rules, &mut edges, 9, &mut out);
        let with_sharp: Vec<_> = out.iter().filter(|t| t.contains(&0)).collect();
        assert_eq!(with_sharp.len(), 1, "the sharp corner is in exactly one triangle: {out:?}");
    }
}

//! Semi-local Collapse (Fig. 5b): two (3, m, 3, n) quads joined by a straight line of valence-four
//! vertices from a valence-three corner of one to a valence-three corner of the other collapse
//! together along their valence-three diagonals. They are the two crossings of the same pair of
//! rings, so collapsing both "unwinds" those rings into two new ones and the mesh keeps the ring
//! condition, which a lone Local Collapse would break.

use super::collapse::{centroid, is_3m3n, mark_touched, merge, ordered_neighbours_from};
use super::mesh::QuadMesh;
use std::collections::HashMap;

/// Applies Semi-local Collapses in rounds until none is left; returns how many pairs collapsed.
pub fn semilocal_collapse(mesh: &mut QuadMesh) -> usize {
    let mut applied = 0;
    loop {
        let val = mesh.valences();
        let nb = mesh.neighbours();
        let edges = mesh.edge_map();
        let mut touched = vec![false; mesh.positions.len()];
        let mut round = 0;
        for pair in find_pairs(mesh, &val, &edges) {
            let [(q1, s1), (q2, s2)] = pair;
            if q1.iter().chain(&q2).any(|&v| touched[v as usize]) {
                continue;
            }
            let groups = [
                (vec![q1[s1], q1[s1 + 2]], centroid(mesh, &q1)),
                (vec![q2[s2], q2[s2 + 2]], centroid(mesh, &q2)),
            ];
            if let Some(next) = merge(mesh, &groups) {
                mark_touched(&mut touched, &nb, &q1);
                mark_touched(&mut touched, &nb, &q2);
                *mesh = next;
                round += 1;
            }
        }
        applied += round;
        if round == 0 {
            return applied;
        }
    }
}

type Candidate = ([u32; 4], usize);

/// Every pair of (3, m, 3, n) quads (each with the corner index of one valence-three vertex)
/// linked by a straight valence-four path, each pair once.
fn find_pairs(mesh: &QuadMesh, val: &[u32], edges: &HashMap<(u32, u32), (u32, u8)>) -> Vec<[Candidate; 2]> {
    let mut pairs = Vec::new();
    for (f1, q1) in mesh.quads.iter().enumerate() {
        for s in 0..2 {
            if !is_3m3n(q1, val, s) {
                continue;
            }
            for start in [s, s + 2] {
                let Some((f2, q2, s2)) = walk(mesh, val, edges, f1, start) else { continue };
                if f1 < f2 {
                    pairs.push([(*q1, s), (q2, s2)]);
                }
            }
        }
    }
    pairs
}

/// From the valence-three corner `c` of quad `f`, follows the corner's one edge outside the quad
/// straight through valence-four vertices. Succeeds when the line ends at a valence-three vertex
/// whose third quad (the one off the line) is another (3, m, 3, n) quad.
fn walk(
    mesh: &QuadMesh,
    val: &[u32],
    edges: &HashMap<(u32, u32), (u32, u8)>,
    f: usize,
    c: usize,
) -> Option<(usize, [u32; 4], usize)> {
    let q = mesh.quads[f];
    let s = q[c];
    let around = ordered_neighbours_from(mesh, edges, (f as u32, c as u8))?;
    // Around a valence-three vertex the fan from corner c lists q[c+1], the outside edge, q[c+3].
    let mut prev = s;
    let mut cur = *around.iter().find(|&&u| u != q[(c + 1) % 4] && u != q[(c + 3) % 4])?;
    for _ in 0..mesh.quads.len() {
        match val[cur as usize] {
            4 => {
                let &(g, j) = edges.get(&(cur, prev))?;
                let ring = ordered_neighbours_from(mesh, edges, (g, j))?;
                let next = *ring.get(2)?;
                prev = cur;
                cur = next;
                if cur == s {
                    return None;
                }
            }
            3 => {
                // The quad at `cur` containing neither edge of the line: the one not holding `prev`.
                let &(g, j) = edges.get(&(cur, prev))?;
                let ring = ordered_neighbours_from(mesh, edges, (g, j))?;
                // ring = [prev, a, b]: the quad between a and b is the third one.
                let &(f2, c2) = edges.get(&(cur, *ring.get(1)?))?;
                let q2 = mesh.quads[f2 as usize];
                let c2 = c2 as usize;
                if f2 as usize != f && is_3m3n(&q2, val, c2 % 2) {
                    return Some((f2 as usize, q2, c2 % 2));
                }
                return None;
            }
            _ => return None,
        }
    }
    None
}

//! Ring Collapse (Fig. 5a): a ring, a closed strip of quads joined through opposite edges, is
//! removed by collapsing every edge it crosses (its "rungs") to the rung's midpoint, so the two
//! sides of the strip become one line. The paper's order: smaller rings first, ties broken by more
//! irregular vertices removed; never a ring removing fewer than four irregular vertices, one that
//! touches itself (Fig. 6b) or one that would merge two valence-three vertices (Fig. 6a).

use super::collapse::{mark_touched, merge};
use super::mesh::QuadMesh;
use glam::Vec3;
use std::collections::{HashMap, HashSet};

/// A collapsible ring: its rungs as (side A vertex, side B vertex) and its quads.
#[derive(Debug, Clone)]
pub struct Ring {
    pub rungs: Vec<(u32, u32)>,
    pub quads: usize,
    /// Irregular vertices before minus after the collapse.
    pub removed: i64,
}

/// Every ring that obeys the paper's rules, in the paper's order.
pub fn rings(mesh: &QuadMesh) -> Vec<Ring> {
    let val = mesh.valences();
    let edges = mesh.edge_map();
    let mut seen: HashSet<(u32, u8)> = HashSet::new();
    let mut out = Vec::new();
    for f in 0..mesh.quads.len() as u32 {
        for dir in 0..2u8 {
            if seen.contains(&(f, dir)) {
                continue;
            }
            if let Some(ring) = trace(mesh, &edges, &val, f, dir, &mut seen) {
                if ring.removed >= 4 {
                    out.push(ring);
                }
            }
        }
    }
    out.sort_by_key(|r| (r.quads, -r.removed));
    out
}

/// Follows the strip entering quad `f` through its edge `dir` until it closes. `None` when the
/// strip meets a quad twice (it crosses itself) or its sides touch, or a rung joins two
/// valence-three vertices.
fn trace(
    mesh: &QuadMesh,
    edges: &HashMap<(u32, u32), (u32, u8)>,
    val: &[u32],
    f0: u32,
    dir: u8,
    seen: &mut HashSet<(u32, u8)>,
) -> Option<Ring> {
    let mut rungs = Vec::new();
    let mut visited = HashSet::new();
    let (mut f, mut c) = (f0, dir);
    let mut ok = true;
    loop {
        seen.insert((f, c % 2));
        if !visited.insert(f) {
            ok = false;
        }
        let q = mesh.quads[f as usize];
        let c_us = c as usize;
        rungs.push((q[(c_us + 1) % 4], q[c_us]));
        // Leave through the opposite edge into the neighbour holding it reversed.
        let (a, b) = (q[(c_us + 2) % 4], q[(c_us + 3) % 4]);
        // A strip that runs into the border is not a ring.
        let &(g, j) = edges.get(&(b, a))?;
        (f, c) = (g, j);
        if f == f0 && c % 2 == dir % 2 || rungs.len() > mesh.quads.len() {
            break;
        }
    }
    if !ok || f != f0 {
        return None;
    }
    let mut side = HashSet::new();
    for &(a, b) in &rungs {
        if !side.insert(a) || !side.insert(b) || val[a as usize] + val[b as usize] < 7 {
            return None;
        }
    }
    let irregular = |v: u32| (v != 4) as i64;
    let before: i64 =
        rungs.iter().map(|&(a, b)| irregular(val[a as usize]) + irregular(val[b as usize])).sum();
    let after: i64 = rungs.iter().map(|&(a, b)| irregular(val[a as usize] + val[b as usize] - 4)).sum();
    Some(Ring { quads: rungs.len(), rungs, removed: before - after })
}

/// Collapses rings in the paper's order, in rounds (rings are recomputed after each round, and
/// within a round a ring near an earlier collapse waits for the next). Returns the number of rings
/// collapsed.
pub fn ring_collapse(mesh: &mut QuadMesh) -> usize {
    let mut applied = 0;
    loop {
        let nb = mesh.neighbours();
        let mut touched = vec![false; mesh.positions.len()];
        let mut round = 0;
        for ring in rings(mesh) {
            let vertices: Vec<u32> = ring.rungs.iter().flat_map(|&(a, b)| [a, b]).collect();
            if vertices.iter().any(|&v| touched[v as usize]) {
                continue;
            }
            let groups: Vec<(Vec<u32>, Vec3)> = ring
                .rungs
                .iter()
                .map(|&(a, b)| {
                    let mid = (mesh.positions[a as usize] + mesh.positions[b as usize]) * 0.5;
                    (vec![a, b], mid)
                })
                .collect();
            if let Some(next) = merge(mesh, &groups) {
                mark_touched(&mut touched, &nb, &vertices);
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

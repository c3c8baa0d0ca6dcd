//! Local Collapse: a quad with valences (3, m, 3, n), 4 ≤ m, n ≤ 6, collapses along its
//! valence-three diagonal to one vertex of valence four (Fig. 4). Applied last, since it breaks
//! the ring condition the other two operators rely on.

use super::collapse::{centroid, is_3m3n, mark_touched, merge};
use super::mesh::QuadMesh;

/// Applies Local Collapses in rounds until none is left; returns how many were applied. Within a
/// round a candidate is skipped once a neighbouring collapse has changed its valences.
pub fn local_collapse(mesh: &mut QuadMesh) -> usize {
    let mut applied = 0;
    loop {
        let val = mesh.valences();
        let nb = mesh.neighbours();
        let mut touched = vec![false; mesh.positions.len()];
        let mut round = 0;
        let candidates: Vec<([u32; 4], usize)> = mesh
            .quads
            .iter()
            .flat_map(|q| (0..2).map(move |s| (*q, s)))
            .filter(|(q, s)| is_3m3n(q, &val, *s))
            .collect();
        for (q, s) in candidates {
            if q.iter().any(|&v| touched[v as usize]) {
                continue;
            }
            let group = vec![q[s], q[s + 2]];
            if let Some(next) = merge(mesh, &[(group, centroid(mesh, &q))]) {
                mark_touched(&mut touched, &nb, &q);
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

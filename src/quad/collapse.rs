//! The one primitive all three collapse operators are built from: merge groups of vertices, drop
//! the quads that degenerate, and keep the result only if it is still a 2-manifold with the same
//! Euler characteristic, the same components and the same border, with no vertex below valence
//! three. Operators decide *what* to merge (the paper's rules); this module guarantees that no
//! collapse can change the topology. Vertices on the border (pinned to the grid's outer faces)
//! are never merged, so the border stays where MC's is. Geometry (crossings, folds) is checked per
//! stage by the caller, since a collapse's effect shows only after re-projection.

use super::mesh::QuadMesh;
use glam::Vec3;
use std::collections::HashMap;

/// Merges each group into its first vertex (moved to the given position) and removes the quads
/// that now repeat a vertex. Vertex ids are kept (merged-away vertices become unused) so callers
/// can keep applying candidates found on the mesh before. `None` when the result would not be a
/// closed 2-manifold with the same Euler characteristic and every valence at least three.
pub fn merge(mesh: &QuadMesh, groups: &[(Vec<u32>, Vec3)]) -> Option<QuadMesh> {
    let mut map: HashMap<u32, u32> = HashMap::new();
    let mut positions = mesh.positions.clone();
    for (group, p) in groups {
        for &v in group {
            if map.insert(v, group[0]).is_some() || mesh.pin(v) != 0 {
                return None;
            }
        }
        positions[group[0] as usize] = *p;
    }
    let quads: Vec<[u32; 4]> = mesh
        .quads
        .iter()
        .map(|q| q.map(|v| map.get(&v).copied().unwrap_or(v)))
        .filter(|q| (0..4).all(|i| (i + 1..4).all(|j| q[i] != q[j])))
        .collect();
    let out = QuadMesh { positions, quads, pins: mesh.pins.clone() };
    let val = out.valences();
    let valid = out.euler() == mesh.euler()
        && (0..val.len()).all(|v| val[v] == 0 || val[v] >= 3 || out.pin(v as u32) != 0)
        && out.is_manifold()
        && out.boundary_edges() == mesh.boundary_edges()
        && out.components() == mesh.components();
    valid.then_some(out)
}

/// The neighbours of the vertex at corner `(f0, c0)` in turning order around it, starting from
/// that corner. `None` when its fan is open (a border vertex): the operators leave those alone.
pub fn ordered_neighbours_from(
    mesh: &QuadMesh,
    edges: &HashMap<(u32, u32), (u32, u8)>,
    (f0, c0): (u32, u8),
) -> Option<Vec<u32>> {
    let v = mesh.quads[f0 as usize][c0 as usize];
    let mut out = Vec::new();
    let (mut f, mut c) = (f0, c0);
    loop {
        let q = mesh.quads[f as usize];
        out.push(q[(c as usize + 1) % 4]);
        let prev = q[(c as usize + 3) % 4];
        (f, c) = *edges.get(&(v, prev))?;
        if f == f0 || out.len() > 64 {
            return Some(out);
        }
    }
}

/// The corner of each quad whose vertex has valence three while the opposite one does too and the
/// other two have valence four to six: the (3, m, 3, n) quads of the Local Collapse.
pub fn is_3m3n(q: &[u32; 4], val: &[u32], start: usize) -> bool {
    let v = |i: usize| val[q[(start + i) % 4] as usize];
    v(0) == 3 && v(2) == 3 && (4..=6).contains(&v(1)) && (4..=6).contains(&v(3))
}

/// Midpoint of a group of vertices: where a collapse puts the merged vertex before re-projection.
pub fn centroid(mesh: &QuadMesh, group: &[u32]) -> Vec3 {
    group.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() / group.len() as f32
}

/// Marks `vertices` and their neighbours (adjacency from before the round) as changed, so later
/// candidates of the same round that read their valences are skipped until the next round.
pub fn mark_touched(touched: &mut [bool], nb: &[Vec<u32>], vertices: &[u32]) {
    for &v in vertices {
        touched[v as usize] = true;
        for &u in &nb[v as usize] {
            touched[u as usize] = true;
        }
    }
}

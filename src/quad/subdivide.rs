//! Bilinear (polygonal) subdivision: every quad becomes four through its edge midpoints and its
//! centre. New vertices all have valence four, so regularity only grows; projecting them onto
//! f = 0 brings back the detail the collapses removed.

use super::mesh::QuadMesh;
use std::collections::HashMap;

/// One subdivision step. Returns the mesh and, per vertex, whether it is new (to be projected).
/// The midpoint of a border edge is pinned to the outer face both its ends lie in.
pub fn subdivide(mesh: &QuadMesh) -> (QuadMesh, Vec<bool>) {
    let mut positions = mesh.positions.clone();
    let mut is_new = vec![false; positions.len()];
    let border: std::collections::HashSet<(u32, u32)> = if mesh.pins.is_empty() {
        Default::default()
    } else {
        let directed: std::collections::HashSet<(u32, u32)> =
            mesh.quads.iter().flat_map(|q| (0..4).map(move |i| (q[i], q[(i + 1) % 4]))).collect();
        directed.iter().copied().filter(|&(a, b)| !directed.contains(&(b, a))).collect()
    };
    let mut pins = mesh.pins.clone();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut quads = Vec::with_capacity(mesh.quads.len() * 4);
    let add = |positions: &mut Vec<_>, is_new: &mut Vec<bool>, p| {
        positions.push(p);
        is_new.push(true);
        positions.len() as u32 - 1
    };
    for q in &mesh.quads {
        let p = q.map(|v| mesh.positions[v as usize]);
        let mut m = [0u32; 4];
        for i in 0..4 {
            let (a, b) = (q[i], q[(i + 1) % 4]);
            let key = (a.min(b), a.max(b));
            m[i] = match mid.get(&key) {
                Some(&v) => v,
                None => {
                    let v = add(&mut positions, &mut is_new, (p[i] + p[(i + 1) % 4]) * 0.5);
                    if !mesh.pins.is_empty() {
                        let on_border = border.contains(&(a, b));
                        pins.push(if on_border { mesh.pin(a) & mesh.pin(b) } else { 0 });
                    }
                    mid.insert(key, v);
                    v
                }
            };
        }
        let c = add(&mut positions, &mut is_new, (p[0] + p[1] + p[2] + p[3]) * 0.25);
        if !mesh.pins.is_empty() {
            pins.push(0);
        }
        quads.push([q[0], m[0], c, m[3]]);
        quads.push([m[0], q[1], m[1], c]);
        quads.push([c, m[1], q[2], m[2]]);
        quads.push([m[3], c, m[2], q[3]]);
    }
    (QuadMesh { positions, quads, pins }, is_new)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subdivided_cube_stays_a_closed_sphere_with_eight_irregular_vertices() {
        let (m, new) = subdivide(&crate::quad::mesh::tests::cube());
        assert_eq!(m.quad_count(), 24);
        assert_eq!(m.vertex_count(), 8 + 12 + 6);
        assert_eq!(new.iter().filter(|&&n| n).count(), 18);
        assert!(m.is_closed_manifold());
        assert_eq!(m.euler(), 2);
        assert_eq!(m.irregular_count(), 8);
    }
}

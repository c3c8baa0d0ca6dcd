//! The quad mesh every stage of the quad method hands to the next, and the connectivity queries the
//! collapse operators share (valences, neighbours, the closed-2-manifold check that guards every
//! collapse, triangulation for rendering).

use crate::mesh::Mesh;
use glam::Vec3;
use std::collections::HashMap;

/// An indexed quad mesh: each face lists four vertices counter-clockwise seen from outside.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QuadMesh {
    pub positions: Vec<Vec3>,
    pub quads: Vec<[u32; 4]>,
    /// Per vertex, bit `a` set when the vertex lies on the grid's outer face normal to axis `a` and
    /// must stay there (the border of a surface cut open by the bounds, as MC cuts it). Empty means
    /// no vertex is pinned. Pinned vertices are exactly the mesh's boundary vertices.
    pub pins: Vec<u8>,
}

impl QuadMesh {
    /// A mesh without pinned vertices.
    pub fn new(positions: Vec<Vec3>, quads: Vec<[u32; 4]>) -> QuadMesh {
        QuadMesh { positions, quads, pins: Vec::new() }
    }

    /// The pinned axes of vertex `v` (see [`QuadMesh::pins`]).
    pub fn pin(&self, v: u32) -> u8 {
        self.pins.get(v as usize).copied().unwrap_or(0)
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn quad_count(&self) -> usize {
        self.quads.len()
    }

    /// Number of distinct edges each vertex has (on a closed manifold, also its number of quads).
    pub fn valences(&self) -> Vec<u32> {
        let mut val = vec![0u32; self.positions.len()];
        for q in &self.quads {
            for &v in q {
                val[v as usize] += 1;
            }
        }
        val
    }

    /// Vertices whose valence is not four (counted only among used vertices).
    pub fn irregular_count(&self) -> usize {
        self.valences().iter().filter(|&&v| v != 0 && v != 4).count()
    }

    /// Share of used vertices with valence four, the paper's measure of regularity.
    pub fn valence4_share(&self) -> f64 {
        let val = self.valences();
        let used = val.iter().filter(|&&v| v != 0).count();
        if used == 0 {
            return 0.0;
        }
        val.iter().filter(|&&v| v == 4).count() as f64 / used as f64
    }

    /// Directed edge `(a, b)` → (quad, corner of `a`): the lookup every traversal starts from.
    pub fn edge_map(&self) -> HashMap<(u32, u32), (u32, u8)> {
        let mut map = HashMap::with_capacity(self.quads.len() * 4);
        for (f, q) in self.quads.iter().enumerate() {
            for i in 0..4 {
                map.insert((q[i], q[(i + 1) % 4]), (f as u32, i as u8));
            }
        }
        map
    }

    /// Neighbours of every vertex along edges (each once).
    pub fn neighbours(&self) -> Vec<Vec<u32>> {
        let mut nb: Vec<Vec<u32>> = vec![Vec::new(); self.positions.len()];
        for q in &self.quads {
            for i in 0..4 {
                let (a, b) = (q[i], q[(i + 1) % 4]);
                for (x, y) in [(a, b), (b, a)] {
                    if !nb[x as usize].contains(&y) {
                        nb[x as usize].push(y);
                    }
                }
            }
        }
        nb
    }

    /// Drops vertices no quad uses and renumbers the rest (collapses leave such holes).
    pub fn compact(&mut self) {
        let mut map = vec![u32::MAX; self.positions.len()];
        let mut positions = Vec::new();
        let mut pins = Vec::new();
        for q in &mut self.quads {
            for v in q.iter_mut() {
                if map[*v as usize] == u32::MAX {
                    map[*v as usize] = positions.len() as u32;
                    positions.push(self.positions[*v as usize]);
                    pins.push(self.pins.get(*v as usize).copied().unwrap_or(0));
                }
                *v = map[*v as usize];
            }
        }
        self.positions = positions;
        self.pins = if self.pins.is_empty() { Vec::new() } else { pins };
    }

    /// Components connected through shared vertices, as the triangle analysis counts them.
    pub fn components(&self) -> usize {
        let mut parent: Vec<u32> = (0..self.positions.len() as u32).collect();
        fn root(parent: &mut [u32], mut v: u32) -> u32 {
            while parent[v as usize] != v {
                parent[v as usize] = parent[parent[v as usize] as usize];
                v = parent[v as usize];
            }
            v
        }
        for q in &self.quads {
            for &v in &q[1..] {
                let (a, b) = (root(&mut parent, q[0]), root(&mut parent, v));
                parent[a as usize] = b;
            }
        }
        let val = self.valences();
        (0..self.positions.len() as u32).filter(|&v| val[v as usize] > 0 && root(&mut parent, v) == v).count()
    }

    /// Edges used by one quad only: the border where the bounds cut the surface open.
    pub fn boundary_edges(&self) -> usize {
        let directed: std::collections::HashSet<(u32, u32)> =
            self.quads.iter().flat_map(|q| (0..4).map(move |i| (q[i], q[(i + 1) % 4]))).collect();
        directed.iter().filter(|&&(a, b)| !directed.contains(&(b, a))).count()
    }

    /// Euler characteristic V − E + F over used vertices (each undirected edge counted once).
    pub fn euler(&self) -> i64 {
        let used = self.valences().iter().filter(|&&v| v != 0).count() as i64;
        let mut edges = std::collections::HashSet::new();
        for q in &self.quads {
            for i in 0..4 {
                let (a, b) = (q[i], q[(i + 1) % 4]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        used - edges.len() as i64 + self.quads.len() as i64
    }

    /// True when every quad has four distinct corners, every directed edge occurs once with its
    /// reverse also present (closed, consistently oriented, two quads per edge), and the quads
    /// around every vertex form a single fan (a disk, not two cones touching at a point).
    pub fn is_closed_manifold(&self) -> bool {
        self.is_manifold() && self.boundary_edges() == 0
    }

    /// Like [`QuadMesh::is_closed_manifold`] but a directed edge may lack its reverse (a border):
    /// every directed edge occurs once, and the quads around every vertex form one fan, closed or
    /// open (a disk or a half-disk).
    pub fn is_manifold(&self) -> bool {
        let mut map: HashMap<(u32, u32), (u32, u8)> = HashMap::with_capacity(self.quads.len() * 4);
        for (f, q) in self.quads.iter().enumerate() {
            for i in 0..4 {
                if q[i] as usize >= self.positions.len() {
                    return false;
                }
                for j in i + 1..4 {
                    if q[i] == q[j] {
                        return false;
                    }
                }
                if map.insert((q[i], q[(i + 1) % 4]), (f as u32, i as u8)).is_some() {
                    return false;
                }
            }
        }
        let val = self.valences();
        let mut seen = vec![false; self.positions.len()];
        for (f, q) in self.quads.iter().enumerate() {
            for (i, &v) in q.iter().enumerate() {
                if std::mem::replace(&mut seen[v as usize], true) {
                    continue;
                }
                // Turn clockwise to the start of an open fan (or once round a closed one) ...
                let (mut g, mut j) = (f as u32, i as u8);
                for _ in 0..val[v as usize] {
                    let quad = &self.quads[g as usize];
                    let next = quad[(j as usize + 1) % 4];
                    match map.get(&(next, v)) {
                        Some(&(h, k)) if (h, (k + 1) % 4) != (f as u32, i as u8) => (g, j) = (h, (k + 1) % 4),
                        _ => break,
                    }
                }
                // ... then count the corners counter-clockwise; one fan must hold them all.
                let start = (g, j);
                let mut steps = 1u32;
                loop {
                    let quad = &self.quads[g as usize];
                    let prev = quad[(j as usize + 3) % 4];
                    match map.get(&(v, prev)) {
                        Some(&c) if c != start && steps <= val[v as usize] => {
                            (g, j) = c;
                            steps += 1;
                        }
                        _ => break,
                    }
                }
                if steps != val[v as usize] {
                    return false;
                }
            }
        }
        true
    }

    /// Two triangles per quad, split along the shorter diagonal (the flatter choice on a curved
    /// surface), for renderers and the triangle-mesh analysis.
    pub fn triangulate(&self) -> Mesh {
        let mut triangles = Vec::with_capacity(self.quads.len() * 2);
        for q in &self.quads {
            let p = q.map(|v| self.positions[v as usize]);
            if p[0].distance_squared(p[2]) <= p[1].distance_squared(p[3]) {
                triangles.push([q[0], q[1], q[2]]);
                triangles.push([q[0], q[2], q[3]]);
            } else {
                triangles.push([q[0], q[1], q[3]]);
                triangles.push([q[1], q[2], q[3]]);
            }
        }
        let mut mesh = Mesh { positions: self.positions.clone(), normals: vec![], triangles };
        mesh.compute_normals_from_faces();
        mesh
    }

    /// Mean and maximum quad aspect ratio: longest over shortest of the two pairs of opposite edge
    /// midlines (1 for a square, large for the slivers a ring collapse leaves).
    pub fn aspect_ratios(&self) -> (f64, f64) {
        let mut sum = 0.0;
        let mut max: f64 = 0.0;
        for q in &self.quads {
            let p = q.map(|v| self.positions[v as usize]);
            let u = ((p[1] + p[2]) - (p[0] + p[3])).length() as f64 * 0.5;
            let w = ((p[2] + p[3]) - (p[0] + p[1])).length() as f64 * 0.5;
            let r = u.max(w) / u.min(w).max(1e-12);
            sum += r;
            max = max.max(r);
        }
        (sum / self.quads.len().max(1) as f64, max)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The unit cube as six outward quads: the smallest closed quad mesh.
    pub(crate) fn cube() -> QuadMesh {
        let positions =
            (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32)).collect();
        let quads = vec![[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        QuadMesh::new(positions, quads)
    }

    #[test]
    fn cube_is_a_closed_manifold_sphere_of_valence_three() {
        let c = cube();
        assert!(c.is_closed_manifold());
        assert_eq!(c.euler(), 2);
        assert_eq!(c.irregular_count(), 8);
        let t = c.triangulate();
        assert_eq!(crate::mesh::analysis::topology(&t).euler, 2);
    }

    #[test]
    fn a_missing_or_flipped_quad_is_caught() {
        let mut c = cube();
        c.quads.pop();
        assert!(!c.is_closed_manifold());
        let mut c = cube();
        c.quads[0].reverse();
        assert!(!c.is_closed_manifold());
        // An open box is a manifold with a border; two boxes sharing one corner are not manifold.
        let mut open = cube();
        open.quads.pop();
        assert!(open.is_manifold() && open.boundary_edges() == 4 && open.euler() == 1);
        let mut two = cube();
        let moved: Vec<Vec3> = two.positions.iter().map(|p| *p + Vec3::splat(1.0)).collect();
        two.positions.extend(moved);
        let copy: Vec<[u32; 4]> =
            two.quads.iter().map(|q| q.map(|v| if v == 0 { 7 } else { v + 8 })).collect();
        two.quads.extend(copy);
        assert!(!two.is_manifold(), "two cubes touching at a corner");
        assert_eq!(cube().components(), 1);
    }
}

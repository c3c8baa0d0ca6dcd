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
}

impl QuadMesh {
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
        for q in &mut self.quads {
            for v in q.iter_mut() {
                if map[*v as usize] == u32::MAX {
                    map[*v as usize] = positions.len() as u32;
                    positions.push(self.positions[*v as usize]);
                }
                *v = map[*v as usize];
            }
        }
        self.positions = positions;
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
        let mut map: HashMap<(u32, u32), (u32, u8)> = HashMap::with_capacity(self.quads.len() * 4);
        for (f, q) in self.quads.iter().enumerate() {
            for i in 0..4 {
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
        if map.keys().any(|&(a, b)| !map.contains_key(&(b, a))) {
            return false;
        }
        // Walk the fan of each vertex from one corner; it must reach every corner at that vertex.
        let val = self.valences();
        let mut seen = vec![false; self.positions.len()];
        for q in &self.quads {
            for i in 0..4 {
                let v = q[i];
                if seen[v as usize] {
                    continue;
                }
                seen[v as usize] = true;
                let mut steps = 0u32;
                let mut corner = (q, i);
                loop {
                    // The edge entering v in this quad, reversed, leaves v in the next quad.
                    let prev = corner.0[(corner.1 + 3) % 4];
                    let (g, j) = map[&(v, prev)];
                    steps += 1;
                    corner = (&self.quads[g as usize], j as usize);
                    if std::ptr::eq(corner.0, q) || steps > val[v as usize] {
                        break;
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
        QuadMesh { positions, quads }
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
    }
}

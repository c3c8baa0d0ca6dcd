//! The indexed triangle mesh every method returns, plus its analysis and export.

use glam::Vec3;

pub mod analysis;
pub mod buckets;
pub mod decimate;
pub mod export;
pub mod pleats;
pub mod smooth;

/// An indexed triangle mesh. Triangles are counter-clockwise seen from outside, so face normals
/// (by the right-hand rule) point out of the solid.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// One unit normal per vertex (same length as `positions`), or empty when not computed.
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// What is wrong with the first triangle that names a vertex past `positions`, or `None` when
    /// every index is in range: meshes built from outside arrays (files, JavaScript) are checked
    /// with it before anything indexes them.
    pub fn index_error(&self) -> Option<String> {
        let n = self.positions.len();
        let t = self.triangles.iter().position(|t| t.iter().any(|&v| v as usize >= n))?;
        Some(format!("triangle {t} {:?} refers past the {n} vertices", self.triangles[t]))
    }

    /// The three corner positions of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    /// Unnormalised face normal of triangle `t` (its length is twice the area).
    #[inline]
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.corners(t);
        (b - a).cross(c - a)
    }

    /// Fills `normals` with area-weighted averages of the incident face normals: used when the
    /// field has no gradient (sampled volumes).
    pub fn compute_normals_from_faces(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for t in 0..self.triangles.len() {
            let n = self.face_normal(t);
            for &v in &self.triangles[t] {
                normals[v as usize] += n;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        self.normals = normals;
    }

    /// Positions as a flat `[x0, y0, z0, x1, ...]` array, the layout WebGL and three.js want.
    pub fn flat_positions(&self) -> Vec<f32> {
        self.positions.iter().flat_map(|p| p.to_array()).collect()
    }

    pub fn flat_normals(&self) -> Vec<f32> {
        self.normals.iter().flat_map(|p| p.to_array()).collect()
    }

    pub fn flat_indices(&self) -> Vec<u32> {
        self.triangles.iter().flatten().copied().collect()
    }
}

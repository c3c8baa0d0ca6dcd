//! Contouring the dual grid (§4): Marching Cubes on every dual cell, with the cell's eight vertices
//! (positions and values) standing in for a cube's corners.
//!
//! - The case comes from the signs alone and uses the crate's default table (ambiguous faces always
//!   separate the inside corners). Two dual cells sharing a face see the same four vertices in the
//!   same roles, so they agree on that face and the output is crack-free.
//! - A crossing is keyed by the pair of dual vertices it lies between, so every dual cell using that
//!   dual edge reuses the same mesh vertex: the mesh is indexed from the start, never welded.
//! - Adaptive cells repeat vertices. A repeated vertex pair has equal values (no crossing), and two
//!   cube edges joining the same pair of dual vertices share one mesh vertex; the triangles this
//!   collapses (a repeated index) are dropped, which removes a polygon edge that has shrunk to a
//!   point and leaves the polygon's other triangles intact.
//! - The crossing is found by root finding on the field along the dual edge, from its inside end to
//!   its outside end (so the result does not depend on which cell asked first), kept at least
//!   [`crate::mc::MIN_EDGE_FRACTION`] of the edge from both ends. Root finding puts every mesh vertex
//!   on the true surface; linear interpolation of the two values would be exact only for fields
//!   linear along the edge.

use super::dual::VertexKey;
use super::tree::{Kind, Octree};
use crate::emc::edges::edge_root;
use crate::field::Field;
use crate::mesh::Mesh;
use crate::tables::{triangle_table, CENTER, EDGES};
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// The dual vertices the contour uses: position, `f - iso` and side, numbered densely.
#[derive(Debug, Default)]
pub struct DualVertices {
    pub positions: Vec<Vec3>,
    pub values: Vec<f32>,
    pub inside: Vec<bool>,
    ids: HashMap<VertexKey, u32>,
    /// Vertices whose value is only a sign so far (empty leaves, boundary copies).
    unknown: Vec<u32>,
}

impl DualVertices {
    /// The id of `key`'s vertex: a leaf's own, or a leaf's projected onto the grid's faces.
    pub fn id(&mut self, tree: &Octree, key: VertexKey) -> u32 {
        if let Some(&id) = self.ids.get(&key) {
            return id;
        }
        let node = &tree.nodes[key.node as usize];
        let p = super::dual::position(tree, key);
        let id = self.positions.len() as u32;
        let exact = key.clamp == 0 && node.kind == Kind::Surface;
        if !exact {
            self.unknown.push(id);
        }
        self.positions.push(p);
        self.values.push(node.value);
        self.inside.push(super::dual::inside(tree, key));
        self.ids.insert(key, id);
        id
    }

    /// Evaluates the values known only by their sign.
    pub fn evaluate(&mut self, field: &dyn Field, iso: f32) {
        let points: Vec<Vec3> = self.unknown.iter().map(|&i| self.positions[i as usize]).collect();
        let mut values = vec![0.0; points.len()];
        field.values(&points, &mut values);
        for (&i, v) in self.unknown.iter().zip(values) {
            // Keep the side the bound proved (a value at the level counts as outside).
            let inside = self.inside[i as usize];
            let v = v - iso;
            self.values[i as usize] = match inside {
                true if v < 0.0 => v,
                true => -f32::MIN_POSITIVE,
                false => v.max(0.0),
            };
        }
        self.unknown.clear();
    }
}

/// A mesh vertex on a dual edge: the dual vertices at its inside and outside ends, and how far
/// from the inside end it lies (fraction of the edge).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    pub inside: u32,
    pub outside: u32,
    pub t: f32,
}

#[derive(Debug, Clone, Default)]
pub struct Contour {
    pub mesh: Mesh,
    /// Per mesh vertex: the dual edge it lies on.
    pub crossings: Vec<Crossing>,
    /// Per triangle: the dual cell (index into the list contoured) that produced it.
    pub cell_of_triangle: Vec<u32>,
}

/// Contours dual cells given as eight dual vertex ids each (octant order).
pub fn contour(cells: &[[u32; 8]], vertices: &DualVertices, field: &dyn Field, iso: f32) -> Contour {
    let table = triangle_table();
    let mut out = Contour::default();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::default();
    for (c, ids) in cells.iter().enumerate() {
        let mut case = 0u8;
        for (corner, &id) in ids.iter().enumerate() {
            case |= (vertices.inside[id as usize] as u8) << corner;
        }
        if case == 0 || case == 255 {
            continue;
        }
        let tris = &table[case as usize];
        let mut local = [u32::MAX; 12];
        for t in tris.triangles() {
            debug_assert!(!t.contains(&CENTER), "the default table needs no centre vertex");
            let v = t.map(|e| {
                let e = e as usize;
                if local[e] == u32::MAX {
                    let [a, b] = EDGES[e].map(|corner| ids[corner as usize]);
                    let (inside, outside) = if vertices.inside[a as usize] { (a, b) } else { (b, a) };
                    local[e] = *edges.entry((inside, outside)).or_insert_with(|| {
                        let (pa, pb) =
                            (vertices.positions[inside as usize], vertices.positions[outside as usize]);
                        let (va, vb) = (vertices.values[inside as usize], vertices.values[outside as usize]);
                        let t = edge_root(field, iso, pa, pb, va, vb);
                        out.crossings.push(Crossing { inside, outside, t });
                        out.mesh.positions.push(pa + (pb - pa) * t);
                        out.mesh.positions.len() as u32 - 1
                    });
                }
                local[e]
            });
            if v[0] != v[1] && v[1] != v[2] && v[0] != v[2] {
                out.mesh.triangles.push(v);
                out.cell_of_triangle.push(c as u32);
            }
        }
    }
    out
}

/// Unit normals from the field's gradient (central differences where it has none).
pub fn field_normals(mesh: &mut Mesh, field: &dyn Field, h: f32) {
    mesh.normals = mesh.positions.iter().map(|&p| crate::emc::edges::field_normal(field, p, h)).collect();
}

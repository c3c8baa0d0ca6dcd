//! Contouring the dual grid (§4): Marching Cubes on every dual cell, with the cell's eight vertices
//! (positions and values) standing in for a cube's corners.
//!
//! - The case comes from the signs, and an ambiguous face joins its inside corners where the field
//!   at its centre is inside ([`super::faces`]; the default table separates them). Two dual cells
//!   sharing a face see the same four vertices in the same roles, so they agree on that face and
//!   the output is crack-free.
//! - A crossing is keyed by the pair of dual vertices it lies between, so every dual cell using that
//!   dual edge reuses the same mesh vertex: the mesh is indexed from the start, never welded.
//! - Adaptive cells repeat vertices. A repeated vertex pair has equal values (no crossing), and two
//!   cube edges joining the same pair of dual vertices share one mesh vertex; the triangles this
//!   collapses (a repeated index) are dropped, which removes a polygon edge that has shrunk to a
//!   point and leaves the polygon's other triangles intact.
//! - The crossing is found by root finding on the field along the dual edge, from its inside end to
//!   its outside end (so the result does not depend on which cell asked first), kept at least
//!   [`crate::mc::MIN_EDGE_FRACTION`] of the edge from both ends, every edge at once
//!   ([`batch_roots`]). Root finding puts every mesh vertex on the true surface; linear
//!   interpolation of the two values would be exact only for fields linear along the edge.

use super::dual::{on_side, VertexKey};
use super::tree::{Kind, Octree};
use crate::field::Field;
use crate::mesh::Mesh;
use crate::tables::{triangle_table_with_faces_without_centre, CENTER, EDGES};
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// The dual vertices the contour uses: position, `f - iso` and side, numbered densely.
#[derive(Debug, Default)]
pub struct DualVertices {
    pub positions: Vec<Vec3>,
    /// Per vertex its leaf's centre ([`super::dual::centre`]), where ambiguous faces are decided.
    pub centres: Vec<Vec3>,
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
        self.centres.push(super::dual::centre(tree, key));
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
            // Keep the side the bound proved.
            self.values[i as usize] = super::dual::on_side(v - iso, self.inside[i as usize]);
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

/// Crossings found before, by the positions of their ends (inside first), so that contouring
/// again after a few vertices moved root-finds only the dual edges that changed.
pub type RootCache = HashMap<[u32; 6], f32>;

fn cache_key(a: Vec3, b: Vec3) -> [u32; 6] {
    [a.x, a.y, a.z, b.x, b.y, b.z].map(f32::to_bits)
}

/// Contours dual cells given as eight dual vertex ids each (octant order).
pub fn contour(
    cells: &[[u32; 8]],
    vertices: &DualVertices,
    field: &dyn Field,
    iso: f32,
    cache: &mut RootCache,
) -> Contour {
    let table = triangle_table_with_faces_without_centre();
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
        let joined = super::faces::joined_faces(case, |k| vertices.centres[ids[k] as usize], field, iso);
        let tris = &table[(case as usize) << 6 | joined as usize];
        let mut local = [u32::MAX; 12];
        for t in tris.triangles() {
            debug_assert!(!t.contains(&CENTER), "the table has no centre vertex");
            let v = t.map(|e| {
                let e = e as usize;
                if local[e] == u32::MAX {
                    let [a, b] = EDGES[e].map(|corner| ids[corner as usize]);
                    let (inside, outside) = if vertices.inside[a as usize] { (a, b) } else { (b, a) };
                    local[e] = *edges.entry((inside, outside)).or_insert_with(|| {
                        out.crossings.push(Crossing { inside, outside, t: f32::NAN });
                        out.crossings.len() as u32 - 1
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
    let ends = |c: &Crossing| (vertices.positions[c.inside as usize], vertices.positions[c.outside as usize]);
    let missing: Vec<usize> = (0..out.crossings.len())
        .filter(|&i| {
            let (a, b) = ends(&out.crossings[i]);
            match cache.get(&cache_key(a, b)) {
                Some(&t) => {
                    out.crossings[i].t = t;
                    false
                }
                None => true,
            }
        })
        .collect();
    let segments: Vec<Segment> = missing
        .iter()
        .map(|&i| {
            let c = out.crossings[i];
            let (a, b) = ends(&c);
            Segment {
                inside: a,
                outside: b,
                f_inside: vertices.values[c.inside as usize],
                f_outside: vertices.values[c.outside as usize],
            }
        })
        .collect();
    for (&i, t) in missing.iter().zip(batch_roots(field, iso, &segments, ROOT_STEPS)) {
        out.crossings[i].t = t;
        let (a, b) = ends(&out.crossings[i]);
        cache.insert(cache_key(a, b), t);
    }
    out.mesh.positions = out
        .crossings
        .iter()
        .map(|c| {
            let (a, b) = ends(c);
            a + (b - a) * c.t
        })
        .collect();
    out
}

/// A dual edge to root-find on: its ends and `f - iso` there (below 0 at the inside end).
#[derive(Debug, Clone, Copy)]
pub struct Segment {
    pub inside: Vec3,
    pub outside: Vec3,
    pub f_inside: f32,
    pub f_outside: f32,
}

/// Regula falsi steps for the mesh's vertices: Illinois' modification keeps the bracket shrinking
/// from both sides, so this many steps reach `f32` resolution on smooth edges and a small fraction
/// of the edge at a kink (the bracket always holds the root).
pub const ROOT_STEPS: usize = 16;

/// Roots of `f - iso` on many segments at once, as fractions of the way from the inside end,
/// kept [`crate::mc::MIN_EDGE_FRACTION`] from both ends: one batch of field values per step, the
/// way the field evaluates fastest.
pub fn batch_roots(field: &dyn Field, iso: f32, segments: &[Segment], steps: usize) -> Vec<f32> {
    let n = segments.len();
    let (mut lo, mut hi) = (vec![0.0f32; n], vec![1.0f32; n]);
    let mut flo: Vec<f32> = segments.iter().map(|s| on_side(s.f_inside, true)).collect();
    let mut fhi: Vec<f32> = segments.iter().map(|s| on_side(s.f_outside, false)).collect();
    let mut side = vec![0i8; n];
    let mut t = vec![0.5f32; n];
    let mut done = vec![false; n];
    let mut at = Vec::with_capacity(n);
    let mut which = Vec::with_capacity(n);
    let mut values = Vec::with_capacity(n);
    for _ in 0..steps {
        at.clear();
        which.clear();
        for i in (0..n).filter(|&i| !done[i]) {
            let d = flo[i] - fhi[i];
            let guess = if d < 0.0 && d.is_finite() {
                lo[i] + (hi[i] - lo[i]) * (flo[i] / d)
            } else {
                0.5 * (lo[i] + hi[i])
            };
            t[i] = guess.clamp(lo[i], hi[i]);
            let s = &segments[i];
            at.push(s.inside + (s.outside - s.inside) * t[i]);
            which.push(i);
        }
        if which.is_empty() {
            break;
        }
        values.clear();
        values.resize(at.len(), 0.0);
        field.values(&at, &mut values);
        for (&i, &v) in which.iter().zip(&values) {
            let v = v - iso;
            if v == 0.0 || hi[i] - lo[i] < 1e-6 {
                done[i] = true;
            }
            if v < 0.0 {
                lo[i] = t[i];
                flo[i] = v;
                if side[i] == -1 {
                    fhi[i] *= 0.5;
                }
                side[i] = -1;
            } else {
                hi[i] = t[i];
                fhi[i] = v;
                if side[i] == 1 {
                    flo[i] *= 0.5;
                }
                side[i] = 1;
            }
        }
    }
    let m = crate::mc::MIN_EDGE_FRACTION;
    t.iter().map(|&t| t.clamp(m, 1.0 - m)).collect()
}

/// Unit normals from the field's gradient (central differences where it has none).
pub fn field_normals(mesh: &mut Mesh, field: &dyn Field, h: f32) {
    mesh.normals = mesh.positions.iter().map(|&p| crate::emc::edges::field_normal(field, p, h)).collect();
}

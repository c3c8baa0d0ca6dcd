//! The geometric half of a merge test: the triangles a merge would make must stay within the
//! tolerance of the surface. The QEF bounds how well one vertex fits the leaf's tangent planes,
//! not where the dual grid's triangles go: a merged leaf's dual cells reach to its neighbours'
//! vertices, and their triangles can cut across a room's corner or a door's opening while the
//! vertex itself fits perfectly. So the star's triangles after the merge (from
//! [`super::safety`]) are built with their crossings root-found, as the contour will have them,
//! and each triangle's centroid and edge midpoints must lie within the tolerance of the surface
//! (first-order distance `|f - iso| / |∇f|`).
//!
//! Crossings are remembered per dual edge: a dual edge keeps its ends until one of them is merged
//! away, after which its key names nothing reachable.

use super::dual::VertexKey;
use super::safety::EdgeTriangle;
use super::tree::{Kind, Octree};
use crate::emc::edges::edge_root;
use crate::field::{gradients_or_differences, Field};
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// Regula falsi steps per crossing: the estimate only has to be good to a small fraction of the
/// tolerance, and Illinois converges superlinearly on the smooth stretches the crossings lie on.
const ROOT_STEPS: usize = 8;

pub struct Fidelity<'a> {
    pub field: &'a dyn Field,
    pub iso: f32,
    /// Largest accepted distance, world units.
    pub tolerance: f32,
    crossings: HashMap<(VertexKey, VertexKey), Vec3>,
    values: HashMap<VertexKey, f32>,
    points: Vec<Vec3>,
}

impl<'a> Fidelity<'a> {
    pub fn new(field: &'a dyn Field, iso: f32, tolerance: f32) -> Fidelity<'a> {
        Fidelity { field, iso, tolerance, crossings: HashMap::default(), values: HashMap::default(), points: Vec::new() }
    }

    /// Whether every triangle of `tris` lies within the tolerance (the merged node's vertex is
    /// already written into the tree).
    pub fn within(&mut self, tree: &Octree, tris: &[EdgeTriangle]) -> bool {
        if tris.is_empty() {
            return true;
        }
        self.find_crossings(tree, tris);
        self.points.clear();
        for t in tris {
            let [a, b, c] = t.map(|e| self.crossings[&e]);
            self.points.extend([(a + b + c) / 3.0, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
        }
        let mut values = vec![0.0; self.points.len()];
        self.field.values(&self.points, &mut values);
        let (mut scratch, mut gradients) = (Vec::new(), Vec::new());
        gradients_or_differences(self.field, &self.points, tree.h * 1e-2, &mut scratch, &mut gradients);
        values.iter().zip(&gradients).all(|(&v, g)| {
            let d = (v - self.iso).abs();
            let len = g.length();
            d <= self.tolerance * if len > 1e-12 { len } else { 1.0 }
        })
    }

    /// Root-finds the crossings of `tris` not known yet, all edges at once: regula falsi with the
    /// Illinois modification, one batch of values per step (the field's batches are what is fast).
    fn find_crossings(&mut self, tree: &Octree, tris: &[EdgeTriangle]) {
        let mut edges: Vec<(VertexKey, VertexKey)> = Vec::new();
        for t in tris {
            for &e in t {
                if !self.crossings.contains_key(&e) && !edges.contains(&e) {
                    edges.push(e);
                }
            }
        }
        if edges.is_empty() {
            return;
        }
        // Per edge: inside end, outside end, values there (f - iso: < 0 at the inside end), bracket.
        let ends: Vec<(Vec3, Vec3)> =
            edges.iter().map(|&(a, b)| (self.vertex(tree, a).0, self.vertex(tree, b).0)).collect();
        let mut lo = vec![0.0f32; edges.len()];
        let mut hi = vec![1.0f32; edges.len()];
        let mut flo: Vec<f32> = edges.iter().map(|&(a, _)| self.vertex(tree, a).1.min(-f32::MIN_POSITIVE)).collect();
        let mut fhi: Vec<f32> = edges.iter().map(|&(_, b)| self.vertex(tree, b).1.max(0.0)).collect();
        let mut side = vec![0i8; edges.len()];
        let mut t = vec![0.5f32; edges.len()];
        let mut at = vec![Vec3::ZERO; edges.len()];
        let mut values = vec![0.0f32; edges.len()];
        for _ in 0..ROOT_STEPS {
            for i in 0..edges.len() {
                let d = flo[i] - fhi[i];
                t[i] = if d < 0.0 { lo[i] + (hi[i] - lo[i]) * (flo[i] / d) } else { 0.5 * (lo[i] + hi[i]) };
                t[i] = t[i].clamp(lo[i], hi[i]);
                at[i] = ends[i].0 + (ends[i].1 - ends[i].0) * t[i];
            }
            self.field.values(&at, &mut values);
            for i in 0..edges.len() {
                let v = values[i] - self.iso;
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
        for (i, e) in edges.into_iter().enumerate() {
            self.crossings.insert(e, at[i]);
        }
    }

    /// The largest estimated distance and where (debugging).
    pub fn worst(&mut self, tree: &Octree, tris: &[EdgeTriangle]) -> (f32, Vec3) {
        let mut best = (0.0, Vec3::ZERO);
        for t in tris {
            let [a, b, c] = t.map(|e| self.crossing(tree, e));
            for p in [(a + b + c) / 3.0, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5] {
                let g = crate::field::gradient_or_differences(self.field, p, tree.h * 1e-2);
                let d = (self.field.value(p) - self.iso).abs() / g.length().max(1e-12);
                if d > best.0 {
                    best = (d, p);
                }
            }
        }
        best
    }

    fn crossing(&mut self, tree: &Octree, edge: (VertexKey, VertexKey)) -> Vec3 {
        if let Some(&p) = self.crossings.get(&edge) {
            return p;
        }
        let (pa, va) = self.vertex(tree, edge.0);
        let (pb, vb) = self.vertex(tree, edge.1);
        let t = edge_root(self.field, self.iso, pa, pb, va, vb);
        let p = pa + (pb - pa) * t;
        self.crossings.insert(edge, p);
        p
    }

    /// A dual vertex's position and `f - iso`, evaluated where only its sign was known.
    fn vertex(&mut self, tree: &Octree, key: VertexKey) -> (Vec3, f32) {
        let p = super::dual::position(tree, key);
        let node = &tree.nodes[key.node as usize];
        if key.clamp == 0 && !matches!(node.kind, Kind::Empty { .. }) {
            return (p, node.value);
        }
        let inside = super::dual::inside(tree, key);
        let (field, iso) = (self.field, self.iso);
        let v = *self.values.entry(key).or_insert_with(|| {
            let v = field.value(p) - iso;
            if inside {
                v.min(-f32::MIN_POSITIVE)
            } else {
                v.max(0.0)
            }
        });
        (p, v)
    }
}

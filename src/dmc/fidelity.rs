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

use super::contour::{batch_roots, Segment};
use super::dual::VertexKey;
use super::safety::EdgeTriangle;
use super::tree::{Kind, Octree};
use crate::field::{values_and_gradients_or_differences, Field};
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// A dual edge, by its ends (inside first): the name of the crossing on it.
type DualEdge = (VertexKey, VertexKey);

/// Regula falsi steps for the crossings the test estimates distances from: a distance estimate
/// needs them good to a small fraction of the tolerance, not to `f32` resolution.
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
        Fidelity {
            field,
            iso,
            tolerance,
            crossings: HashMap::default(),
            values: HashMap::default(),
            points: Vec::new(),
        }
    }

    /// Per star (the triangles a merge would make, with the merged nodes' vertices already
    /// written into the tree), whether every triangle lies within the tolerance; all stars'
    /// crossings and sample points are found and evaluated in one batch each.
    pub fn within(&mut self, tree: &Octree, stars: &[Vec<EdgeTriangle>]) -> Vec<bool> {
        let all: Vec<EdgeTriangle> = stars.iter().flatten().copied().collect();
        self.find_crossings(tree, &all);
        // Per triangle its centroid and its edges' midpoints, each midpoint evaluated once.
        self.points.clear();
        let mut midpoints: HashMap<(DualEdge, DualEdge), u32> =
            HashMap::with_capacity_and_hasher(2 * all.len(), Default::default());
        let mut samples: Vec<[u32; 4]> = Vec::with_capacity(all.len());
        for t in &all {
            let corners = t.map(|e| self.crossings[&e]);
            let [a, b, c] = corners;
            let centroid = self.points.len() as u32;
            self.points.push((a + b + c) / 3.0);
            let mut ids = [centroid; 4];
            for (k, (i, j)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                let key = (t[i].min(t[j]), t[i].max(t[j]));
                let (p, q) = (corners[i], corners[j]);
                let next = self.points.len() as u32;
                let id = *midpoints.entry(key).or_insert(next);
                if id == next {
                    self.points.push((p + q) * 0.5);
                }
                ids[k + 1] = id;
            }
            samples.push(ids);
        }
        let (values, gradients) =
            values_and_gradients_or_differences(self.field, &self.points, tree.h * 1e-2);
        let close: Vec<bool> = values
            .iter()
            .zip(&gradients)
            .map(|(&v, g)| {
                let len = g.length();
                (v - self.iso).abs() <= self.tolerance * if len > 1e-12 { len } else { 1.0 }
            })
            .collect();
        let mut start = 0;
        stars
            .iter()
            .map(|star| {
                let ok = samples[start..start + star.len()].iter().flatten().all(|&p| close[p as usize]);
                start += star.len();
                ok
            })
            .collect()
    }

    /// Root-finds the crossings of `tris` not known yet, all at once.
    fn find_crossings(&mut self, tree: &Octree, tris: &[EdgeTriangle]) {
        let mut edges: Vec<(VertexKey, VertexKey)> =
            tris.iter().flatten().copied().filter(|e| !self.crossings.contains_key(e)).collect();
        // Sorted by one packed integer, in the order of the keys (node, then clamp).
        let packed = |k: VertexKey| (k.node as u128) << 8 | k.clamp as u128;
        edges.sort_unstable_by_key(|&(a, b)| packed(a) << 64 | packed(b));
        edges.dedup();
        let segments: Vec<Segment> = edges
            .iter()
            .map(|&(a, b)| {
                let ((pa, fa), (pb, fb)) = (self.vertex(tree, a), self.vertex(tree, b));
                Segment { inside: pa, outside: pb, f_inside: fa, f_outside: fb }
            })
            .collect();
        for ((e, s), t) in
            edges.into_iter().zip(&segments).zip(batch_roots(self.field, self.iso, &segments, ROOT_STEPS))
        {
            self.crossings.insert(e, s.inside + (s.outside - s.inside) * t);
        }
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
        let v = *self.values.entry(key).or_insert_with(|| super::dual::on_side(field.value(p) - iso, inside));
        (p, v)
    }
}

//! The geometric half of a merge test: the triangles a merge would make must stay within the
//! tolerance of the surface. The QEF bounds how well one vertex fits the leaf's tangent planes,
//! not where the dual grid's triangles go: a merged leaf's dual cells reach to its neighbours'
//! vertices, and their triangles can cut across a room's corner or a door's opening while the
//! vertex itself fits perfectly. So the star's triangles after the merge (from
//! [`super::safety`]) are built with their crossings root-found, as the contour will have them,
//! and each triangle's centroid and edge midpoints must lie within the tolerance of the surface
//! (first-order distance `|f - iso| / |∇f|`).
//!
//! Each star comes with its crossings already named ([`super::safety::Star`]: the safety test
//! names them to compare topologies), so the map of crossings found so far is asked once per
//! crossing of a star, not per triangle corner, and midpoints are named per star by sorting its
//! few edge pairs. Asked per corner (with a batch-wide map of midpoints), those maps were the
//! simplification's largest cost at fine resolutions: a sphere at 256 cells spent 1.0 s in this
//! test, 0.04 s of it root finding. Finding the crossings again instead of remembering them costs
//! more where the field is costly (the gear at 128 cells: simplification 560 -> 670 ms).

use super::contour::{batch_roots, Segment};
use super::dual::VertexKey;
use super::safety::{DualEdge, Star};
use super::tree::{Kind, Octree};
use crate::field::{values_and_gradients_or_differences, Field};
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// Regula falsi steps for the crossings the test estimates distances from: a distance estimate
/// needs them good to a small fraction of the tolerance, not to `f32` resolution.
const ROOT_STEPS: usize = 8;

pub struct Fidelity<'a> {
    pub field: &'a dyn Field,
    pub iso: f32,
    /// Largest accepted distance, world units.
    pub tolerance: f32,
    /// Every crossing found so far, by its dual edge: a dual edge keeps its ends until one of
    /// them is merged away (after which its key names nothing reachable), and stars of
    /// neighbouring candidates share many.
    crossings: HashMap<DualEdge, Vec3>,
    values: HashMap<VertexKey, f32>,
}

impl<'a> Fidelity<'a> {
    pub fn new(field: &'a dyn Field, iso: f32, tolerance: f32) -> Fidelity<'a> {
        Fidelity { field, iso, tolerance, crossings: HashMap::default(), values: HashMap::default() }
    }

    /// Per star (the triangles a merge would make, with the merged nodes' vertices already
    /// written into the tree), whether every triangle lies within the tolerance; all stars'
    /// crossings and sample points are found and evaluated in one batch each.
    pub fn within(&mut self, tree: &Octree, stars: &[Star]) -> Vec<bool> {
        // The stars' dual edges one after the other (stars of one batch share no dual cell, so an
        // edge two of them have is rare, and found twice), and per star its triangles' distinct
        // midpoints, named by sorting its few edge pairs.
        let mut edges: Vec<DualEdge> = Vec::new();
        let mut midpoints: Vec<(u32, u32)> = Vec::new();
        // Per triangle, its three corners' and then its three midpoints' indices.
        let mut triangles: Vec<[u32; 6]> = Vec::with_capacity(stars.iter().map(|s| s.triangles.len()).sum());
        let mut pairs = Vec::new();
        for star in stars {
            let first_edge = edges.len() as u32;
            edges.extend_from_slice(&star.edges);
            let first_midpoint = midpoints.len() as u32;
            let (distinct_midpoints, midpoint_of) = distinct(
                star.triangles.iter().flat_map(|t| {
                    [(0, 1), (1, 2), (2, 0)].map(|(i, j)| {
                        let (a, b) = (first_edge + t[i], first_edge + t[j]);
                        (a.min(b), a.max(b))
                    })
                }),
                &mut pairs,
            );
            midpoints.extend(distinct_midpoints);
            triangles.extend(star.triangles.iter().enumerate().map(|(i, t)| {
                std::array::from_fn(|k| {
                    if k < 3 {
                        first_edge + t[k]
                    } else {
                        first_midpoint + midpoint_of[3 * i + k - 3]
                    }
                })
            }));
        }
        let crossings = self.crossings(tree, &edges);
        let mut points: Vec<Vec3> = triangles
            .iter()
            .map(|t| (crossings[t[0] as usize] + crossings[t[1] as usize] + crossings[t[2] as usize]) / 3.0)
            .collect();
        points.extend(midpoints.iter().map(|&(a, b)| (crossings[a as usize] + crossings[b as usize]) * 0.5));
        let (values, gradients) = values_and_gradients_or_differences(self.field, &points, tree.h * 1e-2);
        let close: Vec<bool> = values
            .iter()
            .zip(&gradients)
            .map(|(&v, g)| {
                let len = g.length();
                (v - self.iso).abs() <= self.tolerance * if len > 1e-12 { len } else { 1.0 }
            })
            .collect();
        let centroids = triangles.len();
        let triangle_close =
            |t: usize| close[t] && triangles[t][3..].iter().all(|&m| close[centroids + m as usize]);
        let mut start = 0;
        stars
            .iter()
            .map(|star| {
                let ok = (start..start + star.triangles.len()).all(triangle_close);
                start += star.triangles.len();
                ok
            })
            .collect()
    }

    /// The crossings on `edges`, those not known yet root-found all at once.
    fn crossings(&mut self, tree: &Octree, edges: &[DualEdge]) -> Vec<Vec3> {
        let mut crossings = vec![Vec3::ZERO; edges.len()];
        let mut missing = Vec::new();
        for (i, e) in edges.iter().enumerate() {
            match self.crossings.get(e) {
                Some(&p) => crossings[i] = p,
                None => missing.push(i),
            }
        }
        let segments: Vec<Segment> = missing
            .iter()
            .map(|&i| {
                let (a, b) = edges[i];
                let ((pa, fa), (pb, fb)) = (self.vertex(tree, a), self.vertex(tree, b));
                Segment { inside: pa, outside: pb, f_inside: fa, f_outside: fb }
            })
            .collect();
        let roots = batch_roots(self.field, self.iso, &segments, ROOT_STEPS);
        for ((&i, s), t) in missing.iter().zip(&segments).zip(roots) {
            crossings[i] = s.inside + (s.outside - s.inside) * t;
            self.crossings.insert(edges[i], crossings[i]);
        }
        crossings
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

/// The distinct keys, sorted, and per key the index of its value among them (`slots`: a buffer).
fn distinct<K: Ord + Copy>(keys: impl Iterator<Item = K>, slots: &mut Vec<(K, u32)>) -> (Vec<K>, Vec<u32>) {
    slots.clear();
    slots.extend(keys.enumerate().map(|(i, k)| (k, i as u32)));
    slots.sort_unstable();
    let mut index = vec![0u32; slots.len()];
    let mut values: Vec<K> = Vec::new();
    for &(k, slot) in slots.iter() {
        if values.last() != Some(&k) {
            values.push(k);
        }
        index[slot as usize] = values.len() as u32 - 1;
    }
    (values, index)
}

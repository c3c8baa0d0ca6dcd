//! A bounding volume hierarchy over axis-aligned boxes, used to find every pair of overlapping boxes
//! without comparing all pairs.
//!
//! A hierarchy rather than a uniform grid because meshes mix triangle sizes freely (a cube's twelve
//! big faces next to a finely meshed sphere); median splits keep the depth at `log2(n)` whatever the
//! sizes, where a grid would have to pick one cell size for all.

use glam::Vec3;

/// A closed axis-aligned box. Boxes that merely touch overlap, so candidates are never missed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    pub fn of_points(points: &[Vec3]) -> Aabb {
        points.iter().fold(Aabb::EMPTY, |b, &p| Aabb { min: b.min.min(p), max: b.max.max(p) })
    }

    pub fn union(self, other: Aabb) -> Aabb {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    #[inline]
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
}

/// Leaves hold at most this many boxes: small enough that leaf-against-leaf work stays cheap, large
/// enough that the tree is not mostly inner nodes.
const LEAF_SIZE: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    /// Leaf: first item in `items`. Inner: index of the right child (the left one follows the node).
    first_or_right: u32,
    /// Items in the leaf; 0 marks an inner node.
    count: u32,
}

/// The hierarchy; item ids are indices into the box slice it was built from.
pub struct Bvh {
    nodes: Vec<Node>,
    items: Vec<u32>,
}

/// Node pairs [`Bvh::overlapping_pairs_until`] walks between two calls of its `tick`.
pub const PAIRS_PER_TICK: usize = 4096;

impl Bvh {
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1),
            items: (0..boxes.len() as u32).collect(),
        };
        if !boxes.is_empty() {
            let mut items = std::mem::take(&mut bvh.items);
            bvh.build_node(boxes, &mut items, 0);
            bvh.items = items;
        }
        bvh
    }

    /// Builds the subtree over `items` (which start at `offset` in the final item list), splitting
    /// at the median centre along the axis where the centres spread most.
    fn build_node(&mut self, boxes: &[Aabb], items: &mut [u32], offset: usize) -> u32 {
        let bounds = items.iter().fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
        let id = self.nodes.len() as u32;
        self.nodes.push(Node { bounds, first_or_right: offset as u32, count: items.len() as u32 });
        if items.len() <= LEAF_SIZE {
            return id;
        }
        let centers = items.iter().fold(Aabb::EMPTY, |b, &i| {
            let c = boxes[i as usize].center();
            Aabb { min: b.min.min(c), max: b.max.max(c) }
        });
        let spread = centers.max - centers.min;
        let axis = if spread.x >= spread.y && spread.x >= spread.z {
            0
        } else if spread.y >= spread.z {
            1
        } else {
            2
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |&a, &b| {
            let ca = boxes[a as usize].center()[axis];
            let cb = boxes[b as usize].center()[axis];
            ca.total_cmp(&cb)
        });
        let (left, right) = items.split_at_mut(mid);
        self.build_node(boxes, left, offset);
        let right_id = self.build_node(boxes, right, offset + mid);
        self.nodes[id as usize].first_or_right = right_id;
        self.nodes[id as usize].count = 0;
        id
    }

    /// Calls `visit(i, j)` once for every unordered pair `i != j` of overlapping boxes.
    pub fn overlapping_pairs(&self, boxes: &[Aabb], visit: impl FnMut(u32, u32)) {
        let Ok(()) = self.overlapping_pairs_until(boxes, visit, || Ok::<(), std::convert::Infallible>(()));
    }

    /// [`Bvh::overlapping_pairs`] that calls `tick` every [`PAIRS_PER_TICK`] node pairs and stops
    /// at its first error: the walk over a large mesh's boxes is long, and a page that abandons
    /// the request must be able to stop it.
    pub fn overlapping_pairs_until<E>(
        &self,
        boxes: &[Aabb],
        mut visit: impl FnMut(u32, u32),
        mut tick: impl FnMut() -> Result<(), E>,
    ) -> Result<(), E> {
        if self.nodes.is_empty() {
            return Ok(());
        }
        let mut stack = vec![(0u32, 0u32)];
        let mut popped = 0usize;
        while let Some(pair) = stack.pop() {
            popped += 1;
            if popped % PAIRS_PER_TICK == 0 {
                tick()?;
            }
            self.step(pair, boxes, &mut visit, |p| stack.push(p));
        }
        Ok(())
    }

    /// The pairs `(i, j)` of overlapping boxes for which `keep(i, j)` holds, each unordered pair
    /// once, in no particular order, found on the threads: the node pairs near the root are
    /// walked here until there are a few per thread, then each is walked on its own.
    pub fn overlapping_pairs_par(
        &self,
        boxes: &[Aabb],
        keep: impl Fn(u32, u32) -> bool + Sync,
    ) -> Vec<(u32, u32)> {
        let mut found = Vec::new();
        if self.nodes.is_empty() {
            return found;
        }
        let wanted = 16 * crate::par::threads();
        let mut frontier = std::collections::VecDeque::from([(0u32, 0u32)]);
        while frontier.len() < wanted {
            let Some(pair) = frontier.pop_front() else { break };
            let keep_pair = |i, j| {
                if keep(i, j) {
                    found.push((i, j));
                }
            };
            self.step(pair, boxes, keep_pair, |p| frontier.push_back(p));
        }
        let frontier: Vec<(u32, u32)> = frontier.into();
        let pieces = crate::par::map(frontier.len(), |k| {
            let mut out = Vec::new();
            let mut stack = vec![frontier[k]];
            while let Some(pair) = stack.pop() {
                let keep_pair = |i, j| {
                    if keep(i, j) {
                        out.push((i, j));
                    }
                };
                self.step(pair, boxes, keep_pair, |p| stack.push(p));
            }
            out
        });
        found.extend(pieces.into_iter().flatten());
        found
    }

    /// One node pair of the walk: `visit(i, j)` for the overlapping boxes of two leaves (or of
    /// one leaf with itself), `push` for the node pairs to walk next.
    fn step(
        &self,
        (a, b): (u32, u32),
        boxes: &[Aabb],
        mut visit: impl FnMut(u32, u32),
        push: impl FnMut((u32, u32)),
    ) {
        let (na, nb) = (self.nodes[a as usize], self.nodes[b as usize]);
        if a == b {
            if na.count > 0 {
                let leaf = self.leaf_items(&na);
                for (k, &i) in leaf.iter().enumerate() {
                    for &j in &leaf[k + 1..] {
                        if boxes[i as usize].overlaps(&boxes[j as usize]) {
                            visit(i, j);
                        }
                    }
                }
            } else {
                let (l, r) = (a + 1, na.first_or_right);
                [(l, l), (r, r), (l, r)].into_iter().for_each(push);
            }
            return;
        }
        if !na.bounds.overlaps(&nb.bounds) {
            return;
        }
        match (na.count > 0, nb.count > 0) {
            (true, true) => {
                for &i in self.leaf_items(&na) {
                    for &j in self.leaf_items(&nb) {
                        if boxes[i as usize].overlaps(&boxes[j as usize]) {
                            visit(i, j);
                        }
                    }
                }
            }
            // Descend the inner node; of two inner nodes, the one with the larger box.
            (false, true) => [(a + 1, b), (na.first_or_right, b)].into_iter().for_each(push),
            (true, false) => [(a, b + 1), (a, nb.first_or_right)].into_iter().for_each(push),
            (false, false) => {
                if half_area(&na.bounds) >= half_area(&nb.bounds) {
                    [(a + 1, b), (na.first_or_right, b)].into_iter().for_each(push);
                } else {
                    [(a, b + 1), (a, nb.first_or_right)].into_iter().for_each(push);
                }
            }
        }
    }

    /// Depth-first walk for queries against one object (a ray, a point): `key(state, bounds)` is
    /// `None` for a node whose subtree cannot matter and otherwise an ordering key (a distance along
    /// the ray, a squared distance to the point); children are visited smallest key first, and a
    /// node's key is asked again just before it is entered, so a `state` that improved meanwhile
    /// (a nearer hit) prunes it. `item(state, id)` is called for every item of each entered leaf.
    pub fn walk<S>(
        &self,
        state: &mut S,
        key: impl Fn(&S, &Aabb) -> Option<f32>,
        mut item: impl FnMut(&mut S, u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0u32];
        while let Some(id) = stack.pop() {
            let node = self.nodes[id as usize];
            if key(state, &node.bounds).is_none() {
                continue;
            }
            if node.count > 0 {
                for &i in self.leaf_items(&node) {
                    item(state, i);
                }
                continue;
            }
            let (l, r) = (id + 1, node.first_or_right);
            let (kl, kr) =
                (key(state, &self.nodes[l as usize].bounds), key(state, &self.nodes[r as usize].bounds));
            // Pushed last, popped first: the nearer child.
            match (kl, kr) {
                (Some(a), Some(b)) if a <= b => stack.extend([r, l]),
                (Some(_), Some(_)) => stack.extend([l, r]),
                (Some(_), None) => stack.push(l),
                (None, Some(_)) => stack.push(r),
                (None, None) => {}
            }
        }
    }

    fn leaf_items(&self, node: &Node) -> &[u32] {
        let start = node.first_or_right as usize;
        &self.items[start..start + node.count as usize]
    }
}

fn half_area(b: &Aabb) -> f32 {
    let d = b.max - b.min;
    d.x * d.y + d.y * d.z + d.z * d.x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic pseudo-random boxes of mixed sizes.
    fn boxes(n: usize) -> Vec<Aabb> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|i| {
                let c = Vec3::new(next(), next(), next()) * 10.0;
                let size = if i % 17 == 0 { 3.0 } else { 0.4 };
                let h = Vec3::new(next(), next(), next()) * size;
                Aabb { min: c - h, max: c + h }
            })
            .collect()
    }

    #[test]
    fn finds_exactly_the_brute_force_pairs() {
        for n in [0, 1, 2, 5, 37, 400] {
            let b = boxes(n);
            let bvh = Bvh::build(&b);
            let mut found = Vec::new();
            bvh.overlapping_pairs(&b, |i, j| found.push((i.min(j), i.max(j))));
            found.sort_unstable();
            let before = found.len();
            found.dedup();
            assert_eq!(found.len(), before, "a pair was reported twice");
            let mut expected = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    if b[i].overlaps(&b[j]) {
                        expected.push((i as u32, j as u32));
                    }
                }
            }
            assert_eq!(found, expected, "n = {n}");
            let mut on_threads: Vec<(u32, u32)> = bvh
                .overlapping_pairs_par(&b, |_, _| true)
                .into_iter()
                .map(|(i, j)| (i.min(j), i.max(j)))
                .collect();
            on_threads.sort_unstable();
            assert_eq!(on_threads, expected, "n = {n}, on the threads");
            let odd = bvh.overlapping_pairs_par(&b, |i, j| (i + j) % 2 == 1);
            assert_eq!(odd.len(), expected.iter().filter(|&&(i, j)| (i + j) % 2 == 1).count(), "n = {n}");
            if n == 400 {
                assert!(expected.len() > 100, "the test needs overlaps to mean anything");
            }
        }
    }

    #[test]
    fn walk_finds_the_nearest_box_like_brute_force() {
        let b = boxes(300);
        let bvh = Bvh::build(&b);
        let dist2 = |p: Vec3, a: &Aabb| (a.min - p).max(p - a.max).max(Vec3::ZERO).length_squared();
        for q in [Vec3::ZERO, Vec3::splat(5.0), Vec3::new(12.0, -3.0, 4.0)] {
            let mut best = (f32::INFINITY, u32::MAX, 0usize);
            bvh.walk(
                &mut best,
                |best, bounds| Some(dist2(q, bounds)).filter(|&d| d <= best.0),
                |best, i| {
                    best.2 += 1;
                    let d = dist2(q, &b[i as usize]);
                    if d < best.0 {
                        (best.0, best.1) = (d, i);
                    }
                },
            );
            let expected = b.iter().map(|a| dist2(q, a)).fold(f32::INFINITY, f32::min);
            assert_eq!(best.0, expected);
            assert!(best.2 < 150, "pruning visited {} of 300 boxes", best.2);
        }
        Bvh::build(&[]).walk(&mut (), |_, _| Some(0.0), |_, _| panic!("no items"));
    }

    #[test]
    fn touching_boxes_overlap() {
        let a = Aabb::of_points(&[Vec3::ZERO, Vec3::ONE]);
        let b = Aabb::of_points(&[Vec3::ONE, Vec3::splat(2.0)]);
        let c = Aabb::of_points(&[Vec3::new(1.001, 0.0, 0.0), Vec3::splat(2.0)]);
        assert!(a.overlaps(&b));
        assert!(!a.overlaps(&c));
    }
}

//! Which triangles lie near a box: a loose grid of cubes (a grid cell, a few edge lengths). A
//! triangle whose bounding box is no wider than a cube is recorded once, in the cube that holds
//! its box's low corner; a larger one in every cube its box overlaps. A query looks at the cubes
//! its box overlaps and those below as far as the widest small box reaches (where low corners of
//! small overlapping boxes can lie) and reports the recorded boxes that overlap its own. EMC's
//! flips and pull-backs, DMC's sliver pass and decimation each ask it, before they change a mesh,
//! which triangles a new one could cross.
//!
//! The triangles given at the start are one list of (cube, triangle) sorted by cube, so building
//! it is one sort and a query a binary search per cube; only the few triangles changed afterwards
//! go into a hash map. Three hash maps of per-cube lists, each triangle in every cube its box
//! touched (ten on average for EMC's fans, whose corners lie on cell faces), cost EMC two thirds
//! of its time on a sphere at 64 cells.

use glam::DVec3;
use rustc_hash::FxHashMap;

/// Triangle ids by where their bounding boxes lie, in cubes of side `cell`.
pub struct TriangleBuckets {
    cell: f64,
    /// (cube, slot) for every triangle given to [`TriangleBuckets::build`], sorted.
    built: Vec<(u64, u32)>,
    /// Slots recorded one by one after the build, each under the cubes of its last box (its
    /// entries in `built` may be stale: `boxes` says where it is).
    added: FxHashMap<u64, Vec<u32>>,
    /// Per triangle id, its slot in the per-slot lists below ([`NO_SLOT`]: never recorded). EMC
    /// records a third of a mesh's triangles or fewer, and per-id lists of boxes for all of them
    /// were most of the cost of building (memory touched for the first time).
    slot_of: Vec<u32>,
    /// Per slot: its triangle, its box as last recorded, whether it is recorded now, and whether
    /// it is in `added`.
    ids: Vec<u32>,
    boxes: Vec<(DVec3, DVec3)>,
    present: Vec<bool>,
    in_added: Vec<bool>,
    /// The largest extent, per axis, of a box recorded once (never more than a cube): how far
    /// below a query's box the low corner of one that overlaps it can lie.
    loose_extent: DVec3,
    /// Query stamps per slot, so a triangle listed twice is reported once.
    seen: Vec<u32>,
    stamp: u32,
}

/// Cube coordinates are kept within ±2²⁰, so that three fit one key.
const KEY_RANGE: i64 = 1 << 20;

/// [`TriangleBuckets::slot_of`] for a triangle that was never recorded.
const NO_SLOT: u32 = u32::MAX;

impl TriangleBuckets {
    /// Buckets of side `cell` over the triangles with these bounding boxes, ids 0, 1, 2, ….
    pub fn build(cell: f64, boxes: impl Iterator<Item = (DVec3, DVec3)>) -> TriangleBuckets {
        TriangleBuckets::build_some(cell, boxes.map(Some))
    }

    /// Buckets over the triangles given a box, ids 0, 1, 2, … (`None`: not recorded, until an
    /// [`insert`](Self::insert)).
    pub fn build_some(cell: f64, boxes: impl Iterator<Item = Option<(DVec3, DVec3)>>) -> TriangleBuckets {
        let mut count = 0;
        let recorded: Vec<(u32, DVec3, DVec3)> = boxes
            .inspect(|_| count += 1)
            .enumerate()
            .filter_map(|(id, b)| b.map(|(lo, hi)| (id as u32, lo, hi)))
            .collect();
        TriangleBuckets::build_sparse(cell, count, recorded)
    }

    /// Buckets over `count` triangles of which those in `recorded` (id and box, in increasing
    /// id) are recorded, until an [`insert`](Self::insert).
    pub fn build_sparse(cell: f64, count: usize, recorded: Vec<(u32, DVec3, DVec3)>) -> TriangleBuckets {
        let mut slot_of = vec![NO_SLOT; count];
        for (slot, &(id, _, _)) in recorded.iter().enumerate() {
            slot_of[id as usize] = slot as u32;
        }
        let slots = recorded.len();
        let mut out = TriangleBuckets {
            cell: if cell > 0.0 && cell.is_finite() { cell } else { 1.0 },
            built: Vec::with_capacity(slots),
            added: FxHashMap::default(),
            slot_of,
            ids: recorded.iter().map(|&(id, _, _)| id).collect(),
            boxes: recorded.into_iter().map(|(_, lo, hi)| (lo, hi)).collect(),
            present: vec![true; slots],
            in_added: vec![false; slots],
            loose_extent: DVec3::ZERO,
            seen: vec![0; slots],
            stamp: 0,
        };
        let mut built = std::mem::take(&mut out.built);
        let mut extent = DVec3::ZERO;
        for (slot, &(lo, hi)) in out.boxes.iter().enumerate() {
            out.for_cubes(lo, hi, |k| built.push((k, slot as u32)));
            extent = out.widen(extent, lo, hi);
        }
        out.loose_extent = extent;
        built.sort_unstable();
        out.built = built;
        out
    }

    /// `extent` widened by a box that is recorded once.
    fn widen(&self, extent: DVec3, lo: DVec3, hi: DVec3) -> DVec3 {
        if self.fits(lo, hi) {
            extent.max(hi - lo)
        } else {
            extent
        }
    }

    fn fits(&self, lo: DVec3, hi: DVec3) -> bool {
        (hi - lo).cmple(DVec3::splat(self.cell)).all()
    }

    /// The cubes a box is recorded in: the one of its low corner if it fits a cube, else all it
    /// overlaps.
    fn for_cubes(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(u64)) {
        let a = self.coords(lo);
        if self.fits(lo, hi) {
            return f(key(a));
        }
        let b = self.coords(hi);
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    f(key([x, y, z]));
                }
            }
        }
    }

    fn coords(&self, p: DVec3) -> [i64; 3] {
        p.to_array().map(|x| ((x / self.cell).floor() as i64).clamp(-KEY_RANGE, KEY_RANGE - 1) + KEY_RANGE)
    }

    /// The slot of triangle `id`, if it was ever recorded.
    fn slot(&self, id: u32) -> Option<usize> {
        self.slot_of.get(id as usize).filter(|&&s| s != NO_SLOT).map(|&s| s as usize)
    }

    /// Records triangle `id` with this bounding box (in place of any box it had).
    pub fn insert(&mut self, id: u32, lo: DVec3, hi: DVec3) {
        let s = match self.slot(id) {
            Some(s) => {
                self.unlist(s);
                s
            }
            None => {
                if id as usize >= self.slot_of.len() {
                    self.slot_of.resize(id as usize + 1, NO_SLOT);
                }
                self.slot_of[id as usize] = self.ids.len() as u32;
                self.ids.push(id);
                self.boxes.push((lo, hi));
                self.present.push(false);
                self.in_added.push(false);
                self.seen.push(0);
                self.ids.len() - 1
            }
        };
        self.boxes[s] = (lo, hi);
        self.present[s] = true;
        self.in_added[s] = true;
        self.loose_extent = self.widen(self.loose_extent, lo, hi);
        let mut keys = Vec::new();
        self.for_cubes(lo, hi, |k| keys.push(k));
        for k in keys {
            self.added.entry(k).or_default().push(s as u32);
        }
    }

    /// How many triangles are recorded now.
    #[cfg(test)]
    pub(crate) fn recorded(&self) -> usize {
        self.present.iter().filter(|&&p| p).count()
    }

    /// Forgets triangle `id`.
    pub fn remove(&mut self, id: u32) {
        if let Some(s) = self.slot(id) {
            self.unlist(s);
            self.present[s] = false;
        }
    }

    /// Takes slot `s` out of the lists in `added`, so that they hold no stale entries to scan.
    fn unlist(&mut self, s: usize) {
        if !self.in_added[s] {
            return;
        }
        self.in_added[s] = false;
        let (lo, hi) = self.boxes[s];
        let mut keys = Vec::new();
        self.for_cubes(lo, hi, |k| keys.push(k));
        for k in keys {
            if let Some(list) = self.added.get_mut(&k) {
                list.retain(|&u| u as usize != s);
            }
        }
    }

    /// Appends to `out` every recorded triangle whose box overlaps the box `[lo, hi]` grown by a
    /// thousandth of a cube (so that touching counts), each once, in no particular order.
    pub fn query(&mut self, lo: DVec3, hi: DVec3, out: &mut Vec<u32>) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.stamp = 1;
        }
        let margin = self.cell * 1e-3;
        let (lo, hi) = (lo - margin, hi + margin);
        let (a, b) = (self.coords(lo - self.loose_extent), self.coords(hi));
        let TriangleBuckets { built, added, ids, boxes, present, seen, stamp, .. } = self;
        let mut take = |&slot: &u32| {
            let s = slot as usize;
            let (blo, bhi) = boxes[s];
            if present[s] && seen[s] != *stamp && blo.cmple(hi).all() && bhi.cmpge(lo).all() {
                seen[s] = *stamp;
                out.push(ids[s]);
            }
        };
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                // One row of cubes is one run of keys.
                let (first, last) = (key([a[0], y, z]), key([b[0], y, z]));
                let start = built.partition_point(|&(k, _)| k < first);
                built[start..].iter().take_while(|&&(k, _)| k <= last).for_each(|(_, s)| take(s));
                if !added.is_empty() {
                    for x in a[0]..=b[0] {
                        added.get(&key([x, y, z])).into_iter().flatten().for_each(&mut take);
                    }
                }
            }
        }
    }
}

fn key([x, y, z]: [i64; 3]) -> u64 {
    ((z as u64) << 42) | ((y as u64) << 21) | x as u64
}

/// The bounding box of a triangle's corners.
pub fn bounds(corners: &[DVec3; 3]) -> (DVec3, DVec3) {
    (corners[0].min(corners[1]).min(corners[2]), corners[0].max(corners[1]).max(corners[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut ids: Vec<u32>) -> Vec<u32> {
        ids.sort_unstable();
        ids
    }

    #[test]
    fn finds_what_overlaps_and_forgets_what_was_removed() {
        let boxes = [
            (DVec3::ZERO, DVec3::new(1.0, 1.0, 0.5)),
            (DVec3::splat(5.0), DVec3::splat(6.0)),
            (DVec3::new(-3.0, -3.0, -3.0), DVec3::new(3.0, 3.0, 3.0)),
        ];
        let mut buckets = TriangleBuckets::build(1.0, boxes.into_iter());
        let mut out = Vec::new();
        buckets.query(DVec3::splat(0.2), DVec3::splat(0.3), &mut out);
        assert_eq!(sorted(out.clone()), vec![0, 2], "each once, though 2 spans many buckets");
        out.clear();
        buckets.query(DVec3::splat(5.5), DVec3::splat(5.5), &mut out);
        assert_eq!(out, vec![1]);
        // Move triangle 0 far away: found there, not where it was.
        buckets.remove(0);
        buckets.insert(0, DVec3::splat(-10.0), DVec3::splat(-9.5));
        out.clear();
        buckets.query(DVec3::splat(0.2), DVec3::splat(0.3), &mut out);
        assert_eq!(out, vec![2]);
        out.clear();
        buckets.query(DVec3::splat(-9.9), DVec3::splat(-9.8), &mut out);
        assert_eq!(out, vec![0]);
        // Removed again, from where it was added; and an id past the build.
        buckets.remove(0);
        buckets.insert(7, DVec3::splat(-10.0), DVec3::splat(-9.5));
        out.clear();
        buckets.query(DVec3::splat(-9.9), DVec3::splat(-9.8), &mut out);
        assert_eq!(out, vec![7]);
    }

    #[test]
    fn a_box_touching_a_bucket_side_is_found_from_both_sides() {
        let mut buckets =
            TriangleBuckets::build(1.0, [(DVec3::new(0.2, 0.2, 0.2), DVec3::new(1.0, 0.5, 0.5))].into_iter());
        let mut out = Vec::new();
        buckets.query(DVec3::new(1.0, 0.2, 0.2), DVec3::new(1.5, 0.5, 0.5), &mut out);
        assert_eq!(out, vec![0]);
    }

    #[test]
    fn agrees_with_a_brute_force_box_test_on_random_boxes() {
        let mut rng = crate::expr::testutil::Rng::new(5);
        let mut boxes: Vec<(DVec3, DVec3)> = (0..300)
            .map(|_| {
                let lo = rng.vec3(-4.0, 4.0).as_dvec3();
                (lo, lo + rng.vec3(0.0, 1.5).as_dvec3())
            })
            .collect();
        let mut buckets = TriangleBuckets::build(0.7, boxes.clone().into_iter());
        for step in 0..200 {
            if step % 2 == 0 {
                let id = rng.below(boxes.len());
                buckets.remove(id as u32);
                let lo = rng.vec3(-4.0, 4.0).as_dvec3();
                boxes[id] = (lo, lo + rng.vec3(0.0, 1.0).as_dvec3());
                buckets.insert(id as u32, boxes[id].0, boxes[id].1);
            }
            let lo = rng.vec3(-4.0, 4.0).as_dvec3();
            let hi = lo + rng.vec3(0.0, 1.0).as_dvec3();
            let mut found = Vec::new();
            buckets.query(lo, hi, &mut found);
            let found = sorted(found);
            for (id, &(blo, bhi)) in boxes.iter().enumerate() {
                let overlaps = !(blo.cmpgt(hi).any() || bhi.cmplt(lo).any());
                let far = blo.cmpgt(hi + 0.01).any() || bhi.cmplt(lo - 0.01).any();
                let reported = found.binary_search(&(id as u32)).is_ok();
                assert!(!overlaps || reported, "box {id} missed at step {step}");
                assert!(!far || !reported, "box {id} far off reported at step {step}");
            }
            let mut unique = found.clone();
            unique.dedup();
            assert_eq!(unique, found, "each id once");
        }
    }
}

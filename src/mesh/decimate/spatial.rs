//! A uniform hash grid of triangle ids for finding the faces near a proposed collapse.
//!
//! A grid rather than the analysis's BVH because the faces move and change shape after every
//! collapse: a moved face is simply inserted again into the cells of its new box, and stale
//! entries stay behind, to be filtered by the caller's alive flags and a box test. Decimation only
//! grows faces, so the cell size chosen from the input's edges keeps every query small.

use glam::DVec3;
use std::collections::HashMap;

pub struct SpatialGrid {
    cell: f64,
    cells: HashMap<[i32; 3], Vec<u32>>,
    /// Query stamps per face id, so a face listed in several cells is reported once.
    seen: Vec<u32>,
    stamp: u32,
}

impl SpatialGrid {
    pub fn new(cell: f64, faces: usize) -> SpatialGrid {
        SpatialGrid {
            cell: cell.max(f64::MIN_POSITIVE),
            cells: HashMap::new(),
            seen: vec![0; faces],
            stamp: 0,
        }
    }

    fn key(&self, p: DVec3) -> [i32; 3] {
        let k = (p / self.cell).floor();
        [k.x as i32, k.y as i32, k.z as i32]
    }

    fn for_cells(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut([i32; 3])) {
        let (a, b) = (self.key(lo), self.key(hi));
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    f([x, y, z]);
                }
            }
        }
    }

    pub fn insert(&mut self, face: u32, lo: DVec3, hi: DVec3) {
        let mut keys = Vec::new();
        self.for_cells(lo, hi, |k| keys.push(k));
        for k in keys {
            let list = self.cells.entry(k).or_default();
            if list.last() != Some(&face) {
                list.push(face);
            }
        }
    }

    /// Every face id ever inserted into a cell that the box `[lo, hi]` touches, each once.
    pub fn query(&mut self, lo: DVec3, hi: DVec3, out: &mut Vec<u32>) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.stamp = 1;
        }
        let mut keys = Vec::new();
        self.for_cells(lo, hi, |k| keys.push(k));
        for k in keys {
            if let Some(list) = self.cells.get(&k) {
                for &f in list {
                    if self.seen[f as usize] != self.stamp {
                        self.seen[f as usize] = self.stamp;
                        out.push(f);
                    }
                }
            }
        }
    }
}

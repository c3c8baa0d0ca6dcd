//! The collapse candidates, cheapest first. Entries go stale as vertices move (a lazy-deletion
//! heap: each collapse pushes its new edges and leaves the old ones to be skipped), so the heap
//! grows to several times the edge count, and popping from it was a quarter of decimation's time,
//! most of it moving 48-byte candidates up and down the heap. The heap holds only each
//! candidate's cost and its slot in a side table; the pops compare the same costs in the same
//! order, so the collapses come out as before.

use glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Collapse `remove` into `keep`, moving `keep` to `target`; stale once either vertex's stamp has
/// moved on.
#[derive(Clone, Copy)]
pub(super) struct Candidate {
    pub cost: f64,
    pub remove: u32,
    pub keep: u32,
    pub target: DVec3,
    pub stamps: [u32; 2],
}

/// A heap entry: a cost and the slot of its candidate.
struct Entry {
    cost: f64,
    slot: u32,
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    /// Reversed, so the max-heap pops the cheapest collapse.
    fn cmp(&self, other: &Self) -> Ordering {
        other.cost.total_cmp(&self.cost)
    }
}

/// Candidates by cost, the cheapest out first.
#[derive(Default)]
pub(super) struct Queue {
    heap: BinaryHeap<Entry>,
    slots: Vec<Candidate>,
    /// Slots whose candidates were popped, for reuse.
    free: Vec<u32>,
}

impl Queue {
    pub fn push(&mut self, candidate: Candidate) {
        let slot = match self.free.pop() {
            Some(slot) => {
                self.slots[slot as usize] = candidate;
                slot
            }
            None => {
                self.slots.push(candidate);
                (self.slots.len() - 1) as u32
            }
        };
        self.heap.push(Entry { cost: candidate.cost, slot });
    }

    pub fn pop(&mut self) -> Option<Candidate> {
        let Entry { slot, .. } = self.heap.pop()?;
        self.free.push(slot);
        Some(self.slots[slot as usize])
    }
}

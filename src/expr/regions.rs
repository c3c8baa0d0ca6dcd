//! Tape specialisation per region: a program specialised on every brick of a box, for meshers that
//! query it many times in the same place.
//!
//! A CSG part of fifty primitives is a tape of hundreds of instructions, and almost all of it is
//! irrelevant near any one point: away from a tooth, the tooth's `min` never wins. Interval
//! arithmetic over a box proves which operand of each `min`/`max` wins throughout it
//! ([`Program::eval_interval_with_choices`]); dropping the losers gives a tape that is a fraction
//! of the length there and equal to the full one, bit for bit, at every point of the box.
//!
//! [`RegionalProgram`] keeps an octree of such tapes over the meshing bounds, built lazily: a
//! brick's tape is specialised from its parent's (so each step works on an already short tape and
//! a subtree that proves nothing shares its parent's), and only bricks somebody queries are ever
//! built, which for a mesher is the crust around the surface. Every [`Field`] query goes to the
//! deepest brick that holds it: points and batches to a leaf, interval boxes to the smallest
//! brick containing them, so the crust traversals carry the shortened tapes down without knowing.
//! Queries outside the bounds use the full program.

use super::program::Program;
use crate::field::Field;
use glam::Vec3;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

/// Deepest level built: 64³ leaf bricks on a cubic box (300 000 over all levels, 7 MB), bricks of
/// four cells at 256³.
pub const MAX_DEPTH: u8 = 6;

/// A brick's box is widened by this fraction of its size on each side before the interval is
/// taken, so points that rounding puts a hair outside their brick are still covered.
const PAD: f32 = 1e-3;

pub struct RegionalProgram<'a> {
    full: &'a Program,
    lo: Vec3,
    /// Side of the (cubic) leaf bricks; a brick of level `l` is `2^(depth - l)` of them.
    leaf: f32,
    depth: u8,
    /// Bricks per axis at each level: cubic bricks cover a non-cubic box with fewer along its
    /// short sides, the last one reaching past the box.
    counts: Vec<[usize; 3]>,
    /// `levels[l]` holds the bricks of level `l`, x fastest; level 0 is one brick holding the box.
    levels: Vec<Vec<Brick>>,
    /// Tapes shorter than this are not specialised further ([`SHORT_TAPE`]).
    short: usize,
}

#[derive(Default)]
struct Brick {
    tape: OnceLock<Arc<Program>>,
    /// Point evaluations asked of the brick before its tape was built.
    asked: AtomicU32,
}

/// Building a brick's tape costs about as much as a few point evaluations on its parent's tape
/// (one interval evaluation and one pass over it), and each later evaluation saves the part the
/// brick drops. A brick is built once it has been asked for this much work: a point evaluation
/// counts [`POINT_WORK`], a batch of `n` points `n / 4` (columns run about four times faster per
/// point) and an interval [`INTERVAL_WORK`]. Far from the surface, where a mesher asks little,
/// bricks keep their parent's tape.
const WORTH_BUILDING: u32 = 16;

/// A point evaluation counts as this much work. EMC's crease walks evaluate a handful of points
/// in each brick they pass, which counted as one each left a tenth of the gear's point queries at
/// 64 cells on a parent's tape of 287 instructions or more (built leaves: median 45), and building
/// after four points cuts EMC's instructions there by 5.6 % (callgrind, one thread: 1 225 ->
/// 1 157 M; the gear at 32 cells -2.4 %; at 128, DMC at 64, the fandisk, the cube with cut-outs,
/// the rocket and the milling within 0.3 %). Building on the first point: -7.0 % and -2.8 %, but
/// DMC +0.9 %.
const POINT_WORK: u32 = 4;

/// An interval evaluation counts as this many point evaluations: it costs about as much as a
/// dozen (the crust's measure). Counted as two, a crust traversal that bounds each box once built
/// a brick's tape only after eight of its boxes had been bounded on the parent's (gear, DMC at
/// depth 6: 3.63 G instructions, 3.36 G at eight).
const INTERVAL_WORK: u32 = 8;

/// Tapes shorter than this are not specialised further.
const SHORT_TAPE: usize = 48;

/// Batches of this many points or more are evaluated in pieces on several threads.
const PARALLEL_BATCH: usize = 8192;

/// Points per piece of a parallel batch: a piece is still a long batch (its per-call costs,
/// grouping by brick, are small beside it), and a batch of `PARALLEL_BATCH` makes two.
const PIECE: usize = PARALLEL_BATCH / 2;

impl<'a> RegionalProgram<'a> {
    /// Specialises `full` over the box `lo..hi` down to `depth` levels (at most [`MAX_DEPTH`]).
    pub fn new(full: &'a Program, lo: Vec3, hi: Vec3, depth: u8) -> RegionalProgram<'a> {
        Self::with_short_tape(full, lo, hi, depth, SHORT_TAPE)
    }

    /// [`RegionalProgram::new`], specialising no tape shorter than `short` (the tests take 0).
    fn with_short_tape(
        full: &'a Program,
        lo: Vec3,
        hi: Vec3,
        depth: u8,
        short: usize,
    ) -> RegionalProgram<'a> {
        // A short program gains less than the lookups cost (measured: the cube minus a ball, 28
        // instructions, meshed 1.4x slower through bricks); it is run as it is.
        let depth = if full.instruction_count() < short { 0 } else { depth.min(MAX_DEPTH) };
        let extent = (hi - lo).max(Vec3::ZERO);
        let leaf = (extent.max_element() / (1u32 << depth) as f32).max(f32::MIN_POSITIVE);
        let leaf_counts = [0, 1, 2].map(|a| ((extent[a] / leaf).ceil() as usize).clamp(1, 1 << depth));
        let counts: Vec<[usize; 3]> =
            (0..=depth).map(|l| leaf_counts.map(|n| n.div_ceil(1 << (depth - l)))).collect();
        let levels =
            counts.iter().map(|c| (0..c[0] * c[1] * c[2]).map(|_| Brick::default()).collect()).collect();
        RegionalProgram { full, lo, leaf, depth, counts, levels, short }
    }

    /// The depth whose leaf bricks are about `cells_per_brick` cells of a grid of `res` cells on
    /// its longest side: small enough to specialise well, large enough that building a brick's tape
    /// (one interval evaluation and one pass over its parent's) is paid back by its points.
    pub fn depth_for(res: usize, cells_per_brick: usize) -> u8 {
        let bricks = (res / cells_per_brick.max(1)).max(1);
        (usize::BITS - 1 - bricks.leading_zeros()).min(MAX_DEPTH as u32) as u8
    }

    fn index(&self, level: u8, [i, j, k]: [usize; 3]) -> usize {
        let [nx, ny, _] = self.counts[level as usize];
        (k * ny + j) * nx + i
    }

    fn side(&self, level: u8) -> f32 {
        self.leaf * (1u32 << (self.depth - level)) as f32
    }

    /// The corners of brick `ijk` of `level`, widened by [`PAD`].
    fn brick_box(&self, level: u8, ijk: [usize; 3]) -> (Vec3, Vec3) {
        let side = self.side(level);
        let lo = self.lo + Vec3::new(ijk[0] as f32, ijk[1] as f32, ijk[2] as f32) * side;
        (lo - Vec3::splat(side * PAD), lo + Vec3::splat(side * (1.0 + PAD)))
    }

    /// The tape for a query of `work` (see [`WORTH_BUILDING`]) in brick `ijk`
    /// of `level`: the brick's own once it has been asked for enough work to pay for building it,
    /// until then its nearest built ancestor's (equal there too, only longer).
    fn tape(&self, level: u8, ijk: [usize; 3], work: u32) -> &Arc<Program> {
        let brick = &self.levels[level as usize][self.index(level, ijk)];
        if let Some(tape) = brick.tape.get() {
            return tape;
        }
        if level == 0 {
            return brick.tape.get_or_init(|| Arc::new(self.full.clone()));
        }
        let parent = self.tape(level - 1, ijk.map(|c| c / 2), work);
        if parent.instruction_count() < self.short {
            return parent;
        }
        if brick.asked.fetch_add(work, Ordering::Relaxed).saturating_add(work) < WORTH_BUILDING {
            return parent;
        }
        brick.tape.get_or_init(|| {
            let (lo, hi) = self.brick_box(level, ijk);
            let (_, choices) = parent.eval_interval_with_choices(lo, hi);
            match parent.specialize(&choices) {
                Some(lean) => Arc::new(lean),
                None => parent.clone(),
            }
        })
    }

    /// The leaf brick holding `p`, or `None` outside the (padded) bricks.
    fn leaf_of(&self, p: Vec3) -> Option<[usize; 3]> {
        let n = self.counts[self.depth as usize];
        let t = (p - self.lo) / self.leaf;
        let mut ijk = [0usize; 3];
        for axis in 0..3 {
            // Widened bricks cover a hair past the bounds: from brick -1 to brick n, whose
            // points lie in [-1, n + 1) in brick units; NaN fails both tests and goes out. The
            // cast truncates, which is `floor` where `max` has left the value non-negative
            // (`floor` itself is a library call on the baseline x86-64 target, a fifth of the
            // look-up's time for every point of every batch).
            let c = t[axis];
            if !(c >= -1.0 && c < (n[axis] + 1) as f32) {
                return None;
            }
            ijk[axis] = (c.max(0.0) as usize).min(n[axis] - 1);
        }
        let (lo, hi) = self.brick_box(self.depth, ijk);
        (p.cmpge(lo).all() && p.cmple(hi).all()).then_some(ijk)
    }

    fn program_at(&self, p: Vec3) -> &Program {
        if self.depth == 0 {
            return self.full;
        }
        match self.leaf_of(p) {
            Some(ijk) => self.tape(self.depth, ijk, POINT_WORK),
            None => self.full,
        }
    }

    /// The tape of the deepest brick whose (padded) box contains the box `lo..hi`: the leaf
    /// brick holding the box's centre, or the first of its ancestors that holds the whole box.
    /// Meshers bound whole cells, which share their faces with the bricks' (up to rounding): the
    /// padding keeps such a box in its own brick, where placing it by its corners would put it
    /// in the common ancestor of the bricks on both sides of a face, often the root.
    fn program_over(&self, lo: Vec3, hi: Vec3) -> &Program {
        if self.depth == 0 {
            return self.full;
        }
        let Some(mut at) = self.leaf_of((lo + hi) * 0.5) else { return self.full };
        let mut level = self.depth;
        loop {
            let (blo, bhi) = self.brick_box(level, at);
            if lo.cmpge(blo).all() && hi.cmple(bhi).all() {
                return self.tape(level, at, INTERVAL_WORK);
            }
            if level == 0 {
                return self.full;
            }
            level -= 1;
            at = at.map(|c| c / 2);
        }
    }

    /// Instruction counts of the full tape and of every leaf brick's tape built so far.
    pub fn tape_lengths(&self) -> TapeLengths {
        let mut leaves: Vec<usize> = self.levels[self.depth as usize]
            .iter()
            .filter_map(|brick| brick.tape.get().map(|p| p.instruction_count()))
            .collect();
        leaves.sort_unstable();
        TapeLengths { full: self.full.instruction_count(), leaves }
    }

    /// Runs `eval` on each group of `points` that share a leaf brick, through that brick's tape;
    /// `out[i]` gets point `i`'s result.
    ///
    /// A batch of [`PARALLEL_BATCH`] points or more (DMC's sample lattice, its root finding and
    /// distance tests) is cut into pieces of [`PIECE`] evaluated on several threads
    /// ([`crate::par`]): a point's result depends only on the point (every brick's tape gives the
    /// full tape's values), so the pieces change nothing but the time.
    fn batched<O: Copy + Default + Send>(
        &self,
        points: &[Vec3],
        out: &mut [O],
        eval: impl Fn(&Program, &[Vec3], &mut [O]) + Sync + Send,
    ) {
        let n = points.len().min(out.len());
        if n >= PARALLEL_BATCH {
            crate::par::map_chunks_mut(&mut out[..n], PIECE, |c, piece| {
                self.batched_by_brick(&points[c * PIECE..c * PIECE + piece.len()], piece, &eval)
            });
        } else {
            self.batched_by_brick(&points[..n], &mut out[..n], &eval);
        }
    }

    /// [`RegionalProgram::batched`] on this thread.
    fn batched_by_brick<O: Copy + Default>(
        &self,
        points: &[Vec3],
        out: &mut [O],
        eval: &impl Fn(&Program, &[Vec3], &mut [O]),
    ) {
        let n = points.len().min(out.len());
        if self.depth == 0 {
            return eval(self.full, &points[..n], &mut out[..n]);
        }
        let keys: Vec<usize> = points[..n]
            .iter()
            .map(|&p| self.leaf_of(p).map_or(usize::MAX, |ijk| self.index(self.depth, ijk)))
            .collect();
        let [nx, ny, _] = self.counts[self.depth as usize];
        let program = |key: usize, points: usize| -> &Program {
            if key == usize::MAX {
                return self.full;
            }
            self.tape(self.depth, [key % nx, key / nx % ny, key / (nx * ny)], (points / 4).max(1) as u32)
        };
        if keys.windows(2).all(|w| w[0] == w[1]) {
            if let Some(&key) = keys.first() {
                eval(program(key, n), &points[..n], &mut out[..n]);
            }
            return;
        }
        // A tile of a grid spans a handful of bricks: group by a linear scan over the few keys
        // seen; a batch scattered over many bricks is sorted instead.
        let mut distinct: Vec<usize> = Vec::new();
        for &key in &keys {
            if !distinct.contains(&key) {
                distinct.push(key);
                if distinct.len() > 32 {
                    break;
                }
            }
        }
        let order: Vec<usize> = if distinct.len() > 32 {
            // Key and index packed into one word (keys are brick numbers, far under 2³², and
            // `usize::MAX` for outside becomes `u32::MAX`): a plain integer sort. Sorting the
            // indices by a look-up of their keys was 3 % of DMC's instructions on the gear.
            if n > u32::MAX as usize {
                let mut order: Vec<usize> = (0..n).collect();
                order.sort_unstable_by_key(|&i| keys[i]);
                order
            } else {
                let mut packed: Vec<u64> =
                    keys.iter().enumerate().map(|(i, &k)| ((k as u32 as u64) << 32) | i as u64).collect();
                packed.sort_unstable();
                packed.into_iter().map(|w| (w & u64::from(u32::MAX)) as usize).collect()
            }
        } else {
            // A counting sort over the distinct keys' positions.
            let group: Vec<usize> =
                keys.iter().map(|k| distinct.iter().position(|d| d == k).expect("seen")).collect();
            let mut next = vec![0usize; distinct.len() + 1];
            for &g in &group {
                next[g + 1] += 1;
            }
            for g in 1..next.len() {
                next[g] += next[g - 1];
            }
            let mut order = vec![0usize; n];
            for (i, &g) in group.iter().enumerate() {
                order[next[g]] = i;
                next[g] += 1;
            }
            order
        };
        // Bricks without a tape of their own run their ancestor's: their points are one batch
        // on it, however many bricks they came from (short groups run point by point).
        let runs: Vec<&[usize]> = order.chunk_by(|&a, &b| keys[a] == keys[b]).collect();
        let mut by_tape: Vec<(&Program, usize)> =
            runs.iter().enumerate().map(|(r, run)| (program(keys[run[0]], run.len()), r)).collect();
        by_tape.sort_by_key(|&(tape, r)| (tape as *const Program as usize, r));
        let mut group_points = Vec::with_capacity(n);
        let mut group_out = Vec::with_capacity(n);
        for same in by_tape.chunk_by(|a, b| std::ptr::eq(a.0, b.0)) {
            let (tape, members) = (same[0].0, same.iter().map(|&(_, r)| r));
            group_points.clear();
            group_points.extend(members.clone().flat_map(|r| runs[r].iter().map(|&i| points[i])));
            group_out.clear();
            group_out.resize(group_points.len(), O::default());
            eval(tape, &group_points, &mut group_out);
            for (&i, &v) in members.flat_map(|r| runs[r].iter()).zip(&group_out) {
                out[i] = v;
            }
        }
    }
}

/// How long the specialised tapes got: what the speed-up rests on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TapeLengths {
    pub full: usize,
    /// One entry per leaf brick built, ascending.
    pub leaves: Vec<usize>,
}

impl TapeLengths {
    /// The `q`-quantile (0 to 1) of the leaf tapes' lengths, or the full length if none was built.
    pub fn quantile(&self, q: f64) -> usize {
        if self.leaves.is_empty() {
            return self.full;
        }
        let i = ((self.leaves.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
        self.leaves[i]
    }
}

impl Field for RegionalProgram<'_> {
    fn value(&self, p: Vec3) -> f32 {
        self.program_at(p).eval(p)
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        Some(self.program_at(p).eval_grad(p).1)
    }

    fn value_and_gradient(&self, p: Vec3) -> (f32, Option<Vec3>) {
        let (v, g) = self.program_at(p).eval_grad(p);
        (v, Some(g))
    }

    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        self.batched(points, out, |program, p, o| program.eval_many(p, o));
    }

    fn gradients(&self, points: &[Vec3], out: &mut [Option<Vec3>]) {
        self.batched(points, out, |program, p, o| program.gradients(p, o));
    }

    fn values_and_gradients(&self, points: &[Vec3], values: &mut [f32], gradients: &mut [Option<Vec3>]) {
        let mut both = vec![(0.0, Vec3::ZERO); points.len().min(values.len()).min(gradients.len())];
        self.batched(points, &mut both, |program, p, o| program.eval_value_grad_many(p, o));
        super::field::unzip_into(&both, values, gradients);
    }

    fn interval(&self, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
        Some(self.program_over(lo, hi).eval_interval(lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use super::super::testutil::{Rng, CASES};
    use super::*;
    use crate::scenes;

    fn random_point(rng: &mut Rng, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * rng.vec3(0.0, 1.0)
    }

    /// The promise everything rests on: wherever a specialised tape is used, its value and its
    /// gradient are the full tape's, bit for bit.
    #[test]
    fn specialised_tapes_agree_bit_for_bit_with_the_full_one() {
        let mut rng = Rng::new(41);
        let gear = scenes::scene("gear").unwrap();
        let mut programs: Vec<(Program, Vec3, Vec3)> =
            CASES.iter().map(|c| (compile(c).unwrap(), Vec3::splat(-1.0), Vec3::ONE)).collect();
        programs.push((compile(gear.source).unwrap(), gear.min, gear.max));
        for (program, lo, hi) in &programs {
            let regional = RegionalProgram::with_short_tape(program, *lo, *hi, 4, 0);
            let points: Vec<Vec3> = (0..2000).map(|_| random_point(&mut rng, *lo, *hi)).collect();
            let mut batch = vec![0.0; points.len()];
            regional.values(&points, &mut batch);
            let mut grads = vec![None; points.len()];
            regional.gradients(&points, &mut grads);
            let (mut both_values, mut both_grads) = (vec![0.0; points.len()], vec![None; points.len()]);
            regional.values_and_gradients(&points, &mut both_values, &mut both_grads);
            for (i, &p) in points.iter().enumerate() {
                let (v, g) = program.eval_grad(p);
                let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                assert!(same(regional.value(p), program.eval(p)), "value at {p}:\n{program}");
                assert!(same(batch[i], program.eval(p)), "batched value at {p}");
                let rg = regional.gradient(p).unwrap();
                let bg = grads[i].unwrap();
                for axis in 0..3 {
                    assert!(same(rg[axis], g[axis]) && same(bg[axis], g[axis]), "gradient at {p}");
                }
                assert!(same(regional.value(p), v));
                assert!(same(both_values[i], v), "value in one pass with the gradient at {p}");
                let both = both_grads[i].unwrap();
                assert!((0..3).all(|axis| same(both[axis], g[axis])), "gradient in one pass at {p}");
            }
        }
    }

    #[test]
    fn intervals_over_sub_boxes_stay_conservative() {
        let mut rng = Rng::new(42);
        let gear = scenes::scene("gear").unwrap();
        let program = compile(gear.source).unwrap();
        let regional = RegionalProgram::with_short_tape(&program, gear.min, gear.max, 5, 0);
        for _ in 0..300 {
            let a = random_point(&mut rng, gear.min, gear.max);
            let size = (gear.max - gear.min) * rng.range(0.0, 0.1);
            let b = (a + size).min(gear.max);
            let (lo, hi) = regional.interval(a, b).unwrap();
            for _ in 0..20 {
                let v = program.eval(random_point(&mut rng, a, b));
                assert!(lo <= v && v <= hi, "{v} outside [{lo}, {hi}] over {a}..{b}");
            }
        }
    }

    #[test]
    fn the_gear_specialises_to_a_fraction_of_its_tape() {
        let gear = scenes::scene("gear").unwrap();
        let program = compile(gear.source).unwrap();
        let regional = RegionalProgram::new(&program, gear.min, gear.max, 4);
        let grid = crate::grid::Grid::with_resolution(gear.min, gear.max, 64).unwrap();
        crate::field::sample_grid(&regional, &grid).unwrap();
        let lengths = regional.tape_lengths();
        // Bricks that got fewer points than pay for their tape (along the grid's last planes,
        // where bricks and tiles do not line up) keep their parent's.
        // Cubic bricks of 0.1: 16 x 16 x 6 over the gear's box.
        assert_eq!(regional.counts[4], [16, 16, 6]);
        assert!(lengths.leaves.len() > 16 * 16 * 6 / 2, "{} bricks built", lengths.leaves.len());
        // Bricks of 0.1 still hold several teeth and holes' worth of tape near the rim.
        assert!(lengths.quantile(0.5) * 3 < lengths.full, "{lengths:?}");
        assert!(lengths.quantile(0.9) * 2 < lengths.full, "{lengths:?}");
        assert!(lengths.quantile(0.0) < 20, "beside one tooth a brick is a few primitives: {lengths:?}");
    }

    /// Meshers bound whole cells, and cells share their faces with the bricks: a box that ends
    /// on its brick's far face is that brick's, not the common ancestor's of the bricks beyond
    /// the face (before, that was often the root: the full tape for most of a crust's boxes).
    #[test]
    fn a_box_ending_on_its_bricks_far_faces_is_bounded_with_the_bricks_tape() {
        let gear = scenes::scene("gear").unwrap();
        let regional = RegionalProgram::new(&gear.field, gear.min, gear.max, 4);
        let full = gear.field.instruction_count();
        let mut shorter = 0;
        for i in 0..16 {
            // Brick (i, 8, 2) and the cells of it that touch its far corner and its near corner.
            let side = regional.side(4);
            let lo = regional.lo + Vec3::new(i as f32, 8.0, 2.0) * side;
            let (hi, cell) = (lo + Vec3::splat(side), Vec3::splat(side / 4.0));
            for (a, b) in [(lo, hi), (hi - cell, hi), (lo, lo + cell)] {
                for _ in 0..3 {
                    let tape = regional.program_over(a, b);
                    assert!(tape.instruction_count() <= full);
                }
                let tape = regional.program_over(a, b);
                assert!(std::ptr::eq(tape, &**regional.tape(4, [i, 8, 2], 0)), "brick {i}: {a} .. {b}");
                shorter += (tape.instruction_count() < full) as usize;
            }
        }
        assert!(shorter > 16, "{shorter} of 48 boxes on a specialised tape");
    }

    #[test]
    fn points_outside_the_bounds_use_the_full_program() {
        let program = compile("union(sphere(0.5), translate(sphere(0.2), 3, 0, 0))").unwrap();
        let regional = RegionalProgram::new(&program, Vec3::splat(-1.0), Vec3::ONE, 3);
        let far = Vec3::new(3.0, 0.0, 0.0);
        assert_eq!(regional.value(far), program.eval(far));
        assert!(regional.value(far) < 0.0);
        assert_eq!(regional.value(Vec3::NAN).is_nan(), program.eval(Vec3::NAN).is_nan());
    }

    #[test]
    fn depth_matches_the_requested_brick_size() {
        assert_eq!(RegionalProgram::depth_for(64, 4), 4);
        assert_eq!(RegionalProgram::depth_for(100, 4), 4);
        assert_eq!(RegionalProgram::depth_for(3, 4), 0);
        assert_eq!(RegionalProgram::depth_for(256, 4), 6);
        assert_eq!(RegionalProgram::depth_for(4096, 4), MAX_DEPTH);
    }
}

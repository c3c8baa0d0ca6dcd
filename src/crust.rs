//! The adaptive "crust" traversal of EMC §2: refine only the parts of the grid that can contain the
//! surface, and evaluate the field only at the corners of the finest cells that do. MC and EMC
//! both sample fields through it.
//!
//! The result is sample-for-sample what the uniform grid would give wherever the surface is: a box
//! whose interval bounds exclude the iso-level has every value of one sign, so its points get a
//! stand-in value of that sign (the bound nearest the iso-level), and a cell of such a box has no
//! sign change on either grid. Cells that may hold the surface are evaluated exactly.

use crate::error::Error;
use crate::field::Field;
use crate::grid::Grid;

/// Boxes at most this many cells on a side are sampled without further bounding.
const LEAF_CELLS: usize = 4;

/// Samples for a whole grid, of which only the crust was evaluated.
pub struct CrustSamples {
    pub values: Vec<f32>,
    /// Points where the field was actually evaluated.
    pub evaluated: usize,
    /// Interval evaluations made by the traversal.
    pub interval_queries: usize,
}

/// Samples `field` on `grid` through the crust traversal, or `None` when the field gives no
/// interval bounds (then the caller samples every point).
pub fn sample_crust(field: &dyn Field, grid: &Grid, iso: f32) -> Option<Result<CrustSamples, Error>> {
    field.interval(grid.origin, grid.origin + grid.spacing)?;
    let traversal = Traversal { field, grid, iso, within: crate::field::level_tolerance(grid, iso) };
    let (boxes, interval_queries) = traversal.boxes([0, 0, 0], grid.cells);
    let samples = Samples::from_boxes(grid, &boxes);
    Some(samples.finish(field, interval_queries))
}

/// What the traversal decided for a box of cells (indices, half-open).
enum Decided {
    /// The level is outside the interval bound: every point has `value`'s sign.
    Fill { lo: [usize; 3], hi: [usize; 3], value: f32 },
    /// A box of a few cells that may hold the surface: its points are evaluated.
    Surface { lo: [usize; 3], hi: [usize; 3] },
}

/// Boxes of more cells than this are split with their halves bounded on two threads.
const PARALLEL_CELLS: usize = 32 * 32 * 32;

struct Traversal<'a> {
    field: &'a dyn Field,
    grid: &'a Grid,
    iso: f32,
    /// How near the level a bound proves nothing ([`crate::field::level_tolerance`]).
    within: f32,
}

impl Traversal<'_> {
    /// The decided boxes of the cells `lo .. hi`, in depth-first order (lower halves first), and
    /// the interval queries made. Large boxes' halves are bounded in parallel ([`crate::par`]);
    /// their lists are joined in that same order, so the samples do not depend on the threads.
    fn boxes(&self, lo: [usize; 3], hi: [usize; 3]) -> (Vec<Decided>, usize) {
        let cells: usize = (0..3).map(|a| hi[a] - lo[a]).product();
        if cells <= PARALLEL_CELLS {
            let mut out = Vec::new();
            let queries = self.visit(lo, hi, &mut out);
            return (out, queries);
        }
        match self.decide(lo, hi) {
            Err(decided) => (vec![decided], 1),
            Ok((left, right)) => {
                let ((mut a, qa), (b, qb)) =
                    crate::par::join(|| self.boxes(lo, left), || self.boxes(right, hi));
                a.extend(b);
                (a, 1 + qa + qb)
            }
        }
    }

    /// [`Traversal::boxes`] on this thread, appending to `out`; returns the interval queries made.
    fn visit(&self, lo: [usize; 3], hi: [usize; 3], out: &mut Vec<Decided>) -> usize {
        match self.decide(lo, hi) {
            Err(decided) => {
                out.push(decided);
                1
            }
            Ok((left, right)) => 1 + self.visit(lo, left, out) + self.visit(right, hi, out),
        }
    }

    /// Bounds the box: decided (`Err`), or split in two along its longest side (the lower half's
    /// `hi` and the upper half's `lo`).
    #[allow(clippy::type_complexity)]
    fn decide(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<([usize; 3], [usize; 3]), Decided> {
        let (wlo, whi) = (self.grid.position(lo[0], lo[1], lo[2]), self.grid.position(hi[0], hi[1], hi[2]));
        let (vlo, vhi) = self.field.interval(wlo, whi).unwrap_or((f32::NEG_INFINITY, f32::INFINITY));
        // The bound itself stands in (not `bound - iso + iso`, which may round onto the level).
        // A bound within evaluation error of the level proves no sign: the box's points are
        // sampled and snapped like any others ([`crate::field::snap_to_level`]).
        if vlo > self.iso + self.within || vhi < self.iso - self.within {
            return Err(Decided::Fill { lo, hi, value: if vlo > self.iso { vlo } else { vhi } });
        }
        let sizes = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let axis = (0..3).max_by_key(|&a| sizes[a]).expect("three axes");
        // Below a few cells a box is cheaper to sample densely (batched, vectorised evaluation)
        // than to keep bounding (each interval query costs about as much as a dozen points).
        if sizes[axis] <= LEAF_CELLS {
            return Err(Decided::Surface { lo, hi });
        }
        let mid = lo[axis] + sizes[axis] / 2;
        let (mut left_hi, mut right_lo) = (hi, lo);
        left_hi[axis] = mid;
        right_lo[axis] = mid;
        Ok((left_hi, right_lo))
    }
}

/// The grid's samples while the decided boxes are applied.
struct Samples<'a> {
    grid: &'a Grid,
    values: Vec<f32>,
    /// Points that are corners of a cell that may hold the surface.
    marked: Vec<bool>,
}

/// Point layers per piece when the boxes are applied on several threads: each piece goes over
/// every box, so pieces are not cut finer than this.
const APPLY_LAYERS: usize = 8;

impl Samples<'_> {
    /// Every point given its stand-in value by the first `Fill` box that holds it (boxes are
    /// closed and share faces, the traversal's order decides) and marked where a `Surface` box
    /// holds it. Pieces of point layers go to threads ([`crate::par`]); each applies the boxes in
    /// order to its own layers, which is what one pass over the grid gives (at 256 cells a serial
    /// pass over the 17 million points was a tenth of the gear's sampling).
    fn from_boxes<'a>(grid: &'a Grid, boxes: &[Decided]) -> Samples<'a> {
        let fills: Vec<_> = boxes
            .iter()
            .filter_map(|b| match *b {
                Decided::Fill { lo, hi, value } => Some((lo, hi, value)),
                Decided::Surface { .. } => None,
            })
            .collect();
        let surfaces: Vec<_> = boxes
            .iter()
            .filter_map(|b| match *b {
                Decided::Surface { lo, hi } => Some((lo, hi, ())),
                Decided::Fill { .. } => None,
            })
            .collect();
        let values = paint_boxes(grid, &fills, f32::NAN, |value, v| {
            if v.is_nan() {
                *v = value;
            }
        });
        let marked = paint_boxes(grid, &surfaces, false, |(), m| *m = true);
        Samples { grid, values, marked }
    }

    /// Evaluates the marked points tile by tile ([`crate::field::sample_tiles`]; they overwrite
    /// stand-ins) and checks them.
    fn finish(mut self, field: &dyn Field, interval_queries: usize) -> Result<CrustSamples, Error> {
        let marked = &self.marked;
        let evaluated = crate::field::sample_tiles(field, self.grid, |n| marked[n], &mut self.values)?;
        crate::field::check_finite(&self.values, self.grid)?;
        Ok(CrustSamples { values: self.values, evaluated, interval_queries })
    }
}

/// One entry per grid point, starting at `blank`, with `paint(payload, entry)` called for every
/// box `(lo, hi, payload)` in order on the entry of every point the closed box `lo..=hi` (point
/// indices) holds, in pieces of point layers on the threads.
fn paint_boxes<T: Copy + Default + Send + Sync, P: Copy + Sync>(
    grid: &Grid,
    boxes: &[([usize; 3], [usize; 3], P)],
    blank: T,
    paint: impl Fn(P, &mut T) + Sync,
) -> Vec<T> {
    let [nx, ny, _] = grid.points();
    let layer = nx * ny;
    // Allocated zeroed (the system hands out zero pages untouched) and blanked piece by piece on
    // the threads: filled with `blank` here, the whole grid's pages were first touched on one
    // thread, which at 256 cells was most of the painting and kept it from scaling.
    let mut entries = vec![T::default(); grid.point_count()];
    crate::par::map_chunks_mut(&mut entries, APPLY_LAYERS * layer, |c, entries| {
        entries.fill(blank);
        let first = c * APPLY_LAYERS;
        for &(lo, hi, payload) in boxes {
            for_rows(grid, lo, hi, first, entries.len() / layer, |row| {
                entries[row].iter_mut().for_each(|e| paint(payload, e))
            });
        }
    });
    entries
}

/// Calls `f` with the index range, counted from point layer `first`, of every row of points
/// (along x) of the closed box `lo..=hi` (point indices) that lies in the `layers` point layers
/// from `first`: a row is contiguous, so painting it is one pass over a slice.
fn for_rows(
    grid: &Grid,
    lo: [usize; 3],
    hi: [usize; 3],
    first: usize,
    layers: usize,
    mut f: impl FnMut(std::ops::Range<usize>),
) {
    let start = grid.index(0, 0, first);
    for k in lo[2].max(first)..=hi[2].min(first + layers - 1) {
        for j in lo[1]..=hi[1] {
            let row = grid.index(lo[0], j, k) - start;
            f(row..row + hi[0] - lo[0] + 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::compile;
    use crate::field::sample_grid;
    use crate::tables::CORNERS;
    use glam::Vec3;

    #[test]
    fn crust_values_agree_in_sign_everywhere_and_exactly_near_the_surface() {
        let field = compile("max(box(.6, .6, .6), .75 - length(x, y, z))").unwrap();
        let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 48).unwrap();
        let crust = sample_crust(&field, &grid, 0.0).unwrap().unwrap();
        let full = sample_grid(&field, &grid).unwrap();
        assert!(crust.evaluated * 3 < full.len(), "{} of {} evaluated", crust.evaluated, full.len());
        for (n, (&c, &f)) in crust.values.iter().zip(&full).enumerate() {
            assert_eq!(c < 0.0, f < 0.0, "point {n}: sign differs ({c} vs {f})");
        }
        // Every corner of every cell the surface crosses was evaluated exactly.
        let mut crossed = 0;
        for k in 0..grid.cells[2] {
            for j in 0..grid.cells[1] {
                for i in 0..grid.cells[0] {
                    let corners = CORNERS.map(|[a, b, c]| grid.index(i + a, j + b, k + c));
                    let inside = corners.iter().filter(|&&n| full[n] < 0.0).count();
                    if inside == 0 || inside == 8 {
                        continue;
                    }
                    crossed += 1;
                    for n in corners {
                        assert_eq!(crust.values[n], full[n], "point {n}");
                    }
                }
            }
        }
        assert!(crossed > 1000);
    }

    /// Large boxes are bounded on several threads; the samples, bit for bit, and the count of
    /// queries are those of one thread.
    #[test]
    fn the_crust_is_the_same_on_one_thread_or_three() {
        let gear = crate::scenes::scene("gear").unwrap();
        let grid = Grid::with_resolution(gear.min, gear.max, 96).unwrap();
        let run = |threads| {
            crate::par::with_threads(threads, || {
                sample_crust(gear.field.as_ref(), &grid, 0.0).unwrap().unwrap()
            })
        };
        let (one, three) = (run(1), run(3));
        assert!(one.values.iter().zip(&three.values).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert_eq!((one.evaluated, one.interval_queries), (three.evaluated, three.interval_queries));
        assert!(one.interval_queries > 100, "{} queries", one.interval_queries);
    }

    #[test]
    fn fields_without_intervals_are_left_to_the_uniform_grid() {
        let grid = Grid::new(Vec3::ZERO, Vec3::ONE, [2, 2, 2]).unwrap();
        assert!(sample_crust(&|p: Vec3| p.x - 0.5, &grid, 0.0).is_none());
    }
}

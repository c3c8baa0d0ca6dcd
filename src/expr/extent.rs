//! The box a shape's inside fits in, found from interval bounds alone, so that a program typed
//! without bounds can still be meshed where it is.
//!
//! For each of the six directions a best-first branch-and-bound search looks for the farthest
//! point that interval arithmetic cannot prove to be outside: cells are kept in a heap by how far
//! they reach in that direction, a cell whose bound on the value is above zero is dropped (no
//! inside point there), and the search stops once the farthest queued cell reaches no more than a
//! tolerance past an inside point already found; that cell's reach is the answer. Every dropped
//! cell holds no inside point and every cell still queued reaches less far, so the answer is
//! never short of the true extent: the box is conservative by construction, and tight up to the
//! tolerance plus interval arithmetic's over-estimate. When the search runs out of budget, the
//! best queued cell's reach is still a valid (looser) answer.

use super::Program;
use crate::Vec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Interval evaluations allowed per direction and pass; a few milliseconds on a 300-op tape.
const BUDGET: usize = 6_000;

/// Half the side of the cube searched first, centred on the origin: a shape reaching beyond it
/// counts as unbounded.
pub const SEARCH_HALF_WIDTH: f32 = 1000.0;

/// Where a shape's inside (value ≤ 0) lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extent {
    /// No point of the search cube can be inside.
    Empty,
    /// The inside reaches the search cube's faces along these directions (`[-x, -y, -z, +x,
    /// +y, +z]`), e.g. a half-space or an unclipped gyroid.
    Unbounded([bool; 6]),
    /// Every inside point lies in `lo..=hi`.
    Bounded { lo: Vec3, hi: Vec3 },
}

/// A cell queued by its reach along the searched direction, and among equal reaches the
/// smallest first: the children on a parent's far side reach exactly as far as it does, so a
/// face square to the direction is followed down one path instead of being tiled breadth-first.
struct Cell {
    reach: f32,
    size: f32,
    lo: Vec3,
    hi: Vec3,
}

impl PartialEq for Cell {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Cell {
    fn cmp(&self, other: &Self) -> Ordering {
        self.reach.total_cmp(&other.reach).then(other.size.total_cmp(&self.size))
    }
}

/// Whether interval bounds leave room for an inside point in the box (NaN bounds do).
fn may_be_inside(program: &Program, lo: Vec3, hi: Vec3) -> bool {
    let low = program.eval_interval(lo, hi).0;
    low <= 0.0 || low.is_nan()
}

/// How far along `axis` (`sign` = +1 or -1) the inside can reach within the box `lo..hi`, to
/// within `tol`: the search stops when the farthest queued cell reaches no more than `tol` past
/// an inside point already seen (the centres of popped cells are tried). `None` when nothing in
/// the box can be inside.
fn reach(program: &Program, lo: Vec3, hi: Vec3, axis: usize, sign: f32, tol: f32) -> Option<f32> {
    let along = |lo: Vec3, hi: Vec3| if sign > 0.0 { hi[axis] } else { -lo[axis] };
    let mut heap = BinaryHeap::new();
    if may_be_inside(program, lo, hi) {
        heap.push(Cell { reach: along(lo, hi), size: (hi - lo).max_element(), lo, hi });
    }
    let mut seen = f32::NEG_INFINITY;
    let mut evaluations = 1;
    while let Some(cell) = heap.pop() {
        let centre = (cell.lo + cell.hi) * 0.5;
        if program.eval(centre) <= 0.0 {
            seen = seen.max(sign * centre[axis]);
        }
        if cell.reach - seen <= tol || evaluations + 8 > BUDGET {
            return Some(sign * cell.reach);
        }
        for octant in 0..8 {
            let pick = |bit: usize, i: usize| {
                if octant >> bit & 1 == 0 {
                    (cell.lo[i], centre[i])
                } else {
                    (centre[i], cell.hi[i])
                }
            };
            let (x, y, z) = (pick(0, 0), pick(1, 1), pick(2, 2));
            let (clo, chi) = (Vec3::new(x.0, y.0, z.0), Vec3::new(x.1, y.1, z.1));
            evaluations += 1;
            if may_be_inside(program, clo, chi) {
                heap.push(Cell { reach: along(clo, chi), size: cell.size * 0.5, lo: clo, hi: chi });
            }
        }
    }
    None
}

/// The six reaches (`[-x, -y, -z, +x, +y, +z]` as coordinates) within `lo..hi`.
fn reaches(program: &Program, lo: Vec3, hi: Vec3, tol: f32) -> Option<[f32; 6]> {
    let mut out = [0.0; 6];
    for (i, slot) in out.iter_mut().enumerate() {
        let sign = if i < 3 { -1.0 } else { 1.0 };
        *slot = reach(program, lo, hi, i % 3, sign, tol)?;
    }
    Some(out)
}

/// The box the inside of `program` fits in, to about 1/500 of its size (looser where the budget
/// runs out first, e.g. on a face square to an axis, which the search must tile): a coarse search
/// of the cube of half width [`SEARCH_HALF_WIDTH`], then a fine one inside what it found.
pub fn inside_extent(program: &Program) -> Extent {
    let w = SEARCH_HALF_WIDTH;
    let (lo, hi) = (Vec3::splat(-w), Vec3::splat(w));
    let coarse_tol = w / 256.0;
    let Some(coarse) = reaches(program, lo, hi, coarse_tol) else {
        return Extent::Empty;
    };
    let open = std::array::from_fn(|i| coarse[i].abs() >= w - coarse_tol);
    if open.iter().any(|&o| o) {
        return Extent::Unbounded(open);
    }
    let (clo, chi) = (Vec3::from_slice(&coarse[..3]), Vec3::from_slice(&coarse[3..]));
    let tol = ((chi - clo).max_element() / 500.0).max(1e-6);
    match reaches(program, clo, chi, tol) {
        Some(fine) => Extent::Bounded { lo: Vec3::from_slice(&fine[..3]), hi: Vec3::from_slice(&fine[3..]) },
        None => Extent::Empty,
    }
}

/// Bounds to mesh `program` in: its [`inside_extent`] grown on every side by `margin` times its
/// longest side (so that the surface stays off the border and a flat part gets a real box).
pub fn auto_bounds(program: &Program, margin: f32) -> Result<(Vec3, Vec3), crate::Error> {
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(crate::Error::InvalidOption(format!("the margin must be a number ≥ 0, got {margin}")));
    }
    match inside_extent(program) {
        Extent::Bounded { lo, hi } => {
            let pad = Vec3::splat((hi - lo).max_element().max(1e-3) * margin);
            Ok((lo - pad, hi + pad))
        }
        Extent::Empty => Err(crate::Error::InvalidOption(
            "the shape has no inside (its value is positive everywhere), so there is nothing to fit the bounds to".into(),
        )),
        Extent::Unbounded(open) => {
            let names = ["-x", "-y", "-z", "+x", "+y", "+z"];
            let dirs: Vec<&str> = names.iter().zip(open).filter(|(_, o)| *o).map(|(n, _)| *n).collect();
            Err(crate::Error::InvalidOption(format!(
                "the shape's inside is unbounded along {} (it reaches {SEARCH_HALF_WIDTH} there); \
                 intersect it with a box or give the bounds yourself",
                dirs.join(", ")
            )))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::compile;

    fn bounded(text: &str) -> (Vec3, Vec3) {
        match inside_extent(&compile(text).unwrap()) {
            Extent::Bounded { lo, hi } => (lo, hi),
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn a_moved_box_is_found_to_within_a_hundredth_of_its_size() {
        // Its faces are square to the axes, the worst case: the search tiles them until the
        // budget runs out.
        let (lo, hi) = bounded("translate(box(0.5, 0.25, 2), 3, -1, 0.5)");
        let (tlo, thi) = (Vec3::new(2.5, -1.25, -1.5), Vec3::new(3.5, -0.75, 2.5));
        let tol = 0.01 * 4.0;
        assert!((lo - tlo).abs().max_element() <= tol && (hi - thi).abs().max_element() <= tol, "{lo} {hi}");
        // Conservative: never inside the true box.
        assert!(lo.cmple(tlo).all() && hi.cmpge(thi).all(), "{lo} {hi}");
    }

    #[test]
    fn half_spaces_and_empty_shapes_are_told_apart() {
        assert_eq!(
            inside_extent(&compile("z").unwrap()),
            Extent::Unbounded([true, true, true, true, true, false])
        );
        assert_eq!(inside_extent(&compile("sphere(0.5) + 1").unwrap()), Extent::Empty);
        let err = auto_bounds(&compile("max(x, -1 - x)").unwrap(), 0.05).unwrap_err().to_string();
        assert!(err.contains("+y") && !err.contains("+x"), "{err}");
    }

    /// Random unions of moved balls and rotated boxes: the found box holds the analytic extent
    /// (a ball's centre ± r; a box turned by R reaches Σ_j |R_ij| h_j from its centre) and is
    /// loose by no more than 1 % of its size.
    #[test]
    fn random_shapes_fit_their_extent_conservatively_and_tightly() {
        let mut rng = crate::expr::testutil::Rng::new(0xe47e);
        for case in 0..60 {
            let (mut tlo, mut thi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            let parts: Vec<String> = (0..1 + case % 5)
                .map(|_| {
                    let c = rng.vec3(-2.0, 2.0);
                    let (shape, reach) = if rng.range(0.0, 1.0) < 0.5 {
                        let r = rng.range(0.1, 0.8);
                        (format!("sphere({r})"), Vec3::splat(r))
                    } else {
                        let h = rng.vec3(0.1, 0.6);
                        let degrees = rng.range(0.0, 90.0);
                        let rot = glam::Mat3::from_axis_angle(
                            Vec3::new(1.0, 2.0, 3.0).normalize(),
                            degrees.to_radians(),
                        );
                        let abs = glam::Mat3::from_cols(rot.x_axis.abs(), rot.y_axis.abs(), rot.z_axis.abs());
                        (format!("rotate(box({}, {}, {}), 1, 2, 3, {degrees})", h.x, h.y, h.z), abs * h)
                    };
                    tlo = tlo.min(c - reach);
                    thi = thi.max(c + reach);
                    format!("translate({shape}, {}, {}, {})", c.x, c.y, c.z)
                })
                .collect();
            let text = format!("union({})", parts.join(", "));
            let (lo, hi) = bounded(&text);
            let size = (thi - tlo).max_element();
            let below = 1e-4 * size;
            assert!(
                lo.cmple(tlo + below).all() && hi.cmpge(thi - below).all(),
                "{text}: {lo}..{hi} inside the true {tlo}..{thi}"
            );
            let slack = 0.01 * size;
            assert!(
                (tlo - lo).max_element() <= slack && (hi - thi).max_element() <= slack,
                "{text}: {lo}..{hi} loose against {tlo}..{thi}"
            );
        }
    }
}

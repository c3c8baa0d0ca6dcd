//! What gets meshed: anything that has a value (and ideally a gradient) at every point of space.
//!
//! Convention used everywhere in the library: **a point is inside when its value is below the
//! iso-level**; the gradient points outward. Signed distance functions (negative inside) follow it.

use crate::error::Error;
use crate::grid::Grid;
use glam::Vec3;
use std::sync::Mutex;

/// A scalar field over space. Implementations with an analytic gradient override [`Field::gradient`];
/// the papers' feature detection and our vertex normals are only as good as that gradient.
/// `Sync` because samplers evaluate slabs of a grid on several threads at once (see [`crate::par`]).
pub trait Field: Sync {
    fn value(&self, p: Vec3) -> f32;

    /// The exact gradient where the field knows it; `None` asks the caller to estimate one.
    fn gradient(&self, _p: Vec3) -> Option<Vec3> {
        None
    }

    /// The value and [`Field::gradient`] at one point. Evaluators that get both from one pass
    /// (the compiled programs' forward differentiation) override this: root finding along EMC's
    /// edges wants both at every step.
    fn value_and_gradient(&self, p: Vec3) -> (f32, Option<Vec3>) {
        (self.value(p), self.gradient(p))
    }

    /// Conservative bounds `(lo, hi)` of the value over the box `[lo, hi]`, where the field can give
    /// them (compiled expressions can): octrees use them to skip space the surface cannot reach.
    fn interval(&self, _lo: Vec3, _hi: Vec3) -> Option<(f32, f32)> {
        None
    }

    /// How steep the field typically is, in its units per unit of length (the length of its
    /// gradient, as a scale): what a distance in world units is multiplied by to be compared
    /// with the field's values or combined with them. Signed distances, the expression
    /// language's shapes, are 1; sampled volumes carry their data's own units (CT numbers,
    /// 16-bit words), often thousands per cell.
    fn steepness(&self) -> f32 {
        1.0
    }

    /// Values at many points at once. Evaluators that vectorise override this; grids call it per row.
    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = self.value(*p);
        }
    }

    /// [`Field::gradient`] at many points at once, the same per point. Evaluators that vectorise
    /// override this: a DMC octree takes a gradient at each of `samples_per_cell³` points per cell.
    fn gradients(&self, points: &[Vec3], out: &mut [Option<Vec3>]) {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = self.gradient(*p);
        }
    }

    /// [`Field::values`] and [`Field::gradients`] at the same points. Evaluators that get both
    /// from one pass (the compiled programs' forward differentiation) override this: DMC takes
    /// both at every sample of its crust and at every point of its distance tests.
    fn values_and_gradients(&self, points: &[Vec3], values: &mut [f32], gradients: &mut [Option<Vec3>]) {
        self.values(points, values);
        self.gradients(points, gradients);
    }
}

/// Any `Fn(Vec3) -> f32` closure is a field (without a gradient).
impl<F: Fn(Vec3) -> f32 + Sync> Field for F {
    fn value(&self, p: Vec3) -> f32 {
        self(p)
    }
}

/// A closure for the value paired with one for the exact gradient.
pub struct WithGradient<V, G> {
    pub value: V,
    pub gradient: G,
}

impl<V: Fn(Vec3) -> f32 + Sync, G: Fn(Vec3) -> Vec3 + Sync> Field for WithGradient<V, G> {
    fn value(&self, p: Vec3) -> f32 {
        (self.value)(p)
    }
    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        Some((self.gradient)(p))
    }
}

/// A field computed by a closure over batches of points, for callers whose function is costly to
/// call (a JavaScript function across the wasm boundary): `f(points, values)` fills `values[i]`
/// with the value at `points[i]` (both slices have the same length) or fails with a message.
///
/// [`BatchFn::sample`] calls it once per z-slab of a grid; the [`Field`] methods call it once per
/// request (one point for [`Field::value`], the six neighbours for the central-difference
/// [`Field::gradient`], the whole slice for [`Field::values`]). A failure is remembered: from then
/// on every value is NaN without calling `f` again, and [`BatchFn::error`] returns the message.
pub struct BatchFn<F> {
    f: F,
    /// Step of the central-difference gradient.
    pub step: f32,
    error: Mutex<Option<String>>,
}

impl<F: Fn(&[Vec3], &mut [f32]) -> Result<(), String>> BatchFn<F> {
    pub fn new(f: F, step: f32) -> Self {
        BatchFn { f, step, error: Mutex::new(None) }
    }

    /// The first failure of the closure, if any.
    pub fn error(&self) -> Option<String> {
        self.failure().clone()
    }

    /// The remembered failure; a poisoned lock (a panic while it was held) still holds a message
    /// or `None`, both valid.
    fn failure(&self) -> std::sync::MutexGuard<'_, Option<String>> {
        self.error.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    fn call(&self, points: &[Vec3], out: &mut [f32]) {
        if self.failure().is_none() {
            match (self.f)(points, out) {
                Ok(()) => return,
                Err(e) => *self.failure() = Some(e),
            }
        }
        out.fill(f32::NAN);
    }

    /// Samples every point of `grid`, x fastest, calling the closure once per z-slab. Fails with
    /// [`Error::FieldFunction`] if the closure does, or [`Error::NonFiniteSample`] naming the first
    /// NaN or infinite value it returned.
    pub fn sample(&self, grid: &Grid) -> Result<Vec<f32>, Error> {
        let [nx, ny, nz] = grid.points();
        let slab = nx * ny;
        let mut values = vec![0.0f32; grid.point_count()];
        let mut points = vec![Vec3::ZERO; slab];
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    points[j * nx + i] = grid.position(i, j, k);
                }
            }
            let start = grid.index(0, 0, k);
            self.call(&points, &mut values[start..start + slab]);
            if let Some(e) = self.error() {
                return Err(Error::FieldFunction(e));
            }
        }
        check_finite(&values, grid)?;
        Ok(values)
    }
}

impl<F: Fn(&[Vec3], &mut [f32]) -> Result<(), String> + Sync> Field for BatchFn<F> {
    fn value(&self, p: Vec3) -> f32 {
        let mut out = [0.0];
        self.call(&[p], &mut out);
        out[0]
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let h = self.step;
        let pts = [
            p + Vec3::X * h,
            p - Vec3::X * h,
            p + Vec3::Y * h,
            p - Vec3::Y * h,
            p + Vec3::Z * h,
            p - Vec3::Z * h,
        ];
        let mut v = [0.0; 6];
        self.call(&pts, &mut v);
        Some(Vec3::new(v[0] - v[1], v[2] - v[3], v[4] - v[5]) / (2.0 * h))
    }

    fn values(&self, points: &[Vec3], out: &mut [f32]) {
        self.call(points, out);
    }
}

/// Gradient of `field` at `p`: its own where it knows one, else central differences with step `h`.
pub fn gradient_or_differences(field: &dyn Field, p: Vec3, h: f32) -> Vec3 {
    field.gradient(p).unwrap_or_else(|| finite_difference_gradient(field, p, h))
}

/// [`gradient_or_differences`] at many points, through [`Field::gradients`]; `out` is resized to
/// `points`, and `scratch` is working memory a caller can keep across calls.
pub fn gradients_or_differences(
    field: &dyn Field,
    points: &[Vec3],
    h: f32,
    scratch: &mut Vec<Option<Vec3>>,
    out: &mut Vec<Vec3>,
) {
    scratch.clear();
    scratch.resize(points.len(), None);
    field.gradients(points, scratch);
    out.clear();
    out.extend(
        points
            .iter()
            .zip(scratch.iter())
            .map(|(&p, g)| g.unwrap_or_else(|| finite_difference_gradient(field, p, h))),
    );
}

/// Values and [`gradient_or_differences`] at many points, in one [`Field::values_and_gradients`]
/// batch (one pass of a compiled program) and central differences where the field has none.
pub fn values_and_gradients_or_differences(
    field: &dyn Field,
    points: &[Vec3],
    h: f32,
) -> (Vec<f32>, Vec<Vec3>) {
    let mut values = vec![0.0; points.len()];
    let mut exact = vec![None; points.len()];
    field.values_and_gradients(points, &mut values, &mut exact);
    let gradients = points
        .iter()
        .zip(&exact)
        .map(|(&p, &g)| g.unwrap_or_else(|| finite_difference_gradient(field, p, h)))
        .collect();
    (values, gradients)
}

/// Central-difference gradient with step `h`: the fallback for fields that know no gradient.
pub fn finite_difference_gradient(field: &dyn Field, p: Vec3, h: f32) -> Vec3 {
    let dx = Vec3::new(h, 0.0, 0.0);
    let dy = Vec3::new(0.0, h, 0.0);
    let dz = Vec3::new(0.0, 0.0, h);
    Vec3::new(
        field.value(p + dx) - field.value(p - dx),
        field.value(p + dy) - field.value(p - dy),
        field.value(p + dz) - field.value(p - dz),
    ) / (2.0 * h)
}

/// Samples `field` at every point of `grid`, one tile of [`TILE`]³ points per [`Field::values`]
/// call: a field specialised per region ([`crate::expr::RegionalProgram`]) then gets long runs of
/// points in one brick, where rows would cut every brick into a few points each.
/// Fails on the first non-finite value, naming it, because meshing it would be silently wrong.
pub fn sample_grid(field: &dyn Field, grid: &Grid) -> Result<Vec<f32>, Error> {
    let mut values = vec![0.0f32; grid.point_count()];
    sample_tiles(field, grid, |_| true, &mut values)?;
    check_finite(&values, grid)?;
    Ok(values)
}

/// Evaluates `field` at the points of `grid` whose index `keep` accepts, tile by tile (one
/// [`Field::values`] call per tile), writing each value to `values` at the point's index; the
/// others are left as they are. Returns how many points were evaluated. Shared by whole grids
/// and by the crust ([`crate::crust`]).
///
/// A slab of tiles ([`TILE`] point layers) is a contiguous run of `values`, so slabs are sampled
/// in parallel ([`crate::par`]), one per thread between two checkpoints of phase "sample" (so
/// one thread checks in after every slab, as a stop asked for in the page needs).
pub fn sample_tiles(
    field: &dyn Field,
    grid: &Grid,
    keep: impl Fn(usize) -> bool + Sync,
    values: &mut [f32],
) -> Result<usize, Error> {
    let [nx, ny, nz] = grid.points();
    let slab_len = nx * ny * TILE;
    let slabs_per_step = crate::par::threads();
    let mut evaluated = 0;
    for (step, run) in values.chunks_mut(slab_len * slabs_per_step).enumerate() {
        let first_slab = step * slabs_per_step;
        crate::progress::checkpoint("sample", (first_slab * TILE) as f32 / nz as f32)?;
        let counts = crate::par::map_chunks_mut(run, slab_len, |s, slab| {
            sample_slab(field, grid, &keep, (first_slab + s) * TILE, slab)
        });
        evaluated += counts.iter().sum::<usize>();
    }
    Ok(evaluated)
}

/// [`sample_tiles`] for the slab of tiles whose lowest point layer is `k0`, whose values are
/// `slab` (starting at the index of point `(0, 0, k0)`).
fn sample_slab(
    field: &dyn Field,
    grid: &Grid,
    keep: &impl Fn(usize) -> bool,
    k0: usize,
    slab: &mut [f32],
) -> usize {
    let [nx, ny, nz] = grid.points();
    let start = grid.index(0, 0, k0);
    let mut points = Vec::with_capacity(TILE * TILE * TILE);
    let mut indices = Vec::with_capacity(TILE * TILE * TILE);
    let mut out = vec![0.0f32; TILE * TILE * TILE];
    let mut evaluated = 0;
    let k1 = (k0 + TILE).min(nz);
    for j0 in (0..ny).step_by(TILE) {
        for i0 in (0..nx).step_by(TILE) {
            points.clear();
            indices.clear();
            for k in k0..k1 {
                for j in j0..(j0 + TILE).min(ny) {
                    for i in i0..(i0 + TILE).min(nx) {
                        let n = grid.index(i, j, k);
                        if keep(n) {
                            points.push(grid.position(i, j, k));
                            indices.push(n - start);
                        }
                    }
                }
            }
            if points.is_empty() {
                continue;
            }
            field.values(&points, &mut out[..points.len()]);
            for (&n, &v) in indices.iter().zip(&out) {
                slab[n] = v;
            }
            evaluated += points.len();
        }
    }
    evaluated
}

/// Points per side of the tiles that grids are sampled in.
pub const TILE: usize = 8;

/// How near the level a sample of a function is taken to lie on it, in units of the float spacing
/// (`f32::EPSILON` relative) at the grid's largest coordinate.
const LEVEL_ULPS: f32 = 16.0;

/// The samples a mesher reads from a function on `grid`: through the crust where `crust` is
/// asked and the field bounds itself (points away from the surface take their bound's sign, see
/// [`crate::crust`]), at every point otherwise; then the ones on the `iso` level given their side
/// ([`snap_to_level`]). Returns the samples and how many points were evaluated.
pub fn sample_level(
    field: &dyn Field,
    grid: &Grid,
    iso: f32,
    crust: bool,
) -> Result<(Vec<f32>, usize), Error> {
    sample_level_with(field, grid, iso, crust, false)
}

/// [`sample_level`] with the samples the grid leaves undecided on the level given their side by
/// the function itself ([`snap_to_level`]): for meshers that read only the samples' signs
/// and find crossings on the function (EMC). Not for interpolating ones: a sample on a face two
/// parts share keeps the value 0 however deep inside the union it lies, so Marching Cubes puts
/// the surface through it either way, and with it inside made more faces turn over where a cone
/// stands on a cylinder (8 of 40 random ones, against 2; EMC 1 against 10).
pub fn sample_level_probed(
    field: &dyn Field,
    grid: &Grid,
    iso: f32,
    crust: bool,
) -> Result<(Vec<f32>, usize), Error> {
    sample_level_with(field, grid, iso, crust, true)
}

fn sample_level_with(
    field: &dyn Field,
    grid: &Grid,
    iso: f32,
    crust: bool,
    probe: bool,
) -> Result<(Vec<f32>, usize), Error> {
    let crust = if crust { crate::crust::sample_crust(field, grid, iso).transpose()? } else { None };
    let (mut values, evaluated) = match crust {
        Some(c) => (c.values, c.evaluated),
        None => (sample_grid(field, grid)?, grid.point_count()),
    };
    snap_to_level(&mut values, grid, iso, probe.then_some(field));
    Ok((values, evaluated))
}

/// Decides the side of the samples of a function that lie on its `iso` level within evaluation
/// error (the sign rule is `value - iso < 0` inside): inside (set just below the level) where the
/// point lies between two inside samples along a grid line and between two outside ones along
/// none, outside (set on it) otherwise.
///
/// A surface lying in a grid plane (a box whose faces fall on grid planes: round numbers on the
/// default bounds) is zero there only up to rounding, and rounding differs from point to point
/// and from primitive to primitive: in a union of two such boxes the samples on a face came out
/// -4e-8, 0 and 1e-8, some points of the face inside and some outside, and the surface stepped
/// between grid planes in teeth. The error of evaluating a distance at coordinates of magnitude
/// `C` is a few float spacings of `C`; within sixteen of them ([`level_tolerance`]) a sample is
/// on the level, and outside, as an exact zero always was: a box's faces stay exact. Except
/// between two inside samples: there the zero comes from parts of a union that share a face
/// (`min` of two distances is zero all over it), and outside they would split the solid in two
/// along the face (the rocket's body and nose at 160 cells, tried). Where air lies on both sides
/// along another line, the parts touch only there (two balls touching at a grid point) and the
/// point stays outside, the parts apart, as before. Samples given as data are the caller's and
/// are not changed. The surface moves by at most the tolerance (crossings keep a thousandth of an
/// edge off their ends anyway: [`crate::mc::MIN_EDGE_FRACTION`]).
///
/// With `probe`, a sample that no grid line decides (no inside samples at both neighbours, no air
/// at both) is asked of the function itself a thousandth of a cell to either side along each
/// axis: inside where some axis has it inside on both sides and none outside on both. The grid's
/// neighbours are a cell away, and within a cell a part can narrow: where a cone stands on a
/// cylinder's top (the rocket's nose on its body, their shared disc in a grid plane), the disc's
/// points near its rim have the cylinder below and air above, a cell up, yet the cone just above
/// them; outside, they made a slit between body and nose at the rim, and EMC fanned a face across
/// it turned over (the rocket at 80 cells, 178° off). A box's face on a grid plane still has air
/// on one side. Two balls touching at a grid point keep the grid's air on both sides across the
/// line joining them, which probes so near would not see (the balls are a millionth apart there).
pub fn snap_to_level(values: &mut [f32], grid: &Grid, iso: f32, probe: Option<&dyn Field>) {
    let within = level_tolerance(grid, iso);
    // Few samples lie on the level: runs of them are ruled out in one vectorised pass each (a
    // branch per sample cost a fifth of a sphere's sampling at 256 cells).
    let on_level: Vec<usize> = crate::par::map_chunks_mut(values, SNAP_CHUNK, |c, chunk| {
        let mut found = Vec::new();
        for (r, run) in chunk.chunks(SNAP_RUN).enumerate() {
            if run.iter().map(|v| ((v - iso).abs() <= within) as u32).sum::<u32>() > 0 {
                let first = c * SNAP_CHUNK + r * SNAP_RUN;
                found.extend((0..run.len()).filter(|&n| (run[n] - iso).abs() <= within).map(|n| first + n));
            }
        }
        found
    })
    .concat();
    let [nx, ny, nz] = grid.points();
    // Per axis through the point, its two neighbours' values where it has both.
    let flanks = |n: usize| {
        let [i, j, k] = grid.unindex(n);
        [(i, nx, 1), (j, ny, nx), (k, nz, nx * ny)].map(|(at, count, step)| {
            (at > 0 && at + 1 < count).then(|| [values[n - step] - iso, values[n + step] - iso])
        })
    };
    // Where the grid decides, its side; where it cannot and there is a function, `None`.
    let by_grid: Vec<Option<bool>> = crate::par::map(on_level.len(), |i| {
        side_between(flanks(on_level[i]).into_iter().flatten(), within)
            .or_else(|| probe.is_none().then_some(false))
    });
    let asked: Vec<usize> =
        on_level.iter().zip(&by_grid).filter(|(_, side)| side.is_none()).map(|(&n, _)| n).collect();
    let mut probed =
        probe.map_or(Vec::new(), |field| probed_sides(field, grid, iso, within, &asked)).into_iter();
    for (&n, side) in on_level.iter().zip(by_grid) {
        let inside = side.unwrap_or_else(|| probed.next().expect("one probed side per sample asked"));
        values[n] = if inside { iso - within } else { iso };
    }
}

/// Per sample `n` of `asked`: its side by [`side_between`] from `field`'s values a
/// [`PROBE_CELLS`] step to either side along each axis (outside where none decides). The six values per sample are
/// taken in batches on the threads: a box's faces on grid planes are all asked (400 000 points
/// at 256 cells), and one value at a time cost a third of the sampling there.
fn probed_sides(field: &dyn Field, grid: &Grid, iso: f32, within: f32, asked: &[usize]) -> Vec<bool> {
    let steps: [Vec3; 3] = std::array::from_fn(|a| {
        let mut d = Vec3::ZERO;
        d[a] = PROBE_CELLS * grid.spacing[a];
        d
    });
    let points: Vec<Vec3> = asked
        .iter()
        .flat_map(|&n| {
            let [i, j, k] = grid.unindex(n);
            let p = grid.position(i, j, k);
            steps.iter().flat_map(move |&d| [p - d, p + d])
        })
        .collect();
    let mut probes = vec![0.0f32; points.len()];
    crate::par::map_chunks_mut(&mut probes, PROBE_BATCH, |c, out| {
        field.values(&points[c * PROBE_BATCH..][..out.len()], out);
    });
    probes
        .chunks_exact(6)
        .map(|ends| {
            side_between(ends.chunks_exact(2).map(|e| [e[0] - iso, e[1] - iso]), within).unwrap_or(false)
        })
        .collect()
}

/// The side of a sample on the level from the values (minus the level) at both ends of lines
/// through it: outside where both ends of some line are beyond `within` outside, else inside where
/// both ends of some line are inside, `None` where no line decides. [`snap_to_level`]'s rule, for
/// the grid's neighbours and for the function's probes alike.
fn side_between(lines: impl IntoIterator<Item = [f32; 2]>, within: f32) -> Option<bool> {
    let (mut inside, mut outside) = (false, false);
    for ends in lines {
        inside |= ends.iter().all(|&d| d < -within);
        outside |= ends.iter().all(|&d| d > within);
    }
    if outside {
        Some(false)
    } else if inside {
        Some(true)
    } else {
        None
    }
}

/// Probe values per batch of [`probed_sides`].
const PROBE_BATCH: usize = 4096;

/// How far to either side of a sample on the level [`snap_to_level`] asks the function,
/// in cells: far enough that evaluation error cannot give the probes a side (crossings stay a
/// thousandth of an edge off the grid points anyway), near enough that no part narrows away.
const PROBE_CELLS: f32 = 1e-3;

/// Samples per piece of the search for samples on the level, and per run tested at once.
const SNAP_CHUNK: usize = 1 << 16;
const SNAP_RUN: usize = 64;

/// How near `iso` a function's sample on `grid` is taken to lie on the level (see
/// [`snap_to_level`]); an interval bound this near it proves no sign either ([`crate::crust`]).
pub fn level_tolerance(grid: &Grid, iso: f32) -> f32 {
    let scale = grid.origin.abs().max(grid.max().abs()).max_element().max(iso.abs());
    LEVEL_ULPS * f32::EPSILON * scale
}

/// Fails with [`Error::NonFiniteSample`] naming the first NaN or infinite sample, and with
/// [`Error::InvalidGrid`] for the first past [`MAX_SAMPLE_MAGNITUDE`].
pub fn check_finite(values: &[f32], grid: &Grid) -> Result<(), Error> {
    if values.len() != grid.point_count() {
        let p = grid.points();
        return Err(Error::InvalidGrid(format!(
            "expected {} x {} x {} = {} samples, got {}",
            p[0],
            p[1],
            p[2],
            grid.point_count(),
            values.len()
        )));
    }
    // One vectorised pass proves the common case; only a grid with a bad sample is searched again
    // for the first one, non-finite samples before oversized ones. (`abs() <= MAX` is false for
    // NaN and the infinities too.)
    let in_range = |chunk: &[f32]| chunk.iter().fold(true, |ok, v| ok & (v.abs() <= MAX_SAMPLE_MAGNITUDE));
    if values.chunks(4096).all(in_range) {
        return Ok(());
    }
    if let Some(n) = values.iter().position(|v| !v.is_finite()) {
        let [i, j, k] = grid.unindex(n);
        return Err(Error::NonFiniteSample {
            index: [i, j, k],
            position: grid.position(i, j, k).to_array(),
            value: values[n],
        });
    }
    if let Some(n) = values.iter().position(|v| v.abs() > MAX_SAMPLE_MAGNITUDE) {
        let [i, j, k] = grid.unindex(n);
        return Err(Error::InvalidGrid(format!(
            "sample ({i}, {j}, {k}) is {}; samples must lie within ±{MAX_SAMPLE_MAGNITUDE:e} so that \
             differences and slopes between them stay finite in f32 (scale the volume down)",
            values[n]
        )));
    }
    Ok(())
}

/// Largest sample magnitude accepted: differences of two samples, and their slopes over cells
/// down to 1e-8 wide, stay finite in `f32`. No physical volume comes near it; a value past it is
/// a corrupt file or a hostile one.
pub const MAX_SAMPLE_MAGNITUDE: f32 = 1e30;

/// Which gradient a [`SampledField`] reports.
///
/// The trade-off is the one of the EMC paper (Kobbelt et al. 2001, §4.1): the gradient of the
/// trilinear interpolant is exactly consistent with the interpolated values, but it is only
/// piecewise continuous: it jumps across every cell face, so normals computed from it (and the
/// feature detection that compares them) show the grid's facets. Central differences at the
/// grid points, blended trilinearly, are continuous everywhere and smoother on curved surfaces
/// (the paper's recommendation for sampled data), at the price of being slightly inconsistent
/// with the interpolant and of blurring over two cells, which rounds sharp features a little.
/// Both are exact on linear fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SampleGradient {
    /// The gradient of the trilinear interpolant: consistent, discontinuous across cell faces.
    Trilinear,
    /// Central differences at the grid points, interpolated trilinearly: continuous (the default).
    #[default]
    CentralDifferences,
}

impl SampleGradient {
    /// The names used by the CLI's `--gradient` and the JS option `gradient`.
    pub const NAMES: [&'static str; 2] = ["trilinear", "central"];

    pub fn parse(name: &str) -> Result<SampleGradient, Error> {
        match name {
            "trilinear" => Ok(SampleGradient::Trilinear),
            "central" => Ok(SampleGradient::CentralDifferences),
            _ => Err(Error::UnknownName {
                kind: "gradient",
                name: name.to_string(),
                known: Self::NAMES.iter().map(|s| s.to_string()).collect(),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SampleGradient::Trilinear => "trilinear",
            SampleGradient::CentralDifferences => "central",
        }
    }
}

/// A sampled volume (CT/MRI stack, or any precomputed grid) seen as a continuous field through
/// trilinear interpolation; its gradient is chosen by [`SampledField::gradient`] (see
/// [`SampleGradient`] for the trade-off).
pub struct SampledField<'a> {
    pub grid: Grid,
    pub values: &'a [f32],
    pub gradient: SampleGradient,
}

impl SampledField<'_> {
    fn locate(&self, p: Vec3) -> ([usize; 3], Vec3) {
        let q = (p - self.grid.origin) / self.grid.spacing;
        let mut base = [0usize; 3];
        let mut frac = Vec3::ZERO;
        for a in 0..3 {
            let c = self.grid.cells[a];
            let t = q[a].clamp(0.0, c as f32);
            let b = (t.floor() as usize).min(c - 1);
            base[a] = b;
            frac[a] = t - b as f32;
        }
        (base, frac)
    }

    fn corners(&self, b: [usize; 3]) -> [f32; 8] {
        std::array::from_fn(|c| {
            self.values[self.grid.index(b[0] + (c & 1), b[1] + ((c >> 1) & 1), b[2] + ((c >> 2) & 1))]
        })
    }
}

impl Field for SampledField<'_> {
    fn value(&self, p: Vec3) -> f32 {
        let (b, t) = self.locate(p);
        let v = self.corners(b);
        let x00 = v[0] + (v[1] - v[0]) * t.x;
        let x10 = v[2] + (v[3] - v[2]) * t.x;
        let x01 = v[4] + (v[5] - v[4]) * t.x;
        let x11 = v[6] + (v[7] - v[6]) * t.x;
        let y0 = x00 + (x10 - x00) * t.y;
        let y1 = x01 + (x11 - x01) * t.y;
        y0 + (y1 - y0) * t.z
    }

    /// The mean length of the samples' gradient (forward differences, each sample with a
    /// neighbour along every axis), 1 where every sample is the same: a signed distance sampled
    /// is about 1, a 16-bit scan thousands per unit.
    fn steepness(&self) -> f32 {
        let [nx, ny, nz] = self.grid.points();
        let strides = [1, nx, nx * ny];
        let (mut sum, mut count) = (0.0f64, 0usize);
        for k in 0..nz.saturating_sub(1) {
            for j in 0..ny.saturating_sub(1) {
                for i in 0..nx.saturating_sub(1) {
                    let n = self.grid.index(i, j, k);
                    let g = Vec3::from_array(std::array::from_fn(|a| {
                        self.values[n + strides[a]] - self.values[n]
                    })) / self.grid.spacing;
                    sum += g.length() as f64;
                    count += 1;
                }
            }
        }
        let mean = (sum / count.max(1) as f64) as f32;
        if mean.is_finite() && mean > 0.0 {
            mean
        } else {
            1.0
        }
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        if self.gradient == SampleGradient::CentralDifferences {
            return Some(crate::mc::sample_gradient(self.values, &self.grid, p));
        }
        let (b, t) = self.locate(p);
        let v = self.corners(b);
        let lerp = |a: f32, b: f32, s: f32| a + (b - a) * s;
        let dx = lerp(lerp(v[1] - v[0], v[3] - v[2], t.y), lerp(v[5] - v[4], v[7] - v[6], t.y), t.z);
        let dy = lerp(lerp(v[2] - v[0], v[3] - v[1], t.x), lerp(v[6] - v[4], v[7] - v[5], t.x), t.z);
        let dz = lerp(lerp(v[4] - v[0], v[5] - v[1], t.x), lerp(v[6] - v[2], v[7] - v[3], t.x), t.y);
        Some(Vec3::new(dx, dy, dz) / self.grid.spacing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_field_reproduces_a_linear_function_and_its_gradient() {
        let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [4, 5, 6]).unwrap();
        let f = |p: Vec3| 2.0 * p.x - 3.0 * p.y + 0.5 * p.z + 1.0;
        let values = sample_grid(&f, &grid).unwrap();
        for gradient in [SampleGradient::Trilinear, SampleGradient::CentralDifferences] {
            let s = SampledField { grid, values: &values, gradient };
            for p in [Vec3::new(0.1, 0.2, 0.3), Vec3::new(-0.77, 0.5, 0.99), Vec3::new(0.999, -0.999, 0.0)] {
                assert!((s.value(p) - f(p)).abs() < 1e-5);
                assert!((s.gradient(p).unwrap() - Vec3::new(2.0, -3.0, 0.5)).length() < 1e-4, "{gradient:?}");
            }
        }
    }

    /// A sampled field's steepness is its gradient's length in its own units (a 16-bit scan's
    /// thousands per unit, a distance's 1), and 1 where the samples say nothing.
    #[test]
    fn sampled_steepness_is_the_gradients_length_in_the_datas_units() {
        let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [4, 5, 6]).unwrap();
        for (f, expected) in [
            (Box::new(|p: Vec3| 3000.0 * p.x - 4000.0 * p.z) as Box<dyn Fn(Vec3) -> f32 + Sync>, 5000.0),
            (Box::new(|p: Vec3| p.length() - 0.5), 1.0),
            (Box::new(|_: Vec3| 7.0), 1.0),
        ] {
            let values = sample_grid(&f, &grid).unwrap();
            let s = SampledField { grid, values: &values, gradient: SampleGradient::Trilinear }.steepness();
            assert!((s - expected).abs() < 0.05 * expected, "{s} against {expected}");
        }
    }

    #[test]
    fn both_gradients_agree_on_linear_fields_everywhere() {
        let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [7, 7, 7]).unwrap();
        let f = |p: Vec3| -0.4 * p.x + 1.5 * p.y - 2.0 * p.z;
        let values = sample_grid(&f, &grid).unwrap();
        let tri = SampledField { grid, values: &values, gradient: SampleGradient::Trilinear };
        let cd = SampledField { grid, values: &values, gradient: SampleGradient::CentralDifferences };
        for i in 0..50 {
            let t = i as f32 / 49.0;
            let p = Vec3::new(-0.95 + 1.9 * t, 0.9 - 1.7 * t * t, (7.0 * t).sin() * 0.9);
            let (a, b) = (tri.gradient(p).unwrap(), cd.gradient(p).unwrap());
            assert!((a - b).length() < 1e-4, "{p}: {a} vs {b}");
        }
    }

    #[test]
    fn central_differences_are_continuous_across_cell_faces_trilinear_is_not() {
        // A curved field: the interpolant's gradient jumps at the face x = 0.5 between two cells.
        let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [4, 4, 4]).unwrap();
        let f = |p: Vec3| p.x * p.x * p.x + p.y * p.y + 0.3 * p.z;
        let values = sample_grid(&f, &grid).unwrap();
        let jump = |gradient| {
            let s = SampledField { grid, values: &values, gradient };
            let p = Vec3::new(0.5, 0.2, 0.1);
            let e = Vec3::new(1e-4, 0.0, 0.0);
            (s.gradient(p + e).unwrap() - s.gradient(p - e).unwrap()).length()
        };
        assert!(jump(SampleGradient::Trilinear) > 0.1, "trilinear jump {}", jump(SampleGradient::Trilinear));
        assert!(
            jump(SampleGradient::CentralDifferences) < 1e-2,
            "central jump {}",
            jump(SampleGradient::CentralDifferences)
        );
    }

    #[test]
    fn batch_fn_samples_one_slab_per_call_and_reports_failures() {
        let grid = Grid::new(Vec3::splat(-1.0), Vec3::splat(1.0), [8, 8, 8]).unwrap();
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let sphere = BatchFn::new(
            |pts: &[Vec3], out: &mut [f32]| {
                calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                for (p, o) in pts.iter().zip(out) {
                    *o = p.length() - 0.7;
                }
                Ok(())
            },
            1e-3,
        );
        let values = sphere.sample(&grid).unwrap();
        assert_eq!(calls.load(std::sync::atomic::Ordering::Relaxed), 9);
        assert_eq!(values, sample_grid(&|p: Vec3| p.length() - 0.7, &grid).unwrap());
        let g = sphere.gradient(Vec3::new(0.3, 0.4, 0.0)).unwrap();
        assert!((g - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-2, "{g}");

        let failing = BatchFn::new(
            |pts: &[Vec3], out: &mut [f32]| {
                if pts[0].z > 0.0 {
                    return Err("boom".to_string());
                }
                out.fill(1.0);
                Ok(())
            },
            1e-3,
        );
        let err = failing.sample(&grid).unwrap_err();
        assert_eq!(err, Error::FieldFunction("boom".into()));
        assert!(failing.value(Vec3::ZERO).is_nan());
    }

    #[test]
    fn non_finite_samples_are_named() {
        let grid = Grid::new(Vec3::ZERO, Vec3::ONE, [2, 2, 2]).unwrap();
        let f = |p: Vec3| {
            if p.x > 0.9 && p.y < 0.1 && p.z < 0.1 {
                f32::NAN
            } else {
                1.0
            }
        };
        let err = sample_grid(&f, &grid).unwrap_err();
        assert!(matches!(err, Error::NonFiniteSample { index: [2, 0, 0], .. }), "{err}");
        assert!(err.to_string().contains("(2, 0, 0)"));
    }
}

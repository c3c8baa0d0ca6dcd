//! The sampling lattice: the single place that maps grid indices to world coordinates, and the
//! reader for raw sample volumes (little-endian `f32`, `u8` or `u16`, x fastest) laid out on it.

use crate::error::Error;
use glam::Vec3;

/// Is `p` in the closed box `[lo, hi]` (cells, leaves, grown cells)?
pub fn in_box(p: Vec3, (lo, hi): (Vec3, Vec3)) -> bool {
    p.cmpge(lo).all() && p.cmple(hi).all()
}

/// Default cap on the number of cells, chosen so that one f32 per sample plus MC's edge caches stay
/// well inside a browser tab's memory (about 300 MB of samples at the cap).
pub const DEFAULT_MAX_CELLS: u64 = 72_000_000;

/// Most cells along one axis of any grid: 2^21, so that every count of points or cells fits in
/// 64 bits and every index along an axis is exact in `f32`.
pub const MAX_CELLS_PER_AXIS: usize = 1 << 21;

/// Largest coordinate any grid may reach: a triangle's area and normal take products of two
/// edge lengths and the volume products of three, which must stay finite in `f32`.
pub const MAX_COORDINATE: f32 = 1e12;

/// Representable `f32` positions a cell must span along each axis: vertices sit as close as 1e-3
/// of an edge to its ends ([`crate::mc::MIN_EDGE_FRACTION`]), which needs about a thousand.
pub const MIN_ULPS_PER_CELL: f32 = 1024.0;

/// The gap between `x` (≥ 0, finite) and the next larger `f32`.
fn f32_ulp(x: f32) -> f32 {
    let x = x.max(f32::MIN_POSITIVE);
    f32::from_bits(x.to_bits() + 1) - x
}

/// A regular lattice of sample points: `cells[a] + 1` points along axis `a`, the first at `origin`,
/// spaced by `spacing` (anisotropic spacing is allowed because CT and MRI stacks have it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub origin: Vec3,
    pub spacing: Vec3,
    pub cells: [usize; 3],
}

impl Grid {
    /// A grid over `[min, max]` with `cells` cells per axis (spacing may differ per axis).
    pub fn new(min: Vec3, max: Vec3, cells: [usize; 3]) -> Result<Grid, Error> {
        check_bounds(min, max)?;
        if cells.contains(&0) {
            return Err(Error::InvalidGrid(format!(
                "every axis needs at least one cell, got {} x {} x {}",
                cells[0], cells[1], cells[2]
            )));
        }
        let extent = max - min;
        let spacing =
            Vec3::new(extent.x / cells[0] as f32, extent.y / cells[1] as f32, extent.z / cells[2] as f32);
        Grid { origin: min, spacing, cells }.checked()
    }

    /// A grid with cubic cells, `res` of them along the longest side of the bounds. The other axes get
    /// as many cells as cover their extent, and the bounds grow (about their centre) to whole cells.
    pub fn with_resolution(min: Vec3, max: Vec3, res: usize) -> Result<Grid, Error> {
        check_bounds(min, max)?;
        if res == 0 {
            return Err(Error::InvalidGrid("resolution must be at least 1 cell".into()));
        }
        if res > MAX_CELLS_PER_AXIS {
            return Err(Error::InvalidGrid(format!(
                "resolution {res} is more than {MAX_CELLS_PER_AXIS} cells along an axis"
            )));
        }
        let extent = max - min;
        let h = extent.max_element() / res as f32;
        let cells = [0, 1, 2].map(|a| ((extent[a] / h) - 1e-4).ceil().max(1.0) as usize);
        let covered = Vec3::new(cells[0] as f32, cells[1] as f32, cells[2] as f32) * h;
        let origin = (min + max) * 0.5 - covered * 0.5;
        Grid { origin, spacing: Vec3::splat(h), cells }.checked()
    }

    /// A lattice of `points[a]` samples along axis `a` (at least 2), the first at `origin`, spaced
    /// by `spacing` (positive): the layout of a raw volume file.
    pub fn from_points(points: [usize; 3], origin: Vec3, spacing: Vec3) -> Result<Grid, Error> {
        if points.iter().any(|&n| n < 2) {
            return Err(Error::InvalidGrid(format!(
                "dims must be three point counts, each at least 2, got {} x {} x {}",
                points[0], points[1], points[2]
            )));
        }
        if !(origin.is_finite() && spacing.is_finite() && spacing.cmpgt(Vec3::ZERO).all()) {
            return Err(Error::InvalidGrid(format!(
                "origin must be finite and spacing positive, got origin {origin}, spacing {spacing}"
            )));
        }
        Grid { origin, spacing, cells: points.map(|n| n - 1) }.checked()
    }

    /// The checks every constructor ends with, so that no grid the library builds can overflow a
    /// count, reach infinity, or have cells that `f32` cannot tell apart. Each is an error rather
    /// than a clamp: a silently different grid would mesh a different surface.
    fn checked(self) -> Result<Grid, Error> {
        if self.cells.iter().any(|&c| c > MAX_CELLS_PER_AXIS) {
            return Err(Error::InvalidGrid(format!(
                "{} x {} x {} cells: at most {MAX_CELLS_PER_AXIS} cells along an axis",
                self.cells[0], self.cells[1], self.cells[2]
            )));
        }
        if self.points().iter().try_fold(1usize, |n, &p| n.checked_mul(p)).is_none() {
            return Err(Error::GridTooLarge { cells: self.cell_count(), max_cells: usize::MAX as u64 });
        }
        let far = self.max();
        let reach = far.abs().max(self.origin.abs()).max_element();
        if reach.is_nan() || reach > MAX_COORDINATE {
            return Err(Error::InvalidGrid(format!(
                "the grid from {} spaced by {} reaches {far}; coordinates must lie within ±{MAX_COORDINATE:e} \
                 so that areas, volumes and normals stay finite in f32",
                self.origin, self.spacing
            )));
        }
        for a in 0..3 {
            let reach = self.origin[a].abs().max(far[a].abs());
            let ulp = f32_ulp(reach);
            if self.spacing[a] < MIN_ULPS_PER_CELL * ulp {
                return Err(Error::InvalidGrid(format!(
                    "cells of {} along {} at coordinates up to {reach} are finer than f32 can place \
                     vertices in ({} representable positions per cell, at least {MIN_ULPS_PER_CELL} \
                     needed); mesh the shape near the origin and move the mesh afterwards",
                    self.spacing[a],
                    ["x", "y", "z"][a],
                    (self.spacing[a] / ulp).floor()
                )));
            }
        }
        Ok(self)
    }

    /// Sample points per axis.
    pub fn points(&self) -> [usize; 3] {
        [self.cells[0] + 1, self.cells[1] + 1, self.cells[2] + 1]
    }

    pub fn point_count(&self) -> usize {
        let p = self.points();
        p[0] * p[1] * p[2]
    }

    /// Cells in the grid; saturates at `u64::MAX` (never wraps), so a size check cannot be fooled.
    pub fn cell_count(&self) -> u64 {
        self.cells.iter().try_fold(1u64, |n, &c| n.checked_mul(c as u64)).unwrap_or(u64::MAX)
    }

    /// World position of sample point `(i, j, k)`.
    #[inline]
    pub fn position(&self, i: usize, j: usize, k: usize) -> Vec3 {
        self.origin + self.spacing * Vec3::new(i as f32, j as f32, k as f32)
    }

    /// Linear index of sample point `(i, j, k)`, x fastest.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        let p = self.points();
        i + p[0] * (j + p[1] * k)
    }

    /// `(i, j, k)` of a linear sample index.
    pub fn unindex(&self, n: usize) -> [usize; 3] {
        let p = self.points();
        [n % p[0], (n / p[0]) % p[1], n / (p[0] * p[1])]
    }

    /// The far corner of the grid.
    pub fn max(&self) -> Vec3 {
        self.position(self.cells[0], self.cells[1], self.cells[2])
    }

    /// Length of a cell's longest side: the natural unit for "within a cell" tolerances.
    pub fn cell_size(&self) -> f32 {
        self.spacing.max_element()
    }

    /// Fails with [`Error::GridTooLarge`] when the grid exceeds `max_cells`.
    pub fn check_size(&self, max_cells: u64) -> Result<(), Error> {
        let cells = self.cell_count();
        if cells > max_cells {
            return Err(Error::GridTooLarge { cells, max_cells });
        }
        Ok(())
    }
}

/// The element type of raw samples. Integer samples become `f32` of the same value (no scaling),
/// so an iso-level for `u8` data is given in 0..=255.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dtype {
    #[default]
    F32,
    U8,
    U16,
}

impl Dtype {
    pub const NAMES: [&'static str; 3] = ["f32", "u8", "u16"];

    pub fn parse(name: &str) -> Result<Dtype, Error> {
        match name {
            "f32" => Ok(Dtype::F32),
            "u8" => Ok(Dtype::U8),
            "u16" => Ok(Dtype::U16),
            _ => Err(Error::UnknownName {
                kind: "dtype",
                name: name.to_string(),
                known: Self::NAMES.iter().map(|s| s.to_string()).collect(),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Dtype::F32 => "f32",
            Dtype::U8 => "u8",
            Dtype::U16 => "u16",
        }
    }

    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            Dtype::F32 => 4,
            Dtype::U8 => 1,
            Dtype::U16 => 2,
        }
    }
}

/// Decodes a raw volume: little-endian samples of type `dtype`, x fastest, exactly one per point
/// of `grid` (a wrong byte count is an error naming both counts, since a guessed layout would
/// mesh garbage). NaN and infinite `f32` samples are left for the mesher to report by position.
pub fn samples_from_bytes(bytes: &[u8], dtype: Dtype, grid: &Grid) -> Result<Vec<f32>, Error> {
    let [nx, ny, nz] = grid.points();
    let expected = grid.point_count() as u64 * dtype.size() as u64;
    if bytes.len() as u64 != expected {
        return Err(Error::InvalidGrid(format!(
            "{nx} x {ny} x {nz} {} samples take {expected} bytes, got {}",
            dtype.name(),
            bytes.len()
        )));
    }
    Ok(match dtype {
        Dtype::F32 => bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect(),
        Dtype::U8 => samples_from_u8(bytes),
        Dtype::U16 => bytes.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]]) as f32).collect(),
    })
}

/// `u8` samples as `f32` of the same value.
pub fn samples_from_u8(values: &[u8]) -> Vec<f32> {
    values.iter().map(|&v| v as f32).collect()
}

/// `u16` samples as `f32` of the same value (exact: every `u16` is an `f32`).
pub fn samples_from_u16(values: &[u16]) -> Vec<f32> {
    values.iter().map(|&v| v as f32).collect()
}

fn check_bounds(min: Vec3, max: Vec3) -> Result<(), Error> {
    if !(min.is_finite() && max.is_finite()) {
        return Err(Error::InvalidGrid(format!("bounds must be finite, got {min} .. {max}")));
    }
    if !(max.cmpgt(min).all()) {
        return Err(Error::InvalidGrid(format!(
            "bounds must have max > min on every axis, got {min} .. {max}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_counts_cells_on_the_longest_side() {
        let g = Grid::with_resolution(Vec3::new(-1.0, -0.5, 0.0), Vec3::new(1.0, 0.5, 0.25), 8).unwrap();
        assert_eq!(g.cells, [8, 4, 1]);
        assert!((g.spacing.x - 0.25).abs() < 1e-6);
        assert!((g.max() - Vec3::new(1.0, 0.5, 0.25)).length() < 1e-5);
    }

    #[test]
    fn index_round_trips() {
        let g = Grid::new(Vec3::ZERO, Vec3::ONE, [3, 4, 5]).unwrap();
        for n in 0..g.point_count() {
            let [i, j, k] = g.unindex(n);
            assert_eq!(g.index(i, j, k), n);
        }
    }

    #[test]
    fn raw_volumes_decode_little_endian_x_fastest() {
        let grid = Grid::from_points([3, 2, 2], Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 1.0, 2.0)).unwrap();
        assert_eq!(grid.cells, [2, 1, 1]);
        assert_eq!(grid.max(), Vec3::new(2.0, 3.0, 5.0));
        let u8s: Vec<u8> = (0..12).collect();
        assert_eq!(samples_from_bytes(&u8s, Dtype::U8, &grid).unwrap()[grid.index(2, 1, 0)], 5.0);
        let u16s: Vec<u8> = (0..12u16).flat_map(|v| (v * 300).to_le_bytes()).collect();
        assert_eq!(samples_from_bytes(&u16s, Dtype::U16, &grid).unwrap()[11], 3300.0);
        let f32s: Vec<u8> = (0..12).flat_map(|v| (v as f32 - 0.5).to_le_bytes()).collect();
        let values = samples_from_bytes(&f32s, Dtype::F32, &grid).unwrap();
        assert_eq!(values[0], -0.5);
        assert_eq!(values[11], 10.5);
        let err = samples_from_bytes(&u16s[..23], Dtype::U16, &grid).unwrap_err().to_string();
        assert_eq!(err, "invalid grid: 3 x 2 x 2 u16 samples take 24 bytes, got 23");
        assert_eq!(Dtype::parse("u16"), Ok(Dtype::U16));
        assert!(Dtype::parse("i16").unwrap_err().to_string().contains("known: f32, u8, u16"));
        assert!(Grid::from_points([1, 2, 2], Vec3::ZERO, Vec3::ONE).is_err());
        assert!(Grid::from_points([2, 2, 2], Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)).is_err());
    }

    #[test]
    fn rejects_empty_and_inverted_grids() {
        assert!(Grid::new(Vec3::ZERO, Vec3::ONE, [0, 1, 1]).is_err());
        assert!(Grid::new(Vec3::ONE, Vec3::ZERO, [1, 1, 1]).is_err());
        assert!(Grid::with_resolution(Vec3::ZERO, Vec3::ONE, 0).is_err());
        let g = Grid::new(Vec3::ZERO, Vec3::ONE, [100, 100, 100]).unwrap();
        assert_eq!(g.check_size(999_999), Err(Error::GridTooLarge { cells: 1_000_000, max_cells: 999_999 }));
    }
}

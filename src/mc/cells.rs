//! A grid's cells as Marching Cubes reads them: which ones the level crosses, found from sign
//! bits, and the tables that turn a crossed cell's corner values into polygons and triangles.
//! Plain MC, its quality variant and EMC all walk cells through here, so they agree on which
//! cells are crossed, in what order, and with which case.

use crate::grid::Grid;
use crate::tables::{
    polygon_table, polygon_table_with_faces, triangle_table, triangle_table_with_faces, CellPolygons,
    CellTriangles, CORNERS,
};

use super::{joined_faces, Topology};

/// The MC tables of a topology: one cell's polygons and their triangles from its corner values.
pub(crate) struct CellTables {
    polygons: &'static [CellPolygons],
    triangles: &'static [CellTriangles],
    topology: Topology,
}

impl CellTables {
    /// The tables of `topology`; the 16 384-entry trilinear ones are built only when asked for.
    pub(crate) fn new(topology: Topology) -> CellTables {
        match topology {
            Topology::Fixed => {
                CellTables { polygons: polygon_table(), triangles: triangle_table(), topology }
            }
            Topology::Trilinear => CellTables {
                polygons: polygon_table_with_faces(),
                triangles: triangle_table_with_faces(),
                topology,
            },
        }
    }

    /// The polygons and triangles of a cell of MC case `case` with corner values `d` (minus the
    /// iso-level); the trilinear topology also looks at which faces join their inside corners.
    pub(crate) fn lookup(&self, case: u8, d: &[f32; 8]) -> (&CellPolygons, &CellTriangles) {
        let joined = match self.topology {
            Topology::Fixed => 0,
            Topology::Trilinear => joined_faces(case, d),
        };
        self.lookup_joined(case, joined)
    }

    /// [`CellTables::lookup`] with the faces that join their inside corners already known (see
    /// [`joined_faces`]; ignored by the fixed topology).
    pub(crate) fn lookup_joined(&self, case: u8, joined: u8) -> (&CellPolygons, &CellTriangles) {
        let key = match self.topology {
            Topology::Fixed => case as usize,
            Topology::Trilinear => (case as usize) << 6 | joined as usize,
        };
        (&self.polygons[key], &self.triangles[key])
    }
}

/// A sweep up a grid's cell layers that finds, in each, the cells the level crosses, from each
/// point layer's signs as bits ([`LayerSigns`]).
pub(crate) struct CrossedCells<'a> {
    values: &'a [f32],
    grid: &'a Grid,
    iso: f32,
    corner_offsets: [usize; 8],
    /// The signs of the next cell layer's lower and upper point layers.
    below: LayerSigns,
    above: LayerSigns,
    next: usize,
}

impl<'a> CrossedCells<'a> {
    /// A sweep whose first layer is cell layer `first` (a z index).
    pub(crate) fn from_layer(values: &'a [f32], grid: &'a Grid, iso: f32, first: usize) -> Self {
        let [nx, ny, _] = grid.points();
        let mut below = LayerSigns::new(grid);
        below.read(values, grid, iso, first);
        CrossedCells {
            values,
            grid,
            iso,
            corner_offsets: CORNERS.map(|[a, b, c]| a + nx * (b + ny * c)),
            below,
            above: LayerSigns::new(grid),
            next: first,
        }
    }

    /// Calls `visit(cell, case, d)` for each cell of the next layer that the level crosses, row by
    /// row and in increasing x (the order [`super::EdgeCache`] needs), with the cell's lowest
    /// corner, its case (bit `c` set where corner `c` is inside, `value - iso < 0`) and its corner
    /// values minus the iso-level; then moves up one layer.
    pub(crate) fn next_layer(&mut self, mut visit: impl FnMut([usize; 3], u8, &[f32; 8])) {
        let k = self.next;
        let [cx, cy, _] = self.grid.cells;
        self.above.read(self.values, self.grid, self.iso, k + 1);
        for j in 0..cy {
            self.below.for_each_mixed_cell(&self.above, j, cx, |i| {
                let base = self.grid.index(i, j, k);
                let d: [f32; 8] =
                    std::array::from_fn(|c| self.values[base + self.corner_offsets[c]] - self.iso);
                let mut case = 0u8;
                for (c, &v) in d.iter().enumerate() {
                    case |= ((v < 0.0) as u8) << c;
                }
                visit([i, j, k], case, &d);
            });
        }
        std::mem::swap(&mut self.below, &mut self.above);
        self.next += 1;
    }
}

/// Bit `b` set where `values[b] - iso < 0`, for up to 64 values. The comparisons go to a byte
/// each, which vectorises, and each 8 bytes of 0/1 become 8 bits in one multiplication: byte `i`
/// times the constant's byte `7 - i` (2^i) lands in bit `56 + i` and nothing else reaches the top
/// byte.
fn inside_bits(values: &[f32], iso: f32) -> u64 {
    let mut flags = [0u8; 64];
    for (flag, &v) in flags.iter_mut().zip(values) {
        *flag = ((v - iso) < 0.0) as u8;
    }
    flags.chunks_exact(8).enumerate().fold(0, |word, (group, bytes)| {
        let bytes = u64::from_le_bytes(bytes.try_into().expect("eight bytes"));
        word | (bytes.wrapping_mul(0x0102_0408_1020_4080) >> 56) << (8 * group)
    })
}

/// Which points of one point layer are inside (`value - iso < 0`, the test that sets a cell's
/// case bits), one bit per point, rows of `words` 64-bit words. Most cells of a grid are far from
/// the level; with the signs as bits a row of 64 cells is found empty in a few word operations,
/// and only the cells the level crosses read their eight values.
struct LayerSigns {
    words: usize,
    bits: Vec<u64>,
}

impl LayerSigns {
    fn new(grid: &Grid) -> Self {
        let [nx, ny, _] = grid.points();
        let words = nx.div_ceil(64);
        LayerSigns { words, bits: vec![0; words * ny] }
    }

    /// Reads point layer `k`.
    fn read(&mut self, values: &[f32], grid: &Grid, iso: f32, k: usize) {
        let [nx, ny, _] = grid.points();
        let layer = &values[grid.index(0, 0, k)..][..nx * ny];
        for (row, bits) in layer.chunks_exact(nx).zip(self.bits.chunks_exact_mut(self.words)) {
            for (chunk, word) in row.chunks(64).zip(bits.iter_mut()) {
                *word = inside_bits(chunk, iso);
            }
        }
    }

    fn row(&self, j: usize) -> &[u64] {
        &self.bits[j * self.words..(j + 1) * self.words]
    }

    /// Calls `visit(i)`, in increasing `i < cx`, for each cell of row `j` between this layer and
    /// `above` whose eight corners are not all on one side.
    fn for_each_mixed_cell(&self, above: &LayerSigns, j: usize, cx: usize, mut visit: impl FnMut(usize)) {
        let rows = [self.row(j), self.row(j + 1), above.row(j), above.row(j + 1)];
        let all = |w: usize| if w < self.words { rows.iter().fold(!0, |a, r| a & r[w]) } else { 0 };
        let any = |w: usize| if w < self.words { rows.iter().fold(0, |a, r| a | r[w]) } else { 0 };
        for w in 0..self.words {
            // Point bit b is corner x of cell b; the cell's other x corner is bit b + 1, the next
            // word's bit 0 for b = 63.
            let (all_here, any_here) = (all(w), any(w));
            let all_in = all_here & (all_here >> 1 | all(w + 1) << 63);
            let any_in = any_here | any_here >> 1 | any(w + 1) << 63;
            let mut mixed = any_in & !all_in;
            let first = w * 64;
            if cx - first < 64 {
                mixed &= (1u64 << (cx - first)) - 1;
            }
            while mixed != 0 {
                visit(first + mixed.trailing_zeros() as usize);
                mixed &= mixed - 1;
            }
        }
    }
}

//! Fans whose centre left its cell, checked against the triangles around them.
//!
//! A feature point may sit up to half a cell outside its cell where the planes meet just beyond it
//! (see [`super::placement`]); that keeps creases that skim a cell's corner on the crease. Inside
//! its cell a fan can only meet its own cell's triangles, which extraction checks; outside, it can
//! cut a neighbour's, as on the gyroid's tightly curved sheets at res 24. Before the edge flips it
//! also pokes through the neighbour's triangles that the flips then replace by ones reaching its
//! centre, so the check runs after the flips: each such fan is tested against the triangles of the 27 cells around its own, and one
//! that cuts any has its centre moved to its best point inside the cell. Only vertex positions
//! change, never the connectivity, so the mesh stays MC's topology.

use super::feature::FeatureKind;
use super::placement::Placement;
use crate::grid::Grid;
use crate::mesh::analysis::self_intersect::triangle_pair_intersects;
use crate::mesh::Mesh;

/// Where each cell's triangles start in the mesh: extraction emits cells in index order. A cell
/// is named by the grid index of its lowest corner ([`Grid::index`]).
#[derive(Debug, Default)]
pub struct CellTriangleIndex {
    /// (cell, first triangle), for the cells that emitted triangles, ascending.
    starts: Vec<(usize, u32)>,
}

impl CellTriangleIndex {
    /// Records that the triangles of `cell` start at `first` (call in ascending cell order).
    pub fn start(&mut self, cell: usize, first: usize) {
        self.starts.push((cell, first as u32));
    }

    /// The triangle range of `cell` in a mesh of `triangle_count` triangles.
    fn range(&self, cell: usize, triangle_count: usize) -> std::ops::Range<usize> {
        let at = self.starts.partition_point(|&(c, _)| c < cell);
        match self.starts.get(at) {
            Some(&(c, first)) if c == cell => {
                let end = self.starts.get(at + 1).map_or(triangle_count, |&(_, next)| next as usize);
                first as usize..end
            }
            _ => 0..0,
        }
    }
}

/// A fan whose centre lies outside its cell, and where it would go inside.
#[derive(Debug, Clone, Copy)]
pub struct OutsideFan {
    pub vertex: u32,
    pub cell: [usize; 3],
    pub kind: FeatureKind,
    pub inside: Placement,
}

/// What extraction leaves for the check: the fans outside their cell, and where each cell's
/// triangles are.
#[derive(Debug, Default)]
pub struct OutsideFans {
    pub index: CellTriangleIndex,
    pub fans: Vec<OutsideFan>,
}

/// Moves the centre of every fan in `fans` that cuts a triangle of the cells around it to its
/// inside placement, and takes those fans out of `fans`: the moved ones are returned.
pub fn pull_back_crossing_fans(
    mesh: &mut Mesh,
    grid: &Grid,
    index: &CellTriangleIndex,
    fans: &mut Vec<OutsideFan>,
) -> Vec<OutsideFan> {
    let [cx, cy, cz] = grid.cells;
    let count = mesh.triangles.len();
    let mut moved = Vec::new();
    fans.retain(|fan| {
        let [i, j, k] = fan.cell;
        let around = |c: usize, n: usize| c.saturating_sub(1)..(c + 2).min(n);
        let nearby: Vec<usize> = around(k, cz)
            .flat_map(|kk| {
                around(j, cy).flat_map(move |jj| around(i, cx).map(move |ii| grid.index(ii, jj, kk)))
            })
            .flat_map(|cell| index.range(cell, count))
            .collect();
        // The fan's triangles, flipped ones included (those may sit in a neighbour's range).
        let own: Vec<usize> =
            nearby.iter().copied().filter(|&t| mesh.triangles[t].contains(&fan.vertex)).collect();
        let cuts =
            nearby.iter().any(|&t| own.iter().any(|&s| s != t && triangle_pair_intersects(mesh, s, t)));
        if cuts {
            mesh.positions[fan.vertex as usize] = fan.inside.position;
            moved.push(*fan);
        }
        !cuts
    });
    moved
}

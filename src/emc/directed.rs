//! Sampled directed distance fields (§3) and their Boolean operations.
//!
//! EMC needs, per grid point, only which side of the surface it is on and, along each of +x, +y,
//! +z, where the surface is crossed within one cell and its normal there. Stored, that record can
//! be combined: the union, intersection or difference of two solids sampled on the same grid is
//! decided edge by edge from the two records alone (the paper's "componentwise min/max"), with no
//! function behind either. That is what lets a triangle mesh or a point cloud be milled by a tool
//! (§5.1), or two scans be joined, and the result still be meshed with sharp edges where the
//! operands' surfaces meet: each crossing keeps its operand's exact position and normal, so the
//! new crease between them is found by EMC's feature detection like any other.
//!
//! One crossing per cell edge is kept (the sign change's); an operand that crosses an edge twice
//! (a sheet thinner than a cell) is already invisible to MC's signs, and stays so.

use super::edges::{EdgeSampler, FieldRoots};
use super::mesh_source::{check_encloses, grid_values, MeshBvh, MeshRays};
use super::{mesh_with_sampler, EmcMesh, EmcOptions, EmcTimings};
use crate::error::Error;
use crate::field::{sample_level_probed, Field};
use crate::grid::Grid;
use crate::mesh::Mesh;
use glam::Vec3;

/// Where the surface crosses a grid edge: the fraction of the way along +axis from the lower grid
/// point, and the unit outward normal there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub normal: Vec3,
}

/// A directed distance field sampled on a grid: per point, inside or not, and per point and axis
/// the crossing on the edge to the next point along +axis, where the sides differ.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectedGrid {
    pub grid: Grid,
    inside: Vec<bool>,
    hits: Vec<[Option<Hit>; 3]>,
}

impl DirectedGrid {
    /// Samples a solid: `values` (below `iso` inside, one per grid point) give the sides, `sampler`
    /// the crossings of the edges whose ends differ (a field's roots, a mesh's ray hits, a point
    /// cloud's tangent planes).
    pub fn sample(
        values: &[f32],
        grid: &Grid,
        iso: f32,
        sampler: &dyn EdgeSampler,
    ) -> Result<DirectedGrid, Error> {
        crate::field::check_finite(values, grid)?;
        let inside: Vec<bool> = values.iter().map(|&v| v - iso < 0.0).collect();
        let mut hits = vec![[None; 3]; inside.len()];
        for (from, axis, next) in grid_edges(grid) {
            if inside[from] != inside[next] {
                let [i, j, k] = grid.unindex(from);
                let a = grid.position(i, j, k);
                let mut b = a;
                b[axis] += grid.spacing[axis];
                let (t, normal) = sampler.crossing(a, b, values[from] - iso, values[next] - iso);
                hits[from][axis] = Some(Hit { t: t.clamp(0.0, 1.0), normal });
            }
        }
        Ok(DirectedGrid { grid: *grid, inside, hits })
    }

    /// Samples a field: sides from its values, crossings by root finding along the edges, normals
    /// from its gradient.
    pub fn from_field(field: &dyn Field, grid: &Grid, iso: f32) -> Result<DirectedGrid, Error> {
        let (values, _) = sample_level_probed(field, grid, iso, false)?;
        let sampler = FieldRoots { field, iso, directed: true, h: grid.cell_size() };
        DirectedGrid::sample(&values, grid, iso, &sampler)
    }

    /// Samples a closed triangle mesh: sides by ray votes, crossings by casting along the edges,
    /// normals of the triangles hit.
    pub fn from_mesh(mesh: &Mesh, grid: &Grid) -> Result<DirectedGrid, Error> {
        let source = MeshBvh::new(mesh)?;
        let values = grid_values(&source, grid);
        check_encloses(&source, &values)?;
        DirectedGrid::sample(&values, grid, 0.0, &MeshRays { mesh: &source, directed: true })
    }

    /// The solid of points in either operand.
    pub fn union(&self, other: &DirectedGrid) -> Result<DirectedGrid, Error> {
        self.combine(other, |a, b| a || b)
    }

    /// The solid of points in both operands.
    pub fn intersect(&self, other: &DirectedGrid) -> Result<DirectedGrid, Error> {
        self.combine(other, |a, b| a && b)
    }

    /// The solid of points in `self` but not in `other` (milling `other` out of `self`).
    pub fn subtract(&self, other: &DirectedGrid) -> Result<DirectedGrid, Error> {
        self.combine(&other.complement(), |a, b| a && b)
    }

    /// Inside and outside swapped, normals turned around.
    pub fn complement(&self) -> DirectedGrid {
        let flip = |h: &Option<Hit>| h.map(|h| Hit { t: h.t, normal: -h.normal });
        DirectedGrid {
            grid: self.grid,
            inside: self.inside.iter().map(|&s| !s).collect(),
            hits: self.hits.iter().map(|h| [flip(&h[0]), flip(&h[1]), flip(&h[2])]).collect(),
        }
    }

    /// Is grid point `index` inside the solid?
    pub fn is_inside(&self, index: usize) -> bool {
        self.inside[index]
    }

    /// The crossing on the edge from grid point `index` along +`axis`, if the sides differ there.
    pub fn hit(&self, index: usize, axis: usize) -> Option<Hit> {
        self.hits[index][axis]
    }

    /// Combines two solids on the same grid point by point with `keep` (a Boolean operation whose
    /// result is monotone in both operands: union, intersection). On an edge where the result
    /// changes side, the operands that changed side the same way did so at their own crossings;
    /// the result changes where the last of them does when every one of them must have changed
    /// (the side it changes *to* is kept only when all are on it), else where the first does.
    fn combine(
        &self,
        other: &DirectedGrid,
        keep: impl Fn(bool, bool) -> bool,
    ) -> Result<DirectedGrid, Error> {
        if self.grid != other.grid {
            return Err(Error::InvalidOption(
                "directed distance fields can only be combined on the same grid".to_string(),
            ));
        }
        let grid = &self.grid;
        let inside: Vec<bool> = self.inside.iter().zip(&other.inside).map(|(&a, &b)| keep(a, b)).collect();
        let mut hits = vec![[None; 3]; inside.len()];
        for (from, axis, next) in grid_edges(grid) {
            if inside[from] == inside[next] {
                continue;
            }
            // The operands whose side changed the way the result's did.
            let changed: Vec<Hit> = [self, other]
                .iter()
                .filter(|g| g.inside[from] == inside[from] && g.inside[next] == inside[next])
                .filter_map(|g| g.hits[from][axis])
                .collect();
            // Would the result still be on its `from` side if only one operand moved to the
            // `next` side? Then both must move: the later crossing counts.
            let target = inside[next];
            let needs_both = keep(target, !target) != target;
            let pick = |a: &Hit, b: &Hit| if (a.t < b.t) == needs_both { *b } else { *a };
            hits[from][axis] = changed.iter().copied().reduce(|a, b| pick(&a, &b));
        }
        Ok(DirectedGrid { grid: *grid, inside, hits })
    }
}

/// Every edge of the grid, as (lower point, axis, upper point) by grid index.
fn grid_edges(grid: &Grid) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
    let [nx, ny, nz] = grid.points();
    (0..grid.point_count()).flat_map(move |from| {
        let [i, j, k] = grid.unindex(from);
        [(i + 1 < nx, [i + 1, j, k]), (j + 1 < ny, [i, j + 1, k]), (k + 1 < nz, [i, j, k + 1])]
            .into_iter()
            .enumerate()
            .filter(|(_, (exists, _))| *exists)
            .map(move |(axis, (_, [a, b, c]))| (from, axis, grid.index(a, b, c)))
    })
}

/// Reads the crossings back for EMC: the edge from `a` along +axis is looked up by its lower end.
struct StoredCrossings<'a> {
    field: &'a DirectedGrid,
}

impl EdgeSampler for StoredCrossings<'_> {
    fn crossing(&self, a: Vec3, b: Vec3, _da: f32, _db: f32) -> (f32, Vec3) {
        let grid = &self.field.grid;
        let cell = ((a - grid.origin) / grid.spacing).round();
        let axis = (b - a).abs().max_position();
        let index = grid.index(cell.x as usize, cell.y as usize, cell.z as usize);
        match self.field.hits[index][axis] {
            Some(hit) => (hit.t, hit.normal),
            // Unreachable for edges whose sides differ; a midpoint keeps the mesh closed anyway.
            None => (0.5, Vec3::ZERO),
        }
    }
}

/// EMC of a directed distance field: the sides give MC's cases, the stored crossings the vertices
/// and the normals that feature detection reads.
pub fn mesh_directed(field: &DirectedGrid, options: &EmcOptions) -> Result<(EmcMesh, EmcTimings), Error> {
    let values: Vec<f32> = field.inside.iter().map(|&inside| if inside { -1.0 } else { 1.0 }).collect();
    let options = EmcOptions { iso: 0.0, ..*options };
    let (mut out, timings) = mesh_with_sampler(&values, &field.grid, &options, &StoredCrossings { field })?;
    out.points_evaluated = 0;
    Ok((out, timings))
}

//! Requests on inputs that are not fields: remeshing a triangle mesh and reconstructing a surface
//! from an oriented point cloud (EMC's own applications, paper §5.3 and §5.2). `method: "emc"`
//! gives the directed distances (ray hits, tangent planes); `"mc"` plain Marching Cubes on the same
//! grid's signed values, the baseline (`"mcq"` with better triangles); `"dmc"` and `"quad"` the
//! trilinear interpolant of those same values.
//!
//! Without `bounds` the grid covers the input's bounding box padded by two cells, `res` cells
//! along its longest side ([`padded_grid`]). The error statistics measure against the input itself:
//! the signed distance to the mesh, or to the tangent plane of the nearest sample.

use super::{dmc_on_samples, sampled_res, Meshed, Method, Output, Request};
use crate::emc::mesh_source::{self, mesh_bounds, padded_grid, MeshBvh};
use crate::emc::orient;
use crate::emc::point_source::{self, PointIndex};
use crate::error::Error;
use crate::field::{Field, SampleGradient, SampledField};
use crate::grid::Grid;
use crate::input::PointCloud;
use crate::mesh::Mesh;
use crate::{mc, mcq, quad};
use glam::Vec3;

/// The request's bounds, or the input's padded by two cells.
fn input_grid(bounds: (Vec3, Vec3), request: &Request) -> Result<Grid, Error> {
    let grid = match request.bounds {
        Some((min, max)) => Grid::with_resolution(min, max, request.res)?,
        None => padded_grid(bounds.0, bounds.1, request.res)?,
    };
    grid.check_size(request.max_cells)?;
    Ok(grid)
}

/// The grid methods and DMC on the grid's signed values (sampled in `sample_ms`): plain MC, MC with
/// better triangles, and DMC and the quad mesher over the trilinear interpolant of the same values.
/// Those two do not query the input directly: its signs are decided per grid point (votes of rays
/// through the grid), which a point query cannot match near the input's edges. Not for EMC, which
/// samples the input along the grid's edges itself.
fn mesh_signed_values(
    values: &[f32],
    grid: &Grid,
    request: &Request,
    sample_ms: f64,
) -> Result<Meshed, Error> {
    Ok(match request.method {
        Method::Mcq => {
            let (mesh, report) = mcq::mesh_samples(values, grid, &request.mcq_options())?;
            Meshed::plain(mesh, mcq::McqReport { sample_ms, ..report }.phases())
        }
        Method::Dmc => dmc_on_samples(values, grid, request)?,
        Method::Quad => {
            let field = SampledField { grid: *grid, values, gradient: SampleGradient::Trilinear };
            // Signs exactly as MC reads them: the samples minus the iso-level.
            let shifted: Vec<f32> = values.iter().map(|v| v - request.iso).collect();
            let level = super::Shifted { field: &field, iso: request.iso };
            let (out, phases) = quad::mesh_samples(&shifted, &level, grid, &request.quad_options())?;
            Meshed::from_quad(out, phases)
        }
        _ => {
            let (mesh, timings) = mc::mesh_samples(values, grid, &request.mc_options())?;
            Meshed::plain(mesh, mc::McTimings { sample_ms, ..timings }.phases())
        }
    })
}

/// The request's own checks, and an iso-level of 0: the surface is the input itself.
fn iso_must_be_zero(request: &Request, what: &str) -> Result<(), Error> {
    request.validate()?;
    if request.iso != 0.0 {
        return Err(Error::InvalidOption(format!("iso must be 0 when {what}, got {}", request.iso)));
    }
    Ok(())
}

/// Remeshes a triangle mesh (counter-clockwise seen from outside, or consistently the other way
/// round, which is detected and turned around). A mesh with holes is meshed by its generalised
/// winding number, which spans them; one that bounds nothing (a sheet) is refused.
pub fn mesh_triangles(mesh: &Mesh, request: &Request) -> Result<Output, Error> {
    iso_must_be_zero(request, "remeshing a triangle mesh (the surface is the mesh)")?;
    let bounds = mesh_bounds(mesh);
    let grid = input_grid(bounds, request)?;
    let source = MeshBvh::new(mesh)?;
    let meshed = match request.method {
        Method::Emc => {
            let (out, timings) = mesh_source::remesh(mesh, &grid, &request.emc_options())?;
            Meshed::from_emc(out, timings)
        }
        _ => {
            let t0 = web_time::Instant::now();
            let values = mesh_source::grid_values(&source, &grid);
            mesh_source::check_encloses(&source, &values)?;
            mesh_signed_values(&values, &grid, request, mc::ms_since(t0))?
        }
    };
    let res = sampled_res(&grid, request);
    let truth = MeshDistance::new(&source, bounds);
    let meshed = meshed.refine(request, &truth, grid.cell_size())?;
    meshed.analyse(request.method, res, &truth, request.analysis)
}

/// Reconstructs the surface an oriented point cloud samples. Normals should point out of the
/// solid; they are scaled to unit length here, and the few that disagree with their neighbours (or
/// all of them, in a cloud exported inside out) are turned around first
/// ([`orient::orient_normals`]); a cloud whose normals have no prevailing orientation is refused.
pub fn mesh_points(cloud: &PointCloud, request: &Request) -> Result<Output, Error> {
    iso_must_be_zero(request, "reconstructing from points (the surface is the samples' tangent planes)")?;
    let mut cloud = cloud.clone().normalized()?;
    cloud.validate()?;
    orient::orient_normals(&mut cloud)?;
    let grid = input_grid(cloud.bounds(), request)?;
    let index = PointIndex::new(&cloud)?;
    let meshed = match request.method {
        Method::Emc => {
            let (out, timings) = point_source::reconstruct(&cloud, &grid, &request.emc_options())?;
            Meshed::from_emc(out, timings)
        }
        _ => {
            let t0 = web_time::Instant::now();
            let values = point_source::grid_values(&index, &grid);
            mesh_signed_values(&values, &grid, request, mc::ms_since(t0))?
        }
    };
    let res = sampled_res(&grid, request);
    let truth = PlaneDistance(&index);
    let meshed = meshed.refine(request, &truth, grid.cell_size())?;
    meshed.analyse(request.method, res, &truth, request.analysis)
}

/// Signed distance to a triangle mesh, the truth a remeshed mesh is measured against: the
/// distance to the nearest point, negative where the offset from that point faces against its
/// triangle's normal. The gradient points from the nearest point, so one projection step lands on
/// the mesh; within `on_surface` of the mesh (where that direction is rounding noise) it is the
/// nearest triangle's normal.
pub struct MeshDistance<'a> {
    pub mesh: &'a MeshBvh,
    pub on_surface: f32,
}

impl<'a> MeshDistance<'a> {
    /// `on_surface` is 1e-5 of the diagonal of `bounds`, a hundred times the tolerance of the
    /// projections in `mesh::analysis::surface_error`.
    pub fn new(mesh: &'a MeshBvh, bounds: (Vec3, Vec3)) -> MeshDistance<'a> {
        MeshDistance { mesh, on_surface: 1e-5 * (bounds.1 - bounds.0).length() }
    }
}

impl Field for MeshDistance<'_> {
    fn value(&self, p: Vec3) -> f32 {
        match self.mesh.closest_point(p) {
            Some((c, t)) => {
                let d = (p - c).length();
                if self.mesh.normal(t).dot(p - c) < 0.0 {
                    -d
                } else {
                    d
                }
            }
            None => f32::INFINITY,
        }
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        let (c, t) = self.mesh.closest_point(p)?;
        let n = self.mesh.normal(t);
        let away = (p - c).normalize_or_zero();
        Some(if (p - c).length() <= self.on_surface || away == Vec3::ZERO {
            n
        } else if n.dot(away) < 0.0 {
            -away
        } else {
            away
        })
    }
}

/// Distance to the tangent plane of the nearest sample (§3.1), the truth a reconstruction is
/// measured against.
pub struct PlaneDistance<'a>(pub &'a PointIndex);

impl Field for PlaneDistance<'_> {
    fn value(&self, p: Vec3) -> f32 {
        self.0.plane_distance(self.0.nearest(p, None), p)
    }

    fn gradient(&self, p: Vec3) -> Option<Vec3> {
        Some(self.0.sample(self.0.nearest(p, None)).1)
    }
}

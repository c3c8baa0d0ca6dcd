//! Extended Marching Cubes (Kobbelt, Botsch, Schwanecke, Seidel 2001): Marching Cubes whose cells
//! detect sharp features from the normals at their edge crossings and, where they find one, place an
//! extra vertex on the feature and fan the cell's polygon around it. A final pass of edge flips turns
//! the feature points of neighbouring cells into connected feature lines.
//!
//! The topology is exactly plain MC's on the same grid (same polygons from [`crate::tables`]), so
//! EMC inherits its watertightness; only the geometry inside each cell changes.
//!
//! Besides fields and samples, EMC meshes triangle meshes ([`mesh_source::remesh`], ray casting)
//! and oriented point clouds ([`point_source::reconstruct`], tangent planes): the paper's §3.1
//! directed distances for its remeshing (§5.3) and reconstruction (§5.2) applications.

pub mod crease;
mod crossings;
pub mod directed;
pub mod edges;
pub mod feature;
pub mod flip;
pub mod lines;
pub mod merge;
pub mod mesh_source;
pub mod nearby;
pub mod orient;
pub mod placement;
mod plan;
pub mod point_source;
pub mod resample;
mod sharp;
pub mod strip;
pub mod untangle;
pub mod winding;

use crate::error::Error;
use crate::field::{check_finite, sample_level_probed, Field};
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mc::{ms_since, CellTables, EdgeCache, Topology, NONE};
use crate::mcq::PolygonRules;
use crate::mesh::analysis::tri_tri::triangles_intersect;
use crate::mesh::Mesh;
use crossings::{ActiveCell, Cells};
use edges::{EdgeSampler, FieldRoots, SampleInterpolation};
use feature::{classify, FeatureKind};
use glam::{DVec3, Vec3};
use placement::{Component, Placed};
use plan::{Plan, EXTRA};
use untangle::OutsideFan;
use web_time::Instant;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmcOptions {
    pub iso: f32,
    /// Sharp when the normal cone's opening min nᵢ·nⱼ is below this (paper: 0.9).
    pub theta_sharp: f32,
    /// Corner when max |nᵢ·n*| exceeds this (paper: 0.7).
    pub phi_corner: f32,
    /// Exact edge crossings by root finding (directed distances); `false` interpolates linearly.
    pub directed: bool,
    /// Run the edge-flipping pass that makes feature lines explicit.
    pub flip_edges: bool,
    pub topology: Topology,
    pub max_cells: u64,
    /// Evaluate the field only where its interval bounds say the surface may be (§2's crust);
    /// the output is identical. Fields without interval bounds are sampled everywhere.
    pub crust: bool,
    /// Triangulate the components without a feature point by the per-cell polygon rules of
    /// [`crate::mcq`] (cut off sharp corners, inner vertex in long or uneven polygons, otherwise
    /// split the largest angle) instead of MC's table; `None` (default) keeps MC's triangles.
    /// Feature fans are unchanged. No vertex snapping.
    pub better_triangles: Option<PolygonRules>,
    /// Move edge points onto curved creases by sampling each sheet again next to the solved point
    /// (see [`resample`]), where the input can be sampled off the grid edges (functions, with
    /// `directed`). There, a feature point the field puts more than 1 % of a cell off the surface
    /// is reported as an approximate centre (see [`placement::Placed::check_surface`]). `false`
    /// keeps the paper's tangent-plane point.
    pub resample_creases: bool,
    /// Collapse one flat crossing into each fan centre (see [`merge`]): gives back the fans' two
    /// extra triangles where a flat face meets the feature, without moving the surface.
    pub merge_flat: bool,
}

impl Default for EmcOptions {
    fn default() -> Self {
        EmcOptions {
            iso: 0.0,
            theta_sharp: 0.9,
            phi_corner: 0.7,
            directed: true,
            flip_edges: true,
            topology: Topology::Fixed,
            max_cells: DEFAULT_MAX_CELLS,
            crust: true,
            better_triangles: None,
            resample_creases: true,
            merge_flat: true,
        }
    }
}

impl EmcOptions {
    pub(crate) fn validate(&self) -> Result<(), Error> {
        let check = |name: &str, v: f32| {
            if (-1.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(Error::InvalidOption(format!("{name} is a cosine and must lie in [-1, 1], got {v}")))
            }
        };
        check("thetaSharp", self.theta_sharp)?;
        check("phiCorner", self.phi_corner)?;
        if !self.iso.is_finite() {
            return Err(Error::InvalidOption(format!("iso must be finite, got {}", self.iso)));
        }
        Ok(())
    }
}

/// An EMC mesh: the triangles plus what it knows about features.
#[derive(Debug, Clone, Default)]
pub struct EmcMesh {
    pub mesh: Mesh,
    /// Per vertex: was it placed on a detected edge or corner?
    pub feature_vertex: Vec<bool>,
    /// The reconstructed feature lines as mesh edges (see [`lines::feature_edges`]): between
    /// feature vertices, bridged through an approximate centre where a crease has a gap.
    pub feature_edges: Vec<[u32; 2]>,
    pub edge_features: usize,
    pub corner_features: usize,
    pub flips: usize,
    /// Grid points where the field was evaluated, and how many the grid has.
    pub points_evaluated: usize,
    pub grid_points: usize,
    /// Sharp components meshed as plain MC instead: their fan around the feature point would fold
    /// over (the planes meet outside the cell), or its centre, only an approximation of the
    /// feature, lies farther from the surface than MC's triangles of the polygon.
    pub rejected_features: usize,
    /// Sharp components fanned around a point off their feature (see [`placement`]): clamped into
    /// the cell or pulled toward the polygon, because no point on the feature gave a valid fan.
    pub approximate_features: usize,
    /// Fan centres outside their cell moved back inside because their fan cut a neighbour's
    /// triangles (see [`untangle`]).
    pub pulled_back_features: usize,
    /// Crossings collapsed into fan centres on flat faces (see [`merge`]).
    pub flat_merges: usize,
}

#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EmcTimings {
    pub sample_ms: f64,
    pub extract_ms: f64,
    pub flip_ms: f64,
}

impl EmcTimings {
    pub fn phases(&self) -> Vec<(String, f64)> {
        vec![
            ("sample".to_string(), self.sample_ms),
            ("extract".to_string(), self.extract_ms),
            ("flip".to_string(), self.flip_ms),
        ]
    }
}

/// EMC over a field: directed distances by root finding, normals from its gradient.
pub fn mesh_field(
    field: &dyn Field,
    grid: &Grid,
    options: &EmcOptions,
) -> Result<(EmcMesh, EmcTimings), Error> {
    options.validate()?;
    grid.check_size(options.max_cells)?;
    let t0 = Instant::now();
    let (values, evaluated) = sample_level_probed(field, grid, options.iso, options.crust)?;
    let sample_ms = ms_since(t0);
    let sampler = FieldRoots { field, iso: options.iso, directed: options.directed, h: grid.cell_size() };
    let (mut mesh, mut timings) = mesh_with_sampler(&values, grid, options, &sampler)?;
    mesh.points_evaluated = evaluated;
    timings.sample_ms = sample_ms;
    Ok((mesh, timings))
}

/// EMC over samples alone: crossings by linear interpolation, normals from the samples' gradient.
pub fn mesh_samples(
    values: &[f32],
    grid: &Grid,
    options: &EmcOptions,
) -> Result<(EmcMesh, EmcTimings), Error> {
    options.validate()?;
    grid.check_size(options.max_cells)?;
    check_finite(values, grid)?;
    let (mut mesh, timings) =
        mesh_with_sampler(values, grid, options, &SampleInterpolation { values, grid })?;
    mesh.points_evaluated = grid.point_count();
    Ok((mesh, timings))
}

/// EMC from grid values (their signs pick the MC case, `value - iso < 0` inside) and any source of
/// edge crossings: the entry point for inputs that are neither fields nor plain samples, such as
/// triangle meshes (ray casting) and point clouds (tangent planes).
pub fn mesh_with_sampler(
    values: &[f32],
    grid: &Grid,
    options: &EmcOptions,
    sampler: &dyn EdgeSampler,
) -> Result<(EmcMesh, EmcTimings), Error> {
    options.validate()?;
    grid.check_size(options.max_cells)?;
    check_finite(values, grid)?;
    let mut timings = EmcTimings::default();
    let t1 = Instant::now();
    let (mut out, mut centres, outside) = extract(values, grid, options, sampler)?;
    out.grid_points = grid.point_count();
    timings.extract_ms = ms_since(t1);
    crate::progress::checkpoint("flip", 0.0)?;
    let t2 = Instant::now();
    // Flip, then pull back the fans outside their cell that cut a neighbour's triangles; where any
    // moved, flip again from the unflipped mesh, so that no flip is kept that was made for a
    // centre's old position (those cut other sheets on the gyroid). Each fan moves at most once.
    // Approximate fan centres are flipped toward too (next to one on its feature): joining
    // neighbouring fan centres takes the chord across a crease out of the mesh.
    let mut outside = outside;
    let unflipped = if outside.is_empty() { Vec::new() } else { out.mesh.triangles.clone() };
    let flip = |out: &mut EmcMesh, centres: &FanCentres| {
        if options.flip_edges {
            out.flips =
                flip::flip_toward_features(&mut out.mesh, &centres.any, &centres.on_feature, grid.spacing);
        }
    };
    flip(&mut out, &centres);
    while pull_back(&mut out, &mut centres, grid, &mut outside) > 0 {
        out.mesh.triangles.clone_from(&unflipped);
        flip(&mut out, &centres);
    }
    if options.merge_flat {
        out.flat_merges = merge::merge_flat_crossings(
            &mut out.mesh,
            &mut centres.any,
            &mut out.feature_vertex,
            &mut centres.crease,
            grid.cell_size(),
        );
    }
    merge::weld_facing_centres(
        &mut out.mesh,
        &mut centres.any,
        &mut out.feature_vertex,
        &mut centres.crease,
        (grid.origin, grid.spacing),
    );
    out.feature_edges =
        lines::feature_edges(&out.mesh, &centres.any, &out.feature_vertex, &centres.crease, grid.cell_size());
    timings.flip_ms = ms_since(t2);
    Ok((out, timings))
}

/// The grid's cells in slabs of cell layers, four per thread at a time between checkpoints
/// ([`crate::par`]; slabs through a part's detail take several times as long as others, and
/// with one slab per thread each step waited for the slowest: extraction of the gear at 256
/// cells on two threads 150 -> 120 ms, median of five), joined as Marching Cubes joins its slabs
/// ([`crate::mc::extract`]): a slab's vertices on its lowest point layer are the slab below's,
/// so the mesh is the one sweep's, vertex for vertex, however the grid is cut. A crossing on a
/// shared layer is computed by both slabs from the same edge and samples, so both decide their
/// cells with the same point. On one thread the slabs are [`CHECKPOINT_LAYERS`] high, so a stop
/// is seen that often.
fn extract(
    values: &[f32],
    grid: &Grid,
    options: &EmcOptions,
    sampler: &dyn EdgeSampler,
) -> Result<(EmcMesh, FanCentres, Vec<OutsideFan>), Error> {
    let cz = grid.cells[2];
    let per_step = match crate::par::threads() {
        1 => 1,
        n => 4 * n,
    };
    let layers = crate::par::piece_len(cz, crate::mc::MIN_SLAB_LAYERS).min(CHECKPOINT_LAYERS);
    let slabs = cz.div_ceil(layers);
    let mut parts = Vec::with_capacity(slabs);
    for first in (0..slabs).step_by(per_step) {
        crate::progress::checkpoint("extract", (first * layers) as f32 / cz as f32)?;
        parts.extend(crate::par::map(per_step.min(slabs - first), |s| {
            let start = (first + s) * layers;
            extract_slab(values, grid, options, sampler, start..(start + layers).min(cz))
        }));
    }
    Ok(join_slabs(parts))
}

/// Cell layers a slab of [`extract`] has at most: EMC spends milliseconds per layer at fine
/// resolutions, and a stop asked for in the page should not wait much longer than that.
const CHECKPOINT_LAYERS: usize = 16;

/// One slab's output, its vertex ids its own; `bottom` and `top` are the ids its edge cache gave
/// the x and y edges of its lowest and highest point layers.
struct Slab {
    out: EmcMesh,
    normals: Vec<Vec3>,
    centres: FanCentres,
    outside: Vec<OutsideFan>,
    bottom: [Vec<u32>; 2],
    top: [Vec<u32>; 2],
}

/// The slabs as one mesh, each slab's lowest-layer vertices merged into the slab below's.
fn join_slabs(slabs: Vec<Slab>) -> (EmcMesh, FanCentres, Vec<OutsideFan>) {
    let mut out = EmcMesh::default();
    let mut normals = Vec::new();
    let mut centres = FanCentres::default();
    let mut outside = Vec::new();
    let mut below_top: Option<[Vec<u32>; 2]> = None;
    for slab in slabs {
        let mut global = vec![NONE; slab.out.mesh.positions.len()];
        if let Some(top) = &below_top {
            for (bottom, top) in slab.bottom.iter().zip(top) {
                for (&local, &shared) in bottom.iter().zip(top) {
                    if local != NONE {
                        debug_assert_eq!(
                            slab.out.mesh.positions[local as usize], out.mesh.positions[shared as usize],
                            "a crossing placed differently by two slabs"
                        );
                        global[local as usize] = shared;
                    }
                }
            }
        }
        for (v, id) in global.iter_mut().enumerate() {
            if *id == NONE {
                *id = out.mesh.positions.len() as u32;
                out.mesh.positions.push(slab.out.mesh.positions[v]);
                normals.push(slab.normals[v]);
                out.feature_vertex.push(slab.out.feature_vertex[v]);
                centres.push(slab.centres.any[v], slab.centres.on_feature[v], slab.centres.crease[v]);
            }
        }
        out.mesh.triangles.extend(slab.out.mesh.triangles.iter().map(|t| t.map(|v| global[v as usize])));
        outside.extend(
            slab.outside.into_iter().map(|fan| OutsideFan { vertex: global[fan.vertex as usize], ..fan }),
        );
        out.edge_features += slab.out.edge_features;
        out.corner_features += slab.out.corner_features;
        out.approximate_features += slab.out.approximate_features;
        out.rejected_features += slab.out.rejected_features;
        below_top = Some(slab.top.map(|plane| {
            plane.into_iter().map(|v| if v == NONE { NONE } else { global[v as usize] }).collect()
        }));
    }
    out.mesh.normals = normals;
    (out, centres, outside)
}

/// EMC on the cell layers `layers` (z indices), with vertex ids of the slab's own.
fn extract_slab(
    values: &[f32],
    grid: &Grid,
    options: &EmcOptions,
    sampler: &dyn EdgeSampler,
    layers: std::ops::Range<usize>,
) -> Slab {
    let [nx, ny, _] = grid.points();
    let mut out = EmcMesh::default();
    let mut cache = EdgeCache::new(nx, ny);
    let tables = CellTables::new(options.topology);
    let cells = Cells { values, grid, iso: options.iso, tables: &tables };
    let mut normals_of_vertex: Vec<Vec3> = Vec::new();
    let mut outside_fans: Vec<OutsideFan> = Vec::new();
    let mut centres = FanCentres::default();

    let first = layers.start;
    let slab_cells = cells.active(layers.clone());
    let crossings = cells.crossings(sampler, &slab_cells);
    for k in layers {
        if k > first {
            cache.advance();
        }
        for cell in slab_cells.layer(k) {
            let ActiveCell { i, j, d, case } = *cell;
            let (polygons, triangles) = tables.lookup(case, &d);
            let mut first_triangle = 0;
            let cell_min = grid.position(i, j, k);
            let cell_max = cell_min + grid.spacing;
            // Pass 1: the polygons' vertices, and for each a feature point where it is sharp.
            let mut plans: Vec<Plan> = Vec::with_capacity(4);
            for (p, poly) in polygons.iter().enumerate() {
                let count = triangles.per_polygon[p] as usize;
                let group = first_triangle..first_triangle + count;
                first_triangle += count;
                let mut by_edge = [NONE; 13];
                for &e in poly {
                    let slot = cache.slot(i, j, e as usize);
                    if *slot == NONE {
                        let (p, n) = crossings.get(grid, [i, j, k], e as usize);
                        *slot = out.mesh.positions.len() as u32;
                        out.mesh.positions.push(p);
                        normals_of_vertex.push(n);
                        out.feature_vertex.push(false);
                        centres.push(false, false, Vec3::ZERO);
                    }
                    by_edge[e as usize] = *slot;
                }
                let ids: Vec<u32> = poly.iter().map(|&e| by_edge[e as usize]).collect();
                let pts: Vec<Vec3> = ids.iter().map(|&v| out.mesh.positions[v as usize]).collect();
                let nrm: Vec<Vec3> = ids.iter().map(|&v| normals_of_vertex[v as usize]).collect();
                let kind = classify(&nrm, options.theta_sharp, options.phi_corner);
                let (mut feature, mut strip, mut sharp_kind) = (None, None, FeatureKind::Smooth);
                if kind != FeatureKind::Smooth {
                    let domain = (grid.origin, grid.max());
                    let component = Component { pts: &pts, nrm: &nrm, cell_min, cell_max, domain };
                    let on_surface = ON_SURFACE * grid.cell_size();
                    let sharp = sharp::solve(kind, &component, sampler, options, on_surface);
                    (feature, sharp_kind) = (sharp.feature, sharp.kind);
                    // No feature vertex: two creases may bound a face narrower than the cell.
                    let met = feature.as_ref().is_some_and(|(placed, _)| placed.at.is_feature_vertex());
                    if sharp_kind != FeatureKind::Smooth && !met && options.resample_creases {
                        let distance = |p: Vec3| sampler.distance(p);
                        strip = strip::solve(&component, options.theta_sharp, &distance, on_surface);
                    }
                    // A feature met, but a face between two creases hidden from the crossings.
                    if let (true, Some(between)) = (met, sharp.between) {
                        strip = strip::hidden(&component, between, sampler, options.theta_sharp, on_surface);
                    }
                }
                let mut plan = Plan { by_edge, ids, pts, nrm, cell_edges: poly, group, feature, strip };
                if plan.strip.is_some() {
                    let rules = options.better_triangles.as_ref();
                    let positions = &out.mesh.positions;
                    if plan.strip_is_nearer(positions, triangles, rules, |p| sampler.distance(p)) {
                        plan.feature = None;
                    } else {
                        plan.strip = None;
                    }
                }
                out.rejected_features += (sharp_kind != FeatureKind::Smooth
                    && plan.feature.is_none()
                    && plan.strip.is_none()) as usize;
                // An approximate centre only bends the patch towards a feature it cannot
                // reach; where it ends up farther from the surface than MC's own triangles
                // of the polygon, MC's are kept.
                if options.resample_creases
                    && plan.approximate_centre_is_worse_than_mc(
                        &out.mesh.positions,
                        triangles,
                        options.better_triangles.as_ref(),
                        |p| sampler.distance(p),
                        WORSE_THAN_MC * grid.cell_size(),
                    )
                {
                    plan.feature = None;
                    out.rejected_features += 1;
                }
                plans.push(plan);
            }
            // Pass 2: where a cell holds several components (sheets close together), their
            // fans must not cross one another or the others' MC triangles. Each centre stays
            // inside the cell (an outside one takes its inside placement: it could not be
            // pulled back later without being decided again), and fans are taken one at a
            // time, each only if it crosses none of the other components' triangles as they
            // stand (MC's, or a fan taken before it). MC's triangles do not cross, and every
            // fan taken keeps it so: the cell is decided once, without a repair afterwards.
            if plans.len() > 1 {
                let rules = options.better_triangles.as_ref();
                let positions = &out.mesh.positions;
                let mut current: Vec<Vec<[DVec3; 3]>> =
                    plans.iter().map(|p| p.plain_triangles(positions, triangles, rules)).collect();
                for a in 0..plans.len() {
                    if let Some((placed, _)) = &mut plans[a].feature {
                        if let Some(inside) = placed.inside.take() {
                            placed.at = inside;
                        }
                    }
                    let Some(fan) = plans[a].fan_triangles() else { continue };
                    let cuts = (0..plans.len())
                        .filter(|&b| b != a)
                        .any(|b| fan.iter().any(|t| current[b].iter().any(|u| triangles_intersect(t, u))));
                    if cuts {
                        plans[a].feature = None;
                        plans[a].strip = None;
                        out.rejected_features += 1;
                    } else {
                        current[a] = fan;
                    }
                }
            }
            // Pass 3: emit.
            for plan in plans {
                if let Some((strip, _)) = &plan.strip {
                    let first = out.mesh.positions.len();
                    for (centre, crease) in strip.centres.iter().zip(&strip.creases) {
                        out.mesh.positions.push(*centre);
                        normals_of_vertex.push(plan.nrm.iter().sum::<Vec3>().normalize_or_zero());
                        out.feature_vertex.push(true);
                        centres.push(true, true, *crease);
                        out.edge_features += 1;
                    }
                    let n = plan.ids.len();
                    let id = |v: usize| if v < n { plan.ids[v] } else { (first + v - n) as u32 };
                    out.mesh.triangles.extend(strip.triangles.iter().map(|t| t.map(id)));
                    continue;
                }
                let Some((Placed { at: f, inside }, kind)) = plan.feature else {
                    let (tris, extra) =
                        plan.plain(&out.mesh.positions, triangles, options.better_triangles.as_ref());
                    let extra_id = out.mesh.positions.len() as u32;
                    if let Some(c) = extra {
                        out.mesh.positions.push(c);
                        normals_of_vertex.push(plan.nrm.iter().sum::<Vec3>().normalize_or_zero());
                        out.feature_vertex.push(false);
                        centres.push(false, false, Vec3::ZERO);
                    }
                    let id = |v: u32| if v == EXTRA { extra_id } else { v };
                    out.mesh.triangles.extend(tris.into_iter().map(|t| t.map(id)));
                    continue;
                };
                let fid = out.mesh.positions.len() as u32;
                if let Some(inside) = inside {
                    outside_fans.push(OutsideFan { vertex: fid, cell: [i, j, k], kind, inside });
                }
                out.mesh.positions.push(f.position);
                normals_of_vertex.push(plan.nrm.iter().sum::<Vec3>().normalize_or_zero());
                out.feature_vertex.push(f.is_feature_vertex());
                let crease = match kind {
                    FeatureKind::Edge => feature::crease_direction(&plan.nrm).unwrap_or(Vec3::ZERO),
                    _ => Vec3::ZERO,
                };
                centres.push(true, f.on_feature, crease);
                match (f.is_feature_vertex(), kind) {
                    (false, _) => out.approximate_features += 1,
                    (true, FeatureKind::Corner) => out.corner_features += 1,
                    (true, _) => out.edge_features += 1,
                }
                let ids = &plan.ids;
                for q in 0..ids.len() {
                    out.mesh.triangles.push([fid, ids[q], ids[(q + 1) % ids.len()]]);
                }
            }
        }
    }
    let (bottom, top) = cache.into_outer_layers();
    Slab { out, normals: normals_of_vertex, centres, outside: outside_fans, bottom, top }
}

/// Per vertex: is it the centre of a feature fan (on the feature or approximately), and is it on
/// its solved feature (a feature vertex, or one off the surface: see
/// [`placement::Placed::check_surface`])? Flips join centres where one of them is on its feature.
#[derive(Default)]
struct FanCentres {
    any: Vec<bool>,
    on_feature: Vec<bool>,
    /// The direction of an edge centre's crease (zero for corners and other vertices): feature
    /// lines follow it (see [`lines::feature_edges`]).
    crease: Vec<Vec3>,
}

impl FanCentres {
    fn push(&mut self, centre: bool, on_feature: bool, crease: Vec3) {
        self.crease.push(crease);
        self.any.push(centre);
        self.on_feature.push(on_feature);
    }
}

/// Moves the centres of fans outside their cell that cut a neighbour's triangles back inside
/// (see [`untangle`]), keeping the feature flags and counts right.
/// Returns how many moved; those are dropped from `outside`.
fn pull_back(
    out: &mut EmcMesh,
    centres: &mut FanCentres,
    grid: &Grid,
    outside: &mut Vec<OutsideFan>,
) -> usize {
    let moved = untangle::pull_back_crossing_fans(&mut out.mesh, grid.spacing, outside);
    for fan in &moved {
        let v = fan.vertex as usize;
        out.pulled_back_features += 1;
        centres.on_feature[v] &= fan.inside.on_feature;
        if out.feature_vertex[v] && !fan.inside.is_feature_vertex() {
            let count = if fan.kind == FeatureKind::Corner {
                &mut out.corner_features
            } else {
                &mut out.edge_features
            };
            *count -= 1;
            out.approximate_features += 1;
            out.feature_vertex[v] = false;
        }
    }
    moved.len()
}

/// How far (in cells) a feature point may lie from the surface, where the input can tell, and
/// still count as on its feature: the precision resampled feature points are held to (the
/// paper's tangent-plane points, `resample_creases: false`, are not checked: on curved creases
/// they err by O(h²)).
const ON_SURFACE: f32 = 0.01;

/// How much farther (in cells) than MC's triangles of its polygon an approximate fan centre may
/// lie from the surface (see [`Plan::approximate_centre_is_worse_than_mc`]). Approximate
/// centres next to a corner bridge the feature lines' gaps a little off the surface; with no
/// slack the rotated box's lines at 64 cells broke into 3 pieces and the gear's at 24 cells
/// left their creases. The centres this is for stood 0.17–0.32 cells off.
const WORSE_THAN_MC: f32 = 0.1;

#[cfg(test)]
mod slab_tests {
    use super::*;
    use crate::scenes;

    /// What a run of [`extract`] decided, in comparable form.
    fn decided(run: &(EmcMesh, FanCentres, Vec<OutsideFan>)) -> impl PartialEq + std::fmt::Debug {
        let (out, centres, outside) = run;
        let fans: Vec<(u32, [usize; 3])> = outside.iter().map(|f| (f.vertex, f.cell)).collect();
        let counts =
            [out.edge_features, out.corner_features, out.approximate_features, out.rejected_features];
        (
            out.mesh.clone(),
            out.feature_vertex.clone(),
            centres.any.clone(),
            centres.on_feature.clone(),
            fans,
            counts,
        )
    }

    /// The slabs joined are one sweep over the grid, with one thread or three: on the gear's field
    /// (features everywhere, exact crossings) and on tall noise grids (interpolated crossings).
    #[test]
    fn joined_slabs_are_one_sweep_vertex_for_vertex() {
        let gear = scenes::scene("gear").unwrap();
        let gear_grid = Grid::with_resolution(gear.min, gear.max, 72).unwrap();
        let gear_values = crate::field::sample_grid(gear.field.as_ref(), &gear_grid).unwrap();
        let mut rng = crate::expr::testutil::Rng::new(11);
        let noise_grid = Grid::from_points([7, 6, 53], Vec3::splat(-1.0), Vec3::new(0.3, 0.25, 0.2)).unwrap();
        let noise: Vec<f32> = (0..noise_grid.point_count()).map(|_| rng.range(-0.5, 0.5)).collect();
        for topology in [Topology::Fixed, Topology::Trilinear] {
            let options = EmcOptions { topology, ..EmcOptions::default() };
            let field_sampler =
                FieldRoots { field: gear.field.as_ref(), iso: 0.0, directed: true, h: gear_grid.cell_size() };
            let noise_sampler = SampleInterpolation { values: &noise, grid: &noise_grid };
            let cases: [(&[f32], &Grid, &dyn EdgeSampler); 2] =
                [(&gear_values, &gear_grid, &field_sampler), (&noise, &noise_grid, &noise_sampler)];
            for (values, grid, sampler) in cases {
                let sweep = join_slabs(vec![extract_slab(values, grid, &options, sampler, 0..grid.cells[2])]);
                assert!(sweep.0.mesh.triangle_count() > 100);
                for threads in [1, 3] {
                    let joined = crate::par::with_threads(threads, || {
                        extract(values, grid, &options, sampler).unwrap()
                    });
                    assert!(
                        decided(&joined) == decided(&sweep),
                        "{topology:?}, {threads} threads, {:?}",
                        grid.cells
                    );
                }
            }
        }
    }
}

//! Plain Marching Cubes: the baseline every other method is measured against.
//!
//! One vertex per intersected grid edge, shared by the (up to four) cells around it through rolling
//! per-layer caches, so the output is indexed from the start and nothing is welded afterwards.
//!
//! **Iso-level rule**: a sample is inside when `value < iso`; a sample exactly at the iso-level is
//! outside. Vertices are kept at least [`MIN_EDGE_FRACTION`] of an edge away from its ends, so a
//! sample at the iso-level never collapses two vertices into one point (no zero-area triangles) and
//! the topology stays that of the sign pattern.

use crate::error::Error;
use crate::field::{check_finite, sample_level, Field};
use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use crate::mesh::Mesh;
use crate::tables::{triangulate_polygon, CellPolygons, CENTER, CORNERS, EDGES, EDGE_AXIS, FACES};
use glam::{DVec3, Vec3};
use web_time::Instant;

mod cells;
pub mod interior;

pub(crate) use cells::{CellTables, CrossedCells};

/// Smallest distance, as a fraction of the edge, between a vertex and the edge's end points.
pub const MIN_EDGE_FRACTION: f32 = 1e-3;

/// How ambiguous cell faces are resolved. Both are consistent between neighbours (watertight).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Topology {
    /// Inside corners on an ambiguous face are always separated: one fixed table, fastest.
    #[default]
    Fixed,
    /// The topology of the trilinear interpolant, as Marching Cubes 33 means it: the asymptotic
    /// decider picks, per face, the connectivity of the bilinear interpolant on that face, and the
    /// interior test ([`interior`]) adds the tunnels the faces cannot see. One exception keeps the
    /// mesh manifold: two tunnels pressed against one face from both sides are left out (see
    /// `tunnels_meet`). Plain MC only; EMC takes the face decisions alone.
    Trilinear,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McOptions {
    pub iso: f32,
    pub topology: Topology,
    /// Refuse grids with more cells than this (see [`crate::grid::DEFAULT_MAX_CELLS`]).
    pub max_cells: u64,
}

impl Default for McOptions {
    fn default() -> Self {
        McOptions { iso: 0.0, topology: Topology::Fixed, max_cells: DEFAULT_MAX_CELLS }
    }
}

impl McOptions {
    pub(crate) fn validate(&self) -> Result<(), Error> {
        if !self.iso.is_finite() {
            return Err(Error::InvalidOption(format!("iso must be finite, got {}", self.iso)));
        }
        if self.max_cells == 0 {
            return Err(Error::InvalidOption("maxCells must be at least 1".into()));
        }
        Ok(())
    }
}

/// Milliseconds spent in each phase of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct McTimings {
    pub sample_ms: f64,
    pub extract_ms: f64,
    pub normals_ms: f64,
}

impl McTimings {
    /// The phases by name, in the order they ran, for [`crate::stats::Stats`].
    pub fn phases(&self) -> Vec<(String, f64)> {
        vec![
            ("sample".to_string(), self.sample_ms),
            ("extract".to_string(), self.extract_ms),
            ("normals".to_string(), self.normals_ms),
        ]
    }
}

/// Samples `field` on `grid`, extracts the iso-surface, and takes vertex normals from the field's
/// gradient (or, when it has none, from the mesh).
pub fn mesh_field(field: &dyn Field, grid: &Grid, options: &McOptions) -> Result<(Mesh, McTimings), Error> {
    grid.check_size(options.max_cells)?;
    let mut timings = McTimings::default();
    let t0 = Instant::now();
    // Where the field bounds itself, only the crust is evaluated: the mesh is the same, since a
    // cell away from the surface has one sign on either grid (see `crate::crust`).
    let (values, _) = sample_level(field, grid, options.iso, true)?;
    timings.sample_ms = ms_since(t0);
    crate::progress::checkpoint("extract", 0.0)?;
    let t1 = Instant::now();
    let mut mesh = extract(&values, grid, options)?;
    timings.extract_ms = ms_since(t1);
    crate::progress::checkpoint("normals", 0.0)?;
    let t2 = Instant::now();
    set_normals(&mut mesh, field);
    timings.normals_ms = ms_since(t2);
    Ok((mesh, timings))
}

/// Vertex normals from the field's gradient where it has one, else from the faces.
pub(crate) fn set_normals(mesh: &mut Mesh, field: &dyn Field) {
    if mesh.positions.first().is_some_and(|&p| field.gradient(p).is_some()) {
        let positions = &mesh.positions;
        mesh.normals = crate::par::map(positions.len(), |v| {
            field.gradient(positions[v]).unwrap_or(Vec3::ZERO).normalize_or_zero()
        });
    } else {
        mesh.compute_normals_from_faces();
    }
}

/// Meshes an already sampled volume (`values` laid out x fastest, see [`Grid::index`]); vertex
/// normals come from central differences of the samples, interpolated along each edge.
pub fn mesh_samples(values: &[f32], grid: &Grid, options: &McOptions) -> Result<(Mesh, McTimings), Error> {
    grid.check_size(options.max_cells)?;
    check_finite(values, grid)?;
    let mut timings = McTimings::default();
    let t1 = Instant::now();
    let mut mesh = extract(values, grid, options)?;
    timings.extract_ms = ms_since(t1);
    let t2 = Instant::now();
    mesh.normals =
        mesh.positions.iter().map(|&p| sample_gradient(values, grid, p).normalize_or_zero()).collect();
    timings.normals_ms = ms_since(t2);
    Ok((mesh, timings))
}

pub(crate) fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Central differences at the grid points around `p`, blended trilinearly (one-sided at the border).
pub(crate) fn sample_gradient(values: &[f32], grid: &Grid, p: Vec3) -> Vec3 {
    let pts = grid.points();
    let q = ((p - grid.origin) / grid.spacing).to_array();
    let base: [usize; 3] = std::array::from_fn(|a| (q[a].max(0.0).floor() as usize).min(grid.cells[a] - 1));
    let frac: [f32; 3] = std::array::from_fn(|a| (q[a] - base[a] as f32).clamp(0.0, 1.0));
    let mut g = Vec3::ZERO;
    for off in CORNERS.iter() {
        let idx = [base[0] + off[0], base[1] + off[1], base[2] + off[2]];
        let w: f32 = (0..3).map(|a| if off[a] == 1 { frac[a] } else { 1.0 - frac[a] }).product();
        if w == 0.0 {
            continue;
        }
        let mut d = Vec3::ZERO;
        for a in 0..3 {
            let lo = if idx[a] > 0 { idx[a] - 1 } else { idx[a] };
            let hi = if idx[a] + 1 < pts[a] { idx[a] + 1 } else { idx[a] };
            let mut i_lo = idx;
            let mut i_hi = idx;
            i_lo[a] = lo;
            i_hi[a] = hi;
            let v_lo = values[grid.index(i_lo[0], i_lo[1], i_lo[2])];
            let v_hi = values[grid.index(i_hi[0], i_hi[1], i_hi[2])];
            d[a] = (v_hi - v_lo) / ((hi - lo) as f32 * grid.spacing[a]);
        }
        g += d * w;
    }
    g
}

pub(crate) const NONE: u32 = u32::MAX;

/// Vertex ids of the edges starting at the points of two point layers (x and y edges) and of the
/// z edges between them; swapped as the sweep moves up one layer.
pub(crate) struct EdgeCache {
    nx: usize,
    /// x- and y-edges of the lower and upper layer: `[layer][axis][i + nx * j]`.
    layer_edges: [[Vec<u32>; 2]; 2],
    z_edges: Vec<u32>,
    /// Slots handed out while empty, per plane (lower x, lower y, upper x, upper y, z): a layer
    /// is cleared by resetting these rather than the whole plane, which at 256² points per layer
    /// cost more than the crossed cells did.
    touched: [Vec<u32>; 5],
    /// The x- and y-edges of the first layer, kept when the sweep leaves it (for joining slabs).
    first_layer: Option<[Vec<u32>; 2]>,
}

impl EdgeCache {
    pub(crate) fn new(nx: usize, ny: usize) -> Self {
        let plane = || vec![NONE; nx * ny];
        EdgeCache {
            nx,
            layer_edges: [[plane(), plane()], [plane(), plane()]],
            z_edges: plane(),
            touched: Default::default(),
            first_layer: None,
        }
    }

    pub(crate) fn advance(&mut self) {
        self.layer_edges.swap(0, 1);
        self.touched.swap(0, 2);
        self.touched.swap(1, 3);
        if self.first_layer.is_none() {
            let fresh = [vec![NONE; self.z_edges.len()], vec![NONE; self.z_edges.len()]];
            self.first_layer = Some(std::mem::replace(&mut self.layer_edges[1], fresh));
            self.touched[2].clear();
            self.touched[3].clear();
        }
        let [[_, _], [upper_x, upper_y]] = &mut self.layer_edges;
        let [_, _, touched_x, touched_y, touched_z] = &mut self.touched;
        for (plane, touched) in [(upper_x, touched_x), (upper_y, touched_y), (&mut self.z_edges, touched_z)] {
            for &at in touched.iter() {
                plane[at as usize] = NONE;
            }
            touched.clear();
        }
    }

    /// The x- and y-edge ids of the sweep's first and last point layers.
    pub(crate) fn into_outer_layers(self) -> ([Vec<u32>; 2], [Vec<u32>; 2]) {
        let [lower, upper] = self.layer_edges;
        (self.first_layer.unwrap_or(lower), upper)
    }

    /// The slot of cell-local edge `e` of the cell whose lowest corner is `(i, j)` in the current slab.
    #[inline]
    pub(crate) fn slot(&mut self, i: usize, j: usize, e: usize) -> &mut u32 {
        let lo = CORNERS[EDGES[e][0] as usize];
        let at = (i + lo[0]) + self.nx * (j + lo[1]);
        let (slot, plane) = match EDGE_AXIS[e] {
            2 => (&mut self.z_edges[at], 4),
            axis => (&mut self.layer_edges[lo[2]][axis][at], 2 * lo[2] + axis),
        };
        if *slot == NONE {
            self.touched[plane].push(at as u32);
        }
        slot
    }
}

/// Cell layers a slab of [`extract`] has at least (where there are threads to cut for).
pub(crate) const MIN_SLAB_LAYERS: usize = 8;

/// Extracts the `options.iso` level set of a sampled grid.
///
/// Slabs of cell layers ([`crate::par::piece_len`]: one slab on one thread) are extracted in
/// parallel, each with vertex ids of its own, then joined in order: a slab's vertices on its
/// lowest point layer are the ones the slab below made on its highest (both made them from the
/// same two samples, so they are the same points), and the rest keep the order they were made in.
/// That is exactly the mesh one sweep over the whole grid makes, vertex for vertex, however the
/// grid is cut.
pub fn extract(values: &[f32], grid: &Grid, options: &McOptions) -> Result<Mesh, Error> {
    check_finite(values, grid)?;
    let cz = grid.cells[2];
    let layers = crate::par::piece_len(cz, MIN_SLAB_LAYERS);
    let slabs = crate::par::map(cz.div_ceil(layers), |s| {
        extract_slab(values, grid, options, s * layers..((s + 1) * layers).min(cz))
    });
    Ok(join_slabs(slabs))
}

/// A slab's mesh and the ids its edge cache gave the x and y edges of its lowest and highest
/// point layers (`[axis][i + nx * j]`, [`NONE`] where the level does not cross).
struct Slab {
    mesh: Mesh,
    bottom: [Vec<u32>; 2],
    top: [Vec<u32>; 2],
}

/// The slabs' meshes as one, their shared vertices merged (see [`extract`]).
fn join_slabs(slabs: Vec<Slab>) -> Mesh {
    let mut mesh = Mesh::default();
    let mut below_top: Option<[Vec<u32>; 2]> = None;
    for slab in slabs {
        let mut global = vec![NONE; slab.mesh.positions.len()];
        if let Some(top) = &below_top {
            for (bottom, top) in slab.bottom.iter().zip(top) {
                for (&local, &shared) in bottom.iter().zip(top) {
                    if local != NONE {
                        debug_assert_ne!(shared, NONE, "a crossed edge made by one slab only");
                        global[local as usize] = shared;
                    }
                }
            }
        }
        for (id, &p) in global.iter_mut().zip(&slab.mesh.positions) {
            if *id == NONE {
                *id = mesh.positions.len() as u32;
                mesh.positions.push(p);
            }
        }
        mesh.triangles.extend(slab.mesh.triangles.iter().map(|t| t.map(|v| global[v as usize])));
        below_top = Some(slab.top.map(|plane| {
            plane.into_iter().map(|v| if v == NONE { NONE } else { global[v as usize] }).collect()
        }));
    }
    mesh
}

/// Extracts the cells of the layers `layers` (cell z indices) with vertex ids of their own.
fn extract_slab(values: &[f32], grid: &Grid, options: &McOptions, layers: std::ops::Range<usize>) -> Slab {
    let iso = options.iso;
    let mut mesh = Mesh::default();
    let tables = CellTables::new(options.topology);
    let cache = for_each_crossed_cell_in(values, grid, iso, layers, |ijk, case, d, cache| {
        let mut cell = Cell { grid, ijk, d, ids: [NONE; 13] };
        let mut joined = 0;
        if options.topology == Topology::Trilinear {
            joined = joined_faces(case, d);
            let joins = interior::interior_joins(case, joined, d);
            if !joins.is_empty() && !tunnels_meet(values, grid, iso, ijk, case) {
                let (polygons, _) = tables.lookup_joined(case, joined);
                cell.emit_with_tunnels(case, joined, polygons, &joins, cache, &mut mesh);
                return;
            }
        }
        let (polygons, tris) = tables.lookup_joined(case, joined);
        let mut at = 0;
        for (poly, &count) in polygons.iter().zip(&tris.per_polygon) {
            let group = &tris.edges[3 * at..3 * (at + count as usize)];
            at += count as usize;
            cell.emit_untangled(poly, group, cache, &mut mesh);
        }
    });
    let (bottom, top) = cache.into_outer_layers();
    Slab { mesh, bottom, top }
}

/// Visits every cell the `iso` level crosses in the sweep order [`EdgeCache`] needs, with the
/// cell's lowest corner, its case (bit `c` set when corner `c` is inside) and its values minus
/// `iso`. Methods that build on Marching Cubes' vertices (issue 7's quality method) share it, so
/// vertices are shared per grid edge exactly as here.
pub(crate) fn for_each_crossed_cell(
    values: &[f32],
    grid: &Grid,
    iso: f32,
    visit: impl FnMut([usize; 3], u8, &[f32; 8], &mut EdgeCache),
) {
    for_each_crossed_cell_in(values, grid, iso, 0..grid.cells[2], visit);
}

/// [`for_each_crossed_cell`] over the cell layers `layers` (z indices) alone; returns the cache,
/// which holds the ids of the edges of the range's highest point layer (and its first one's).
fn for_each_crossed_cell_in(
    values: &[f32],
    grid: &Grid,
    iso: f32,
    layers: std::ops::Range<usize>,
    mut visit: impl FnMut([usize; 3], u8, &[f32; 8], &mut EdgeCache),
) -> EdgeCache {
    let [nx, ny, _] = grid.points();
    let mut cache = EdgeCache::new(nx, ny);
    let first = layers.start;
    let mut cells = CrossedCells::from_layer(values, grid, iso, first);
    for k in layers {
        if k > first {
            cache.advance();
        }
        cells.next_layer(|ijk, case, d| visit(ijk, case, d, &mut cache));
    }
    cache
}

/// The vertex on cell edge `e` of `cell` (values `d`): looked up in the cache, or placed by
/// [`edge_point`] and appended to `positions` the first time any cell around the edge asks.
pub(crate) fn edge_vertex(
    cache: &mut EdgeCache,
    positions: &mut Vec<Vec3>,
    grid: &Grid,
    cell: [usize; 3],
    e: usize,
    d: &[f32; 8],
) -> u32 {
    let slot = cache.slot(cell[0], cell[1], e);
    if *slot == NONE {
        *slot = positions.len() as u32;
        positions.push(edge_point(grid, cell, e, d));
    }
    *slot
}

/// The signed corner values of cell `ijk`, in [`CORNERS`] order.
fn cell_values(values: &[f32], grid: &Grid, iso: f32, ijk: [usize; 3]) -> [f32; 8] {
    std::array::from_fn(|c| {
        let [a, b, e] = CORNERS[c];
        values[grid.index(ijk[0] + a, ijk[1] + b, ijk[2] + e)] - iso
    })
}

/// Whether a neighbour across one of the ambiguous faces of cell `ijk` also has an interior join.
/// Two tunnels pressed against the same face from both sides (the face's saddle barely on the other
/// side of the level) would both lie in that face, and their tubes would share edges: then both
/// cells keep their faces' answer instead. The rule is symmetric, so the two cells agree.
fn tunnels_meet(values: &[f32], grid: &Grid, iso: f32, ijk: [usize; 3], case: u8) -> bool {
    FACES.iter().enumerate().any(|(f, corners)| {
        if !crate::tables::face_is_ambiguous(case, f) {
            return false;
        }
        // The face's fixed axis and side, read off its corners.
        let axis = (0..3)
            .find(|&a| corners.iter().all(|&c| CORNERS[c as usize][a] == CORNERS[corners[0] as usize][a]));
        let Some(axis) = axis else { return false };
        let mut other = ijk;
        if CORNERS[corners[0] as usize][axis] == 1 {
            if ijk[axis] + 1 >= grid.cells[axis] {
                return false;
            }
            other[axis] += 1;
        } else {
            if ijk[axis] == 0 {
                return false;
            }
            other[axis] -= 1;
        }
        let d = cell_values(values, grid, iso, other);
        let case = d.iter().enumerate().fold(0u8, |m, (c, &v)| m | ((v < 0.0) as u8) << c);
        !interior::interior_joins(case, joined_faces(case, &d), &d).is_empty()
    })
}

/// One cell being emitted: where it is, its signed corner values, and the mesh ids of its edge
/// vertices found so far (index [`CENTER`] for a polygon's centre vertex).
struct Cell<'a> {
    grid: &'a Grid,
    ijk: [usize; 3],
    d: &'a [f32; 8],
    ids: [u32; 13],
}

impl Cell<'_> {
    /// The shared vertex on cell edge `e`, created by the first cell that needs it.
    fn vertex(&mut self, e: u8, cache: &mut EdgeCache, mesh: &mut Mesh) -> u32 {
        let e = e as usize;
        if self.ids[e] == NONE {
            self.ids[e] = edge_vertex(cache, &mut mesh.positions, self.grid, self.ijk, e, self.d);
        }
        self.ids[e]
    }

    /// The triangles of one polygon, as edge ids (and [`CENTER`]) in table form.
    fn emit_polygon(&mut self, group: &[u8], cache: &mut EdgeCache, mesh: &mut Mesh) {
        for &e in group.iter().filter(|&&e| e != CENTER) {
            self.vertex(e, cache, mesh);
        }
        if group.contains(&CENTER) {
            self.ids[CENTER as usize] = mesh.positions.len() as u32;
            mesh.positions.push(polygon_center(&mesh.positions, group, &self.ids));
        }
        for t in group.chunks_exact(3) {
            mesh.triangles.push([t[0], t[1], t[2]].map(|e| self.ids[e as usize]));
        }
    }

    /// One polygon by the table's triangles `group`, or fanned around its centre where two of
    /// those cross (see [`untangled`]).
    fn emit_untangled(&mut self, poly: &[u8], group: &[u8], cache: &mut EdgeCache, mesh: &mut Mesh) {
        // In the table's order, as `emit_polygon` would create them: the output stays the same
        // vertex for vertex where the table's triangles are kept.
        for &e in group.iter().chain(poly).filter(|&&e| e != CENTER) {
            self.vertex(e, cache, mesh);
        }
        let ids = self.ids;
        let fan = untangled(poly, group, |e| mesh.positions[ids[e as usize] as usize]);
        self.emit_polygon(fan.as_deref().unwrap_or(group), cache, mesh);
    }

    /// A cell whose interior joins what its faces keep apart: the joined polygons become tubes.
    fn emit_with_tunnels(
        &mut self,
        case: u8,
        joined: u8,
        polygons: &CellPolygons,
        joins: &[(u8, u8, bool)],
        cache: &mut EdgeCache,
        mesh: &mut Mesh,
    ) {
        let (rest, tubes) = interior::tunnels(case, joined, polygons, joins);
        let all: Vec<&[u8]> = polygons.iter().collect();
        for k in rest {
            let group: Vec<u8> = triangulate_polygon(all[k]).concat();
            self.emit_untangled(all[k], &group, cache, mesh);
        }
        for (a, b) in tubes {
            for e in all[a].iter().chain(all[b]) {
                self.vertex(*e, cache, mesh);
            }
            let positions = &mesh.positions;
            let ids = self.ids;
            let area = |t: [u8; 3]| {
                let [p, q, r] = t.map(|e| positions[ids[e as usize] as usize]);
                (q - p).cross(r - p).length() as f64
            };
            let uncrossed = |band: &[[u8; 3]]| {
                let tris: Vec<([u32; 3], [DVec3; 3])> = band
                    .iter()
                    .map(|t| (t.map(u32::from), t.map(|e| positions[ids[e as usize] as usize].as_dvec3())))
                    .collect();
                !any_pair_crosses(&tris)
            };
            match interior::tube(all[a], all[b], |_, _| true, area, uncrossed) {
                Some(band) => mesh.triangles.extend(band.iter().map(|t| t.map(|e| ids[e as usize]))),
                None => {
                    for k in [a, b] {
                        let group: Vec<u8> = triangulate_polygon(all[k]).concat();
                        self.emit_untangled(all[k], &group, cache, mesh);
                    }
                }
            }
        }
    }
}

/// `None` when the table's triangles `group` of polygon `poly` (edge ids, vertex positions by
/// `at`) do not cross one another; else the fan of `poly` around its centre ([`CENTER`]), in
/// table form. A skew polygon whose vertices sit near opposite ends of their edges (coarse or
/// random samples) can fold the table's diagonals over each other, and no fixed choice of
/// diagonals avoids that for every position. The fan cannot cross itself: seen from a point
/// strictly inside the convex cell, each fan triangle lies in the cone over its polygon edge, and
/// the polygon's edges lie in the cell's faces and meet only at their shared vertices, so two fan
/// triangles meet only along their common edge. Tables that fan already are left as they are.
pub(crate) fn untangled(poly: &[u8], group: &[u8], at: impl Fn(u8) -> Vec3) -> Option<Vec<u8>> {
    if group.contains(&CENTER) || group.len() <= 3 {
        return None;
    }
    let triangle =
        |t: &[u8]| ([t[0], t[1], t[2]].map(u32::from), [t[0], t[1], t[2]].map(|e| at(e).as_dvec3()));
    // Polygons of Marching Cubes' tables have at most 12 vertices (10 triangles): on the stack, as
    // this runs for every polygon of every crossed cell.
    let mut stack = [([0u32; 3], [DVec3::ZERO; 3]); 12];
    let count = group.len() / 3;
    let crosses = if count <= stack.len() {
        for (slot, t) in stack.iter_mut().zip(group.chunks_exact(3)) {
            *slot = triangle(t);
        }
        any_pair_crosses(&stack[..count])
    } else {
        any_pair_crosses(&group.chunks_exact(3).map(triangle).collect::<Vec<_>>())
    };
    crosses.then(|| (0..poly.len()).flat_map(|k| [CENTER, poly[k], poly[(k + 1) % poly.len()]]).collect())
}

/// Do two of `tris` (ids, corners) cross, by the self-intersection checker's rules?
fn any_pair_crosses(tris: &[([u32; 3], [DVec3; 3])]) -> bool {
    (0..tris.len()).any(|s| (s + 1..tris.len()).any(|t| indexed_pair_intersects(tris[s], tris[t])))
}

/// Where the surface crosses cell edge `e`, by linear interpolation of the signed values `d`.
pub(crate) fn edge_point(grid: &Grid, cell: [usize; 3], e: usize, d: &[f32; 8]) -> Vec3 {
    let [a, b] = EDGES[e];
    let (da, db) = (d[a as usize], d[b as usize]);
    let t = (da / (da - db)).clamp(MIN_EDGE_FRACTION, 1.0 - MIN_EDGE_FRACTION);
    let [ai, aj, ak] = CORNERS[a as usize];
    let pa = grid.position(cell[0] + ai, cell[1] + aj, cell[2] + ak);
    let mut step = Vec3::ZERO;
    step[EDGE_AXIS[e]] = grid.spacing[EDGE_AXIS[e]];
    pa + step * t
}

/// The centre vertex of a polygon that needs one (see [`crate::tables::CENTER`]): the mean of its
/// edge vertices, which lies inside the cell because they all lie on its boundary.
pub(crate) fn polygon_center(positions: &[Vec3], group: &[u8], ids: &[u32; 13]) -> Vec3 {
    let mut seen = [false; 12];
    let (mut sum, mut n) = (Vec3::ZERO, 0.0);
    for &e in group.iter().filter(|&&e| e != CENTER) {
        if !std::mem::replace(&mut seen[e as usize], true) {
            sum += positions[ids[e as usize] as usize];
            n += 1.0;
        }
    }
    sum / n
}

/// For each ambiguous face, whether the bilinear interpolant joins the inside corners across the face
/// (its saddle value is below the iso-level). Computed from the face's corners in the face's own
/// fixed order, so both cells sharing the face reach the same bit.
pub(crate) fn joined_faces(case: u8, d: &[f32; 8]) -> u8 {
    let mut bits = 0u8;
    for (f, corners) in FACES.iter().enumerate() {
        if !crate::tables::face_is_ambiguous(case, f) {
            continue;
        }
        let [a, b, c, e] = corners.map(|c| d[c as usize] as f64);
        // Bilinear saddle value (a, c diagonal; b, e diagonal); sign of numerator over denominator.
        let saddle = (a * c - b * e) / (a + c - b - e);
        // The inside corners' diagonal is joined across the face when the saddle is inside too.
        if saddle < 0.0 {
            bits |= 1 << f;
        }
    }
    bits
}

#[cfg(test)]
mod slab_tests {
    use super::*;

    /// The sign-bit scan visits exactly the cells whose eight corners are not all on one side, in
    /// sweep order, with their cases: on random grids whose rows end on, before and after a word
    /// boundary, with values on the level itself among them.
    #[test]
    fn the_sign_bit_scan_visits_every_mixed_cell_and_no_other() {
        let mut rng = crate::expr::testutil::Rng::new(11);
        for nx in [2, 3, 63, 64, 65, 66, 127, 128, 129, 200] {
            let points = [nx, 2 + rng.below(5), 2 + rng.below(5)];
            let grid = Grid::from_points(points, Vec3::ZERO, Vec3::ONE).unwrap();
            // Mostly one sign, so whole words are skipped; a few points on the level exactly.
            let values: Vec<f32> = (0..grid.point_count())
                .map(|_| match rng.below(8) {
                    0 => -1.0,
                    1 => 0.25,
                    _ => 1.0 + rng.range(0.0, 1.0),
                })
                .collect();
            let iso = 0.25;
            let mut visited = Vec::new();
            for_each_crossed_cell(&values, &grid, iso, |ijk, case, _, _| visited.push((ijk, case)));
            let mut expected = Vec::new();
            for k in 0..grid.cells[2] {
                for j in 0..grid.cells[1] {
                    for i in 0..grid.cells[0] {
                        let d = cell_values(&values, &grid, iso, [i, j, k]);
                        let case = d.iter().enumerate().fold(0u8, |c, (n, &v)| c | ((v < 0.0) as u8) << n);
                        if case != 0 && case != 255 {
                            expected.push(([i, j, k], case));
                        }
                    }
                }
            }
            assert!(!expected.is_empty(), "nx {nx}: no mixed cells to find");
            assert_eq!(visited, expected, "nx {nx}");
        }
    }

    /// The slabs joined are exactly one sweep over the whole grid (see [`extract`]), on tall random
    /// grids of several slabs, in both topologies, with one thread or several.
    #[test]
    fn joined_slabs_are_one_sweep_vertex_for_vertex() {
        let mut rng = crate::expr::testutil::Rng::new(7);
        for round in 0..40 {
            let points = [3 + rng.below(8), 3 + rng.below(8), 2 + rng.below(60)];
            let grid = Grid::from_points(points, Vec3::splat(-1.0), Vec3::new(0.3, 0.25, 0.2)).unwrap();
            // Smooth blobs on odd rounds (long crossing sheets through the slab seams), noise on even.
            let values: Vec<f32> = (0..grid.point_count())
                .map(|n| {
                    let [i, j, k] = grid.unindex(n);
                    if round % 2 == 1 {
                        (grid.position(i, j, k) * Vec3::new(2.0, 3.0, 0.4))
                            .to_array()
                            .iter()
                            .map(|v| v.sin())
                            .sum::<f32>()
                            + rng.range(0.0, 0.3)
                    } else {
                        rng.range(-0.5, 0.5)
                    }
                })
                .collect();
            for topology in [Topology::Fixed, Topology::Trilinear] {
                let options = McOptions { topology, ..McOptions::default() };
                let sweep = join_slabs(vec![extract_slab(&values, &grid, &options, 0..grid.cells[2])]);
                for threads in [1, 3] {
                    let joined =
                        crate::par::with_threads(threads, || extract(&values, &grid, &options).unwrap());
                    assert!(joined == sweep, "round {round}, {points:?}, {topology:?}, {threads} threads");
                }
            }
        }
    }
}

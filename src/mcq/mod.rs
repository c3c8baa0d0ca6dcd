//! Marching Cubes with better triangles (issue 7, seed paper 004): the same vertices as
//! [`crate::mc`], shared per grid edge by the same sweep, but each cell's polygon border from
//! [`crate::tables::polygon_table`] is triangulated by the paper's rules (`polygon.rs`) instead of
//! the fixed table, after an optional vertex snapping step (`snap.rs`) that removes the tiny edges
//! near grid points which no per-cell rule can fix.
//!
//! Always uses the default (fixed) case table: its polygons need no centre vertex, so the Marching
//! Cubes triangulation the snapping step validates its merges on is made of grid-edge vertices only.

pub(crate) mod polygon;
mod snap;

pub use polygon::PolygonRules;

use crate::error::Error;
use crate::field::{check_finite, sample_level, Field, SampleGradient, SampledField};
use crate::grid::{in_box, Grid, DEFAULT_MAX_CELLS};
use crate::mc::{edge_vertex, for_each_crossed_cell, ms_since, set_normals};
use crate::mesh::{analysis, Mesh};
use crate::tables::polygon_table;
use glam::Vec3;
use polygon::{key, Corner};
use std::collections::HashSet;
use web_time::Instant;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McqOptions {
    pub iso: f32,
    pub max_cells: u64,
    pub rules: PolygonRules,
    /// Merge vertices closer than this (in cells, per axis) to a grid point onto it; `None` keeps
    /// the paper's purely per-cell method.
    pub snap: Option<f32>,
    /// Move inserted vertices onto the surface (Newton steps along the gradient, kept inside their
    /// cell). The paper leaves them in the polygon's plane.
    pub project: bool,
}

impl Default for McqOptions {
    fn default() -> Self {
        McqOptions {
            iso: 0.0,
            max_cells: DEFAULT_MAX_CELLS,
            rules: PolygonRules::default(),
            snap: Some(DEFAULT_SNAP),
            project: true,
        }
    }
}

impl McqOptions {
    pub(crate) fn validate(&self) -> Result<(), Error> {
        let bad = |msg: String| Err(Error::InvalidOption(msg));
        if !self.iso.is_finite() {
            return bad(format!("iso must be finite, got {}", self.iso));
        }
        if let Some(alpha) = self.snap {
            // Past half a cell a vertex would be near two grid points at once.
            if !(alpha > 0.0 && alpha < 0.5) {
                return bad(format!("snap must be in (0, 0.5) cells, got {alpha}"));
            }
        }
        // A polygon's angles sum to less than 180° per corner; past 90° every corner is "bad".
        let cut = self.rules.cut_angle_deg;
        if !(0.0..=90.0).contains(&cut) {
            return bad(format!("cutAngle is in degrees and must lie in 0..=90, got {cut}"));
        }
        // A four-sided polygon's longest over shortest edge: 1 is a rhombus, below 1 never holds.
        let ratio = self.rules.quad_ratio;
        if !(ratio.is_finite() && ratio >= 1.0) {
            return bad(format!("quadRatio must be finite and at least 1, got {ratio}"));
        }
        if self.max_cells == 0 {
            return bad("maxCells must be at least 1".into());
        }
        Ok(())
    }
}

/// Default snapping distance in cells (see docs/mcq.md's measurements).
pub const DEFAULT_SNAP: f32 = 0.3;

/// What a run did, besides the mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct McqReport {
    pub polygons: usize,
    /// Vertices merged away by snapping.
    pub merged: usize,
    /// Vertices inserted inside polygons.
    pub inserted: usize,
    pub sample_ms: f64,
    pub extract_ms: f64,
    pub snap_ms: f64,
    pub triangulate_ms: f64,
    /// The self-intersection pass that undoes crossing projections.
    pub uncross_ms: f64,
    pub normals_ms: f64,
}

impl McqReport {
    pub fn phases(&self) -> Vec<(String, f64)> {
        [
            ("sample", self.sample_ms),
            ("extract", self.extract_ms),
            ("snap", self.snap_ms),
            ("triangulate", self.triangulate_ms),
            ("uncross", self.uncross_ms),
            ("normals", self.normals_ms),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), *v))
        .collect()
    }
}

/// One cell's polygon border: vertex ids and the cell edges they sit on, in border order.
pub(crate) struct CellPolygon {
    pub cell: [usize; 3],
    pub verts: Vec<u32>,
    pub edges: Vec<u8>,
}

/// Samples `field` on `grid` and meshes it; normals come from the field's gradient.
pub fn mesh_field(field: &dyn Field, grid: &Grid, options: &McqOptions) -> Result<(Mesh, McqReport), Error> {
    grid.check_size(options.max_cells)?;
    let t0 = Instant::now();
    let (values, _) = sample_level(field, grid, options.iso, false)?;
    let sample_ms = ms_since(t0);
    let (mesh, mut report) = extract(&values, grid, options, field)?;
    report.sample_ms = sample_ms;
    Ok((mesh, report))
}

/// Meshes an already sampled volume; its trilinear interpolant stands in for the field, with its
/// own gradient (the exact derivative of the values, which is what Newton's projection needs).
pub fn mesh_samples(values: &[f32], grid: &Grid, options: &McqOptions) -> Result<(Mesh, McqReport), Error> {
    grid.check_size(options.max_cells)?;
    check_finite(values, grid)?;
    extract(values, grid, options, &SampledField { grid: *grid, values, gradient: SampleGradient::Trilinear })
}

fn extract(
    values: &[f32],
    grid: &Grid,
    options: &McqOptions,
    field: &dyn Field,
) -> Result<(Mesh, McqReport), Error> {
    check_finite(values, grid)?;
    options.validate()?;
    let mut report = McqReport::default();
    let t = Instant::now();
    let mut positions = vec![];
    let mut polys = vec![];
    let table = polygon_table();
    for_each_crossed_cell(values, grid, options.iso, |cell, case, d, cache| {
        for edges in table[case as usize].iter() {
            let verts = edges
                .iter()
                .map(|&e| edge_vertex(cache, &mut positions, grid, cell, e as usize, d))
                .collect();
            polys.push(CellPolygon { cell, verts, edges: edges.to_vec() });
        }
    });
    report.polygons = polys.len();
    report.extract_ms = ms_since(t);

    let t = Instant::now();
    let snapped = match options.snap {
        Some(alpha) => snap::snap(&mut positions, &polys, grid, alpha, |g, free| {
            // The merged vertex may move off the grid point onto the surface, but no further than
            // the vertices it replaces were (so it stays in the cells around the point).
            if !options.project {
                return g;
            }
            let on = newton(field, options.iso, g, free);
            let reach = grid.spacing * alpha;
            if on.is_finite() && (on - g).abs().cmple(reach).all() {
                on
            } else {
                g
            }
        }),
        None => snap::Snapped {
            rep: (0..positions.len() as u32).collect(),
            corner: vec![None; positions.len()],
            merged: 0,
        },
    };
    report.merged = snapped.merged;
    // Where each projected vertex would sit unprojected: a merged vertex on its grid point.
    let mut unprojected: Vec<Option<Vec3>> = snapped
        .corner
        .iter()
        .map(|g| g.filter(|_| options.project).map(|g| grid.position(g[0], g[1], g[2])))
        .collect();
    let find = |mut v: u32| {
        while snapped.rep[v as usize] != v {
            v = snapped.rep[v as usize];
        }
        v
    };
    // Borders after merging: consecutive repeats dropped, collapsed polygons gone.
    let borders: Vec<(usize, Vec<Corner>)> = polys
        .iter()
        .enumerate()
        .filter_map(|(p, poly)| {
            let mut border: Vec<Corner> = vec![];
            for (&v, &e) in poly.verts.iter().zip(&poly.edges) {
                let id = find(v);
                if border.last().is_some_and(|c| c.id == id) {
                    continue;
                }
                let faces = match snapped.corner[id as usize] {
                    Some(g) => corner_faces(poly.cell, g),
                    None => Corner::on_edge(id, positions[id as usize], e as usize).faces,
                };
                border.push(Corner { id, pos: positions[id as usize], faces });
            }
            while border.len() > 1 && border[0].id == border[border.len() - 1].id {
                border.pop();
            }
            (border.len() >= 3).then_some((p, border))
        })
        .collect();
    report.snap_ms = ms_since(t);

    let t = Instant::now();
    let mut edges: HashSet<(u32, u32)> = HashSet::new();
    for (_, border) in &borders {
        for (k, c) in border.iter().enumerate() {
            edges.insert(key(c.id, border[(k + 1) % border.len()].id));
        }
    }
    let mut triangles = vec![];
    for (p, border) in &borders {
        let inner = positions.len() as u32;
        let first = triangles.len();
        if let Some(c) = polygon::triangulate(border, &options.rules, &mut edges, inner, &mut triangles) {
            // Inside its cell, the inner vertex is the apex of a cone over its border, which lies
            // on the cell's boundary once merged vertices are back on their grid points (where
            // `unproject_where_crossing` puts them): that cone crosses nothing. Merged vertices
            // projected off their grid points can pull the rules' point out of the cell (into the
            // neighbour's triangles), so it is kept in the cell.
            let c = in_cell(c, grid, polys[*p].cell);
            let on_surface = if options.project {
                // On the surface, unless that makes the fan's worst angle worse than in the plane.
                let on = project(field, options.iso, c, grid, polys[*p].cell);
                let fan = &triangles[first..];
                if fan_min_angle(&positions, fan, inner, on) >= fan_min_angle(&positions, fan, inner, c) {
                    on
                } else {
                    c
                }
            } else {
                c
            };
            unprojected.push((options.project && on_surface != c).then_some(c));
            positions.push(on_surface);
            report.inserted += 1;
        }
    }
    let mut mesh = compact(positions, triangles, &mut unprojected);
    report.triangulate_ms = ms_since(t);
    let t = Instant::now();
    if options.project {
        unproject_where_crossing(&mut mesh, &unprojected);
    }
    report.uncross_ms = ms_since(t);

    let t = Instant::now();
    set_normals(&mut mesh, field);
    report.normals_ms = ms_since(t);
    Ok((mesh, report))
}

/// The smallest angle of the triangles around inner vertex `inner` if it sat at `at`.
fn fan_min_angle(positions: &[Vec3], fan: &[[u32; 3]], inner: u32, at: Vec3) -> f32 {
    let pos = |v: u32| if v == inner { at } else { positions[v as usize] };
    fan.iter()
        .filter(|t| t.contains(&inner))
        .flat_map(|t| {
            let p = t.map(pos);
            (0..3).map(move |a| (p[(a + 1) % 3] - p[a]).angle_between(p[(a + 2) % 3] - p[a]))
        })
        .fold(f32::MAX, f32::min)
}

/// The faces of `cell` that grid point `g` (one of its corners) lies on.
fn corner_faces(cell: [usize; 3], g: [usize; 3]) -> u8 {
    (0..3).fold(0, |m, a| m | if g[a] == cell[a] { 1 << (2 * a) } else { 1 << (2 * a + 1) })
}

/// A few Newton steps towards `field = iso` along the gradient; the start point if they leave the
/// cell (an inner vertex outside its cell could cross the neighbours' triangles).
fn project(field: &dyn Field, iso: f32, start: Vec3, grid: &Grid, cell: [usize; 3]) -> Vec3 {
    let lo = grid.position(cell[0], cell[1], cell[2]);
    let hi = lo + grid.spacing;
    let p = newton(field, iso, start, [true; 3]);
    let inside = in_box(p, (lo, hi)) && p.is_finite();
    if inside {
        p
    } else {
        start
    }
}

/// How far (in cells) inner vertices stay off their cell's faces: a vertex in a face would lay
/// its triangles over the neighbour's.
const INNER_INSET: f32 = 1e-2;

/// `p` moved into `cell` shrunk by [`INNER_INSET`] (unchanged where it lies there already).
fn in_cell(p: Vec3, grid: &Grid, cell: [usize; 3]) -> Vec3 {
    let lo = grid.position(cell[0], cell[1], cell[2]);
    let inset = grid.spacing * INNER_INSET;
    p.clamp(lo + inset, lo + grid.spacing - inset)
}

/// A few Newton steps from `start` towards `field = iso` along the gradient restricted to the
/// `free` axes (`start` when the field has no usable gradient there).
fn newton(field: &dyn Field, iso: f32, start: Vec3, free: [bool; 3]) -> Vec3 {
    let mask = Vec3::from(free.map(|f| f as u8 as f32));
    let mut p = start;
    for _ in 0..4 {
        let Some(g) = field.gradient(p).map(|g| g * mask) else { return start };
        let g2 = g.length_squared();
        if g2 < 1e-20 {
            return start;
        }
        p -= g * ((field.value(p) - iso) / g2);
    }
    p
}

/// Projection moves a vertex without looking at the triangles around it, which can then cross
/// another sheet close by: every projected vertex of a crossing triangle pair goes back to where
/// it was before projection (its grid point, or its polygon's plane), where nothing crossed in
/// any of our tests, until no pair crosses. Costs one self-intersection pass when nothing crosses.
fn unproject_where_crossing(mesh: &mut Mesh, unprojected: &[Option<Vec3>]) {
    loop {
        let mut moved = false;
        for pair in analysis::self_intersecting_pairs(mesh) {
            for t in pair {
                for v in mesh.triangles[t as usize] {
                    if let Some(p) = unprojected[v as usize] {
                        moved |= mesh.positions[v as usize] != p;
                        mesh.positions[v as usize] = p;
                    }
                }
            }
        }
        if !moved {
            return;
        }
    }
}

/// Drops vertices no triangle uses (merged ones) and renumbers (`extra` per vertex along).
fn compact(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>, extra: &mut Vec<Option<Vec3>>) -> Mesh {
    let mut map = vec![u32::MAX; positions.len()];
    let mut mesh = Mesh::default();
    for t in &triangles {
        for &v in t {
            if map[v as usize] == u32::MAX {
                map[v as usize] = mesh.positions.len() as u32;
                mesh.positions.push(positions[v as usize]);
            }
        }
    }
    mesh.triangles = triangles.iter().map(|t| t.map(|v| map[v as usize])).collect();
    let mut kept = vec![None; mesh.positions.len()];
    for (old, &new) in map.iter().enumerate() {
        if new != u32::MAX {
            kept[new as usize] = extra[old];
        }
    }
    *extra = kept;
    mesh
}

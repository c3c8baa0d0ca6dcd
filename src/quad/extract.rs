//! The first quad mesh: the dual of Marching Cubes' polygon mesh on the same grid (the fixed case
//! table of [`crate::tables::polygon_table`]). One vertex per MC polygon (a component of the
//! surface inside one cell), one quad per grid edge the surface crosses, joining the four polygons
//! around that edge in turning order.
//!
//! Why the dual and not the paper's "outside faces of the cut cells": those faces join inside
//! regions that touch only along a cell edge or corner (26-connectivity), while MC's fixed table
//! separates them (inside is 6-connected), so the two disagree about topology on ordinary inputs
//! (eight balls close together became one genus-5 surface). MC's polygon mesh is a 2-manifold in
//! which every interior vertex (a crossed grid edge) has exactly four polygons around it, so its dual
//! is a quad mesh with the same V − E + F and the same components *by construction*; nothing is
//! re-paired or repaired afterwards. Seen from the dual grid (points at cell centres), the quads are
//! the dual grid's faces the surface crosses, each dual grid point split into one vertex per polygon:
//! the paper's cell faces, with MC's rule for which corners belong together.
//!
//! **The grid's boundary** is treated as MC treats it: a surface reaching the bounds is cut open there,
//! and the quad mesh has the same boundary loops. A polygon edge lying in the grid's outer face gets a
//! boundary vertex at its midpoint, and a crossed edge in that face becomes the quad (its two polygons
//! and the two boundary vertices); a crossed edge on one of the grid's twelve outer edges (one polygon
//! around it) becomes the quad (polygon, boundary vertex, the crossing itself, boundary vertex). The
//! counts still match: V* − E* + F* = F − E_interior + V_interior = MC's V − E + F. Boundary vertices
//! are pinned to their outer face (or edge) in [`QuadMesh::pins`], so later stages keep them there.
//!
//! **When the dual is not a mesh**: two polygons of neighbouring cells can share *two* polygon edges
//! (both cells join the diagonal corners of their common ambiguous face through their interiors); the
//! dual then has two edges between the same two vertices, which no indexed quad mesh can hold, and
//! the dual's straight quads can cross where the surface is wild. Then the extraction returns the
//! dual's bilinear subdivision instead, built directly: each MC polygon of n sides is split into n
//! quads (its centre, the midpoints of two consecutive polygon edges, the crossing between). That
//! mesh always exists and has MC's topology too; with every crossing at its edge's midpoint, each of
//! its quads lies in one cell and meets the neighbour cell only in the polygon edges of their common
//! face, so it cannot cross itself (checked on all 256 cases and on random grids in the tests).

use super::mesh::QuadMesh;
use crate::grid::Grid;
use crate::mc::edge_point;
use crate::mesh::analysis;
use crate::tables::{edge_faces, polygon_table, CORNERS, EDGES, EDGE_AXIS};
use glam::Vec3;
use std::collections::HashMap;

/// What the extraction found, for the stats.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ExtractCounts {
    /// Cells the surface cuts.
    pub data_leaves: usize,
    /// MC polygons (vertices of the dual).
    pub polygons: usize,
    /// Crossed grid edges (quads of the dual).
    pub crossings: usize,
    /// Vertices on the grid's outer faces, where the surface is cut open as MC's is.
    pub boundary_vertices: usize,
    /// Pairs of polygons sharing two polygon edges (a dual with a double edge).
    pub double_edges: usize,
    /// The dual could not be used (double edges, or its quads cross or fold), so the split polygon
    /// mesh with crossings at edge midpoints was returned instead.
    pub split: bool,
}

/// MC's polygon mesh on a grid: every polygon as a cycle of crossed grid edges, outward.
struct Polygons {
    /// Lowest corner of each polygon's cell.
    cell: Vec<[usize; 3]>,
    /// Polygon `p`'s crossings are `keys[start[p]..start[p + 1]]`, and their cell-local edge ids
    /// `local[..]` alike.
    start: Vec<usize>,
    keys: Vec<usize>,
    local: Vec<u8>,
    /// Directed polygon edge (crossing, next crossing) → polygon.
    owner: HashMap<(usize, usize), u32>,
    /// Every crossing once, in the order cells first met it (so the output is deterministic), with
    /// the first polygon holding it.
    crossings: Vec<(usize, u32)>,
    /// Where MC puts each crossing (linear interpolation, kept off the edge's ends).
    position: HashMap<usize, Vec3>,
}

impl Polygons {
    fn of(&self, p: u32) -> std::ops::Range<usize> {
        self.start[p as usize]..self.start[p as usize + 1]
    }

    /// The crossings before and after `key` in polygon `p`.
    fn around(&self, p: u32, key: usize) -> (usize, usize) {
        let r = self.of(p);
        let ks = &self.keys[r];
        let i = ks.iter().position(|&k| k == key).expect("the polygon holds the crossing");
        (ks[(i + ks.len() - 1) % ks.len()], ks[(i + 1) % ks.len()])
    }

    /// The axis of the grid's outer face that polygon `p`'s edge from its `i`-th crossing to the next
    /// lies in, if it lies in one.
    fn outer_face(&self, grid: &Grid, p: u32, i: usize) -> Option<usize> {
        let r = self.of(p);
        let n = r.len();
        let (ea, eb) = (self.local[r.start + i] as usize, self.local[r.start + (i + 1) % n] as usize);
        let [fa, fb] = edge_faces(ea);
        let shared = if edge_faces(eb).contains(&fa) { fa } else { fb };
        let (axis, side) = (shared / 2, shared % 2);
        let c = self.cell[p as usize][axis];
        let on_outer = if side == 0 { c == 0 } else { c + 1 == grid.cells[axis] };
        on_outer.then_some(axis)
    }
}

/// The global key of cell-local edge `e` of cell `c`: three keys per grid point, one per axis.
fn edge_key(grid: &Grid, c: [usize; 3], e: usize) -> usize {
    let lo = CORNERS[EDGES[e][0] as usize];
    grid.index(c[0] + lo[0], c[1] + lo[1], c[2] + lo[2]) * 3 + EDGE_AXIS[e]
}

/// The grid point and axis of a crossing key.
fn key_point(grid: &Grid, key: usize) -> ([usize; 3], usize) {
    (grid.unindex(key / 3), key % 3)
}

fn polygons(values: &[f32], grid: &Grid) -> Polygons {
    let table = polygon_table();
    let [cx, cy, cz] = grid.cells;
    let mut out = Polygons {
        cell: Vec::new(),
        start: vec![0],
        keys: Vec::new(),
        local: Vec::new(),
        owner: HashMap::new(),
        crossings: Vec::new(),
        position: HashMap::new(),
    };
    for k in 0..cz {
        for j in 0..cy {
            for i in 0..cx {
                let c = [i, j, k];
                let d: [f32; 8] = std::array::from_fn(|n| {
                    let o = CORNERS[n];
                    values[grid.index(i + o[0], j + o[1], k + o[2])]
                });
                // Inside is `value < 0` (the samples are already minus the iso-level), as in MC.
                let case = d.iter().enumerate().fold(0u8, |m, (n, &v)| m | ((v < 0.0) as u8) << n);
                for poly in table[case as usize].iter() {
                    let p = out.cell.len() as u32;
                    out.cell.push(c);
                    let keys: Vec<usize> = poly.iter().map(|&e| edge_key(grid, c, e as usize)).collect();
                    for (n, (&key, &e)) in keys.iter().zip(poly).enumerate() {
                        out.owner.insert((key, keys[(n + 1) % keys.len()]), p);
                        out.position.entry(key).or_insert_with(|| {
                            out.crossings.push((key, p));
                            edge_point(grid, c, e as usize, &d)
                        });
                    }
                    out.keys.extend_from_slice(&keys);
                    out.local.extend_from_slice(poly);
                    out.start.push(out.keys.len());
                }
            }
        }
    }
    out
}

/// The pinned axes of the crossing `key`: the grid's outer faces its edge lies in.
fn crossing_pins(grid: &Grid, key: usize) -> u8 {
    let (point, axis) = key_point(grid, key);
    (0..3).filter(|&a| a != axis && (point[a] == 0 || point[a] == grid.cells[a])).fold(0, |m, a| m | 1 << a)
}

/// Extracts the quad mesh of the samples (inside where `value < 0`, the iso-level already
/// subtracted) on `grid`: the dual of MC's polygon mesh, or where that is not a valid
/// intersection-free mesh, its split (see the module documentation).
pub fn extract(values: &[f32], grid: &Grid) -> (QuadMesh, ExtractCounts) {
    let polys = polygons(values, grid);
    let mut counts = ExtractCounts {
        data_leaves: {
            let mut cells: Vec<&[usize; 3]> = polys.cell.iter().collect();
            cells.dedup();
            cells.len()
        },
        polygons: polys.cell.len(),
        crossings: polys.crossings.len(),
        ..ExtractCounts::default()
    };
    counts.double_edges = double_edges(&polys);
    if counts.double_edges == 0 {
        if let Some(mesh) = dual(&polys, grid) {
            if geometry_ok(&mesh) {
                counts.boundary_vertices = mesh.pins.iter().filter(|&&p| p != 0).count();
                return (mesh, counts);
            }
        }
    }
    let mesh = split(&polys, grid);
    counts.split = true;
    counts.boundary_vertices = mesh.pins.iter().filter(|&&p| p != 0).count();
    (mesh, counts)
}

/// Pairs of polygons that share more than one polygon edge.
fn double_edges(polys: &Polygons) -> usize {
    let mut shared: HashMap<(u32, u32), u32> = HashMap::new();
    for (&(a, b), &p) in &polys.owner {
        if let Some(&q) = polys.owner.get(&(b, a)) {
            if p < q {
                *shared.entry((p, q)).or_default() += 1;
            }
        }
    }
    shared.values().filter(|&&n| n > 1).count()
}

/// Whether the triangulated mesh is free of crossings, folds and zero-area triangles, with finite
/// coordinates: what every stage of the quad method must hand on.
pub fn geometry_ok(mesh: &QuadMesh) -> bool {
    if !mesh.positions.iter().all(|p| p.is_finite()) {
        return false;
    }
    let t = mesh.triangulate();
    analysis::degenerate_triangles(&t) == 0
        && analysis::folded_pairs(&t).is_empty()
        && analysis::self_intersections(&t) == 0
}

/// The dual: `None` when a fan around a crossing is not what a manifold polygon mesh gives (never
/// expected; the caller then takes the split) or the result is not a manifold.
fn dual(polys: &Polygons, grid: &Grid) -> Option<QuadMesh> {
    let mut positions: Vec<Vec3> = (0..polys.cell.len() as u32)
        .map(|p| {
            let r = polys.of(p);
            let n = r.len() as f32;
            polys.keys[r].iter().map(|k| polys.position[k]).sum::<Vec3>() / n
        })
        .collect();
    let mut pins = vec![0u8; positions.len()];
    // One boundary vertex per polygon edge in the grid's outer face, keyed by the directed edge.
    let mut outer: HashMap<(usize, usize), u32> = HashMap::new();
    for p in 0..polys.cell.len() as u32 {
        let r = polys.of(p);
        let n = r.len();
        for i in 0..n {
            if let Some(axis) = polys.outer_face(grid, p, i) {
                let (a, b) = (polys.keys[r.start + i], polys.keys[r.start + (i + 1) % n]);
                outer.insert((a, b), positions.len() as u32);
                positions.push((polys.position[&a] + polys.position[&b]) * 0.5);
                pins.push(1 << axis);
            }
        }
    }
    let mut quads = Vec::with_capacity(polys.crossings.len());
    for &(v, p0) in &polys.crossings {
        // Turn clockwise to the first polygon after the boundary (or all the way round).
        let mut p = p0;
        for _ in 0..4 {
            let (_, next) = polys.around(p, v);
            match polys.owner.get(&(next, v)) {
                Some(&q) if q != p0 => p = q,
                _ => break,
            }
        }
        let first = p;
        // Then counter-clockwise, seen from outside: the polygon across the edge to the crossing
        // before `v` in `p` holds that edge reversed.
        let mut face = vec![first];
        let closed = loop {
            let (prev, _) = polys.around(p, v);
            match polys.owner.get(&(v, prev)) {
                Some(&q) if q == first => break true,
                Some(&q) => {
                    p = q;
                    face.push(q);
                    if face.len() > 4 {
                        return None;
                    }
                }
                None => break false,
            }
        };
        if !closed {
            let (prev, _) = polys.around(p, v);
            let (_, next) = polys.around(first, v);
            face.push(*outer.get(&(prev, v))?);
            if face.len() == 2 {
                // One polygon: the crossing, on one of the grid's outer edges, closes the quad.
                face.push(positions.len() as u32);
                positions.push(polys.position[&v]);
                pins.push(crossing_pins(grid, v));
            }
            face.push(*outer.get(&(v, next))?);
        }
        if face.len() != 4 {
            return None;
        }
        quads.push([face[0], face[1], face[2], face[3]]);
    }
    let mesh = QuadMesh { positions, quads, pins };
    mesh.is_manifold().then_some(mesh)
}

/// The split polygon mesh: per polygon corner one quad (centre, midpoint of the edge before, the
/// crossing, midpoint of the edge after), every crossing at its edge's midpoint.
fn split(polys: &Polygons, grid: &Grid) -> QuadMesh {
    let mut positions = Vec::new();
    let mut pins = Vec::new();
    let mut crossing: HashMap<usize, u32> = HashMap::new();
    for &(key, _) in &polys.crossings {
        let (point, axis) = key_point(grid, key);
        let mut at = grid.position(point[0], point[1], point[2]);
        at[axis] += grid.spacing[axis] * 0.5;
        crossing.insert(key, positions.len() as u32);
        positions.push(at);
        pins.push(crossing_pins(grid, key));
    }
    let mut middle: HashMap<(usize, usize), u32> = HashMap::new();
    let mut quads = Vec::new();
    for p in 0..polys.cell.len() as u32 {
        let r = polys.of(p);
        let n = r.len();
        let keys = &polys.keys[r.clone()];
        let centre = positions.len() as u32;
        positions.push(keys.iter().map(|k| positions[crossing[k] as usize]).sum::<Vec3>() / n as f32);
        pins.push(0);
        let mids: Vec<u32> = (0..n)
            .map(|i| {
                let (a, b) = (keys[i], keys[(i + 1) % n]);
                *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    positions
                        .push((positions[crossing[&a] as usize] + positions[crossing[&b] as usize]) * 0.5);
                    pins.push(polys.outer_face(grid, p, i).map_or(0, |axis| 1 << axis));
                    positions.len() as u32 - 1
                })
            })
            .collect();
        for i in 0..n {
            quads.push([centre, mids[(i + n - 1) % n], crossing[&keys[i]], mids[i]]);
        }
    }
    QuadMesh { positions, quads, pins }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mc::{self, McOptions};

    /// Deterministic xorshift: every sign pattern the tests try is reproducible.
    fn signs(seed: u64, n: usize, density: f64) -> Vec<f32> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                if ((s >> 11) as f64 / (1u64 << 53) as f64) < density {
                    -1.0
                } else {
                    1.0
                }
            })
            .collect()
    }

    /// MC's topology on the same samples: Euler characteristic, components, boundary edges.
    fn mc_topology(values: &[f32], grid: &Grid) -> (i64, usize, usize) {
        let m = mc::extract(values, grid, &McOptions::default()).unwrap();
        let t = analysis::topology(&m);
        (t.euler, t.components, t.boundary_edges)
    }

    fn quad_topology(m: &QuadMesh) -> (i64, usize, usize) {
        let t = analysis::topology(&m.triangulate());
        (t.euler, t.components, t.boundary_edges)
    }

    #[test]
    fn one_inside_point_gives_a_closed_octahedron_of_six_polygons() {
        let grid = Grid::new(Vec3::ZERO, Vec3::splat(4.0), [4, 4, 4]).unwrap();
        let mut v = vec![1.0f32; grid.point_count()];
        v[grid.index(2, 2, 2)] = -1.0;
        let (m, counts) = extract(&v, &grid);
        assert_eq!(counts.data_leaves, 8);
        // Eight corner triangles around the point, six crossed edges: the dual is a cube.
        assert_eq!((m.vertex_count(), m.quad_count()), (8, 6));
        assert!(m.is_closed_manifold() && !counts.split);
        assert_eq!(m.euler(), 2);
    }

    #[test]
    fn every_single_cell_case_has_mcs_topology_and_no_crossings() {
        // One cell: every surface reaches the bounds, so this is the boundary handling on all cases.
        let grid = Grid::new(Vec3::ZERO, Vec3::ONE, [1, 1, 1]).unwrap();
        for case in 1..255u32 {
            let v: Vec<f32> = (0..8).map(|c| if case >> c & 1 == 1 { -1.0 } else { 1.0 }).collect();
            let (m, counts) = extract(&v, &grid);
            assert!(m.is_manifold(), "case {case}");
            let (q, mc) = (quad_topology(&m), mc_topology(&v, &grid));
            assert_eq!((q.0, q.1), (mc.0, mc.1), "case {case}");
            assert!(q.2 > 0 && mc.2 > 0, "case {case}: cut open by the bounds, as MC is");
            assert!(geometry_ok(&m), "case {case}: {counts:?}");
            assert!(split(&polygons(&v, &grid), &grid).is_manifold());
            assert!(geometry_ok(&split(&polygons(&v, &grid), &grid)), "split of case {case}");
        }
    }

    #[test]
    fn random_sign_patterns_give_mcs_topology_padded_or_not() {
        let grid = Grid::new(Vec3::ZERO, Vec3::splat(6.0), [6, 6, 6]).unwrap();
        let (mut splits, mut boundary) = (0, 0);
        for seed in 1..300u64 {
            let density = [0.12, 0.3, 0.5][seed as usize % 3];
            let mut v = signs(seed * 7919, grid.point_count(), density);
            if seed % 2 == 0 {
                for (n, x) in v.iter_mut().enumerate() {
                    if grid.unindex(n).iter().any(|&c| c == 0 || c == 6) {
                        *x = 1.0;
                    }
                }
            }
            let (m, c) = extract(&v, &grid);
            assert!(m.is_manifold(), "seed {seed}: {c:?}");
            let (mc_euler, mc_parts, mc_open) = mc_topology(&v, &grid);
            assert_eq!(quad_topology(&m), (mc_euler, mc_parts, quad_topology(&m).2), "seed {seed}");
            assert_eq!(mc_open == 0, m.is_closed_manifold(), "seed {seed}: closed where MC is");
            assert!(geometry_ok(&m), "seed {seed}: {c:?}");
            // The split is the fallback that must always hold.
            let s = split(&polygons(&v, &grid), &grid);
            assert!(s.is_manifold() && geometry_ok(&s), "seed {seed}: split");
            splits += c.split as usize;
            boundary += (c.boundary_vertices > 0) as usize;
        }
        assert!(splits > 0 && boundary > 0, "both fallbacks exercised: {splits} {boundary}");
    }
}

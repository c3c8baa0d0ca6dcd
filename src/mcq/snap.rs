//! Vertex snapping (the step later quality-MC work adds to per-cell re-triangulation): Marching
//! Cubes vertices within `alpha` cells of a grid point are merged into one vertex on that grid
//! point. The tiny edges between them, which no per-cell change can fix (any triangle on a tiny
//! edge has a tiny angle), disappear.
//!
//! Merges are edge collapses on the Marching Cubes triangulation of the polygons, each checked
//! before it is made: the two vertices must share an edge whose link is exactly its two opposite
//! vertices (so the surface stays a closed 2-manifold of the same topology), no remaining triangle
//! may turn over, and no cell polygon may be pinched (its merged vertices must stay consecutive),
//! so the merged polygons are again simple borders the per-cell step can triangulate.

use super::CellPolygon;
use crate::grid::Grid;
use crate::tables::triangulate_polygon;
use glam::Vec3;
use std::collections::BTreeMap;

/// What snapping did: `rep[v]` is the vertex `v` was merged into (itself if none), `corner[v]`
/// the grid point a merged vertex now sits on.
pub(super) struct Snapped {
    pub rep: Vec<u32>,
    pub corner: Vec<Option<[usize; 3]>>,
    /// Vertices merged away.
    pub merged: usize,
}

struct Collapser<'a> {
    positions: &'a mut [Vec3],
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    /// Triangles (possibly dead) around each vertex.
    vt: Vec<Vec<u32>>,
    /// Polygons around each vertex (after merges, around its representative).
    vp: Vec<Vec<u32>>,
    polys: &'a [CellPolygon],
    rep: Vec<u32>,
}

/// `place` says where a merged vertex goes, given its grid point and the axes along which it may
/// move (the grid point itself, or its projection onto the surface).
pub(super) fn snap(
    positions: &mut [Vec3],
    polys: &[CellPolygon],
    grid: &Grid,
    alpha: f32,
    place: impl Fn(Vec3, [bool; 3]) -> Vec3,
) -> Snapped {
    let n = positions.len();
    let mut c = Collapser {
        tris: vec![],
        alive: vec![],
        vt: vec![vec![]; n],
        vp: vec![vec![]; n],
        polys,
        rep: (0..n as u32).collect(),
        positions,
    };
    for (p, poly) in polys.iter().enumerate() {
        for &v in &poly.verts {
            c.vp[v as usize].push(p as u32);
        }
        let local = |e: u8| poly.verts[poly.edges.iter().position(|&x| x == e).expect("edge of the polygon")];
        for t in triangulate_polygon(&poly.edges) {
            let tri = t.map(local);
            for &v in &tri {
                c.vt[v as usize].push(c.tris.len() as u32);
            }
            c.tris.push(tri);
            c.alive.push(true);
        }
    }
    // Vertices near a grid point, grouped by the point, nearest first.
    let mut clusters: BTreeMap<[usize; 3], Vec<(f32, u32)>> = BTreeMap::new();
    for (v, p) in c.positions.iter().enumerate() {
        let q = (*p - grid.origin) / grid.spacing;
        let g = q.round();
        let d = (q - g).abs().max_element();
        if d < alpha {
            clusters.entry(g.to_array().map(|x| x as usize)).or_default().push((d, v as u32));
        }
    }
    let mut corner = vec![None; n];
    let mut merged = 0;
    for (g, mut members) in clusters {
        if members.len() < 2 {
            continue;
        }
        members.sort_by(|a, b| a.0.total_cmp(&b.0));
        let m = members[0].1;
        let at = grid.position(g[0], g[1], g[2]);
        // On the border of a clipped surface, the vertex stays in the domain's faces.
        let free: [bool; 3] = std::array::from_fn(|a| g[a] > 0 && g[a] < grid.cells[a]);
        let target = (place(at, [true; 3]), place(at, free));
        let mut rest: Vec<u32> = members[1..].iter().map(|x| x.1).collect();
        // A member may only become adjacent to `m` once another has merged: retry until stuck.
        loop {
            let before = rest.len();
            rest.retain(|&v| !c.try_collapse(m, v, target));
            if rest.len() == before {
                break;
            }
        }
        let done = members.len() - 1 - rest.len();
        if done > 0 {
            corner[m as usize] = Some(g);
            merged += done;
        }
    }
    Snapped { rep: c.rep, corner, merged }
}

impl Collapser<'_> {
    fn find(&self, mut v: u32) -> u32 {
        while self.rep[v as usize] != v {
            v = self.rep[v as usize];
        }
        v
    }

    fn live(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.vt[v as usize].iter().copied().filter(|&t| self.alive[t as usize])
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut out: Vec<u32> =
            self.live(v).flat_map(|t| self.tris[t as usize]).filter(|&x| x != v).collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Whether `v` lies on the border of an open surface: an edge there has one triangle only.
    fn on_border(&self, v: u32) -> bool {
        let mut around: Vec<u32> =
            self.live(v).flat_map(|t| self.tris[t as usize]).filter(|&x| x != v).collect();
        around.sort_unstable();
        around.chunk_by(|a, b| a == b).any(|run| run.len() == 1)
    }

    /// Merges `v` into `m`, moving `m` to `target.0`, or to `target.1` (which stays in the domain's
    /// faces) when either is on the border of a clipped surface, if that keeps everything valid.
    fn try_collapse(&mut self, m: u32, v: u32, target: (Vec3, Vec3)) -> bool {
        let shared: Vec<u32> = self.live(v).filter(|&t| self.tris[t as usize].contains(&m)).collect();
        let (border_m, border_v) = (self.on_border(m), self.on_border(v));
        // An inner edge joins two border vertices only across the surface: merging them would
        // pinch it. A border edge (one triangle) may go if its opposite vertex is inside, so
        // the border just loses a vertex.
        let valid = match shared.len() {
            2 => !(border_m && border_v),
            1 => {
                let o = self.tris[shared[0] as usize].into_iter().find(|&x| x != m && x != v);
                o.is_some_and(|o| !self.on_border(o))
            }
            _ => false,
        };
        if !valid {
            return false;
        }
        let target = if border_m || border_v { target.1 } else { target.0 };
        let mut opposite: Vec<u32> =
            shared.iter().flat_map(|&t| self.tris[t as usize]).filter(|&x| x != m && x != v).collect();
        opposite.sort_unstable();
        let (nm, nv) = (self.neighbours(m), self.neighbours(v));
        let common: Vec<u32> = nm.iter().copied().filter(|x| nv.contains(x)).collect();
        // The merged vertex keeps at least three neighbours, and so do the opposite vertices.
        if common != opposite
            || nm.len() + nv.len() < 5 + shared.len()
            || opposite.iter().any(|&o| self.neighbours(o).len() < 4)
        {
            return false;
        }
        // No remaining triangle may turn over or collapse.
        let moved = |x: u32| if x == m || x == v { target } else { self.positions[x as usize] };
        for t in self.live(m).chain(self.live(v)) {
            let tri = self.tris[t as usize];
            if tri.contains(&m) && tri.contains(&v) {
                continue;
            }
            let old = tri.map(|x| self.positions[x as usize]);
            let new = tri.map(moved);
            let (n0, n1) =
                ((old[1] - old[0]).cross(old[2] - old[0]), (new[1] - new[0]).cross(new[2] - new[0]));
            if n0.dot(n1) <= 0.25 * n0.length() * n1.length() {
                return false;
            }
        }
        // No polygon may be pinched: its vertices in {m, v} must form one run.
        for &p in self.vp[m as usize].iter().chain(&self.vp[v as usize]) {
            let cycle: Vec<bool> = self.polys[p as usize]
                .verts
                .iter()
                .map(|&x| {
                    let r = self.find(x);
                    r == m || r == v
                })
                .collect();
            let k = cycle.len();
            let runs = (0..k).filter(|&i| cycle[i] && !cycle[(i + k - 1) % k]).count();
            if runs > 1 {
                return false;
            }
        }
        for t in std::mem::take(&mut self.vt[v as usize]) {
            let tri = &mut self.tris[t as usize];
            if tri.contains(&m) {
                self.alive[t as usize] = false;
            } else if self.alive[t as usize] {
                tri.iter_mut().filter(|x| **x == v).for_each(|x| *x = m);
                self.vt[m as usize].push(t);
            }
        }
        let moved_polys = std::mem::take(&mut self.vp[v as usize]);
        self.vp[m as usize].extend(moved_polys);
        self.rep[v as usize] = m;
        self.positions[m as usize] = target;
        true
    }
}

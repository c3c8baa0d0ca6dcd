//! Cube topology and the Marching Cubes case tables, generated once from first principles.
//!
//! Nothing here is typed in by hand: for each of the 256 sign configurations we walk the six cube
//! faces, cut each face by segments that keep the inside on a fixed side, and chain the segments into
//! closed polygons. Because a face's segments depend only on that face's four corners (and, for the
//! trilinear option, on its asymptotic decider), the two cells sharing a face always agree, which is
//! what makes every Marching Cubes output watertight and manifold. The triangle table is derived from
//! the polygon table, so the two can never disagree (issue 7's quality method needs the polygons).
//!
//! Numbering: corner `c` sits at `(c & 1, (c >> 1) & 1, (c >> 2) & 1)`; a case has bit `c` set when
//! corner `c` is inside (value below the iso-level). Edges are listed x-edges, y-edges, z-edges.

use std::sync::OnceLock;

/// Offset of each corner in cell units.
pub const CORNERS: [[usize; 3]; 8] = {
    let mut c = [[0usize; 3]; 8];
    let mut i = 0;
    while i < 8 {
        c[i] = [i & 1, (i >> 1) & 1, (i >> 2) & 1];
        i += 1;
    }
    c
};

/// The 12 cube edges as (lower corner, upper corner); `EDGE_AXIS[e]` is the axis the edge runs along.
pub const EDGES: [[u8; 2]; 12] =
    [[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7], [0, 4], [1, 5], [2, 6], [3, 7]];

pub const EDGE_AXIS: [usize; 12] = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2];

/// The edge joining corners `a` and `b` (which must differ in exactly one bit).
pub const fn edge_between(a: u8, b: u8) -> u8 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    let mut e = 0;
    while e < 12 {
        if EDGES[e][0] == lo && EDGES[e][1] == hi {
            return e as u8;
        }
        e += 1;
    }
    panic!("corners are not joined by a cube edge");
}

/// Face `f = 2 * axis + side`: its four corners in the order `(u, v) = (0,0), (1,0), (1,1), (0,1)`
/// with `u = axis + 1`, `v = axis + 2` (mod 3). This order is counter-clockwise seen from `+axis`,
/// and it is the same for both cells sharing the face, so per-face decisions are bit-identical.
pub const FACES: [[u8; 4]; 6] = {
    let mut faces = [[0u8; 4]; 6];
    let mut f = 0;
    while f < 6 {
        let axis = f / 2;
        let side = f % 2;
        let u = (axis + 1) % 3;
        let v = (axis + 2) % 3;
        let uv = [(0, 0), (1, 0), (1, 1), (0, 1)];
        let mut k = 0;
        while k < 4 {
            faces[f][k] = ((side << axis) | (uv[k].0 << u) | (uv[k].1 << v)) as u8;
            k += 1;
        }
        f += 1;
    }
    faces
};

/// A face is ambiguous when its inside corners sit on one diagonal only.
pub fn face_is_ambiguous(case: u8, face: usize) -> bool {
    let [a, b, c, d] = FACES[face].map(|corner| case >> corner & 1);
    a == c && b == d && a != b
}

/// The closed polygons a case cuts out of a cell, as cycles of edge ids, oriented so that their
/// normals (right-hand rule) point from inside to outside.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CellPolygons {
    /// Packed cycles: a length `n`, then `n` edge ids, repeated. 12 edges + 4 lengths fit in 16.
    data: [u8; 16],
    len: u8,
}

impl CellPolygons {
    pub fn iter(&self) -> impl Iterator<Item = &[u8]> {
        let data = &self.data[..self.len as usize];
        let mut at = 0;
        std::iter::from_fn(move || {
            if at >= data.len() {
                return None;
            }
            let n = data[at] as usize;
            let poly = &data[at + 1..at + 1 + n];
            at += n + 1;
            Some(poly)
        })
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn push(&mut self, cycle: &[u8]) {
        let at = self.len as usize;
        self.data[at] = cycle.len() as u8;
        self.data[at + 1..at + 1 + cycle.len()].copy_from_slice(cycle);
        self.len += 1 + cycle.len() as u8;
    }
}

/// Builds the polygons of `case`. Bit `f` of `joined_faces` says that on ambiguous face `f` the two
/// inside corners are connected across the face (the face saddle is inside); otherwise they are
/// separated. Bits of unambiguous faces are ignored.
pub fn build_cell_polygons(case: u8, joined_faces: u8) -> CellPolygons {
    let inside = |c: u8| case >> c & 1 == 1;
    // next[e] = the edge the boundary of the inside region goes to after edge e.
    let mut next = [u8::MAX; 12];
    for (f, corners) in FACES.iter().enumerate() {
        // Walk the face counter-clockwise as seen from outside the cube.
        let ring: [u8; 4] =
            if f % 2 == 1 { *corners } else { [corners[0], corners[3], corners[2], corners[1]] };
        // Crossings in ring order: (edge, leaving = goes from an inside to an outside corner).
        let mut crossings = [(0u8, false); 4];
        let mut n = 0;
        for k in 0..4 {
            let (a, b) = (ring[k], ring[(k + 1) % 4]);
            if inside(a) != inside(b) {
                crossings[n] = (edge_between(a, b), inside(a));
                n += 1;
            }
        }
        let joined = joined_faces >> f & 1 == 1;
        for k in 0..n {
            let (edge, leaving) = crossings[k];
            if !leaving {
                continue;
            }
            // Cutting off the inside corner links a leaving edge to the entering edge before it;
            // joining the inside corners across the face links it to the entering edge after it.
            let partner = if n == 4 && joined { (k + 1) % n } else { (k + n - 1) % n };
            next[edge as usize] = crossings[partner].0;
        }
    }
    let mut polygons = CellPolygons::default();
    let mut seen = [false; 12];
    for start in 0..12u8 {
        if next[start as usize] == u8::MAX || seen[start as usize] {
            continue;
        }
        let mut cycle = Vec::with_capacity(12);
        let mut e = start;
        while !seen[e as usize] {
            seen[e as usize] = true;
            cycle.push(e);
            e = next[e as usize];
        }
        // The walk keeps the inside on its left seen from outside the cube, so the cycle's right-hand
        // normal points into the inside region; reverse it to point outward.
        cycle.reverse();
        polygons.push(&cycle);
    }
    polygons
}

/// Stands for an extra vertex at the centre of its polygon in triangle lists (edge ids are 0..12).
pub const CENTER: u8 = 12;

/// Triangles of a case: at most 12 edges in at most 4 polygons give at most 12 triangles (with a
/// centre vertex), 36 ids. Triangles are grouped by polygon, in polygon order (`per_polygon` counts them), so methods
/// that treat polygons separately (EMC's feature cells) can find each polygon's own triangles.
#[derive(Clone, Copy, Debug)]
pub struct CellTriangles {
    pub edges: [u8; 36],
    pub count: u8,
    pub per_polygon: [u8; 4],
}

impl CellTriangles {
    pub fn triangles(&self) -> impl Iterator<Item = [u8; 3]> + '_ {
        self.edges[..3 * self.count as usize].chunks_exact(3).map(|t| [t[0], t[1], t[2]])
    }
}

/// The two cube faces edge `e` lies on.
pub fn edge_faces(e: usize) -> [usize; 2] {
    let axis = EDGE_AXIS[e];
    let corner = CORNERS[EDGES[e][0] as usize];
    let [u, v] = [(axis + 1) % 3, (axis + 2) % 3];
    [2 * u + corner[u], 2 * v + corner[v]]
}

fn share_face(a: u8, b: u8) -> bool {
    let (fa, fb) = (edge_faces(a as usize), edge_faces(b as usize));
    fa.iter().any(|f| fb.contains(f))
}

/// Triangulates one polygon so that no diagonal joins two vertices on a common cube face: such a
/// diagonal would lie flat in the face, where the neighbour's triangles lie too, and the two cells'
/// diagonals could cross there (a self-intersection, though the topology stays fine).
///
/// Some long polygons of the trilinear table (8, 9 and 12 sides, winding over several faces) have
/// no such triangulation; they are fanned around an extra vertex at their centre ([`CENTER`]), as
/// Marching Cubes 33 does for the same configurations. The default table never needs one.
pub fn triangulate_polygon(poly: &[u8]) -> Vec<[u8; 3]> {
    fn split(poly: &[u8], idx: &[usize], out: &mut Vec<[u8; 3]>) -> bool {
        let n = idx.len();
        if n == 3 {
            out.push([poly[idx[0]], poly[idx[1]], poly[idx[2]]]);
            return true;
        }
        // The base idx[0]–idx[n-1] is an edge or an accepted diagonal; pick an apex for it.
        for k in 1..n - 1 {
            let left_ok = k == 1 || !share_face(poly[idx[0]], poly[idx[k]]);
            let right_ok = k == n - 2 || !share_face(poly[idx[k]], poly[idx[n - 1]]);
            if !(left_ok && right_ok) {
                continue;
            }
            let mark = out.len();
            out.push([poly[idx[0]], poly[idx[k]], poly[idx[n - 1]]]);
            if (k < 2 || split(poly, &idx[..=k], out)) && (k > n - 3 || split(poly, &idx[k..], out)) {
                return true;
            }
            out.truncate(mark);
        }
        false
    }
    let idx: Vec<usize> = (0..poly.len()).collect();
    let mut out = Vec::with_capacity(poly.len() - 2);
    if !split(poly, &idx, &mut out) {
        out.clear();
        for k in 0..poly.len() {
            out.push([CENTER, poly[k], poly[(k + 1) % poly.len()]]);
        }
    }
    out
}

fn triangulate(polygons: &CellPolygons) -> CellTriangles {
    triangulate_with(polygons, triangulate_polygon)
}

/// [`triangulate_polygon`], or where that needs a [`CENTER`] vertex, a fan from the polygon's
/// first vertex: for cells that are not cubes, where a centre would lie on no edge.
fn triangulate_polygon_without_centre(poly: &[u8]) -> Vec<[u8; 3]> {
    let tris = triangulate_polygon(poly);
    if !tris.iter().any(|t| t.contains(&CENTER)) {
        return tris;
    }
    (1..poly.len() - 1).map(|k| [poly[0], poly[k], poly[k + 1]]).collect()
}

fn triangulate_with(polygons: &CellPolygons, polygon: fn(&[u8]) -> Vec<[u8; 3]>) -> CellTriangles {
    let mut out = CellTriangles { edges: [0; 36], count: 0, per_polygon: [0; 4] };
    for (p, poly) in polygons.iter().enumerate() {
        for tri in polygon(poly) {
            let at = 3 * out.count as usize;
            out.edges[at..at + 3].copy_from_slice(&tri);
            out.count += 1;
            out.per_polygon[p] += 1;
        }
    }
    out
}

/// The default case table: inside corners on an ambiguous face are always separated. Consistent
/// between neighbours because it depends on signs alone.
pub fn polygon_table() -> &'static [CellPolygons; 256] {
    static TABLE: OnceLock<[CellPolygons; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|case| build_cell_polygons(case as u8, 0)))
}

/// Triangles of the default table.
pub fn triangle_table() -> &'static [CellTriangles; 256] {
    static TABLE: OnceLock<[CellTriangles; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|case| triangulate(&polygon_table()[case])))
}

/// The faces of `case` that are ambiguous, as a bit set over face ids.
fn ambiguous_faces(case: u8) -> u8 {
    (0..6).filter(|&f| face_is_ambiguous(case, f)).fold(0, |m, f| m | 1 << f)
}

/// A table over every (case, joined-faces) pair, indexed `case << 6 | joined_faces`, built from
/// `entry` only where no bit of an unambiguous face is set; the other entries copy the one with
/// those bits cleared (a subset, so a smaller index, already built). Most cases have no ambiguous
/// face, so this builds 1/40 of the entries: building them all cost more than some whole meshes.
fn table_over_joined_faces<T: Copy>(entry: impl Fn(u8, u8) -> T) -> Vec<T> {
    let mut table: Vec<T> = Vec::with_capacity(256 * 64);
    for case in 0..=255u8 {
        let ambiguous = ambiguous_faces(case);
        for joined in 0..64u8 {
            let canonical = joined & ambiguous;
            let value = if canonical == joined {
                entry(case, joined)
            } else {
                table[(case as usize) << 6 | canonical as usize]
            };
            table.push(value);
        }
    }
    table
}

/// Polygons for every (case, joined-faces) pair, indexed `case << 6 | joined_faces`.
pub fn polygon_table_with_faces() -> &'static [CellPolygons] {
    static TABLE: OnceLock<Vec<CellPolygons>> = OnceLock::new();
    TABLE.get_or_init(|| table_over_joined_faces(build_cell_polygons))
}

/// Triangles for every (case, joined-faces) pair: the trilinear-topology option picks the face bits
/// per cell with the asymptotic decider. 16 384 small entries, built on first use.
pub fn triangle_table_with_faces() -> &'static [CellTriangles] {
    static TABLE: OnceLock<Vec<CellTriangles>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let polygons = polygon_table_with_faces();
        table_over_joined_faces(|case, joined| triangulate(&polygons[(case as usize) << 6 | joined as usize]))
    })
}

/// [`triangle_table_with_faces`] with no [`CENTER`] vertex (a polygon that would need one is fanned
/// from its first vertex): Dual Marching Cubes' cells, whose every mesh vertex lies on a dual
/// edge.
pub fn triangle_table_with_faces_without_centre() -> &'static [CellTriangles] {
    static TABLE: OnceLock<Vec<CellTriangles>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let polygons = polygon_table_with_faces();
        table_over_joined_faces(|case, joined| {
            triangulate_with(
                &polygons[(case as usize) << 6 | joined as usize],
                triangulate_polygon_without_centre,
            )
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_built_from_ambiguous_faces_only_equal_tables_built_entry_by_entry() {
        let same = |a: &CellTriangles, b: &CellTriangles| {
            a.count == b.count && a.per_polygon == b.per_polygon && a.triangles().eq(b.triangles())
        };
        for k in 0..256 * 64 {
            let polygons = build_cell_polygons((k >> 6) as u8, (k & 63) as u8);
            assert_eq!(polygon_table_with_faces()[k], polygons, "entry {k}");
            assert!(same(&triangle_table_with_faces()[k], &triangulate(&polygons)), "entry {k}");
            let without_centre = triangulate_with(&polygons, triangulate_polygon_without_centre);
            assert!(same(&triangle_table_with_faces_without_centre()[k], &without_centre), "entry {k}");
        }
    }

    #[test]
    fn faces_hold_four_corners_with_a_fixed_coordinate() {
        for (f, corners) in FACES.iter().enumerate() {
            let axis = f / 2;
            for &c in corners {
                assert_eq!(CORNERS[c as usize][axis], f % 2);
            }
            for k in 0..4 {
                edge_between(corners[k], corners[(k + 1) % 4]);
            }
        }
    }

    #[test]
    fn every_crossing_edge_is_used_exactly_once() {
        for case in 0..=255u8 {
            for joined in 0..64u8 {
                let polys = build_cell_polygons(case, joined);
                let mut used = [0; 12];
                for p in polys.iter() {
                    assert!(p.len() >= 3, "case {case}: polygon {p:?}");
                    for &e in p {
                        used[e as usize] += 1;
                    }
                }
                for (e, &[a, b]) in EDGES.iter().enumerate() {
                    let crosses = (case >> a & 1) != (case >> b & 1);
                    assert_eq!(used[e], crosses as i32, "case {case} edge {e}");
                }
            }
        }
    }

    #[test]
    fn no_triangle_edge_lies_flat_in_a_cube_face_unless_it_is_a_polygon_edge() {
        for k in 0..256 * 64 {
            let polys = build_cell_polygons((k >> 6) as u8, (k & 63) as u8);
            for poly in polys.iter() {
                let tris = triangulate_polygon(poly);
                if tris.iter().any(|t| t.contains(&CENTER)) {
                    assert_ne!(k & 63, 0, "the default table needs no centre vertex");
                    assert_eq!(tris.len(), poly.len());
                    continue;
                }
                assert_eq!(tris.len(), poly.len() - 2);
                let is_polygon_edge = |a: u8, b: u8| {
                    (0..poly.len()).any(|q| {
                        let (x, y) = (poly[q], poly[(q + 1) % poly.len()]);
                        (x, y) == (a, b) || (x, y) == (b, a)
                    })
                };
                for t in &tris {
                    for q in 0..3 {
                        let (a, b) = (t[q], t[(q + 1) % 3]);
                        assert!(
                            is_polygon_edge(a, b) || !share_face(a, b),
                            "case {} polygon {poly:?}",
                            k >> 6
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn complementary_configurations_have_the_classic_polygon_counts() {
        let table = polygon_table();
        assert_eq!(table[0].iter().count(), 0);
        assert_eq!(table[255].iter().count(), 0);
        assert_eq!(table[1].iter().map(|p| p.len()).collect::<Vec<_>>(), vec![3]);
        // One face diagonal (corners 0 and 3): separated by default, joined on request.
        let diagonal: u8 = 0b1001;
        assert_eq!(table[diagonal as usize].iter().count(), 2);
        let bottom = 4; // face z = 0
        assert!(face_is_ambiguous(diagonal, bottom));
        assert_eq!(build_cell_polygons(diagonal, 1 << bottom).iter().count(), 1);
        // Body diagonal (corners 0 and 7): two triangles in every table.
        assert_eq!(table[0b1000_0001].iter().count(), 2);
    }
}

//! The interior half of the trilinear topology (Marching Cubes 33's interior tests): whether two
//! parts of the inside (or of the outside) that the cell's faces keep apart meet inside the cell,
//! and if so the tube that joins their polygons.
//!
//! The face decider settles everything the faces can see. What they cannot see happens at the
//! interior critical points of the trilinear interpolant, and only there: a trilinear function is
//! harmonic, so it has no interior extrema, only up to two saddles, and level sets change how they
//! connect only at critical points. At a body saddle `p` every coordinate plane through `p` cuts the
//! interpolant in a bilinear function with its own saddle at `p` (the Hessian's diagonal is zero),
//! whose value `s` separates the section's diagonals: one diagonal lies below `s`, the other above.
//! If `s < iso`, the two corners of the lower diagonal are inside and joined through `p` in that
//! plane; each lies on a vertical cube edge, along which it reaches the inside endpoint. Symmetric
//! for the outside when `s > iso`. This is exact where the published case-by-case tests (Chernyaev;
//! corrected by Lewiner et al. and by Custodio et al.) are exact, and needs no case numbers.

use crate::tables::{CellPolygons, CORNERS, EDGES};
use glam::DVec3;

/// Union-find over the 8 corners of a cell.
#[derive(Clone, Copy)]
struct Corners([u8; 8]);

impl Corners {
    fn new() -> Self {
        Corners(std::array::from_fn(|c| c as u8))
    }

    fn find(&mut self, c: u8) -> u8 {
        let mut r = c;
        while self.0[r as usize] != r {
            r = self.0[r as usize];
        }
        self.0[c as usize] = r;
        r
    }

    /// Joins the groups of `a` and `b`; whether they were apart.
    fn union(&mut self, a: u8, b: u8) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        self.0[ra as usize] = rb;
        ra != rb
    }
}

/// The trilinear interpolant of the corner values `d` (corner `c` at `CORNERS[c]`).
fn trilinear(d: &[f32; 8], p: DVec3) -> f64 {
    (0..8)
        .map(|c| {
            let [x, y, z] = CORNERS[c];
            let w = |bit: usize, t: f64| if bit == 1 { t } else { 1.0 - t };
            d[c] as f64 * w(x, p.x) * w(y, p.y) * w(z, p.z)
        })
        .sum()
}

/// Interior critical points of the trilinear interpolant in the open unit cube (at most two).
fn body_saddles(d: &[f32; 8]) -> Vec<DVec3> {
    let v = |c: usize| d[c] as f64;
    // F = a + b u + c v + d w + e uv + f vw + g wu + h uvw in the cell's own coordinates.
    let (b, c, dd) = (v(1) - v(0), v(2) - v(0), v(4) - v(0));
    let e = v(3) - v(1) - v(2) + v(0);
    let f = v(6) - v(2) - v(4) + v(0);
    let g = v(5) - v(1) - v(4) + v(0);
    let h = v(7) - v(3) - v(5) - v(6) + v(1) + v(2) + v(4) - v(0);
    let scale = d.iter().fold(0.0f64, |m, &x| m.max((x as f64).abs())).max(f64::MIN_POSITIVE);
    let mut out = Vec::with_capacity(2);
    if h.abs() > 1e-9 * scale {
        // Shifting by (-f, -g, -e)/h turns the gradient equations into VW = A, UW = B, UV = C.
        let aa = (e * g - b * h) / (h * h);
        let bb = (e * f - c * h) / (h * h);
        let cc = (f * g - dd * h) / (h * h);
        let abc = aa * bb * cc;
        if abc > 0.0 && aa != 0.0 && bb != 0.0 && cc != 0.0 {
            let s = abc.sqrt();
            let shift = DVec3::new(-f / h, -g / h, -e / h);
            for sign in [1.0, -1.0] {
                out.push(shift + DVec3::new(sign * s / aa, sign * s / bb, sign * s / cc));
            }
        }
    } else {
        // No cubic term: the gradient is linear, [[0,e,g],[e,0,f],[g,f,0]] p = -(b,c,d).
        let m = glam::DMat3::from_cols(DVec3::new(0.0, e, g), DVec3::new(e, 0.0, f), DVec3::new(g, f, 0.0));
        if (2.0 * e * f * g).abs() > 1e-12 * scale * scale * scale {
            out.push(m.inverse() * -DVec3::new(b, c, dd));
        }
    }
    out.retain(|p| p.cmpgt(DVec3::ZERO).all() && p.cmplt(DVec3::ONE).all());
    out
}

/// Corner groups of the cell's boundary: corners of one sign joined along cube edges and, on each
/// face, along the diagonal the face decision joins (`joined` bit set: the inside diagonal).
fn boundary_groups(case: u8, joined: u8) -> Corners {
    let mut g = Corners::new();
    let inside = |c: u8| case >> c & 1 == 1;
    for [a, b] in EDGES {
        if inside(a) == inside(b) {
            g.union(a, b);
        }
    }
    for (f, corners) in crate::tables::FACES.iter().enumerate() {
        if !crate::tables::face_is_ambiguous(case, f) {
            continue;
        }
        let [p, q, r, s] = *corners;
        // On an ambiguous face one diagonal is inside, the other outside; the decision joins one.
        let (ins, outs) = if inside(p) { ((p, r), (q, s)) } else { ((q, s), (p, r)) };
        let (x, y) = if joined >> f & 1 == 1 { ins } else { outs };
        g.union(x, y);
    }
    g
}

/// Pairs of boundary groups (given by a member corner) joined inside the cell, inside pairs first
/// flagged `true`. Empty for almost every cell.
pub fn interior_joins(case: u8, joined: u8, d: &[f32; 8]) -> Vec<(u8, u8, bool)> {
    let mut groups = boundary_groups(case, joined);
    let mut joins = Vec::new();
    for p in body_saddles(d) {
        let s = trilinear(d, p);
        if s == 0.0 {
            continue;
        }
        let want_inside = s < 0.0;
        // The section z = p.z: its corners on the four z-edges, in (x, y) = 00, 10, 01, 11 order.
        let section: [f64; 4] = std::array::from_fn(|k| {
            let (x, y) = ((k & 1) as f64, (k >> 1) as f64);
            trilinear(d, DVec3::new(x, y, p.z))
        });
        let beyond = |v: f64| if want_inside { v < s } else { v > s };
        let diagonal = if beyond(section[0]) && beyond(section[3]) {
            [0, 3]
        } else if beyond(section[1]) && beyond(section[2]) {
            [1, 2]
        } else {
            continue; // a degenerate section (saddle on a diagonal's level): nothing to join
        };
        // Each section corner reaches, along its z-edge (corners k and k + 4), the endpoint(s) of its sign.
        let reach = |k: usize| -> Option<u8> {
            [k as u8, k as u8 + 4].into_iter().find(|&c| (d[c as usize] < 0.0) == want_inside)
        };
        if let (Some(a), Some(b)) = (reach(diagonal[0]), reach(diagonal[1])) {
            let (ra, rb) = (groups.find(a), groups.find(b));
            if groups.union(ra, rb) {
                joins.push((ra, rb, want_inside));
            }
        }
    }
    joins
}

/// The polygons of a cell with tunnels: for each interior join, the two polygons bordering the
/// joined groups (on the side of one common group of the other sign) are replaced by a tube between
/// them. Returns the untouched polygons (as indices into `polygons`) and the tubes (pairs of
/// polygon indices). A join whose polygons cannot be found is left out (the faces' answer stands).
pub fn tunnels(
    case: u8,
    joined: u8,
    polygons: &CellPolygons,
    joins: &[(u8, u8, bool)],
) -> (Vec<usize>, Vec<(usize, usize)>) {
    let mut groups = boundary_groups(case, joined);
    let inside = |c: u8| case >> c & 1 == 1;
    // Each polygon separates one inside group from one outside group (read off any of its edges).
    let sides: Vec<(u8, u8)> = polygons
        .iter()
        .map(|poly| {
            let [a, b] = EDGES[poly[0] as usize];
            let (i, o) = if inside(a) { (a, b) } else { (b, a) };
            (groups.find(i), groups.find(o))
        })
        .collect();
    let mut used = vec![false; sides.len()];
    let mut tubes = Vec::new();
    for &(a, b, join_inside) in joins {
        let (ga, gb) = (groups.find(a), groups.find(b));
        // The polygon of a joined group, on the side of the group (of the other sign) they share.
        let own = |k: usize| if join_inside { sides[k].0 } else { sides[k].1 };
        let other = |k: usize| if join_inside { sides[k].1 } else { sides[k].0 };
        let pick = (0..sides.len()).filter(|&k| !used[k] && own(k) == ga).find_map(|k| {
            (0..sides.len()).find(|&l| !used[l] && own(l) == gb && other(l) == other(k)).map(|l| (k, l))
        });
        if let Some((k, l)) = pick {
            used[k] = true;
            used[l] = true;
            tubes.push((k, l));
        }
    }
    let rest = (0..sides.len()).filter(|&k| !used[k]).collect();
    (rest, tubes)
}

/// Triangles of a tube between two polygons (vertex lists in the table's outward orientation),
/// keeping each polygon edge's direction so the neighbours still match: walk `a` forwards and `b`
/// backwards, choosing the band of least total triangle `area` by dynamic programming over every
/// starting rung (an edge from one rim to the other); the least-area band is the one that neither
/// twists nor folds. A rung `rung_ok` refuses is never used; `None` if every band would need one. No
/// rung may appear twice (a rim fanned to one vertex pinches the band). Of the bands found (one
/// per starting rung) the least-area one `band_ok` accepts is kept: on skewed rims the least-area
/// band can fold over itself, and the caller's test says which bands cross.
pub fn tube<T: Copy>(
    a: &[T],
    b: &[T],
    rung_ok: impl Fn(T, T) -> bool,
    area: impl Fn([T; 3]) -> f64,
    band_ok: impl Fn(&[[T; 3]]) -> bool,
) -> Option<Vec<[T; 3]>> {
    let c: Vec<T> = b.iter().rev().copied().collect();
    let (n, m) = (a.len(), c.len());
    let mut best: Option<(f64, Vec<[T; 3]>)> = None;
    for i0 in 0..n {
        for j0 in 0..m {
            let ai = |i: usize| a[(i0 + i) % n];
            let cj = |j: usize| c[(j0 + j) % m];
            if !rung_ok(ai(0), cj(0)) {
                continue;
            }
            // total[i][j]: least cost of a band from rung (0, 0) to rung (i, j); `from_a` records
            // whether that rung was reached by advancing along `a`.
            let mut total = vec![vec![f64::INFINITY; m + 1]; n + 1];
            let mut from_a = vec![vec![false; m + 1]; n + 1];
            total[0][0] = 0.0;
            for i in 0..=n {
                for j in 0..=m {
                    // The band starts by advancing along `a` and ends advancing along `b`; every
                    // band has such a starting rung, and this keeps any rung from appearing twice.
                    if (i, j) == (0, 0) || (i, j) == (n, 0) || i == 0 || j == m && i < n {
                        continue;
                    }
                    if !rung_ok(ai(i), cj(j)) {
                        continue;
                    }
                    let via_a = if i > 0 && (i, j) != (n, m) {
                        total[i - 1][j] + area([ai(i - 1), ai(i), cj(j)])
                    } else {
                        f64::INFINITY
                    };
                    let via_c =
                        if j > 0 { total[i][j - 1] + area([cj(j), cj(j - 1), ai(i)]) } else { f64::INFINITY };
                    total[i][j] = via_a.min(via_c);
                    from_a[i][j] = via_a <= via_c;
                }
            }
            let score = total[n][m];
            if !score.is_finite() || best.as_ref().is_some_and(|(s, _)| *s <= score) {
                continue;
            }
            let mut out = Vec::with_capacity(n + m);
            let (mut i, mut j) = (n, m);
            while (i, j) != (0, 0) {
                if from_a[i][j] {
                    out.push([ai(i - 1), ai(i), cj(j)]);
                    i -= 1;
                } else {
                    out.push([cj(j), cj(j - 1), ai(i)]);
                    j -= 1;
                }
            }
            if band_ok(&out) {
                best = Some((score, out));
            }
        }
    }
    best.map(|(_, tris)| tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_saddles_found_are_critical_points() {
        let d = [-1.0, 0.3, 0.4, 0.2, 0.5, 0.25, 0.35, -0.8];
        let saddles = body_saddles(&d);
        assert!(!saddles.is_empty());
        for p in saddles {
            let eps = 1e-6;
            let grad = DVec3::new(
                trilinear(&d, p + DVec3::X * eps) - trilinear(&d, p - DVec3::X * eps),
                trilinear(&d, p + DVec3::Y * eps) - trilinear(&d, p - DVec3::Y * eps),
                trilinear(&d, p + DVec3::Z * eps) - trilinear(&d, p - DVec3::Z * eps),
            ) / (2.0 * eps);
            assert!(grad.length() < 1e-6, "{p}: {grad}");
        }
    }

    #[test]
    fn a_body_diagonal_joins_through_the_middle_only_when_the_middle_is_inside() {
        // Case 4: corners 0 and 7 inside. The interpolant along the diagonal decides.
        let case = 0b1000_0001;
        let tunnel = [-1.0, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, -1.0];
        assert!(trilinear(&tunnel, DVec3::splat(0.5)) < 0.0);
        assert_eq!(interior_joins(case, 0, &tunnel).len(), 1);
        let apart = [-0.2, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -0.2];
        assert!(interior_joins(case, 0, &apart).is_empty());
        // The joined polygons become one tube of 6 triangles (MC33's case 4.1.2).
        let polygons = crate::tables::build_cell_polygons(case, 0);
        let (rest, tubes) = tunnels(case, 0, &polygons, &interior_joins(case, 0, &tunnel));
        assert!(rest.is_empty());
        assert_eq!(tubes.len(), 1);
    }

    #[test]
    fn a_tube_keeps_both_rims_in_their_direction_and_closes() {
        let a = [0, 1, 2];
        let b = [10, 11, 12, 13];
        let tris =
            tube(&a, &b, |_, _| true, |t: [i32; 3]| (t[0] % 10 - t[2] % 10).abs() as f64, |_| true).unwrap();
        assert_eq!(tris.len(), 7);
        let mut directed = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for rim in [&a[..], &b[..]] {
            for k in 0..rim.len() {
                assert_eq!(directed.get(&(rim[k], rim[(k + 1) % rim.len()])), Some(&1));
            }
        }
        // Every other edge is used once each way: the band is a manifold annulus.
        for (&(p, q), &n) in &directed {
            let on_rim =
                [&a[..], &b[..]].iter().any(|r| (0..r.len()).any(|k| (r[k], r[(k + 1) % r.len()]) == (p, q)));
            if !on_rim {
                assert_eq!((n, directed.get(&(q, p))), (1, Some(&1)), "{p}->{q}");
            }
        }
    }
}

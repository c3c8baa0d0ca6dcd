//! The slivers left after the collapses. EMC's feature fans leave thin triangles at vertices that
//! never move (corners, line vertices), a quadric order leaves thin strips on gently curved parts,
//! and the collapse guard only keeps new triangles from being worse than the ones they replace.
//! Where an edge of a sliver can be collapsed into something better it is; then the edge of a
//! sliver across a nearly flat pair of faces is flipped, which changes no vertex, so the creases
//! stay. Both pass the collapse's crossing and distance checks, the latter under the bound or,
//! without one, the largest distance the collapses left: angles are not bought with distance.

use super::{key, min_angle, Kind, State};
use glam::DVec3;

/// Below this smallest angle a triangle is a sliver worth flipping (the "bad triangles" of the
/// demo and the goal).
const SLIVER_DEG: f64 = 10.0;
/// Only pairs of faces this close to coplanar are flipped: across a sharper bend a flip cuts off
/// a ridge or fills a valley that the distance check may not see between its samples (20° left
/// the fandisk's needles whose long edge bends 20.0–20.2°).
const FLAT_DEG: f64 = 30.0;
/// Sweeps over the slivers: a flip can make its neighbour flippable.
const SWEEPS: usize = 4;

impl State<'_> {
    /// Collapses an edge of each sliver where that leaves every new angle above the sliver's
    /// and passes the collapse's checks: the thin triangles a quadric order leaves on gently
    /// curved strips, which no flip mends (two of them make a thin rectangle, and either diagonal
    /// is as thin). How many went.
    pub(super) fn collapse_slivers(&mut self) -> usize {
        self.sweep_slivers(|state, f, angle| state.collapse_sliver(f, angle))
    }

    /// Calls `mend` with every live face whose smallest angle is under [`SLIVER_DEG`] (and that
    /// angle), sweeping again while one was mended, at most [`SWEEPS`] times; how many were.
    fn sweep_slivers(&mut self, mut mend: impl FnMut(&mut Self, u32, f64) -> bool) -> usize {
        let sliver = SLIVER_DEG.to_radians();
        let mut count = 0;
        for _ in 0..SWEEPS {
            let before = count;
            for f in 0..self.tris.len() as u32 {
                if self.alive[f as usize] {
                    let angle = min_angle(&self.corners(f));
                    if angle < sliver && mend(self, f, angle) {
                        count += 1;
                    }
                }
            }
            if count == before {
                break;
            }
        }
        count
    }

    /// Collapses one edge of sliver `f`, shortest first, either way round, with every new angle
    /// over the sliver's smallest, `angle`.
    fn collapse_sliver(&mut self, f: u32, angle: f64) -> bool {
        let t = self.tris[f as usize];
        let length = |e: &[u32; 2]| (self.pos[e[0] as usize] - self.pos[e[1] as usize]).length();
        let mut edges: Vec<[u32; 2]> = (0..3).map(|i| [t[i], t[(i + 1) % 3]]).collect();
        edges.sort_by(|a, b| length(a).total_cmp(&length(b)));
        let angle_above = angle * (1.0 + 1e-4);
        let mut done = false;
        'edges: for [a, b] in edges {
            for (u, v) in [(a, b), (b, a)] {
                let movable = match self.kind[u as usize] {
                    Kind::Free => true,
                    Kind::Line => self.lines.contains_key(&key(u, v)),
                    Kind::Fixed => false,
                };
                if !movable {
                    continue;
                }
                let (pu, pv) = (self.pos[u as usize], self.pos[v as usize]);
                let mut placements = vec![pv];
                if self.kind[u as usize] == Kind::Free && self.kind[v as usize] == Kind::Free {
                    placements.push(0.5 * (pu + pv));
                }
                if let Some(plan) = self.check(u, v, &placements, angle_above) {
                    self.apply(u, v, plan);
                    done = true;
                    break 'edges;
                }
            }
        }
        done
    }

    /// Moves a free vertex of each sliver towards its neighbours' centre (all the way, then half)
    /// where every face around it ends up with a larger smallest angle than the fan's before, and
    /// the move passes the collapse's checks: the slivers whose edges cannot collapse (a free
    /// vertex between fixed ones, next to a crease) and whose pair is not flat enough to flip.
    /// How many moved.
    pub(super) fn relax_slivers(&mut self) -> usize {
        self.sweep_slivers(|state, f, _| {
            let free: Vec<u32> = state.tris[f as usize]
                .into_iter()
                .filter(|&v| state.kind[v as usize] == Kind::Free)
                .collect();
            free.into_iter().any(|v| {
                let floor = state.fan_min_angle(v) * (1.0 + 1e-4);
                state.move_toward_centre(v, floor, 1.0) || state.move_toward_centre(v, floor, 0.5)
            })
        })
    }

    /// Splits, at its midpoint, the longest edge of each sliver that is not a feature edge: a
    /// free vertex where there was none. Slivers whose corners all lie on feature lines (a flat
    /// face between a curved crease, densely sampled, and a straight one, thinned out to its
    /// ends) can be mended neither by a collapse nor by moving a corner, and a flip of such a
    /// face only trades one thin triangle for another: the face needs a vertex of its own, a
    /// Steiner point, which the passes after this one move, collapse and flip into place. The
    /// split moves nothing (the new vertex lies on the edge, its four faces on the old two), so
    /// it needs no check but the error bound's, whose samples move. No split takes the count of
    /// faces over `room`. How many edges were split.
    pub(super) fn split_slivers(&mut self, room: usize) -> usize {
        let sliver = SLIVER_DEG.to_radians();
        let mut count = 0;
        for f in 0..self.tris.len() as u32 {
            if self.alive_count + 2 > room {
                break;
            }
            if !self.alive[f as usize] || min_angle(&self.corners(f)) >= sliver {
                continue;
            }
            let t = self.tris[f as usize];
            let length = |i: usize| (self.pos[t[i] as usize] - self.pos[t[(i + 1) % 3] as usize]).length();
            let longest = (0..3)
                .filter(|&i| !self.lines.contains_key(&key(t[i], t[(i + 1) % 3])))
                .max_by(|&i, &j| length(i).total_cmp(&length(j)));
            if let Some(i) = longest {
                count += self.split_edge(f, t[i], t[(i + 1) % 3]) as usize;
            }
        }
        count
    }

    /// Splits the edge `a → b` of face `f1 = (a, b, c)` and its neighbour `f2 = (b, a, d)` at
    /// the edge's midpoint `m`: `(a, m, c)`, `(m, b, c)`, `(b, m, d)`, `(m, a, d)`, wound as
    /// before. Whether the edge had that neighbour and kept to the error bound (and was split).
    pub(super) fn split_edge(&mut self, f1: u32, a: u32, b: u32) -> bool {
        // Exactly one other face on the edge, wound the other way along it: not an open or a
        // non-manifold edge, where four new faces would not cover what was there.
        let on_edge: Vec<u32> = self.faces_of[a as usize]
            .iter()
            .copied()
            .filter(|&g| self.tris[g as usize].contains(&b))
            .collect();
        let (t1, f2) = match on_edge[..] {
            [x, y] if x == f1 || y == f1 => (self.tris[f1 as usize], if x == f1 { y } else { x }),
            _ => return false,
        };
        let t2 = self.tris[f2 as usize];
        let runs = |t: [u32; 3], from: u32, to: u32| (0..3).any(|i| t[i] == from && t[(i + 1) % 3] == to);
        if !runs(t1, a, b) || !runs(t2, b, a) {
            return false;
        }
        let m = self.pos.len() as u32;
        let midpoint = 0.5 * (self.pos[a as usize] + self.pos[b as usize]);
        // The surface stays, but the points where its distance is measured move: none of them
        // may leave the bound (or, where the old faces were already outside it, get farther).
        let corners =
            |t: [u32; 3], from: u32| t.map(|v| if v == from { midpoint } else { self.pos[v as usize] });
        let new = [corners(t1, b), corners(t1, a), corners(t2, a), corners(t2, b)];
        let old = [self.corners(f1), self.corners(f2)];
        if !self.within_error(midpoint, &new) && self.face_distance(&new) > self.face_distance(&old) {
            return false;
        }
        self.pos.push(midpoint);
        self.kind.push(Kind::Free);
        self.moved.push(true);
        self.quadric.push(Default::default());
        self.area.push(0.0);
        self.stamp.push(0);
        self.line_neighbours.push(Vec::new());
        let replace = |t: [u32; 3], from: u32| t.map(|v| if v == from { m } else { v });
        let (f3, f4) = (self.tris.len() as u32, self.tris.len() as u32 + 1);
        self.tris[f1 as usize] = replace(t1, b);
        self.tris[f2 as usize] = replace(t2, a);
        self.tris.push(replace(t1, a));
        self.tris.push(replace(t2, b));
        self.alive.extend([true, true]);
        self.alive_count += 2;
        let third = |t: [u32; 3]| t.into_iter().find(|&v| v != a && v != b).unwrap_or(a);
        let (c, d) = (third(t1), third(t2));
        self.faces_of[a as usize].retain(|&g| g != f2);
        self.faces_of[a as usize].push(f4);
        self.faces_of[b as usize].retain(|&g| g != f1);
        self.faces_of[b as usize].push(f3);
        self.faces_of[c as usize].push(f3);
        self.faces_of[d as usize].push(f4);
        self.faces_of.push(vec![f1, f2, f3, f4]);
        for f in [f1, f2, f3, f4] {
            self.insert_face(f);
        }
        true
    }

    /// Flips the non-feature edges of slivers where that raises the pair's smallest angle.
    pub(super) fn improve_angles(&mut self) {
        self.sweep_slivers(|state, f, _| {
            let t = state.tris[f as usize];
            (0..3).any(|i| state.try_flip(f, t[i], t[(i + 1) % 3]))
        });
    }

    /// Flips edge `a → b` of face `f1 = (a, b, c)` with its neighbour `f2 = (b, a, d)` into
    /// `(a, d, c)` and `(d, b, c)`, if that is allowed and better.
    fn try_flip(&mut self, f1: u32, a: u32, b: u32) -> bool {
        if self.lines.contains_key(&key(a, b)) {
            return false;
        }
        let Some(&f2) =
            self.faces_of[a as usize].iter().find(|&&g| g != f1 && self.tris[g as usize].contains(&b))
        else {
            return false;
        };
        let third = |f: u32| self.tris[f as usize].into_iter().find(|&w| w != a && w != b);
        let (Some(c), Some(d)) = (third(f1), third(f2)) else { return false };
        if c == d || self.faces_of[c as usize].iter().any(|&g| self.tris[g as usize].contains(&d)) {
            return false;
        }
        let p = |w: u32| self.pos[w as usize];
        let old = [self.corners(f1), self.corners(f2)];
        let new = [[p(a), p(d), p(c)], [p(d), p(b), p(c)]];
        let normal = |c: &[DVec3; 3]| (c[1] - c[0]).cross(c[2] - c[0]).try_normalize();
        let (Some(n1), Some(n2)) = (normal(&old[0]), normal(&old[1])) else { return false };
        let flat = FLAT_DEG.to_radians().cos();
        let Some(mean) = (n1 + n2).try_normalize() else { return false };
        if n1.dot(n2) < flat || new.iter().any(|c| normal(c).is_none_or(|n| n.dot(mean) < flat)) {
            return false;
        }
        let worst = |cs: &[[DVec3; 3]; 2]| min_angle(&cs[0]).min(min_angle(&cs[1]));
        if worst(&new) <= worst(&old) {
            return false;
        }
        let changed = [(f1, [a, d, c]), (f2, [d, b, c])];
        // A flip moves no vertex: it may not leave the bound, or where the old pair was already
        // outside it (a sliver along a curved crease), not get farther.
        let allowed = self.within_error(p(c), &new) || self.face_distance(&new) <= self.face_distance(&old);
        if !allowed || self.crosses(&changed, &new, &[]) {
            return false;
        }
        self.tris[f1 as usize] = changed[0].1;
        self.tris[f2 as usize] = changed[1].1;
        self.faces_of[a as usize].retain(|&g| g != f2);
        self.faces_of[b as usize].retain(|&g| g != f1);
        self.faces_of[c as usize].push(f2);
        self.faces_of[d as usize].push(f1);
        self.insert_face(f1);
        self.insert_face(f2);
        true
    }
}

//! Redoing the previous [`super::improve`] run's changes on a mesh contoured again.
//!
//! **Why.** Each untangling round moves the vertices of a few leaves and contours the whole
//! octree again; away from those leaves the new contour is the old one, vertex for vertex (root
//! finding is cached by the dual edge's ends), so searching the best change for every bad triangle
//! again repeats the previous run's work: on the gear at depth 7 two extra rounds each cost as much
//! as the first.
//!
//! **Why a change redone is one the search could have made.** Mesh vertices are known by their
//! positions (bit for bit; a position held by two vertices in either mesh is known by neither). A
//! vertex is *clean* while the triangles around it are the ones around it in the previous run at
//! the same point of its changes: at the start, when its fan is the same set of triangles; after
//! each change redone, because both runs made the same change; a change not redone makes every
//! vertex of its triangles unclean, since the previous run changed their fans and this one did
//! not. A change is redone only when every vertex of its triangles is clean. What its checks read
//! is then the same as when it was made: its triangles (their shape, their distance from the
//! surface) and the fans of their vertices (the link condition and the neighbour counts of a
//! collapse, the missing edge of a flip). The one check that reads farther, crossings with the
//! triangles nearby, is made again where one of those is not clean (a triangle of clean vertices
//! is one the previous run had at that point, and its check passed against all of them); a change
//! that would now cross is not redone. Where the triangles that are not clean lie is kept as the
//! cubes their boxes touch, so that most changes are redone without a search for their neighbours.

use super::{Change, Work};
use glam::{DVec3, Vec3};
use rustc_hash::{FxHashMap, FxHashSet};

/// One change as made: per face, its triangle before and after (`None` where it went), in the
/// run's vertex ids.
pub(super) type Logged = Vec<([u32; 3], Option<[u32; 3]>)>;

/// What one run of [`super::improve`] started from and did, in the order it did it.
#[derive(Debug, Clone, Default)]
pub struct History {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// The changes, and whether each was a flip.
    changes: Vec<(Logged, bool)>,
}

impl History {
    pub(super) fn new(positions: &[Vec3], triangles: &[[u32; 3]], changes: Vec<(Logged, bool)>) -> History {
        History { positions: positions.to_vec(), triangles: triangles.to_vec(), changes }
    }
}

const NONE: u32 = u32::MAX;

/// Per position (bit for bit), the vertex there, or [`NONE`] where two vertices share it.
fn ids_by_position(positions: &[Vec3]) -> FxHashMap<[u32; 3], u32> {
    let mut ids = FxHashMap::default();
    ids.reserve(positions.len());
    for (v, p) in positions.iter().enumerate() {
        ids.entry(p.to_array().map(f32::to_bits)).and_modify(|id| *id = NONE).or_insert(v as u32);
    }
    ids
}

/// A triangle turned to start at its smallest vertex: equal for the same triangle the same way
/// round.
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let r = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
    [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
}

/// Cubes of side `cube` that the bounding box of a triangle with a vertex not clean touches.
struct Unclean {
    cube: f64,
    cubes: FxHashSet<[i64; 3]>,
}

impl Unclean {
    /// The cubes a triangle's box touches, grown by a hundredth of a cube (more than the
    /// margin of [`crate::mesh::buckets::TriangleBuckets::query`]).
    fn cubes_of(cube: f64, corners: &super::Corners, mut f: impl FnMut([i64; 3])) {
        let (lo, hi) = crate::mesh::buckets::bounds(corners);
        let margin = DVec3::splat(cube * 1e-2);
        let at = |p: DVec3| (p / cube).floor().to_array().map(|x| x as i64);
        let (a, b) = (at(lo - margin), at(hi + margin));
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    f([x, y, z]);
                }
            }
        }
    }

    fn add(&mut self, corners: &super::Corners) {
        Unclean::cubes_of(self.cube, corners, |c| {
            self.cubes.insert(c);
        });
    }

    /// Whether a new triangle of `change` touches a cube where a triangle not clean may lie.
    fn near(&self, work: &Work, change: &Change) -> bool {
        change.iter().any(|&(f, t)| {
            let Some(t) = t.filter(|&t| t != work.triangles[f as usize]) else { return false };
            let mut near = false;
            Unclean::cubes_of(self.cube, &work.corners(t), |c| near |= self.cubes.contains(&c));
            near
        })
    }
}

/// Redoes `history`'s changes on `work` (fresh, no change made yet) where they are known to be
/// the same (see the module docs), appending them to `work`'s log; how many were redone. `cube`
/// is the side of the cubes in which [`Work::clear`] looks for triangles nearby.
pub(super) fn replay(work: &mut Work, history: &History, cube: f64) -> usize {
    if history.changes.is_empty() {
        return 0;
    }
    let new_ids = ids_by_position(work.positions);
    let old_ids = ids_by_position(&history.positions);
    let to_new: Vec<u32> = history
        .positions
        .iter()
        .map(|p| {
            let key = p.to_array().map(f32::to_bits);
            match (old_ids.get(&key), new_ids.get(&key)) {
                (Some(&old), Some(&new)) if old != NONE => new,
                _ => NONE,
            }
        })
        .collect();
    let map = |t: [u32; 3]| -> Option<[u32; 3]> {
        let m = t.map(|v| to_new[v as usize]);
        (!m.contains(&NONE)).then_some(m)
    };

    // Clean at the start: the same fan, triangle for triangle (as multisets).
    let mut old_fans: Vec<Vec<u32>> = vec![Vec::new(); history.positions.len()];
    for (f, t) in history.triangles.iter().enumerate() {
        for &v in t {
            old_fans[v as usize].push(f as u32);
        }
    }
    let mut clean = vec![false; work.positions.len()];
    let (mut was, mut is) = (Vec::new(), Vec::new());
    for (old, fan) in old_fans.iter().enumerate() {
        let new = to_new[old];
        if new == NONE || work.faces_of[new as usize].len() != fan.len() {
            continue;
        }
        was.clear();
        was.extend(fan.iter().map_while(|&f| map(history.triangles[f as usize]).map(canonical)));
        if was.len() != fan.len() {
            continue;
        }
        is.clear();
        is.extend(work.faces_of[new as usize].iter().map(|&g| canonical(work.triangles[g as usize])));
        was.sort_unstable();
        is.sort_unstable();
        clean[new as usize] = was == is;
    }

    let mut unclean = Unclean { cube, cubes: FxHashSet::default() };
    for f in 0..work.triangles.len() {
        let t = work.triangles[f];
        if t.iter().any(|&v| !clean[v as usize]) {
            unclean.add(&work.corners(t));
        }
    }

    let mut redone = 0;
    let mut change: Change = Vec::new();
    for (logged, flip) in &history.changes {
        change.clear();
        if translate(work, logged, &to_new, &clean, &mut change).is_some()
            && (!unclean.near(work, &change) || work.clear(&change))
        {
            work.apply(&change, *flip);
            redone += 1;
            continue;
        }
        // Not redone: the previous run changed these vertices' fans and this one did not.
        for &(before, after) in logged {
            for v in before.iter().chain(after.iter().flatten()) {
                let new = to_new[*v as usize];
                if new != NONE && std::mem::take(&mut clean[new as usize]) {
                    for i in 0..work.faces_of[new as usize].len() {
                        let f = work.faces_of[new as usize][i];
                        unclean.add(&work.corners(work.triangles[f as usize]));
                    }
                }
            }
        }
    }
    redone
}

/// `logged` as a change of `work`'s faces, if every vertex of its triangles is clean and each of
/// its triangles is here, once.
fn translate(
    work: &Work,
    logged: &Logged,
    to_new: &[u32],
    clean: &[bool],
    change: &mut Change,
) -> Option<()> {
    let map = |t: [u32; 3]| {
        let m = t.map(|v| to_new[v as usize]);
        m.iter().all(|&v| v != NONE && clean[v as usize]).then_some(m)
    };
    for &(before, after) in logged {
        let here = map(before)?;
        let wanted = canonical(here);
        let mut faces = work.faces_of[here[0] as usize]
            .iter()
            .filter(|&&g| canonical(work.triangles[g as usize]) == wanted);
        let (Some(&f), None) = (faces.next(), faces.next()) else { return None };
        let after = match after {
            // A triangle kept as it was stays as it is here (it may start at another corner).
            Some(t) if t == before => Some(work.triangles[f as usize]),
            Some(t) => Some(map(t)?),
            None => None,
        };
        change.push((f, after));
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::super::{improve, History, Improved};
    use crate::dmc::contour::Contour;
    use crate::mc::{self, McOptions};
    use crate::mesh::analysis;
    use crate::{Field, Grid};

    /// Marching Cubes' mesh of a scene with creases at 32 cells (slivers and spikes along every
    /// crease), as a contour to improve, with its field and finest cell.
    fn contour_of(name: &str) -> (Contour, Box<dyn Field>, f32) {
        let scene = crate::scenes::scene(name).unwrap();
        let grid = Grid::with_resolution(scene.min, scene.max, 32).unwrap();
        let (mesh, _) = mc::mesh_field(scene.field.as_ref(), &grid, &McOptions::default()).unwrap();
        let cells = vec![0; mesh.triangles.len()];
        let contour = Contour { mesh, crossings: Vec::new(), cell_of_triangle: cells };
        let h = grid.spacing.max_element();
        (contour, scene.field, h)
    }

    fn improved(contour: &Contour, field: &dyn Field, h: f32, history: &mut History) -> (Contour, Improved) {
        let mut out = contour.clone();
        let stats = improve(&mut out, field, 0.0, 0.1 * h, h, history);
        (out, stats)
    }

    #[test]
    fn an_unchanged_mesh_is_improved_to_the_same_mesh_by_redoing_every_change() {
        for name in ["rotated_box", "fandisk"] {
            let (contour, field, h) = contour_of(name);
            let mut history = History::default();
            let (first, done) = improved(&contour, field.as_ref(), h, &mut history);
            assert!(done.collapses + done.flips > 10, "{name}: {done:?}");
            assert_eq!(done.replayed, 0);
            let (again, redone) = improved(&contour, field.as_ref(), h, &mut history);
            assert_eq!(redone.replayed, done.collapses + done.flips, "{name}");
            assert_eq!(
                (redone.collapses, redone.flips, redone.left),
                (done.collapses, done.flips, done.left)
            );
            assert_eq!(again.mesh.triangles, first.mesh.triangles, "{name}");
        }
    }

    #[test]
    fn a_mesh_changed_in_one_place_is_improved_as_cleanly_redoing_the_changes_elsewhere() {
        for name in ["rotated_box", "fandisk"] {
            let (contour, field, h) = contour_of(name);
            let mut history = History::default();
            let (_, done) = improved(&contour, field.as_ref(), h, &mut history);
            // Vertices in a ball around one of them move by a thousandth of a cell (every one of
            // them is then new to the history), as those of an untangled leaf do.
            let mut changed = contour.clone();
            let centre = changed.mesh.positions[changed.mesh.positions.len() / 3];
            for p in &mut changed.mesh.positions {
                if p.distance(centre) < 3.0 * h {
                    *p += glam::Vec3::splat(1e-3 * h);
                }
            }
            let (fresh, from_scratch) = improved(&changed, field.as_ref(), h, &mut History::default());
            let (redone, stats) = improved(&changed, field.as_ref(), h, &mut history);
            assert!(stats.replayed > 0 && stats.replayed < done.collapses + done.flips, "{name}: {stats:?}");
            let before = analysis::topology(&changed.mesh);
            for (mesh, how) in [(&redone.mesh, "redone"), (&fresh.mesh, "from scratch")] {
                let after = analysis::topology(mesh);
                assert!(after.is_closed_manifold(), "{name} {how}");
                assert_eq!(
                    (after.euler, after.components),
                    (before.euler, before.components),
                    "{name} {how}"
                );
                assert!(analysis::self_intersecting_pairs(mesh).is_empty(), "{name} {how}");
                assert!(analysis::folded_pairs(mesh).is_empty(), "{name} {how}");
            }
            // As good as improving from scratch, give or take the order the changes were made in.
            assert!(
                stats.left <= from_scratch.left + from_scratch.left / 10 + 2,
                "{name}: {stats:?} {from_scratch:?}"
            );
        }
    }
}

//! The edge-flipping pass of EMC (§4.3): after the fans are in, flip every edge whose two opposite
//! vertices are feature points, so feature lines become explicit chains of mesh edges.
//!
//! A flip is a decision about a mesh that does not cross itself, and must keep it so: its two new
//! triangles reach from one fan centre across a cell face to the next, over triangles of both
//! cells and (where a centre sits outside its cell, or a neighbour's fan reaches in) of cells
//! around them, none of which the fans' own construction knew of. So a flip is made only when
//! neither new triangle crosses any triangle near it as the mesh stands (see
//! [`super::nearby`]); each accepted flip then leaves every pair it did not touch as it was.
//!
//! Flips are decided in slabs on the threads. A candidate looks only at triangles whose boxes
//! meet its own quad's box (the crossing test, the fold test's neighbours, the edge it would
//! make) and changes only triangles inside that box, so two candidates whose boxes are apart
//! cannot see each other's flips. Slabs thicker than any candidate's box, taken in two phases
//! (every other slab, then the rest), keep every slab of a phase apart from the others: the
//! order within a phase does not matter, and the mesh is the same on any number of threads.
//! (On every scene we mesh it is also the mesh of one pass in vertex order, where the first flip
//! decided was known to be the first: flips in different slabs did not meet there either.) On
//! the gear at 256 cells the decisions took 130 ms on one thread and 70 on two.

use super::nearby::NearbyTriangles;
use crate::mesh::analysis::bvh::Aabb;
use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use crate::mesh::analysis::tri_tri::folded_within;
use crate::mesh::Mesh;
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// How close (degrees) the half-planes of two triangles across an edge may come before a flip
/// that makes them counts as folding them onto each other. A crease EMC joins opens wider than
/// this; a pair nearer is a fold (on the gear at 64 cells, two triangles in its top face, which
/// lies in a grid plane, came 1.5° apart and a later merge made them cross).
const FLIP_FOLD_DEG: f64 = 10.0;

/// One pass over all edges; returns how many were flipped. `is_feature` marks the fan centres,
/// `on_feature` those of them that lie on their feature: a flip must join two centres, at least
/// one of them on its feature (two approximate centres side by side make no feature line, and on
/// the gyroid at 72 cells such flips cut the triangles of a second sheet in the same cells).
/// A flip is also refused when the new edge
/// already exists (it would make the mesh non-manifold), when a new triangle would be degenerate, or
/// when a new triangle would face against the vertex normal (`mesh.normals`, from the field) of its
/// non-feature vertex (a fold-over), and when a new triangle would cross a triangle near it
/// (`spacing`: the grid's cell, the size of the neighbourhoods searched). Candidates are decided
/// in slabs in two phases (see the module docs), each slab's in the order of their vertex ids, so
/// the same mesh always gets the same flips, on any number of threads.
pub fn flip_toward_features(
    mesh: &mut Mesh,
    is_feature: &[bool],
    on_feature: &[bool],
    spacing: Vec3,
) -> usize {
    // Directed edge (from, to) → the triangle that has it. Closed manifold meshes have each edge
    // once in each direction.
    // Only triangles at a feature point can take part in a flip (both triangles of a flipped edge
    // have one), which keeps this map small: feature cells are few.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::default();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if !tri.iter().any(|&v| is_feature[v as usize]) {
            continue;
        }
        for k in 0..3 {
            directed.insert((tri[k], tri[(k + 1) % 3]), t as u32);
        }
    }
    let mut edges: Vec<(u32, u32)> = directed.keys().copied().filter(|&(a, b)| a < b).collect();
    edges.sort_unstable();
    // Each candidate edge (a, b) with its two triangles and their far corners (c, d): an edge
    // between two crossings, between two fan centres, one of them on its feature. Only edges
    // between two crossing vertices are flipped: turning an edge that already ends at a feature
    // point would join that point's two neighbours on the feature line past it. A flip only makes
    // triangles with a fan centre and no edge between two crossings, so it never changes another
    // candidate's triangles: these are the candidates throughout, and their quads hold every
    // triangle a flip can make.
    let candidates: Vec<Candidate> = edges
        .into_iter()
        .filter_map(|(a, b)| {
            let (&t1, &t2) = (directed.get(&(a, b))?, directed.get(&(b, a))?);
            let c = opposite(mesh.triangles[t1 as usize], a, b);
            let d = opposite(mesh.triangles[t2 as usize], b, a);
            let joins_centres = c != d && is_feature[c as usize] && is_feature[d as usize];
            let flippable = joins_centres
                && (on_feature[c as usize] || on_feature[d as usize])
                && !is_feature[a as usize]
                && !is_feature[b as usize];
            flippable.then_some(Candidate { a, b, t1, t2, c, d })
        })
        .collect();
    if candidates.is_empty() {
        return 0;
    }
    let region: Vec<Aabb> = candidates
        .iter()
        .map(|q| Aabb::of_points(&[q.a, q.b, q.c, q.d].map(|v| mesh.positions[v as usize])))
        .collect();
    let mut nearby = NearbyTriangles::around(mesh, spacing, &region);
    let slabs = slabs(&region, spacing.max_element());
    let mut flips = 0;
    for phase in [0, 1] {
        let in_phase: Vec<&Vec<usize>> = slabs.iter().skip(phase).step_by(2).collect();
        let decided = crate::par::map(in_phase.len(), |s| {
            let mut view = SlabView::new(mesh, &directed, &nearby, spacing.max_element());
            in_phase[s].iter().filter_map(|&q| view.try_flip(&candidates[q])).collect::<Vec<_>>()
        });
        for q in decided.into_iter().flatten() {
            let (tri1, tri2) = q.made();
            mesh.triangles[q.t1 as usize] = tri1;
            mesh.triangles[q.t2 as usize] = tri2;
            for t in [q.t1, q.t2] {
                nearby.insert(t, &mesh.corners(t as usize));
            }
            for (edge, t) in q.edge_changes() {
                match t {
                    Some(t) => directed.insert(edge, t),
                    None => directed.remove(&edge),
                };
            }
            flips += 1;
        }
    }
    flips
}

/// Thinnest slab, in cells: a slab's candidates are decided one after another, so each
/// slab should hold enough of them to be worth a task.
const MIN_SLAB_CELLS: f32 = 4.0;

/// The candidates (indices into `quads`, their boxes) by slab across the axis they spread
/// along most, in their order within each. A slab is thicker than any candidate's box by more
/// than the crossing test's margin, so a candidate's box reaches at most into the next slab and
/// never meets the box of a candidate two slabs away.
fn slabs(quads: &[Aabb], cell: f32) -> Vec<Vec<usize>> {
    let all = quads.iter().fold(Aabb::EMPTY, |u, &b| u.union(b));
    let axis = (all.max - all.min).max_position();
    let reach = quads.iter().fold(0.0f32, |r, b| r.max(b.max[axis] - b.min[axis]));
    let thickness = (reach + 0.01 * cell).max(MIN_SLAB_CELLS * cell);
    let slab_of = |b: &Aabb| ((b.min[axis] - all.min[axis]) / thickness).floor();
    let last = quads.iter().fold(0.0f32, |s, b| s.max(slab_of(b)));
    if !last.is_finite() || !thickness.is_finite() || thickness <= 0.0 {
        return vec![(0..quads.len()).collect()];
    }
    let mut slabs = vec![Vec::new(); last as usize + 1];
    for (q, b) in quads.iter().enumerate() {
        slabs[slab_of(b) as usize].push(q);
    }
    slabs
}

/// The mesh as one slab's candidates see it while a phase is decided: the mesh and its
/// crossing-test buckets as the phase found them, shared with the other slabs of the phase (none
/// of which can touch a triangle this slab looks at), and this slab's own flips on top.
struct SlabView<'a> {
    mesh: &'a Mesh,
    directed: &'a HashMap<(u32, u32), u32>,
    nearby: &'a NearbyTriangles,
    /// Triangles this slab has flipped, as they are now.
    flipped: HashMap<u32, [u32; 3]>,
    /// The flipped triangles by the cubes of a cell their boxes (grown by `margin`) reach into.
    flipped_near: HashMap<[i32; 3], Vec<u32>>,
    cell: f32,
    /// Directed edges this slab's flips made (`Some`: the triangle holding it) or took away.
    edges: HashMap<(u32, u32), Option<u32>>,
    /// How far apart two boxes may be and still count as touching (the buckets' margin).
    margin: f32,
}

impl<'a> SlabView<'a> {
    fn new(
        mesh: &'a Mesh,
        directed: &'a HashMap<(u32, u32), u32>,
        nearby: &'a NearbyTriangles,
        cell: f32,
    ) -> Self {
        let (flipped, flipped_near, edges) = (HashMap::default(), HashMap::default(), HashMap::default());
        SlabView { mesh, directed, nearby, flipped, flipped_near, cell, edges, margin: 1e-3 * cell }
    }

    fn triangle(&self, t: u32) -> [u32; 3] {
        self.flipped.get(&t).copied().unwrap_or(self.mesh.triangles[t as usize])
    }

    fn edge(&self, edge: (u32, u32)) -> Option<u32> {
        match self.edges.get(&edge) {
            Some(&t) => t,
            None => self.directed.get(&edge).copied(),
        }
    }

    fn grown(&self, b: Aabb) -> Aabb {
        Aabb { min: b.min - Vec3::splat(self.margin), max: b.max + Vec3::splat(self.margin) }
    }

    /// The cubes of side `cell` that box `b` reaches into.
    fn cubes(&self, b: Aabb) -> impl Iterator<Item = [i32; 3]> {
        let [lo, hi] = [b.min, b.max].map(|p| (p / self.cell).floor().as_ivec3());
        (lo.z..=hi.z)
            .flat_map(move |z| (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| [x, y, z])))
    }

    /// Whether triangle `ids` crosses any triangle near it other than `skip`.
    fn crosses(&self, ids: [u32; 3], skip: [u32; 2]) -> bool {
        let p = |v: u32| self.mesh.positions[v as usize];
        let corners = ids.map(p);
        let here = Aabb::of_points(&corners);
        let new = (ids, corners.map(|c| c.as_dvec3()));
        let crosses = |t: u32| {
            let tri = self.triangle(t);
            !skip.contains(&t) && indexed_pair_intersects(new, (tri, tri.map(|v| p(v).as_dvec3())))
        };
        // The shared buckets hold a flipped triangle where it was: this slab's flips are tested
        // where they are now.
        self.nearby.near_shared(&corners).into_iter().filter(|t| !self.flipped.contains_key(t)).any(crosses)
            || self.cubes(here).any(|cube| {
                self.flipped_near.get(&cube).into_iter().flatten().any(|&t| {
                    here.overlaps(&self.grown(Aabb::of_points(&self.triangle(t).map(p)))) && crosses(t)
                })
            })
    }

    /// Flips `q` if it passes every test against the mesh as this slab sees it.
    fn try_flip(&mut self, q: &Candidate) -> Option<Candidate> {
        let &Candidate { a, b, t1, t2, c, d } = q;
        if self.edge((c, d)).is_some() || self.edge((d, c)).is_some() {
            return None;
        }
        // Fold-over test against the field, not the old triangles: the two old triangles
        // straddle the crease and their normals are a poor reference. Each new triangle lies on
        // one side of the crease, the side of its one non-feature vertex, and must face the way
        // the field's normal at that vertex does.
        let mesh = self.mesh;
        let p = |v: u32| mesh.positions[v as usize];
        let new1 = normal(p(c), p(a), p(d));
        let new2 = normal(p(d), p(b), p(c));
        if new1 == Vec3::ZERO || new2 == Vec3::ZERO {
            return None;
        }
        if new1.dot(mesh.normals[a as usize]) <= 0.0 || new2.dot(mesh.normals[b as usize]) <= 0.0 {
            return None;
        }
        // Where the non-feature vertices lie on the crease themselves (a rim in a grid plane),
        // their normals are perpendicular to a flat face's triangles and the test above cannot
        // see those turn over: refuse a flip whose new triangles fold onto each other or onto a
        // neighbour.
        let d64 = |v: u32| p(v).as_dvec3();
        let folds_onto_neighbour = |u: u32, v: u32, w: u32| {
            self.edge((v, u)).is_some_and(|n| {
                let x = opposite(self.triangle(n), u, v);
                folded_within(d64(v) - d64(u), d64(w) - d64(u), d64(x) - d64(u), FLIP_FOLD_DEG)
            })
        };
        if folded_within(d64(d) - d64(c), d64(a) - d64(c), d64(b) - d64(c), FLIP_FOLD_DEG)
            || [(c, a, d), (a, d, c), (d, b, c), (b, c, d)]
                .iter()
                .any(|&(u, v, w)| folds_onto_neighbour(u, v, w))
        {
            return None;
        }
        let (tri1, tri2) = q.made();
        if [tri1, tri2].iter().any(|&t| self.crosses(t, [t1, t2])) {
            return None;
        }
        for (t, tri) in [(t1, tri1), (t2, tri2)] {
            self.flipped.insert(t, tri);
            let cubes: Vec<_> = self.cubes(self.grown(Aabb::of_points(&tri.map(p)))).collect();
            for cube in cubes {
                self.flipped_near.entry(cube).or_default().push(t);
            }
        }
        self.edges.extend(q.edge_changes());
        Some(Candidate { ..*q })
    }
}

/// An edge (a, b) between two crossings, its triangles t1 (holding a → b) and t2, and their
/// far corners c and d, both fan centres.
#[derive(Clone, Copy)]
struct Candidate {
    a: u32,
    b: u32,
    t1: u32,
    t2: u32,
    c: u32,
    d: u32,
}

impl Candidate {
    /// The triangles the flip makes in place of t1 and t2.
    fn made(&self) -> ([u32; 3], [u32; 3]) {
        let Candidate { a, b, c, d, .. } = *self;
        ([c, a, d], [d, b, c])
    }

    /// The directed edges the flip changes: each with the triangle that holds it after the
    /// flip, `None` for the two halves of the old edge.
    fn edge_changes(&self) -> [((u32, u32), Option<u32>); 8] {
        let Candidate { a, b, t1, t2, c, d } = *self;
        [
            ((a, b), None),
            ((b, a), None),
            ((c, a), Some(t1)),
            ((a, d), Some(t1)),
            ((d, c), Some(t1)),
            ((d, b), Some(t2)),
            ((b, c), Some(t2)),
            ((c, d), Some(t2)),
        ]
    }
}

fn opposite(tri: [u32; 3], a: u32, b: u32) -> u32 {
    tri.into_iter().find(|&v| v != a && v != b).expect("triangle holds the edge")
}

fn normal(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    (b - a).cross(c - a).normalize_or_zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Boxes of candidates in slabs of one phase never meet (with the crossing test's margin),
    /// every candidate is in one slab, in its order: on random boxes of random reach, spread
    /// along a random axis.
    #[test]
    fn slabs_of_one_phase_are_apart() {
        let mut rng = crate::expr::testutil::Rng::new(5);
        for round in 0..50 {
            let cell = rng.range(0.01, 0.1);
            let reach = cell * rng.range(0.1, 6.0);
            let spread =
                Vec3::new(rng.range(0.0, 1.0), rng.range(0.0, 1.0), rng.range(0.0, 1.0)) * 40.0 * cell;
            let quads: Vec<Aabb> = (0..200 + rng.below(300))
                .map(|_| {
                    let at =
                        spread * Vec3::new(rng.range(0.0, 1.0), rng.range(0.0, 1.0), rng.range(0.0, 1.0));
                    let size = Vec3::new(rng.range(0.0, reach), rng.range(0.0, reach), rng.range(0.0, reach));
                    Aabb { min: at, max: at + size }
                })
                .collect();
            let slabs = slabs(&quads, cell);
            let mut seen: Vec<usize> = slabs.iter().flatten().copied().collect();
            assert!(slabs.iter().all(|s| s.windows(2).all(|w| w[0] < w[1])), "round {round}: order kept");
            seen.sort_unstable();
            assert_eq!(seen, (0..quads.len()).collect::<Vec<_>>(), "round {round}: each once");
            let margin = Vec3::splat(1e-3 * cell);
            for (s, slab) in slabs.iter().enumerate() {
                for other in slabs.iter().skip(s + 2).step_by(2) {
                    for &a in slab {
                        let grown = Aabb { min: quads[a].min - margin, max: quads[a].max + margin };
                        assert!(
                            other.iter().all(|&b| !grown.overlaps(&quads[b])),
                            "round {round}: slabs meet"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn flips_the_diagonal_between_two_feature_points_once() {
        // A square a=0 (0,0) b=1 (1,1) split along a-b; c=2 (1,0) and d=3 (0,1) are feature points.
        let mut mesh = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            triangles: vec![[0, 2, 1], [0, 1, 3]],
        };
        let feature = [false, false, true, true];
        assert_eq!(flip_toward_features(&mut mesh, &feature, &feature, Vec3::ONE), 1);
        let has_cd = mesh.triangles.iter().any(|t| t.contains(&2) && t.contains(&3));
        assert!(has_cd);
        for t in 0..2 {
            assert!(mesh.face_normal(t).z > 0.0, "orientation kept");
        }
        assert_eq!(flip_toward_features(&mut mesh, &feature, &feature, Vec3::ONE), 0, "nothing left to flip");
    }

    #[test]
    fn refuses_a_flip_that_would_face_against_the_field() {
        let mut mesh = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![-Vec3::Z; 4],
            triangles: vec![[0, 2, 1], [0, 1, 3]],
        };
        assert_eq!(
            flip_toward_features(
                &mut mesh,
                &[false, false, true, true],
                &[false, false, true, true],
                Vec3::ONE
            ),
            0
        );
    }
}

//! The topological safety test of a merge: replacing a node's eight leaf children by the node
//! itself, as one leaf with one vertex, must leave the contour's topology as it was.
//!
//! A merge changes only the dual cells that have a child (afterwards: the node) among their eight
//! leaves: the *star* of the merge, the dual cells at the octree vertices in the node's closed box.
//! The star's outer faces are made of other leaves only, so the contour crosses them in the same
//! curves before and after (the case table decides a face from its four signs and, where they are
//! ambiguous, the field at the centre of its four leaves: [`super::faces`]). If the
//! contour inside the star is, before and after, a set of discs each bounded by exactly one of
//! those curves, then the two are homeomorphic relative to the curves, and gluing the unchanged
//! rest of the contour back gives a surface homeomorphic to the one before: same components, same
//! genus, no hole opened or closed. That is what this test checks, combinatorially (Euler
//! characteristic and boundary loops of each component of the star's contour, every edge on at
//! most two triangles); it is sufficient, not necessary, so it may refuse a harmless merge (an
//! annulus kept as an annulus), never accept a harmful one.
//!
//! Applied to every merge in turn, the test makes the simplified contour homeomorphic to the
//! contour of the unsimplified finest level, by induction over the merges. It is our own
//! criterion, with the guarantee of Ju et al. 2002 §4.2 (their tests are on the signs of a primal
//! grid; DMC's signs are at the dual vertices, where theirs do not apply).

use super::dual::{self, dual_cell_by, VertexKey};
use super::tree::{Kind, Octree, NONE};
use crate::field::Field;
use crate::mesh::analysis::topology::UnionFind;
use crate::tables::{triangle_table_with_faces_without_centre, EDGES};
use rustc_hash::FxHashMap as HashMap;

/// A dual edge by its ends (inside end, outside end): the name of the crossing on it.
pub type DualEdge = (VertexKey, VertexKey);

/// The contour a merge would leave in its star: the dual edges its triangles' corners lie on,
/// each once, and the triangles as indices into them.
#[derive(Debug, Clone, Default)]
pub struct Star {
    pub edges: Vec<DualEdge>,
    pub triangles: Vec<[u32; 3]>,
}

/// Buffers one thread's safety tests reuse from merge to merge: a test allocates nothing of its
/// own, and allocation was a fifth of its time (a merge tests a few dozen dual cells).
#[derive(Default)]
pub struct Scratch {
    around: Neighbourhood,
    stack: Vec<u32>,
    marked: Vec<([u32; 3], u8)>,
    marks: Vec<u8>,
    points: Vec<([u32; 3], bool)>,
    cells_before: Vec<[VertexKey; 8]>,
    cells_after: Vec<[VertexKey; 8]>,
    crossings: Crossings,
    tris_before: Vec<[u32; 3]>,
    tris_after: Vec<[u32; 3]>,
    boundary_before: Vec<(u32, u32)>,
    discs: Discs,
    /// Per crossing, its index in the star returned (`u32::MAX`: none yet).
    used: Vec<u32>,
}

/// Whether making internal node `n` (whose children are all leaves) a leaf whose vertex has value
/// `value` keeps the contour's topology; if it does, the contour the star would then hold.
pub fn merge_is_safe(
    tree: &Octree,
    n: u32,
    value: f32,
    field: &dyn Field,
    iso: f32,
    scratch: &mut Scratch,
) -> Option<Star> {
    let Scratch {
        around,
        stack,
        marked,
        marks,
        points,
        cells_before,
        cells_after,
        crossings,
        tris_before,
        tris_after,
        boundary_before,
        discs,
        used,
    } = scratch;
    around.fill(tree, n, stack);
    // The star's points before the merge: the children's corners and the neighbours' corners on
    // the node's closed box. After it, the children's corners that are neither the node's own nor
    // a neighbour's are no octree vertices any more; the others keep their dual cells, with every
    // child among their leaves replaced by the node. So each point's leaves are located once.
    let first = tree.nodes[n as usize].children;
    let children = first..first + 8;
    cells_before.clear();
    cells_after.clear();
    star_points(tree, n, around, marked, marks, points);
    for &(p, kept) in points.iter() {
        let Some(cell) = dual_cell_by(tree, p, |q| around.leaf_at(tree, q)) else { continue };
        cells_before.push(cell);
        if kept {
            cells_after.push(cell.map(|k| {
                if children.contains(&k.node) {
                    VertexKey { node: n, ..k }
                } else {
                    k
                }
            }));
        }
    }
    let sign_before = |k: VertexKey| dual::inside(tree, k);
    let sign_after =
        |k: VertexKey| if k.node == n { k.clamp == 0 && value < 0.0 } else { dual::inside(tree, k) };
    let joined = |cell: &[VertexKey; 8], case: u8| {
        super::faces::joined_faces(case, |k| dual::centre(tree, cell[k]), field, iso)
    };
    crossings.clear();
    star_triangles(cells_before, sign_before, joined, crossings, tris_before);
    star_triangles(cells_after, sign_after, joined, crossings, tris_after);
    if tris_before.is_empty() && tris_after.is_empty() {
        return Some(Star::default());
    }
    boundary_before.clear();
    boundary_before.extend_from_slice(discs.boundary(tris_before, crossings.len())?);
    match discs.boundary(tris_after, crossings.len()) {
        Some(after) if after == &boundary_before[..] => Some(star(tris_after, crossings, used)),
        _ => None,
    }
}

/// The star of `tris` (crossing ids): the crossings they use, in the order of first use.
fn star(tris: &[[u32; 3]], crossings: &Crossings, used: &mut Vec<u32>) -> Star {
    reset(used, crossings.len(), u32::MAX);
    let mut star = Star { edges: Vec::new(), triangles: Vec::with_capacity(tris.len()) };
    for t in tris {
        star.triangles.push(t.map(|v| {
            if used[v as usize] == u32::MAX {
                used[v as usize] = star.edges.len() as u32;
                star.edges.push(crossings.edges[v as usize]);
            }
            used[v as usize]
        }));
    }
    star
}

/// The star's points of a merge of node `n`, each once, in the order of their keys (z, then y,
/// then x: the order that names the crossings), with whether it stays an octree vertex after the
/// merge (a neighbour's corner or the node's own). Marked on the lattice of the node's closed box
/// where that is small, sorted otherwise.
fn star_points(
    tree: &Octree,
    n: u32,
    around: &Neighbourhood,
    marked: &mut Vec<([u32; 3], u8)>,
    marks: &mut Vec<u8>,
    points: &mut Vec<([u32; 3], bool)>,
) {
    const POINT: u8 = 1;
    const KEPT: u8 = 2;
    let (lo, hi) = tree.int_box(n);
    let first = tree.nodes[n as usize].children;
    let children = first..first + 8;
    marked.clear();
    points.clear();
    for &leaf in around.leaves.iter().filter(|l| !children.contains(l)) {
        for p in corners(tree, leaf) {
            if (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a]) {
                marked.push((p, POINT | KEPT));
            }
        }
    }
    for child in children.filter(|&c| tree.nodes[c as usize].kind != Kind::Absent) {
        marked.extend(corners(tree, child).map(|p| (p, POINT)));
    }
    marked.extend(corners(tree, n).map(|p| (p, KEPT)));
    let side: [u32; 3] = std::array::from_fn(|a| hi[a] - lo[a] + 1);
    let lattice = side.iter().map(|&s| s as u64).product::<u64>();
    if lattice <= MAPPED_CELLS as u64 {
        let index =
            |p: [u32; 3]| (((p[2] - lo[2]) * side[1] + p[1] - lo[1]) * side[0] + p[0] - lo[0]) as usize;
        marks.clear();
        marks.resize(lattice as usize, 0);
        for &(p, mark) in marked.iter() {
            marks[index(p)] |= mark;
        }
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let mark = marks[index([x, y, z])];
                    if mark & POINT != 0 {
                        points.push(([x, y, z], mark & KEPT != 0));
                    }
                }
            }
        }
    } else {
        marked.sort_unstable_by_key(|&(p, _)| dual::point_key(p));
        for same in marked.chunk_by(|a, b| a.0 == b.0) {
            let mark = same.iter().fold(0, |m, &(_, k)| m | k);
            if mark & POINT != 0 {
                points.push((same[0].0, mark & KEPT != 0));
            }
        }
    }
}

/// Lattice points (as `[u32; 3]`) of the corners of leaf `n`.
fn corners(tree: &Octree, n: u32) -> [[u32; 3]; 8] {
    let (lo, hi) = tree.int_box(n);
    std::array::from_fn(|c| std::array::from_fn(|a| if (c >> a) & 1 == 1 { hi[a] } else { lo[a] }))
}

/// The leaves around a node: every leaf meeting its box grown by one finest cell (clipped to the
/// grid), from one walk down from the smallest node holding that box. The star's points are the
/// corners of these leaves, and every leaf of the star's dual cells is one of them. Where the grown
/// box is small (merges near the finest level: nearly all of them) each of its finest cells is
/// mapped to its leaf, so nothing is located from the root again; a larger box (near the top of a
/// deep octree, mostly empty leaves) locates through the tree from the walk's start instead.
#[derive(Default)]
struct Neighbourhood {
    lo: [u32; 3],
    dims: [u32; 3],
    /// The node the walk started from: it holds the grown box.
    start: u32,
    /// Per finest cell of the grown box (x fastest), its leaf; empty for a large box.
    leaf: Vec<u32>,
    /// The leaves meeting the grown box, children of the node included.
    leaves: Vec<u32>,
}

/// Grown boxes of at most this many finest cells are mapped cell by cell (a box of 30 cells on
/// a side; the merge of eight finest cells grows to 64).
const MAPPED_CELLS: u32 = 1 << 15;

impl Neighbourhood {
    /// The neighbourhood of node `n`, in place of the one held (`stack`: the walk's, reused).
    fn fill(&mut self, tree: &Octree, n: u32, stack: &mut Vec<u32>) {
        let (lo, hi) = tree.int_box(n);
        let glo = lo.map(|c| c.saturating_sub(1));
        let ghi: [u32; 3] = std::array::from_fn(|a| (hi[a] + 1).min(tree.cells[a]));
        let dims: [u32; 3] = std::array::from_fn(|a| ghi[a] - glo[a]);
        let cells = dims.iter().map(|&d| d as u64).product::<u64>();
        let start = tree.common_ancestor(glo, ghi.map(|c| c - 1), NONE);
        let mapped = cells <= MAPPED_CELLS as u64;
        let around = self;
        around.lo = glo;
        around.dims = dims;
        around.start = start;
        around.leaf.clear();
        if mapped {
            around.leaf.resize(cells as usize, NONE);
        }
        around.leaves.clear();
        stack.clear();
        stack.push(start);
        while let Some(m) = stack.pop() {
            let (mlo, mhi) = tree.int_box(m);
            if (0..3).any(|a| mhi[a] <= glo[a] || mlo[a] >= ghi[a]) {
                continue;
            }
            let node = &tree.nodes[m as usize];
            match node.kind {
                Kind::Absent => {}
                Kind::Internal => stack.extend((0..8).map(|c| node.children + c)),
                _ => {
                    around.leaves.push(m);
                    if !mapped {
                        continue;
                    }
                    let (flo, fhi): ([u32; 3], [u32; 3]) = (
                        std::array::from_fn(|a| mlo[a].max(glo[a])),
                        std::array::from_fn(|a| mhi[a].min(ghi[a])),
                    );
                    for z in flo[2]..fhi[2] {
                        for y in flo[1]..fhi[1] {
                            let row = around.index([flo[0], y, z]);
                            around.leaf[row..row + (fhi[0] - flo[0]) as usize].fill(m);
                        }
                    }
                }
            }
        }
    }

    fn index(&self, q: [u32; 3]) -> usize {
        let [x, y, z] = std::array::from_fn(|a| q[a] - self.lo[a]);
        ((z * self.dims[1] + y) * self.dims[0] + x) as usize
    }

    /// The leaf holding finest cell `q` (inside the grown box).
    fn leaf_at(&self, tree: &Octree, q: [u32; 3]) -> u32 {
        if self.leaf.is_empty() {
            tree.locate_from(self.start, q, NONE)
        } else {
            self.leaf[self.index(q)]
        }
    }
}

/// Mesh vertices of the star's contours, named by their dual edge (inside end, outside end) so that
/// the contours before and after a merge share the names of the crossings they share.
#[derive(Default)]
struct Crossings {
    ids: HashMap<DualEdge, u32>,
    /// Per id, its dual edge.
    edges: Vec<DualEdge>,
}

impl Crossings {
    fn id(&mut self, edge: DualEdge) -> u32 {
        let next = self.edges.len() as u32;
        let id = *self.ids.entry(edge).or_insert(next);
        if id == next {
            self.edges.push(edge);
        }
        id
    }

    fn len(&self) -> usize {
        self.edges.len()
    }

    fn clear(&mut self) {
        self.ids.clear();
        self.edges.clear();
    }
}

/// The contour's triangles in the dual cells `cells`, as crossing ids; triangles that collapse in a
/// degenerate cell are dropped, as [`super::contour`] drops them.
fn star_triangles(
    cells: &[[VertexKey; 8]],
    inside: impl Fn(VertexKey) -> bool,
    joined: impl Fn(&[VertexKey; 8], u8) -> u8,
    crossings: &mut Crossings,
    out: &mut Vec<[u32; 3]>,
) {
    let table = triangle_table_with_faces_without_centre();
    out.clear();
    for cell in cells {
        let signs = cell.map(&inside);
        let case = signs.iter().enumerate().fold(0u8, |c, (i, &s)| c | (s as u8) << i);
        if case == 0 || case == 255 {
            continue;
        }
        for t in table[(case as usize) << 6 | joined(cell, case) as usize].triangles() {
            let v = t.map(|e| {
                let [a, b] = EDGES[e as usize].map(|corner| corner as usize);
                let edge = if signs[a] { (cell[a], cell[b]) } else { (cell[b], cell[a]) };
                crossings.id(edge)
            });
            if v[0] != v[1] && v[1] != v[2] && v[0] != v[2] {
                out.push(v);
            }
        }
    }
}

/// The buffers of [`Discs::boundary`], reused from star to star.
#[derive(Default)]
struct Discs {
    start: Vec<u32>,
    fill: Vec<u32>,
    high: Vec<u32>,
    counted: Vec<((u32, u32), u8)>,
    boundary: Vec<(u32, u32)>,
    pieces: UnionFind,
    loops: UnionFind,
    degree: Vec<u8>,
    /// Per vertex, its piece's root (`u32::MAX`: on no triangle).
    root: Vec<u32>,
    euler2: Vec<i64>,
    loop_of: Vec<u32>,
}

/// `v` cleared and filled with `n` copies of `x`.
fn reset<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    v.clear();
    v.resize(n, x);
}

impl Discs {
    /// The boundary edges (sorted pairs, sorted) of a triangle set that is a disjoint union of
    /// discs, each bounded by one loop; `None` for anything else (a closed piece, an annulus, a
    /// handle, an edge on three triangles, two pieces meeting at a point).
    fn boundary(&mut self, tris: &[[u32; 3]], vertices: usize) -> Option<&[(u32, u32)]> {
        // The edges as sorted pairs, bucketed by their low end (a counting sort: crossing ids are
        // small and dense) and each bucket, a handful, sorted by the high end: distinct edges in
        // order, with their use counts, in linear time. A star is tested for every merge tried,
        // so this is one of DMC's hottest loops.
        let edge = |t: &[u32; 3], i: usize| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            (a.min(b), a.max(b))
        };
        let start = &mut self.start;
        reset(start, vertices + 1, 0);
        for t in tris {
            for i in 0..3 {
                start[edge(t, i).0 as usize + 1] += 1;
            }
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        reset(&mut self.high, tris.len() * 3, 0);
        self.fill.clone_from(start);
        for t in tris {
            for i in 0..3 {
                let (lo, hi) = edge(t, i);
                self.high[self.fill[lo as usize] as usize] = hi;
                self.fill[lo as usize] += 1;
            }
        }
        // Distinct edges with their use counts.
        let counted = &mut self.counted;
        counted.clear();
        for lo in 0..vertices {
            let bucket = &mut self.high[start[lo] as usize..start[lo + 1] as usize];
            bucket.sort_unstable();
            for &hi in bucket.iter() {
                match counted.last_mut() {
                    Some((last, uses)) if *last == (lo as u32, hi) => {
                        *uses += 1;
                        if *uses > 2 {
                            return None;
                        }
                    }
                    _ => counted.push(((lo as u32, hi), 1)),
                }
            }
        }
        // Pieces (joined through shared vertices), each vertex's found once; per piece twice its
        // Euler characteristic, 2V - F - L: a piece's E is (3F + L) / 2 with L boundary edges.
        let pieces = &mut self.pieces;
        pieces.reset(vertices);
        for t in tris {
            pieces.union(t[0], t[1]);
            pieces.union(t[1], t[2]);
        }
        let (root, euler2) = (&mut self.root, &mut self.euler2);
        reset(root, vertices, u32::MAX);
        reset(euler2, vertices, 0);
        for t in tris {
            for &v in t {
                if root[v as usize] == u32::MAX {
                    root[v as usize] = pieces.find(v);
                    euler2[root[v as usize] as usize] += 2;
                }
            }
            euler2[root[t[0] as usize] as usize] -= 1;
        }
        self.boundary.clear();
        self.boundary.extend(counted.iter().filter(|(_, u)| *u == 1).map(|&(e, _)| e));
        let degree = &mut self.degree;
        reset(degree, vertices, 0);
        self.loops.reset(vertices);
        for &(a, b) in &self.boundary {
            degree[a as usize] += 1;
            degree[b as usize] += 1;
            self.loops.union(a, b);
            euler2[root[a as usize] as usize] -= 1;
        }
        // Per piece (by root): the boundary loop seen (u32::MAX: none).
        let loop_of = &mut self.loop_of;
        reset(loop_of, vertices, u32::MAX);
        for v in 0..vertices {
            if root[v] == u32::MAX {
                continue;
            }
            match degree[v] {
                0 => {}
                2 => {
                    let (piece, l) = (root[v] as usize, self.loops.find(v as u32));
                    if loop_of[piece] == u32::MAX {
                        loop_of[piece] = l;
                    } else if loop_of[piece] != l {
                        return None;
                    }
                }
                _ => return None,
            }
        }
        for v in 0..vertices {
            if root[v] == v as u32 && (euler2[v] != 2 || loop_of[v] == u32::MAX) {
                return None;
            }
        }
        Some(&self.boundary)
    }
}

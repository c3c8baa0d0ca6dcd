//! The dual grid (§3): one dual cell per *octree vertex*, a point that is a corner of some leaf,
//! listing the eight leaves around it (octant `c = x | y << 1 | z << 2` relative to the point).
//! Leaves larger than their neighbours appear several times, so adaptive dual cells are degenerate
//! hexahedra; between two consecutive octree vertices along a line the four leaves around the
//! line do not change, so neighbouring dual cells share their faces and the contour is closed.
//!
//! Octree vertices are found from the leaves themselves (each leaf's eight corners) and the leaves
//! around a vertex by point location, rather than by Ju et al.'s cellProc/faceProc/edgeProc
//! recursion: the same definition then serves the whole grid and the few dual cells around one
//! node that [`super::safety`] examines before a merge, and a merge that has not happened yet can
//! be examined by locating with the merged node taken as a leaf.
//!
//! **The boundary.** At a vertex on a face of the grid, the octants beyond it are the leaves
//! inside mirrored onto the face: a [`VertexKey`] with those axes *clamped*, whose vertex is the
//! leaf's projected onto the face and is always outside (the field is clipped to the bounds, see
//! [`super::bounds`]). So the dual grid fills the bounds exactly and the contour is closed
//! wherever a solid reaches them.

use super::tree::{Kind, Octree, NONE};

/// A leaf (`node`) or its copy flattened onto the grid's boundary: for axis `a`, bits `2a..2a+2` of
/// `clamp` are 0 (free), 1 (onto the low face) or 2 (the high face).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexKey {
    pub node: u32,
    pub clamp: u8,
}

impl VertexKey {
    pub fn side(self, axis: usize) -> u8 {
        (self.clamp >> (2 * axis)) & 3
    }
}

/// Packs a lattice point (each coordinate at most 2^16) into one integer.
pub fn point_key(p: [u32; 3]) -> u64 {
    p[0] as u64 | (p[1] as u64) << 21 | (p[2] as u64) << 42
}

/// The dual cell at lattice point `p` (finest cells, inside the grid's closed box), with `merged`
/// seen as a leaf; `None` where `p` is a corner of none of the leaves around it.
pub fn dual_cell(tree: &Octree, p: [u32; 3], merged: u32) -> Option<[VertexKey; 8]> {
    let below = |a: usize| p[a].saturating_sub(1);
    let above = |a: usize| p[a].min(tree.cells[a] - 1);
    let start = tree.common_ancestor([below(0), below(1), below(2)], [above(0), above(1), above(2)], merged);
    dual_cell_by(tree, p, |q| tree.locate_from(start, q, merged))
}

/// [`dual_cell`] with the leaf holding a finest cell given by `leaf_at`: the octants around `p`,
/// those beyond the grid's faces clamped onto them.
pub fn dual_cell_by(
    tree: &Octree,
    p: [u32; 3],
    mut leaf_at: impl FnMut([u32; 3]) -> u32,
) -> Option<[VertexKey; 8]> {
    let mut keys = [VertexKey { node: NONE, clamp: 0 }; 8];
    let mut corner = false;
    for (o, key) in keys.iter_mut().enumerate() {
        let mut q = [0u32; 3];
        let mut clamp = 0u8;
        for a in 0..3 {
            if (o >> a) & 1 == 1 {
                if p[a] < tree.cells[a] {
                    q[a] = p[a];
                } else {
                    q[a] = p[a] - 1;
                    clamp |= 2 << (2 * a);
                }
            } else if p[a] > 0 {
                q[a] = p[a] - 1;
            } else {
                q[a] = 0;
                clamp |= 1 << (2 * a);
            }
        }
        let leaf = leaf_at(q);
        if !corner {
            let (lo, hi) = tree.int_box(leaf);
            corner = (0..3).all(|a| p[a] == lo[a] || p[a] == hi[a]);
        }
        *key = VertexKey { node: leaf, clamp };
    }
    corner.then_some(keys)
}

/// Whether the vertex of `key` is inside (below the iso-level). Boundary copies never are.
pub fn inside(tree: &Octree, key: VertexKey) -> bool {
    if key.clamp != 0 {
        return false;
    }
    let node = &tree.nodes[key.node as usize];
    match node.kind {
        Kind::Empty { inside } => inside,
        _ => node.value < 0.0,
    }
}

/// Where the vertex of `key` lies: its leaf's, projected onto the grid's faces it is clamped to.
pub fn position(tree: &Octree, key: VertexKey) -> glam::Vec3 {
    project(tree, key, tree.nodes[key.node as usize].vertex)
}

/// The centre of `key`'s leaf, projected like [`position`]: where the dual grid's vertex would be
/// if every vertex sat at its leaf's centre, which depends on the octree alone.
pub fn centre(tree: &Octree, key: VertexKey) -> glam::Vec3 {
    let (lo, hi) = tree.world_box(key.node);
    project(tree, key, (lo + hi) * 0.5)
}

/// `p` projected onto the grid's faces `key` is clamped to.
fn project(tree: &Octree, key: VertexKey, mut p: glam::Vec3) -> glam::Vec3 {
    let grid_hi = tree.point(tree.cells);
    for a in 0..3 {
        match key.side(a) {
            1 => p[a] = tree.origin[a],
            2 => p[a] = grid_hi[a],
            _ => {}
        }
    }
    p
}

/// `value` (`f - iso`) held on the side `inside` says it is on: a value rounding put at the level
/// or beyond it becomes the nearest value on that side (the level itself counts as outside).
/// Crossings are root-found between the two sides, so both ends must say which they are on.
pub fn on_side(value: f32, inside: bool) -> f32 {
    if inside {
        value.min(-f32::MIN_POSITIVE)
    } else {
        value.max(0.0)
    }
}

/// The stand-in value of a vertex whose side alone is known (an empty leaf's, proven by its
/// interval bound); its value is evaluated only if a crossing needs it.
pub fn side_only(inside: bool) -> f32 {
    if inside {
        -f32::MIN_POSITIVE
    } else {
        f32::MIN_POSITIVE
    }
}

/// Calls `emit` once per dual cell of the octree whose vertices are not all on one side.
pub fn for_each_mixed_cell(tree: &Octree, mut emit: impl FnMut(&[VertexKey; 8])) {
    let mut seen = rustc_hash::FxHashSet::default();
    for leaf in tree.leaves() {
        let (lo, hi) = tree.int_box(leaf);
        for c in 0..8 {
            let p = std::array::from_fn(|a| if (c >> a) & 1 == 1 { hi[a] } else { lo[a] });
            if !seen.insert(point_key(p)) {
                continue;
            }
            if let Some(cell) = dual_cell(tree, p, NONE) {
                let first = inside(tree, cell[0]);
                if cell.iter().any(|&k| inside(tree, k) != first) {
                    emit(&cell);
                }
            }
        }
    }
}

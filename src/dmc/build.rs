//! The finest level, built once: the *crust* (every finest cell the surface may reach) found top
//! down by interval bounds, then sampled once.
//!
//! **Never missing the surface.** A node is split while its interval bound contains the iso-level,
//! down to the finest level; a node becomes a coarse leaf only when its bound excludes the level,
//! which proves it wholly inside or wholly outside. No sample decides that a cell is empty, so a
//! shell thinner than any sample spacing is still found. A field without bounds makes every finest
//! cell crust (and the work cap applies to all of them).
//!
//! **Sampling.** Each crust cell is sampled on a lattice of `samples_per_cell` points per axis, its
//! corners included, shared with its neighbours, so a cell costs `(samples_per_cell - 1)³` new
//! samples. Each sample adds the tangent plane of the function's graph to its cell's 4-D QEF
//! ([`super::qef`]); a parent's QEF is the sum of its children's, so simplification
//! ([`super::simplify`]) samples nothing more.

use super::bounds::Clipped;
use super::qef::Qef;
use super::tree::{Kind, Octree};
use crate::error::Error;
use crate::field::Field;
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// A vertex is kept this fraction of its leaf's side inside the leaf: a vertex on a face would make
/// the dual cells on both sides degenerate there.
pub const MARGIN: f32 = 1e-3;

#[derive(Debug, Clone, Copy, Default)]
pub struct BuildStats {
    pub crust_cells: usize,
    pub samples: usize,
}

/// Splits the octree down to the crust. Fails when the crust would take more samples than
/// `max_cells` (counted as `samples_per_cell³` per crust cell).
pub fn crust(
    tree: &mut Octree,
    field: &dyn Field,
    iso: f32,
    samples_per_cell: usize,
    max_cells: u64,
) -> Result<BuildStats, Error> {
    let per_cell = (samples_per_cell as u64).pow(3);
    let max_crust = (max_cells / per_cell).max(1);
    let mut stats = BuildStats::default();
    let mut stack = vec![0u32];
    while let Some(n) = stack.pop() {
        let (lo, hi) = tree.world_box(n);
        if let Some((a, b)) = field.interval(lo, hi) {
            if a > iso || b < iso {
                tree.nodes[n as usize].kind = Kind::Empty { inside: b < iso };
                continue;
            }
        }
        if tree.nodes[n as usize].level == tree.depth {
            tree.nodes[n as usize].kind = Kind::Surface;
            stats.crust_cells += 1;
            if stats.crust_cells as u64 > max_crust {
                return Err(Error::InvalidOption(format!(
                    "the surface crosses more than {max_crust} finest cells of {per_cell} samples each, \
                     more work than maxCells allows; lower the maximum depth or raise maxCells"
                )));
            }
            continue;
        }
        let first = tree.split(n);
        for c in (0..8).rev() {
            if tree.nodes[(first + c) as usize].kind != Kind::Absent {
                stack.push(first + c);
            }
        }
    }
    Ok(stats)
}

/// Samples the crust cells, gives each its QEF and its vertex, and puts the vertices of the empty
/// leaves at their centres. Every value is `f - iso`.
pub fn sample(tree: &mut Octree, field: &Clipped, iso: f32, samples_per_cell: usize, stats: &mut BuildStats) {
    let k = (samples_per_cell - 1) as u32;
    let spacing = tree.h / k as f32;
    let leaves = tree.leaves();
    let crust: Vec<u32> =
        leaves.iter().copied().filter(|&n| tree.nodes[n as usize].kind == Kind::Surface).collect();
    let (points, cell_samples) = lattice(tree, &crust, k);
    stats.samples = points.len();
    let (values, gradients) =
        crate::field::values_and_gradients_or_differences(field, &points, spacing * 1e-2);

    let per_cell = samples_per_cell.pow(3);
    // Each crust cell's QEF and its minimiser (an SVD) are its own, so the cells go to the
    // threads and are stored in order: the same vertices on any count.
    let placed = {
        let tree = &*tree;
        crate::par::map(crust.len(), |i| {
            let (lo, hi) = tree.world_box(crust[i]);
            let mut qef = Qef::new((lo + hi) * 0.5);
            for &s in &cell_samples[i * per_cell..(i + 1) * per_cell] {
                let (v, g) = (values[s as usize], gradients[s as usize]);
                if v.is_finite() && g.is_finite() {
                    qef.add(points[s as usize], v - iso, g);
                }
            }
            let placed = place(&qef, lo, hi);
            (qef, placed, (lo + hi) * 0.5)
        })
    };
    let mut vertices = Vec::with_capacity(crust.len());
    let mut free = Vec::with_capacity(crust.len());
    let mut centres = Vec::with_capacity(crust.len());
    for (&n, (qef, placed, centre)) in crust.iter().zip(placed) {
        centres.push(centre);
        vertices.push(placed.vertex);
        free.push(placed.free);
        tree.nodes[n as usize].qef = tree.qefs.len() as u32;
        tree.qefs.push(qef);
    }
    let at = settle_vertices(field, iso, &mut vertices, &centres, &free, tree.h);
    for ((&n, &v), &f) in crust.iter().zip(&vertices).zip(&at) {
        let node = &mut tree.nodes[n as usize];
        node.vertex = v;
        node.value = f;
    }
    for &n in &leaves {
        if let Kind::Empty { inside } = tree.nodes[n as usize].kind {
            let (lo, hi) = tree.world_box(n);
            let node = &mut tree.nodes[n as usize];
            node.vertex = (lo + hi) * 0.5;
            node.value = super::dual::side_only(inside);
        }
    }
    settle_isolated(tree, field, iso, &crust, &centres);
}

/// The crust's sample lattice: each point once, and per crust cell (in `crust`'s order) its
/// `(k + 1)³` points' indices, x fastest.
///
/// A lattice point is shared by the up to eight crust cells around it, so points are named in a
/// map; the cells go layer by layer along z with one map per lattice plane of the layer, and a
/// layer's top plane is the next layer's bottom one. Each map then holds one plane's points of the
/// crust, small enough to stay in cache: one map of every point (2.4 million for a sphere at 256
/// cells) took 270 ms, probing memory at random.
fn lattice(tree: &Octree, crust: &[u32], k: u32) -> (Vec<Vec3>, Vec<u32>) {
    let per_cell = ((k + 1) as usize).pow(3);
    let coord = |i: u32| tree.nodes[crust[i as usize] as usize].coord;
    // The cells by layer (a counting sort on z, keeping the crust's order within a layer).
    let layers = tree.cells[2] as usize;
    let mut start = vec![0u32; layers + 1];
    for i in 0..crust.len() as u32 {
        start[coord(i)[2] as usize + 1] += 1;
    }
    for z in 0..layers {
        start[z + 1] += start[z];
    }
    let mut by_layer = vec![0u32; crust.len()];
    let mut fill = start.clone();
    for i in 0..crust.len() as u32 {
        let z = coord(i)[2] as usize;
        by_layer[fill[z] as usize] = i;
        fill[z] += 1;
    }
    let mut planes: Vec<HashMap<u64, u32>> = vec![HashMap::default(); k as usize + 1];
    let mut points = Vec::new();
    let mut cell_samples = vec![0u32; crust.len() * per_cell];
    for z in 0..layers {
        let cells = &by_layer[start[z] as usize..start[z + 1] as usize];
        for &i in cells {
            let c = coord(i);
            let mut slot = i as usize * per_cell;
            for dz in 0..=k {
                for dy in 0..=k {
                    for dx in 0..=k {
                        let l = [c[0] * k + dx, c[1] * k + dy, c[2] * k + dz];
                        let key = (l[1] as u64) << 32 | l[0] as u64;
                        cell_samples[slot] = *planes[dz as usize].entry(key).or_insert_with(|| {
                            points.push(
                                tree.lattice(Vec3::new(l[0] as f32, l[1] as f32, l[2] as f32) / k as f32),
                            );
                            points.len() as u32 - 1
                        });
                        slot += 1;
                    }
                }
            }
        }
        // The top plane is the next layer's bottom one; the others are done with.
        planes.swap(0, k as usize);
        for plane in &mut planes[1..] {
            plane.clear();
        }
    }
    (points, cell_samples)
}

/// Whether the dual vertex of the leaf holding finest cell `q` (offset by `d`) is inside; beyond
/// the grid the vertices are the boundary's copies, always outside.
fn neighbour_inside(tree: &Octree, q: [u32; 3], d: [i32; 3]) -> bool {
    let mut at = [0u32; 3];
    for a in 0..3 {
        let c = q[a] as i64 + d[a] as i64;
        if c < 0 || c >= tree.cells[a] as i64 {
            return false;
        }
        at[a] = c as u32;
    }
    let node = tree.locate(at, super::tree::NONE);
    super::dual::inside(tree, super::dual::VertexKey { node, clamp: 0 })
}

/// The crust vertices that the finest level's contour would wrap in a bubble of their own, moved
/// to their leaf centre's side.
///
/// A vertex whose side differs from its leaf centre's is what lets a wall thinner than a cell
/// survive, but only as part of the wall: its neighbours along the wall share its side. One that
/// shares its side with none of the vertices it is joined to (an inside vertex with every face
/// neighbour's vertex outside; an outside one with all 26 around it inside, since Marching Cubes'
/// table joins outside corners across faces and cubes) is alone in its side of the dual grid, and
/// the contour closes a bubble around it. Where the centre agrees with it, that bubble is a part
/// smaller than a cell seen by its centre, and stays; where it does not, the vertex was drawn there
/// by a feature of the function (a ridge inside the solid that the QEF reached by stopping at its
/// leaf's corner, or a crease whose vertex lies a hair on the other side of the level, found on
/// random CSG trees: flat bubbles lying on the surface, one face turned over). So such a vertex
/// takes its centre's side, as Marching Cubes on the lattice of centres gives it. Two such
/// vertices cannot be neighbours (each would need the other's neighbours on both sides), so one
/// pass decides them all.
fn settle_isolated(tree: &mut Octree, field: &Clipped, iso: f32, crust: &[u32], centres: &[Vec3]) {
    const FACES: [[i32; 3]; 6] = [[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]];
    let around: Vec<[i32; 3]> =
        (0..27).map(|i| [i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1]).filter(|d| *d != [0, 0, 0]).collect();
    let isolated: Vec<usize> = (0..crust.len())
        .filter(|&i| {
            let node = &tree.nodes[crust[i] as usize];
            let (q, inside) = (node.coord, node.value < 0.0);
            if inside {
                FACES.iter().all(|&d| !neighbour_inside(tree, q, d))
            } else {
                around.iter().all(|&d| neighbour_inside(tree, q, d))
            }
        })
        .collect();
    let points: Vec<Vec3> = isolated.iter().map(|&i| centres[i]).collect();
    let mut at_centre = vec![0.0; points.len()];
    field.values(&points, &mut at_centre);
    for (&i, &fc) in isolated.iter().zip(&at_centre) {
        let n = crust[i] as usize;
        let (v, value) = (tree.nodes[n].vertex, tree.nodes[n].value);
        let inside = fc < iso;
        if (value < 0.0) == inside {
            continue;
        }
        let (moved, f) = toward_side(field, iso, v, centres[i], inside, fc);
        tree.nodes[n].vertex = moved;
        tree.nodes[n].value = f - iso;
    }
}

/// The point nearest `v` on the segment to `centre` (where the field is `f_centre`, on the side
/// `inside`) at which the field is on that side too, by bisection, and the field there.
fn toward_side(
    field: &dyn Field,
    iso: f32,
    v: Vec3,
    centre: Vec3,
    inside: bool,
    f_centre: f32,
) -> (Vec3, f32) {
    let (mut bad, mut good) = (0.0f32, 1.0f32);
    let mut good_value = f_centre;
    for _ in 0..8 {
        let mid = 0.5 * (bad + good);
        let f = field.value(v + (centre - v) * mid);
        if (f < iso) == inside {
            good = mid;
            good_value = f;
        } else {
            bad = mid;
        }
    }
    (v + (centre - v) * good, good_value)
}

/// Each vertex's value `f - iso`, and the vertex moved where its side had to be decided.
///
/// A vertex on a feature often lies *on* the iso-level: on a crease of the surface, or on a ridge
/// of the field that only touches the level (two parts of a union sharing a face: `min(f1, f2)` is
/// 0 all over the shared face, inside the solid). Which side such a vertex counts on decides the
/// topology, and its value is rounding noise: taken as it comes, it makes pinholes in unions and
/// bubbles beside creases. The same holds for a vertex the leaf's box stopped short of its
/// minimiser (not `free`): the feature it was drawn to lies in a neighbour, and its side is the
/// side of a point of that feature's neighbourhood, not of its own leaf (beside a fin's corner,
/// an isolated inside vertex in an outside leaf: a bubble). So such vertices, and any within
/// [`LEVEL_BAND`] of a finest cell of the level, take the side of their leaf's centre (the side
/// Marching Cubes on the lattice of centres would give them) and move toward the centre
/// (bisection on the segment) until the field agrees. A free vertex clearly off the level keeps
/// its own side: that is how a wall thinner than a leaf, whose vertex the QEF puts on the wall's
/// mid-surface, survives.
pub fn settle_vertices(
    field: &dyn Field,
    iso: f32,
    vertices: &mut [Vec3],
    centres: &[Vec3],
    free: &[bool],
    h: f32,
) -> Vec<f32> {
    let mut at = vec![0.0; vertices.len()];
    field.values(vertices, &mut at);
    let band = LEVEL_BAND * h;
    let near: Vec<usize> = (0..at.len())
        .filter(|&i| (at[i] - iso).abs() <= if free[i] { band } else { band * STOPPED_BAND })
        .collect();
    let points: Vec<Vec3> = near.iter().map(|&i| centres[i]).collect();
    let mut at_centre = vec![0.0; points.len()];
    field.values(&points, &mut at_centre);
    for (k, &i) in near.iter().enumerate() {
        let inside = at_centre[k] < iso;
        if (at[i] < iso) == inside {
            continue;
        }
        // The field agrees at the centre: find where it starts to, nearest the vertex.
        (vertices[i], at[i]) = toward_side(field, iso, vertices[i], centres[i], inside, at_centre[k]);
    }
    at.iter().map(|v| v - iso).collect()
}

/// Vertices this close to the level (fraction of a finest cell; DMC sees every field in units of
/// length, see [`super::bounds::Clipped`]) take their leaf centre's side.
pub const LEVEL_BAND: f32 = 1e-4;

/// How many times wider that band is for vertices stopped on their leaf's boundary.
pub const STOPPED_BAND: f32 = 500.0;

/// Where a leaf's vertex goes.
#[derive(Debug, Clone, Copy)]
pub struct Placed {
    pub vertex: Vec3,
    /// The QEF's root-mean-square residual there.
    pub rms: f64,
    /// The minimiser lies inside the leaf (not stopped on its boundary).
    pub free: bool,
}

/// The QEF's minimiser in the leaf `[lo, hi]` shrunk by [`MARGIN`] (its centre if it has no
/// samples).
pub fn place(qef: &Qef, lo: Vec3, hi: Vec3) -> Placed {
    let margin = (hi - lo) * MARGIN;
    let (lo, hi) = (lo + margin, hi - margin);
    let centre = (lo + hi) * 0.5;
    if qef.count() == 0 {
        return Placed { vertex: centre, rms: 0.0, free: true };
    }
    let s = qef.minimise_in_box(lo, hi, None);
    let p = s.position.as_vec3();
    if !p.is_finite() {
        return Placed { vertex: centre, rms: f64::INFINITY, free: false };
    }
    let p = p.clamp(lo, hi);
    let free = (0..3).all(|a| p[a] > lo[a] && p[a] < hi[a]);
    Placed { vertex: p, rms: s.rms, free }
}

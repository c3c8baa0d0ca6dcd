//! Directed distances from a closed triangle mesh (paper §3.1, "Polygonal meshes"): EMC as a
//! remesher (§5.3). Every edge crossing is where an axis-aligned ray from the grid point first
//! meets a triangle, and its normal is that triangle's, so sharp edges and corners of the input
//! come back as feature lines and corners of the output.
//!
//! For a mesh with holes or a border (`open_edges`) the votes below are not defined (a line
//! through a hole counts one crossing too few from there on), and inside is where the generalised
//! winding number ([`super::winding`]) exceeds 1/2 instead: the holes are closed by a surface
//! spanning their rims, with crossings interpolated where a grid edge passes through a hole. A
//! mesh that bounds nothing (a sheet) is refused ([`check_encloses`]).
//!
//! Three queries over one [`MeshBvh`] (a bounding volume hierarchy over the triangles):
//! - **inside or outside** at every grid point: the winding number of the mesh around the point,
//!   counted along the grid line through it in each of the three axis directions (the signed
//!   crossings before the point; exact for a closed mesh). The point is inside when at least two of
//!   the three lines give a non-zero winding number: one line grazing an edge of a mesh with a
//!   small defect cannot flip it. Overlapping closed shells count as their union (non-zero rule).
//! - **the crossing** on a grid edge whose ends differ: the first hit of the ray along the edge
//!   ([`MeshRays`]). The hit test is the same watertight one the winding numbers use, so the ray
//!   finds exactly the crossings that made the ends differ.
//! - **the distance** to the nearest triangle, for the grid values ([`grid_values`]) and for the
//!   fallback normal when a ray finds no hit.
//!
//! The hit test works in the plane orthogonal to the ray: the ray meets a triangle when the point
//! lies inside its projection. Edge functions are computed in `f64`, each shared edge the same way
//! (endpoints in a fixed order) for both triangles that have it, and points exactly on a projected
//! edge or vertex belong to exactly one of the triangles there (the top-left rule of rasterisers).
//! So a ray through an edge or vertex of a closed mesh counts one crossing, never zero or two.

mod probe;

use super::edges::EdgeSampler;
use super::winding::WindingTree;
use super::{mesh_with_sampler, EmcMesh, EmcOptions, EmcTimings};
use crate::error::Error;
use crate::grid::Grid;
use crate::mc::ms_since;
use crate::mesh::analysis::bvh::{Aabb, Bvh};
use crate::mesh::Mesh;
use glam::{DVec2, Vec3};
use std::collections::HashMap;
use web_time::Instant;

/// A triangle's corners as bits, turned so the smallest comes first: the same key for the same
/// triangle listed from any of its corners, a different one when it is wound the other way (a
/// triangle and its reverse are two sheets that cancel, not a repeat).
fn cyclic_key(corners: [Vec3; 3]) -> [[u32; 3]; 3] {
    let bits = corners.map(|p| p.to_array().map(f32::to_bits));
    let first = (0..3).min_by_key(|&i| bits[i]).unwrap_or(0);
    [bits[first], bits[(first + 1) % 3], bits[(first + 2) % 3]]
}

/// A triangle mesh prepared for ray and distance queries.
pub struct MeshBvh {
    triangles: Vec<[Vec3; 3]>,
    /// Unit face normals, pointing out of the solid.
    normals: Vec<Vec3>,
    boxes: Vec<Aabb>,
    bvh: Bvh,
    /// How many triangles of the input were left out for having no area.
    pub degenerate: usize,
    /// How many were left out for repeating an earlier triangle (the same corners, wound the same
    /// way): an exporter's duplicate would count twice in every winding number through it and
    /// turn its side of the surface inside out.
    pub duplicates: usize,
    /// Whether the input was inside out (negative enclosed volume, or winding number where it has
    /// holes) and was turned around.
    pub flipped: bool,
    /// Edges of the input used by an odd number of triangles (`open_edges`): the edges of its
    /// holes or border. Where there are any, inside is decided by the generalised winding number.
    pub open_edges: usize,
    winding: Option<WindingTree>,
}

impl MeshBvh {
    /// Whether the generalised winding number exceeds 1/2 (inside, as [`grid_values`] decides it)
    /// at a point just beside one of the faces: a thousandth of the face's longest edge off its
    /// centroid, on either side, for up to [`FACE_PROBES`] faces spread over the mesh. Beside a
    /// closed surface's face the number is 1 on the inside; beside a flat sheet it stays under
    /// 1/2 on both sides.
    pub fn encloses_beside_faces(&self) -> bool {
        let Some(tree) = &self.winding else { return false };
        beside_faces(&self.triangles).any(|(_, points)| points.iter().any(|&p| tree.winding(p) > 0.5))
    }

    /// Indexes the triangles of `mesh`. Triangles without area are left out (no ray can hit them
    /// and they have no normal), and so are repeats of a triangle already listed; a mesh whose
    /// triangles enclose a negative volume (with holes: whose winding number is negative, see
    /// `inside_out_by_winding`) is taken to be inside out and turned around, so normals point
    /// out of the solid either way.
    pub fn new(mesh: &Mesh) -> Result<MeshBvh, Error> {
        let n = mesh.positions.len();
        if let Some(t) = mesh.triangles.iter().position(|t| t.iter().any(|&v| v as usize >= n)) {
            return Err(Error::InvalidOption(format!(
                "triangle {t} {:?} refers past the {n} vertices of the mesh",
                mesh.triangles[t]
            )));
        }
        if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::InvalidOption(format!("vertex {v} at {} is not finite", mesh.positions[v])));
        }
        let mut triangles = Vec::with_capacity(mesh.triangles.len());
        let mut volume = 0.0f64;
        let mut seen = std::collections::HashSet::with_capacity(mesh.triangles.len());
        let mut degenerate = 0;
        let mut duplicates = 0;
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            if (b - a).cross(c - a).length_squared() <= 0.0 {
                degenerate += 1;
                continue;
            }
            if !seen.insert(cyclic_key([a, b, c])) {
                duplicates += 1;
                continue;
            }
            triangles.push([a, b, c]);
        }
        // Six times the enclosed volume, about the middle of the box so that it means something
        // for an open mesh too (a closed one's is the same about any point).
        let (lo, hi) = triangles
            .iter()
            .flatten()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let middle = ((lo + hi) * 0.5).as_dvec3();
        for [a, b, c] in &triangles {
            let (a, b, c) = (a.as_dvec3() - middle, b.as_dvec3() - middle, c.as_dvec3() - middle);
            volume += a.dot(b.cross(c));
        }
        if triangles.is_empty() {
            return Err(Error::InvalidOption(format!(
                "the mesh has no triangles with area ({} degenerate ones) and encloses nothing",
                degenerate
            )));
        }
        let open_edges = open_edges(mesh).len();
        let mut winding = (open_edges > 0).then(|| WindingTree::new(&triangles));
        let flipped = match &winding {
            Some(tree) => inside_out_by_winding(tree, &triangles),
            None => volume < 0.0,
        };
        if flipped {
            for t in &mut triangles {
                t.swap(1, 2);
            }
            winding = winding.map(|_| WindingTree::new(&triangles));
        }
        let normals =
            triangles.iter().map(|[a, b, c]| (*b - *a).cross(*c - *a).normalize_or_zero()).collect();
        let boxes: Vec<Aabb> = triangles.iter().map(|t| Aabb::of_points(t)).collect();
        let bvh = Bvh::build(&boxes);
        Ok(MeshBvh { triangles, normals, boxes, bvh, degenerate, duplicates, flipped, open_edges, winding })
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Unit outward normal of (kept) triangle `t`.
    pub fn normal(&self, t: u32) -> Vec3 {
        self.normals[t as usize]
    }

    /// The first triangle the axis-aligned segment `a → b` meets, as the fraction `t` of the way
    /// from `a` and the triangle's index; `None` when it meets none (or `b - a` is not along an axis).
    ///
    /// The segment is half open towards larger coordinates, `[min, max)` along its axis, like the
    /// steps of the winding-number sweep in [`MeshBvh::inside_votes`]: a crossing exactly at a grid
    /// point belongs to the grid edge that starts there.
    pub fn first_hit(&self, a: Vec3, b: Vec3) -> Option<(f32, u32)> {
        let axis = axis_of(b - a)?;
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let (from, to) = (a[axis], b[axis]);
        let (lo, hi) = (from.min(to), from.max(to));
        // (distance from a along the axis, triangle)
        let mut best: (f64, u32) = (f64::INFINITY, u32::MAX);
        self.bvh.walk(
            &mut best,
            |best, bx| {
                let across = bx.min[u] <= a[u] && a[u] <= bx.max[u] && bx.min[v] <= a[v] && a[v] <= bx.max[v];
                let along = bx.min[axis] <= hi && lo <= bx.max[axis];
                let near = if to >= from { bx.min[axis] - from } else { from - bx.max[axis] };
                let near = near.max(0.0);
                (across && along && near as f64 <= best.0).then_some(near)
            },
            |best, t| {
                if let Some((x, _)) = axis_hit(&self.triangles[t as usize], axis, a) {
                    let distance = (x - from as f64).abs();
                    if x >= lo as f64 && x < hi as f64 && (distance, t) < *best {
                        *best = (distance, t);
                    }
                }
            },
        );
        (best.1 != u32::MAX).then(|| ((best.0 / (hi - lo) as f64).clamp(0.0, 1.0) as f32, best.1))
    }

    /// Distance from `p` to the nearest triangle and that triangle, if one is within `max_distance`.
    pub fn nearest(&self, p: Vec3, max_distance: f32) -> Option<(f32, u32)> {
        let mut best: (f32, u32) = (max_distance * max_distance, u32::MAX);
        self.bvh.walk(
            &mut best,
            |best, bx| {
                let d = box_distance_squared(p, bx);
                (d <= best.0).then_some(d)
            },
            |best, t| {
                if box_distance_squared(p, &self.boxes[t as usize]) > best.0 {
                    return;
                }
                let d = (closest_point_on_triangle(p, &self.triangles[t as usize]) - p).length_squared();
                if d < best.0 || (d == best.0 && best.1 == u32::MAX) {
                    *best = (d, t);
                }
            },
        );
        (best.1 != u32::MAX).then(|| (best.0.sqrt(), best.1))
    }

    /// The point of the mesh nearest to `p` and the triangle it lies on.
    pub fn closest_point(&self, p: Vec3) -> Option<(Vec3, u32)> {
        let (_, t) = self.nearest(p, f32::INFINITY)?;
        Some((closest_point_on_triangle(p, &self.triangles[t as usize]), t))
    }

    /// Per grid point, how many of the three axis lines through it find it inside (non-zero
    /// winding number, counting the signed crossings between the line's start and the point).
    pub fn inside_votes(&self, grid: &Grid) -> Vec<u8> {
        let pts = grid.points();
        let mut votes = vec![0u8; grid.point_count()];
        let mut hits: Vec<(f64, i32)> = Vec::new();
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for j in 0..pts[u] {
                for k in 0..pts[v] {
                    let mut ijk = [0usize; 3];
                    (ijk[u], ijk[v]) = (j, k);
                    let q = grid.position(ijk[0], ijk[1], ijk[2]);
                    hits.clear();
                    self.bvh.walk(
                        &mut hits,
                        |_, bx| {
                            (bx.min[u] <= q[u] && q[u] <= bx.max[u] && bx.min[v] <= q[v] && q[v] <= bx.max[v])
                                .then_some(0.0)
                        },
                        |hits, t| {
                            if let Some((x, sign)) = axis_hit(&self.triangles[t as usize], axis, q) {
                                // A ray along +axis enters where the normal faces against it.
                                hits.push((x, -sign));
                            }
                        },
                    );
                    hits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                    let (mut winding, mut next) = (0i32, 0usize);
                    for i in 0..pts[axis] {
                        ijk[axis] = i;
                        let x = grid.position(ijk[0], ijk[1], ijk[2])[axis] as f64;
                        while next < hits.len() && hits[next].0 < x {
                            winding += hits[next].1;
                            next += 1;
                        }
                        if winding != 0 {
                            votes[grid.index(ijk[0], ijk[1], ijk[2])] += 1;
                        }
                    }
                }
            }
        }
        votes
    }
}

/// The open edges of a triangle mesh, as pairs of corner positions: edges used by an odd number of
/// its triangles (repeats of a triangle, the same [`cyclic_key`], counted once). Corners are
/// matched by their coordinates, so a mesh whose faces do not share vertices (as in STL, or an
/// exporter that splits vertices at seams) counts as closed where it is.
///
/// Around a closed surface (any number of shells, overlapping or not, non-manifold edges
/// included) every edge has an even number of triangles, and a line crossing it changes its
/// winding number only where it crosses the surface; at an edge of a hole the winding number
/// jumps in mid-air, so inside and outside are not defined. Triangles without area stay in the
/// count (a zero-area sliver in a closed mesh closes it as much as any other triangle; one
/// repeating a corner uses its edge twice). Faces wound against their neighbours leave edges used
/// twice the same way: those are not open, and the votes of the three axes (module documentation)
/// decide around them as before.
fn open_edges(mesh: &Mesh) -> Vec<(Vec3, Vec3)> {
    let key = |p: Vec3| (p + Vec3::ZERO).to_array().map(f32::to_bits);
    let mut uses: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::with_capacity(mesh.triangles.len() * 2);
    let mut counted = std::collections::HashSet::with_capacity(mesh.triangles.len());
    for t in 0..mesh.triangles.len() {
        let corners = mesh.corners(t);
        let area = (corners[1] - corners[0]).cross(corners[2] - corners[0]).length_squared() > 0.0;
        if area && !counted.insert(cyclic_key(corners)) {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (key(corners[k]), key(corners[(k + 1) % 3]));
            if a != b {
                *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
    }
    let mut open: Vec<([u32; 3], [u32; 3])> =
        uses.into_iter().filter(|e| e.1 % 2 == 1).map(|e| e.0).collect();
    open.sort_unstable();
    let position = |bits: [u32; 3]| Vec3::from(bits.map(f32::from_bits));
    open.into_iter().map(|(a, b)| (position(a), position(b))).collect()
}

/// The axis `d` runs along, when its other two components are exactly zero.
fn axis_of(d: Vec3) -> Option<usize> {
    let nonzero = d.cmpne(Vec3::ZERO).bitmask();
    match nonzero {
        0b001 => Some(0),
        0b010 => Some(1),
        0b100 => Some(2),
        _ => None,
    }
}

/// Where the line through `q` along `axis` meets `tri`: the coordinate along the axis and the sign
/// of the triangle normal's component on the axis. `None` when the line misses the triangle or the
/// triangle is edge-on to it.
fn axis_hit(tri: &[Vec3; 3], axis: usize, q: Vec3) -> Option<(f64, i32)> {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let p = tri.map(|c| DVec2::new(c[u] as f64, c[v] as f64));
    let x = DVec2::new(q[u] as f64, q[v] as f64);
    // (u, v, axis) is a cyclic order of (x, y, z), so this is the normal's component on the axis.
    let area = orient(p[0], p[1], p[2]);
    if area == 0.0 {
        return None;
    }
    let ccw = area > 0.0;
    // Edge k runs from vertex k+1 to k+2 and its function weighs vertex k.
    let mut w = [0.0f64; 3];
    for k in 0..3 {
        let (from, to) = (p[(k + 1) % 3], p[(k + 2) % 3]);
        let e = edge_function(from, to, x);
        // Seen counter-clockwise, the edge runs the other way round on a clockwise triangle.
        let (value, dir) = if ccw { (e, to - from) } else { (-e, from - to) };
        if value < 0.0 || (value == 0.0 && !top_left(dir)) {
            return None;
        }
        w[k] = e;
    }
    let sum = w[0] + w[1] + w[2];
    let coordinate =
        (w[0] * tri[0][axis] as f64 + w[1] * tri[1][axis] as f64 + w[2] * tri[2][axis] as f64) / sum;
    Some((coordinate, if ccw { 1 } else { -1 }))
}

/// Twice the signed area of `a b c`: positive when counter-clockwise.
fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// `orient(from, to, x)`, always evaluated with the two endpoints in the same order, so the two
/// triangles sharing an edge get exactly opposite values.
fn edge_function(from: DVec2, to: DVec2, x: DVec2) -> f64 {
    if (from.x, from.y) < (to.x, to.y) {
        orient(from, to, x)
    } else {
        -orient(to, from, x)
    }
}

/// Tie-break for points exactly on an edge: of the two directions an edge can run, exactly one is
/// "top-left", so of two triangles on either side of it exactly one owns the point.
fn top_left(dir: DVec2) -> bool {
    dir.y < 0.0 || (dir.y == 0.0 && dir.x > 0.0)
}

fn box_distance_squared(p: Vec3, b: &Aabb) -> f32 {
    (b.min - p).max(p - b.max).max(Vec3::ZERO).length_squared()
}

/// The point of triangle `abc` nearest to `p`, by the region of the triangle's plane `p` projects
/// into (a vertex, an edge, or the interior).
fn closest_point_on_triangle(p: Vec3, [a, b, c]: &[Vec3; 3]) -> Vec3 {
    let (ab, ac, ap) = (*b - *a, *c - *a, p - *a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - *b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return *a + ab * (d1 / (d1 - d3));
    }
    let cp = p - *c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return *a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return *b + (*c - *b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let sum = va + vb + vc;
    *a + ab * (vb / sum) + ac * (vc / sum)
}

/// Signed values at the grid points: negative inside (by [`MeshBvh::inside_votes`], two of three;
/// for a mesh with holes, where the generalised winding number exceeds 1/2),
/// positive outside. What matters for EMC is the sign; the magnitude is the distance to the
/// nearest triangle at every point with a neighbour of the other sign (the only values Marching
/// Cubes interpolates, and those are within a cell of the surface), and two cells elsewhere. An
/// inside point on the surface gets the smallest negative float, so its sign survives.
pub fn grid_values(mesh: &MeshBvh, grid: &Grid) -> Vec<f32> {
    let inside: Vec<bool> = match &mesh.winding {
        Some(tree) => (0..grid.point_count())
            .map(|n| {
                let [i, j, k] = grid.unindex(n);
                tree.winding(grid.position(i, j, k)) > 0.5
            })
            .collect(),
        None => mesh.inside_votes(grid).iter().map(|&v| v >= 2).collect(),
    };
    let band = 2.0 * grid.cell_size();
    let pts = grid.points();
    let mut values = vec![0.0f32; grid.point_count()];
    for k in 0..pts[2] {
        for j in 0..pts[1] {
            for i in 0..pts[0] {
                let n = grid.index(i, j, k);
                let ijk = [i, j, k];
                let mut near_surface = false;
                for axis in 0..3 {
                    for step in [-1isize, 1] {
                        let Some(c) = ijk[axis].checked_add_signed(step).filter(|&c| c < pts[axis]) else {
                            continue;
                        };
                        let mut other = ijk;
                        other[axis] = c;
                        near_surface |= inside[grid.index(other[0], other[1], other[2])] != inside[n];
                    }
                }
                let distance = if near_surface {
                    mesh.nearest(grid.position(i, j, k), band).map_or(band, |(d, _)| d)
                } else {
                    band
                };
                values[n] = if inside[n] { -distance.max(f32::MIN_POSITIVE) } else { distance };
            }
        }
    }
    values
}

/// Whether triangles with holes are wound inside out, by their generalised winding number (`tree`,
/// built over them). Just behind a face (against its normal) and just in front of it the number
/// is about 1 and 0 where the faces are wound outward, 0 and -1 where they are wound the other
/// way, holes or not; so the area-weighted sum of the two over the faces (those of
/// [`beside_faces`]) has the winding's sign. The enclosed volume, which decides for closed meshes,
/// depends on the point it is taken about once faces are missing: a face missing from a small part
/// far from that point outweighs the part's whole volume (random shells meshed into specks, a few
/// faces punched out, were turned inside out and then refused as enclosing nothing).
fn inside_out_by_winding(tree: &WindingTree, triangles: &[[Vec3; 3]]) -> bool {
    let sum: f64 = beside_faces(triangles)
        .map(|(area, points)| area as f64 * points.iter().map(|&p| tree.winding(p)).sum::<f64>())
        .sum();
    sum < 0.0
}

/// Up to [`FACE_PROBES`] faces spread over `triangles`, each as twice its area and the points a
/// thousandth of its longest edge off its centroid, behind it (against its normal) and in front.
fn beside_faces(triangles: &[[Vec3; 3]]) -> impl Iterator<Item = (f32, [Vec3; 2])> + '_ {
    let stride = triangles.len().div_ceil(FACE_PROBES).max(1);
    triangles.iter().step_by(stride).map(|&[a, b, c]| {
        let cross = (b - a).cross(c - a);
        let off = cross.normalize_or_zero() * (1e-3 * a.distance(b).max(b.distance(c)).max(c.distance(a)));
        let centroid = (a + b + c) / 3.0;
        (cross.length(), [centroid - off, centroid + off])
    })
}

/// Faces `beside_faces` yields at most: orientation and the sheet test of a mesh with holes cost
/// two winding numbers each.
pub const FACE_PROBES: usize = 1024;

/// Refuses the grid values of a mesh with holes where no grid point is inside: an open surface
/// that bounds nothing (a sheet, a lone face) has a winding number below 1/2 everywhere, and an
/// empty output would say nothing about why. A solid whose inside falls between the grid points
/// meshes to nothing as any surface smaller than a cell does, with holes or without: so before
/// refusing, the winding number is also taken just beside the mesh's faces
/// ([`MeshBvh::encloses_beside_faces`]), where a thin shell with a few holes is inside and a sheet
/// is not.
pub fn check_encloses(mesh: &MeshBvh, values: &[f32]) -> Result<(), Error> {
    if mesh.open_edges > 0 && !values.iter().any(|&v| v < 0.0) && !mesh.encloses_beside_faces() {
        return Err(Error::InvalidOption(format!(
            "the mesh has {} open edges (holes or a border) and encloses nothing: its generalised \
             winding number is below 1/2 at every grid point, so it is a sheet rather than the \
             surface of a solid",
            mesh.open_edges
        )));
    }
    Ok(())
}

/// EMC's edge crossings on a triangle mesh: the first ray hit along the edge and the hit
/// triangle's normal (`directed`), or, like plain MC, the linear interpolation of the end values.
///
/// When the ray finds no triangle (the ends' signs came from the other two axes' votes, which only
/// happens around defects of the mesh) the crossing is interpolated too. Interpolated crossings
/// take the normal of the triangle nearest to them.
pub struct MeshRays<'a> {
    pub mesh: &'a MeshBvh,
    pub directed: bool,
}

impl EdgeSampler for MeshRays<'_> {
    fn crossing(&self, a: Vec3, b: Vec3, da: f32, db: f32) -> (f32, Vec3) {
        if self.directed {
            if let Some((t, tri)) = self.mesh.first_hit(a, b) {
                let n = self.mesh.normal(tri);
                // Outward is from the inside end towards the outside end; a face the input wound
                // the wrong way round still gives an outward normal.
                let flip = n.dot(b - a) * (db - da) < 0.0;
                return (t, if flip { -n } else { n });
            }
        }
        let t = da / (da - db);
        let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.5 };
        let n = self
            .mesh
            .nearest(a + (b - a) * t, f32::INFINITY)
            .map_or(Vec3::ZERO, |(_, tri)| self.mesh.normal(tri));
        (t, n)
    }

    /// The nearest hit on the segment, where the segment meets the mesh an odd number of times
    /// (its ends on opposite sides of a closed mesh); `None` for an even count, which includes a
    /// hit counted twice on a shared edge, and for a mesh with holes, whose sides are not decided
    /// by crossings.
    fn crossing_on_segment(&self, a: Vec3, b: Vec3) -> Option<(f32, Vec3)> {
        if !self.directed || self.mesh.open_edges > 0 {
            return None;
        }
        let hits = self.mesh.segment_hits(a, b);
        let &(t, tri) = hits.first()?;
        (hits.len() % 2 == 1).then(|| (t, self.mesh.normal(tri)))
    }

    /// The exact distance to the nearest triangle.
    fn distance(&self, p: Vec3) -> Option<f32> {
        self.directed.then(|| self.mesh.nearest(p, f32::INFINITY).map(|(d, _)| d)).flatten()
    }
}

/// EMC remeshing of a closed triangle mesh on `grid` (paper §5.3): the output has the grid's
/// uniform vertex distribution and keeps the input's sharp edges and corners as feature lines.
/// See the module documentation for how inside, crossings and normals are found;
/// `options.directed = false` gives the linear-interpolation baseline and `options.crust` does not
/// apply (every grid point is classified). `options.iso` must be 0: the surface is the mesh.
pub fn remesh(mesh: &Mesh, grid: &Grid, options: &EmcOptions) -> Result<(EmcMesh, EmcTimings), Error> {
    options.validate()?;
    if options.iso != 0.0 {
        return Err(Error::InvalidOption(format!(
            "iso must be 0 when remeshing a triangle mesh (the surface is the mesh), got {}",
            options.iso
        )));
    }
    grid.check_size(options.max_cells)?;
    let t0 = Instant::now();
    let source = MeshBvh::new(mesh)?;
    let values = grid_values(&source, grid);
    check_encloses(&source, &values)?;
    let sample_ms = ms_since(t0);
    let sampler = MeshRays { mesh: &source, directed: options.directed };
    let (mut out, mut timings) = mesh_with_sampler(&values, grid, options, &sampler)?;
    out.points_evaluated = grid.point_count();
    timings.sample_ms = sample_ms;
    Ok((out, timings))
}

/// The smallest box holding every vertex some triangle uses; `(+inf, -inf)` for a mesh without
/// triangles (which [`padded_grid`] refuses).
pub fn mesh_bounds(mesh: &Mesh) -> (Vec3, Vec3) {
    mesh.triangles
        .iter()
        .flatten()
        .filter_map(|&v| mesh.positions.get(v as usize))
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
}

/// The grid for meshing an input with bounds `min..max`: cubic cells, `res` of them along the
/// longest side of the bounds padded by two cells on every side (so the surface never touches the
/// grid's border and stays closed). `res` must exceed 4, the padding.
pub fn padded_grid(min: Vec3, max: Vec3, res: usize) -> Result<Grid, Error> {
    if res <= 4 {
        return Err(Error::InvalidGrid(format!(
            "resolution must be at least 5 cells (2 of padding on each side), got {res}"
        )));
    }
    if !(min.is_finite() && max.is_finite() && max.cmpge(min).all()) {
        return Err(Error::InvalidGrid(format!("the input has no finite bounds ({min} .. {max})")));
    }
    let longest = (max - min).max_element();
    if longest <= 0.0 {
        return Err(Error::InvalidGrid(format!(
            "the input is a single point ({min}); it has no extent to mesh"
        )));
    }
    let h = longest / (res - 4) as f32;
    Grid::with_resolution(min - Vec3::splat(2.0 * h), max + Vec3::splat(2.0 * h), res)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures::{cube, mc_sphere, octahedron};

    fn brute_nearest(m: &MeshBvh, p: Vec3) -> f32 {
        m.triangles
            .iter()
            .map(|t| (closest_point_on_triangle(p, t) - p).length())
            .fold(f32::INFINITY, f32::min)
    }

    #[test]
    fn closest_points_land_in_every_region_of_the_triangle() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let cases = [
            (Vec3::new(-1.0, -1.0, 1.0), Vec3::ZERO),
            (Vec3::new(2.0, -0.5, 0.0), Vec3::X),
            (Vec3::new(-0.5, 3.0, 0.0), Vec3::Y),
            (Vec3::new(0.5, -1.0, 2.0), Vec3::new(0.5, 0.0, 0.0)),
            (Vec3::new(-1.0, 0.25, 0.0), Vec3::new(0.0, 0.25, 0.0)),
            (Vec3::new(1.0, 1.0, -1.0), Vec3::new(0.5, 0.5, 0.0)),
            (Vec3::new(0.25, 0.25, 3.0), Vec3::new(0.25, 0.25, 0.0)),
        ];
        for (p, expected) in cases {
            assert!((closest_point_on_triangle(p, &t) - expected).length() < 1e-6, "{p}");
        }
    }

    #[test]
    fn nearest_matches_brute_force() {
        let (sphere, _) = mc_sphere(12);
        let m = MeshBvh::new(&sphere).unwrap();
        for i in 0..200 {
            let f = i as f32;
            let p = Vec3::new((f * 0.37).sin(), (f * 0.73).cos(), (f * 0.11).sin() * 1.3);
            let (d, _) = m.nearest(p, f32::INFINITY).unwrap();
            assert!((d - brute_nearest(&m, p)).abs() < 1e-6, "{p}");
            assert!(m.nearest(p, 0.5 * d).is_none());
        }
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_count_once() {
        // The unit cube's diagonals split each face along x = y etc.; grid lines through
        // (0.5, 0.5) hit those diagonals, and lines through 0 and 1 run along faces and edges.
        let m = MeshBvh::new(&cube()).unwrap();
        let grid = Grid::new(Vec3::splat(-0.5), Vec3::splat(1.5), [4, 4, 4]).unwrap();
        let votes = m.inside_votes(&grid);
        for (n, &vote) in votes.iter().enumerate() {
            let [i, j, k] = grid.unindex(n);
            let p = grid.position(i, j, k);
            let strictly_inside = p.cmpgt(Vec3::ZERO).all() && p.cmplt(Vec3::ONE).all();
            let outside = p.cmplt(Vec3::ZERO).any() || p.cmpgt(Vec3::ONE).any();
            if strictly_inside {
                assert_eq!(vote, 3, "{p}");
            } else if outside {
                assert_eq!(vote, 0, "{p}");
            }
        }
        // A segment along a face diagonal's projection hits exactly one of the two triangles.
        let (t, tri) = m.first_hit(Vec3::new(0.5, 0.5, -1.0), Vec3::new(0.5, 0.5, 0.5)).unwrap();
        assert!((t - 2.0 / 3.0).abs() < 1e-6);
        assert_eq!(m.normal(tri), -Vec3::Z);
        let (t, _) = m.first_hit(Vec3::new(0.5, 0.5, 0.5), Vec3::new(0.5, 0.5, -1.0)).unwrap();
        assert!((t - 1.0 / 3.0).abs() < 1e-6);
        assert!(m.first_hit(Vec3::new(0.5, 0.5, 0.2), Vec3::new(0.5, 0.5, 0.8)).is_none());
        assert!(m.first_hit(Vec3::new(0.5, 0.5, 0.2), Vec3::new(0.5, 0.6, 0.8)).is_none());
    }

    #[test]
    fn inside_out_meshes_are_turned_around() {
        let mut m = octahedron();
        for t in &mut m.triangles {
            t.swap(0, 1);
        }
        let bvh = MeshBvh::new(&m).unwrap();
        assert!(bvh.flipped);
        let (_, tri) = bvh.nearest(Vec3::new(2.0, 2.0, 2.0), f32::INFINITY).unwrap();
        assert!(bvh.normal(tri).dot(Vec3::ONE) > 0.0);
        let grid = Grid::new(Vec3::splat(-1.5), Vec3::splat(1.5), [2, 2, 2]).unwrap();
        assert_eq!(
            bvh.inside_votes(&grid)[grid.index(1, 1, 1)],
            3,
            "the centre, on lines through the vertices"
        );
    }

    #[test]
    fn open_edges_are_counted_by_position() {
        let m = cube();
        // Every face's vertices split apart (as an STL would have them): still closed.
        let mut split = Mesh::default();
        for t in 0..m.triangles.len() {
            let base = split.positions.len() as u32;
            split.positions.extend(m.corners(t));
            split.triangles.push([base, base + 1, base + 2]);
        }
        assert!(open_edges(&split).is_empty());
        // A zero-area triangle repeating a corner and a repeated triangle change nothing.
        let mut extra = m.clone();
        extra.triangles.push([0, 0, 1]);
        extra.triangles.push(m.triangles[3]);
        assert!(open_edges(&extra).is_empty());
        // One triangle missing: its three edges are open.
        let mut holed = m.clone();
        holed.triangles.remove(5);
        assert_eq!(open_edges(&holed).len(), 3);
        assert_eq!(MeshBvh::new(&holed).unwrap().open_edges, 3);
        assert_eq!(MeshBvh::new(&m).unwrap().open_edges, 0);
        // A face wound the wrong way round is not a hole.
        let mut misturned = m.clone();
        misturned.triangles[5].swap(1, 2);
        assert!(open_edges(&misturned).is_empty());
        // A triangle [0, 0, 1] uses its edge twice; alone it would be open once the cube's face
        // next to it is gone.
        let mut sliver = holed.clone();
        sliver.triangles.push([0, 0, 1]);
        assert_eq!(open_edges(&sliver).len(), 3);
    }

    /// `cube()` scaled by `size` about its lowest corner, moved to `at`, with triangle `punched`
    /// left out where there is one.
    fn punched_cube(size: Vec3, at: Vec3, punched: Option<usize>) -> Mesh {
        let mut m = cube();
        for p in &mut m.positions {
            *p = at + *p * size;
        }
        if let Some(t) = punched {
            m.triangles.remove(t);
        }
        m
    }

    fn joined(a: &Mesh, b: &Mesh) -> Mesh {
        let mut m = a.clone();
        let n = m.positions.len() as u32;
        m.positions.extend(&b.positions);
        m.triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + n)));
        m
    }

    #[test]
    fn holed_meshes_keep_their_winding_wherever_their_parts_lie() {
        // Two small cubes at opposite corners of the box, a face punched out of one: the enclosed
        // volume about the box's middle is the missing face's, negative where that face looked
        // away from the middle; the winding number is not fooled.
        for punched in 0..12 {
            let a = punched_cube(Vec3::splat(0.01), Vec3::ZERO, Some(punched));
            let b = punched_cube(Vec3::splat(0.01), Vec3::ONE, None);
            let m = MeshBvh::new(&joined(&a, &b)).unwrap();
            assert!(m.open_edges > 0 && !m.flipped, "face {punched} punched: turned inside out");
            let mut inverted = joined(&a, &b);
            for t in &mut inverted.triangles {
                t.swap(1, 2);
            }
            assert!(MeshBvh::new(&inverted).unwrap().flipped, "face {punched} punched, inverted");
        }
    }

    #[test]
    fn thin_solids_with_holes_are_not_sheets() {
        // A slab a thousandth of its width thick, a face punched out of its top: no grid point
        // falls inside it, as none would were it closed, and it meshes to nothing rather than
        // being refused as a sheet.
        let slab = punched_cube(Vec3::new(1.0, 1.0, 0.001), Vec3::new(0.0, 0.0, 0.0123), Some(11));
        let source = MeshBvh::new(&slab).unwrap();
        assert!(source.open_edges > 0 && !source.flipped);
        let (lo, hi) = mesh_bounds(&slab);
        let values = grid_values(&source, &padded_grid(lo, hi, 12).unwrap());
        assert!(values.iter().all(|&v| v >= 0.0), "a grid point fell inside the slab");
        assert!(source.encloses_beside_faces());
        check_encloses(&source, &values).unwrap();
    }

    #[test]
    fn sheets_are_refused() {
        let square = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            normals: vec![],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let source = MeshBvh::new(&square).unwrap();
        assert_eq!(source.open_edges, 4);
        let grid = padded_grid(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), 12).unwrap();
        let err = check_encloses(&source, &grid_values(&source, &grid)).unwrap_err().to_string();
        assert!(err.contains("4 open edges") && err.contains("encloses nothing"), "{err}");
    }

    #[test]
    fn bad_meshes_are_refused() {
        let mut m = cube();
        m.triangles.push([0, 1, 8]);
        assert!(matches!(MeshBvh::new(&m), Err(Error::InvalidOption(msg)) if msg.contains("triangle 12")));
        let flat = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            normals: vec![],
            triangles: vec![[0, 1, 2]],
        };
        assert!(MeshBvh::new(&flat).is_err());
        assert!(padded_grid(Vec3::ZERO, Vec3::ONE, 4).is_err());
        assert!(padded_grid(Vec3::ONE, Vec3::ONE, 16).is_err());
        let (lo, hi) = mesh_bounds(&Mesh::default());
        assert!(padded_grid(lo, hi, 16).is_err());
    }

    #[test]
    fn padded_grid_has_res_cells_and_two_cells_of_margin() {
        let g = padded_grid(Vec3::ZERO, Vec3::new(2.0, 1.0, 0.0), 20).unwrap();
        assert_eq!(g.cells[0], 20);
        let h = g.cell_size();
        assert!((h - 2.0 / 16.0).abs() < 1e-6);
        assert!((g.origin.x + 2.0 * h).abs() < 1e-5);
        assert!(g.origin.y <= -2.0 * h + 1e-5 && g.max().y >= 1.0 + 2.0 * h - 1e-5);
        assert!(g.origin.z <= -2.0 * h + 1e-5 && g.max().z >= 2.0 * h - 1e-5);
    }
}

//! Gives back the fans' extra triangles where it costs nothing: a fan over a component of n
//! crossings has n triangles where MC's polygon has n − 2, so EMC adds a vertex and two triangles
//! per feature point (on the cube minus sphere at 32 cells, 30 % more triangles than MC). Where a
//! crossing next to a fan centre has all its triangles in one plane (a flat face meeting the
//! crease), collapsing it into the centre removes that vertex and two triangles without moving
//! the surface: the fan of the centre over the same planar polygon covers the same region.
//!
//! At most one collapse per fan centre, so the mesh stays as fine as MC's away from features and
//! no long triangles grow from the creases.

use super::nearby::NearbyTriangles;
use super::placement::INSET;
use crate::mesh::analysis::self_intersect::indexed_pair_intersects;
use crate::mesh::Mesh;
use glam::Vec3;

/// How far (in cells) the one-ring of a crossing may lie from its plane for the crossing to count
/// as flat: far below the 1 % of a cell that feature points are held to, far above root finding's
/// residual on a plane.
pub const FLAT_TOLERANCE: f32 = 1e-3;

/// Cosine of the largest angle between a collapsed triangle's normal and the plane's: refuses
/// triangles that would flip or turn into slivers whose normal is noise.
const MIN_NORMAL_COSINE: f32 = 0.996;

/// Collapses, into each fan centre, its nearest neighbour that is a flat crossing (see the module
/// doc), then drops the removed vertices (`positions`, `normals`, `fan_centre` and
/// `feature_vertex` are compacted, triangles renumbered). `h` is the cell size. Returns how many vertices were removed.
///
/// A collapse is refused when it would change the topology (the link condition: the centre and the
/// crossing share exactly the two neighbours of their common edge), when it would join the centre
/// to another fan centre it is not joined to already (a false feature line across the flat face),
/// or when a triangle would flip or degenerate.
pub fn merge_flat_crossings(
    mesh: &mut Mesh,
    fan_centre: &mut Vec<bool>,
    feature_vertex: &mut Vec<bool>,
    crease: &mut Vec<Vec3>,
    h: f32,
) -> usize {
    let n = mesh.positions.len();
    let mut incident = incident_near_centres(mesh, fan_centre);
    let mut dead = vec![false; mesh.triangles.len()];
    let mut removed = vec![false; n];
    let tolerance = FLAT_TOLERANCE * h;
    let mut merged = 0;
    for centre in (0..n).filter(|&v| fan_centre[v]) {
        let neighbours = ring(mesh, &incident[centre], centre as u32);
        let best = neighbours
            .iter()
            .filter(|&&a| !fan_centre[a as usize] && !removed[a as usize])
            .filter(|&&a| can_collapse(mesh, &incident, fan_centre, a, centre as u32, &neighbours, tolerance))
            .min_by(|&&a, &&b| {
                let d = |v: u32| mesh.positions[v as usize].distance_squared(mesh.positions[centre]);
                d(a).total_cmp(&d(b))
            })
            .copied();
        let Some(a) = best else { continue };
        collapse(mesh, &mut incident, &mut dead, a, centre as u32);
        removed[a as usize] = true;
        merged += 1;
    }
    if merged > 0 {
        compact(mesh, [fan_centre, feature_vertex], crease, &removed, &dead);
    }
    merged
}

/// Welds pairs of fan centres that stand for one feature point lying in the cell face between
/// them, and drops the two triangles they fold back to back. Where a feature point (a cone's apex,
/// a corner) lies in a grid plane, both cells beside it place their centre on it, each kept
/// a hundredth of a cell inside its own cell, and both fan the edge their polygons share in that
/// face: two triangles lying in the face, one on top of the other, turned 90° from a surface that
/// crosses the face (a fin on the cube with cut-outs, whose countersink's apex lies in a grid
/// plane at 32, 48, 64 and 128 cells). One vertex on the face serves both fans, and the two
/// triangles, then the same triangle twice in opposite orientations, cover nothing.
///
/// The flips run first and may have turned that edge into one joining the two centres, with the
/// same two triangles standing as flat in the face (a fin); that pair is welded alike (with the
/// looser `SAME`, fins on 161 random countersinks went from 31 to 13: docs/emc.md).
///
/// Only that configuration is welded: the two centres differ along one axis alone, by at most
/// two insets and a quarter of the grid's spacing there, with a grid plane between them, where
/// the vertex goes; under the link condition (they share exactly the edge's two ends, or the two
/// crossings of the flipped pair, as neighbours, and are joined only where flipped), so the
/// surface keeps its topology and stays manifold; and
/// where no triangle around the welded vertex would cross another (on noise over cells six times
/// longer than wide, a weld put a centre on the face between two of MC's polygon centres a
/// fiftieth of a cell either side of it: eight crossing pairs, `props_grids` seed 3500133).
/// Compacts like [`merge_flat_crossings`]; returns how many pairs it welded.
pub fn weld_facing_centres(
    mesh: &mut Mesh,
    fan_centre: &mut Vec<bool>,
    feature_vertex: &mut Vec<bool>,
    crease: &mut Vec<Vec3>,
    grid: (Vec3, Vec3),
) -> usize {
    let mut incident = incident_near_centres(mesh, fan_centre);
    // The edges between two crossings or between two fan centres, with the triangle on each
    // side: sorted, an edge's two triangles are neighbours in the list. The pair of centres
    // either faces each other over an edge between crossings, or was joined by a flip of that
    // edge (`flip::flip_toward_features` runs first): then the two triangles are the same two
    // crossings and centres turned the other way, as flat in the face.
    let mut edges: Vec<((u32, u32), u32)> = Vec::new();
    let fanned = |tri: &&[u32; 3]| tri.iter().any(|&v| fan_centre[v as usize]);
    for (t, tri) in mesh.triangles.iter().enumerate().filter(|(_, tri)| fanned(tri)) {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if fan_centre[a as usize] == fan_centre[b as usize] {
                edges.push(((a.min(b), a.max(b)), t as u32));
            }
        }
    }
    edges.sort_unstable();
    let mut dead = vec![false; mesh.triangles.len()];
    let mut removed = vec![false; mesh.positions.len()];
    let mut welded = 0;
    // Built at the first weld that gets as far as the crossing test.
    let mut nearby: Option<NearbyTriangles> = None;
    for pair in edges.windows(2) {
        let [(e, t1), (f, t2)] = [pair[0], pair[1]];
        if e != f || dead[t1 as usize] || dead[t2 as usize] {
            continue;
        }
        let holds_edge = |t: u32| [e.0, e.1].iter().all(|v| mesh.triangles[t as usize].contains(v));
        if !holds_edge(t1) || !holds_edge(t2) {
            continue; // an end was welded away since the list was made
        }
        let apex = |t: u32| mesh.triangles[t as usize].into_iter().find(|&v| v != e.0 && v != e.1);
        let (Some(x1), Some(x2)) = (apex(t1), apex(t2)) else { continue };
        // The two centres and the two crossings they share, and whether the centres are joined.
        let (c1, c2, mut shared, joined) =
            if fan_centre[e.0 as usize] { (e.0, e.1, [x1, x2], true) } else { (x1, x2, [e.0, e.1], false) };
        shared.sort_unstable();
        let (p1, p2) = (mesh.positions[c1 as usize], mesh.positions[c2 as usize]);
        if c1 == c2 || shared[0] == shared[1] {
            continue;
        }
        if !fan_centre[c1 as usize]
            || !fan_centre[c2 as usize]
            || shared.iter().any(|&v| fan_centre[v as usize])
        {
            continue;
        }
        let Some(on_face) = across_one_grid_plane(p1, p2, grid) else { continue };
        let (ring1, ring2) = (ring(mesh, &incident[c1 as usize], c1), ring(mesh, &incident[c2 as usize], c2));
        let common: Vec<u32> = ring1.iter().copied().filter(|v| ring2.binary_search(v).is_ok()).collect();
        if common != shared || ring1.binary_search(&c2).is_ok() != joined {
            continue;
        }
        let around: Vec<u32> = incident[c1 as usize]
            .iter()
            .chain(&incident[c2 as usize])
            .copied()
            .filter(|&t| t != t1 && t != t2)
            .collect();
        let welded_triangles: Vec<([u32; 3], [Vec3; 3])> = around
            .iter()
            .map(|&t| {
                let tri = mesh.triangles[t as usize].map(|v| if v == c2 { c1 } else { v });
                (tri, tri.map(|v| if v == c1 { on_face } else { mesh.positions[v as usize] }))
            })
            .collect();
        let nearby = nearby.get_or_insert_with(|| NearbyTriangles::new(mesh, grid.1));
        let skip: Vec<u32> = around.iter().copied().chain([t1, t2]).collect();
        if weld_crosses(mesh, nearby, &welded_triangles, &skip) {
            continue;
        }
        for (&t, (_, corners)) in around.iter().zip(&welded_triangles) {
            nearby.insert(t, corners);
        }
        for t in [t1, t2] {
            nearby.remove(t);
            dead[t as usize] = true;
            for v in mesh.triangles[t as usize] {
                incident[v as usize].retain(|&u| u != t);
            }
        }
        for t in std::mem::take(&mut incident[c2 as usize]) {
            mesh.triangles[t as usize].iter_mut().filter(|v| **v == c2).for_each(|v| *v = c1);
            incident[c1 as usize].push(t);
        }
        mesh.positions[c1 as usize] = on_face;
        feature_vertex[c1 as usize] |= feature_vertex[c2 as usize];
        removed[c2 as usize] = true;
        welded += 1;
    }
    if welded > 0 {
        compact(mesh, [fan_centre, feature_vertex], crease, &removed, &dead);
    }
    welded
}

/// Whether a weld's triangles around the welded vertex (ids and corners, the vertex at its new
/// place) would cross a triangle near them other than those in `skip` (the ones they replace and
/// the two the weld drops), or one another.
fn weld_crosses(
    mesh: &Mesh,
    nearby: &mut NearbyTriangles,
    welded: &[([u32; 3], [Vec3; 3])],
    skip: &[u32],
) -> bool {
    let d64 = |c: &[Vec3; 3]| c.map(|p| p.as_dvec3());
    nearby.any_crosses(mesh, welded, skip)
        || welded.iter().enumerate().any(|(i, (a, ca))| {
            welded[i + 1..].iter().any(|(b, cb)| indexed_pair_intersects((*a, d64(ca)), (*b, d64(cb))))
        })
}

/// How far (in cells) two centres' other coordinates may differ and still count as one point: the
/// two cells place their centres each from its own arithmetic, and a millionth of a cell (what
/// this was) is under one rounding step of a coordinate near 0.36 at 128 cells (seed 18245 of
/// `cone_apexes_in_grid_planes_leave_no_fins`: 3e-8 apart, 2e-6 of a cell).
const SAME: f32 = 1e-4;

/// Where two centres kept [`INSET`] off either side of one grid plane (the grid's origin and
/// spacing in `grid`) meet in it: their midpoint, put on the plane; `None` unless they differ along
/// one axis alone (to [`SAME`] of the spacing), by at most 2.25 insets there, across a plane.
fn across_one_grid_plane(p1: Vec3, p2: Vec3, (origin, spacing): (Vec3, Vec3)) -> Option<Vec3> {
    let d = (p2 - p1).abs();
    let axis = d.max_position();
    let same = (0..3).all(|a| a == axis || d[a] <= SAME * spacing[a]);
    if !same || d[axis] > 2.25 * INSET * spacing[axis] {
        return None;
    }
    let mut mid = (p1 + p2) * 0.5;
    let plane = origin[axis] + ((mid[axis] - origin[axis]) / spacing[axis]).round() * spacing[axis];
    let (lo, hi) = (p1[axis].min(p2[axis]), p1[axis].max(p2[axis]));
    if !(lo < plane && plane < hi) {
        return None;
    }
    mid[axis] = plane;
    Some(mid)
}

/// The triangles at each fan centre and at each vertex of a fan centre's one-ring; other
/// vertices' lists are left empty. Both passes here only look at fan centres and at crossings
/// next to one, and building lists for every vertex (over 200 000 at 256 cells) cost more than
/// the passes.
fn incident_near_centres(mesh: &Mesh, fan_centre: &[bool]) -> Vec<Vec<u32>> {
    let mut near = vec![false; mesh.positions.len()];
    for tri in mesh.triangles.iter().filter(|tri| tri.iter().any(|&v| fan_centre[v as usize])) {
        tri.iter().for_each(|&v| near[v as usize] = true);
    }
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri.iter().filter(|&&v| near[v as usize]) {
            incident[v as usize].push(t as u32);
        }
    }
    incident
}

/// The vertices joined to `v` by the triangles `tris` (each once).
fn ring(mesh: &Mesh, tris: &[u32], v: u32) -> Vec<u32> {
    let mut out: Vec<u32> =
        tris.iter().flat_map(|&t| mesh.triangles[t as usize]).filter(|&u| u != v).collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Whether crossing `a` may collapse into `centre` (whose one-ring is `centre_ring`).
fn can_collapse(
    mesh: &Mesh,
    incident: &[Vec<u32>],
    fan_centre: &[bool],
    a: u32,
    centre: u32,
    centre_ring: &[u32],
    tolerance: f32,
) -> bool {
    let tris = &incident[a as usize];
    let p = |v: u32| mesh.positions[v as usize];
    let plane: Vec3 = tris.iter().map(|&t| mesh.face_normal(t as usize)).sum::<Vec3>().normalize_or_zero();
    if plane == Vec3::ZERO {
        return false;
    }
    let a_ring = ring(mesh, tris, a);
    // Only a closed umbrella (as many neighbours as triangles) may move: a crossing on the mesh's
    // border lies in a face of the grid's bounds, and collapsing it would pull the border inward,
    // off the bounds the surface is clipped by (found by the random unpadded grids).
    if a_ring.len() != tris.len() {
        return false;
    }
    if a_ring.iter().any(|&v| (p(v) - p(a)).dot(plane).abs() > tolerance) {
        return false;
    }
    // Link condition: exactly the two triangles of edge (a, centre), and their two far vertices
    // the only common neighbours.
    let shared = tris.iter().filter(|&&t| mesh.triangles[t as usize].contains(&centre)).count();
    let common = a_ring.iter().filter(|v| centre_ring.binary_search(v).is_ok()).count();
    if shared != 2 || common != 2 {
        return false;
    }
    if a_ring.iter().any(|&v| v != centre && fan_centre[v as usize] && centre_ring.binary_search(&v).is_err())
    {
        return false;
    }
    tris.iter().map(|&t| mesh.triangles[t as usize]).filter(|tri| !tri.contains(&centre)).all(|tri| {
        let [x, y, z] = tri.map(|v| if v == a { p(centre) } else { p(v) });
        (y - x).cross(z - x).normalize_or_zero().dot(plane) >= MIN_NORMAL_COSINE
    })
}

/// Replaces `a` by `centre` in its triangles; the two that held both die.
fn collapse(mesh: &mut Mesh, incident: &mut [Vec<u32>], dead: &mut [bool], a: u32, centre: u32) {
    for t in std::mem::take(&mut incident[a as usize]) {
        let tri = &mut mesh.triangles[t as usize];
        if tri.contains(&centre) {
            dead[t as usize] = true;
            for v in *tri {
                incident[v as usize].retain(|&u| u != t);
            }
        } else {
            tri.iter_mut().filter(|v| **v == a).for_each(|v| *v = centre);
            incident[centre as usize].push(t);
        }
    }
}

/// Drops removed vertices and dead triangles, renumbering what is left.
fn compact(
    mesh: &mut Mesh,
    flags: [&mut Vec<bool>; 2],
    crease: &mut Vec<Vec3>,
    removed: &[bool],
    dead: &[bool],
) {
    let mut new_index = vec![u32::MAX; removed.len()];
    let mut next = 0u32;
    for (v, &gone) in removed.iter().enumerate() {
        if !gone {
            new_index[v] = next;
            next += 1;
        }
    }
    let keep = |v: &usize| !removed[*v];
    mesh.positions = (0..removed.len()).filter(keep).map(|v| mesh.positions[v]).collect();
    if !mesh.normals.is_empty() {
        mesh.normals = (0..removed.len()).filter(keep).map(|v| mesh.normals[v]).collect();
    }
    for flag in flags {
        *flag = (0..removed.len()).filter(keep).map(|v| flag[v]).collect();
    }
    *crease = (0..removed.len()).filter(keep).map(|v| crease[v]).collect();
    let triangles = std::mem::take(&mut mesh.triangles);
    mesh.triangles = triangles
        .into_iter()
        .zip(dead)
        .filter(|(_, &d)| !d)
        .map(|(t, _)| t.map(|v| new_index[v as usize]))
        .collect();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::fixtures;
    use crate::mesh::analysis::topology;

    /// A flat square of crossings around a centre vertex, closed by a pyramid below: the centre
    /// (fan centre) and its neighbours all lie in z = 0.
    fn flat_patch() -> Mesh {
        // 0..8: ring of the square (corners and mid-edges), 8: centre, 9: near crossing, 10: apex.
        let positions = [
            [-1.0, -1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.3, 0.1, 0.0],
            [0.0, 0.0, -1.0],
        ];
        // Upward-facing triangles: ring vertices 0..8 around the centre 8, with 9 inserted
        // between the centre and ring vertices 2, 3, 4.
        let mut triangles: Vec<[u32; 3]> =
            vec![[8, 0, 1], [8, 1, 2], [8, 4, 5], [8, 5, 6], [8, 6, 7], [8, 7, 0]];
        triangles.extend([[8, 2, 9], [9, 2, 3], [9, 3, 4], [8, 9, 4]]);
        // Pyramid below, facing down.
        for k in 0..8u32 {
            triangles.push([10, (k + 1) % 8, k]);
        }
        fixtures::mesh(&positions, &triangles)
    }

    #[test]
    fn a_flat_crossing_collapses_into_its_fan_centre_without_changing_area_or_topology() {
        let mut mesh = flat_patch();
        let before = topology(&mesh);
        let area = crate::mesh::analysis::quality::surface_area(&mesh);
        let mut centre = vec![false; 11];
        centre[8] = true;
        let mut feature = centre.clone();
        assert_eq!(
            merge_flat_crossings(&mut mesh, &mut centre, &mut feature, &mut vec![Vec3::ZERO; 11], 1.0),
            1
        );
        assert_eq!(mesh.vertex_count(), 10);
        assert_eq!(mesh.triangle_count(), 16);
        assert_eq!(feature.iter().filter(|&&f| f).count(), 1);
        let after = topology(&mesh);
        assert!(after.is_closed_manifold());
        assert_eq!(after.euler, before.euler);
        let area_after = crate::mesh::analysis::quality::surface_area(&mesh);
        assert!((area - area_after).abs() < 1e-6, "{area} vs {area_after}");
        // The nearest crossing went: no vertex left at (0.3, 0.1, 0).
        assert!(mesh.positions.iter().all(|p| p.distance(Vec3::new(0.3, 0.1, 0.0)) > 1e-6));
    }

    #[test]
    fn a_crossing_off_the_plane_stays() {
        let mut mesh = flat_patch();
        mesh.positions[9].z = 0.01;
        let mut centre = vec![false; 11];
        centre[8] = true;
        let mut feature = centre.clone();
        // Ring vertices 1..7 are flat around their own neighbours, but each is joined to the apex
        // below, so none is flat; the raised crossing is off its plane by 0.01 > 1e-3.
        assert_eq!(
            merge_flat_crossings(&mut mesh, &mut centre, &mut feature, &mut vec![Vec3::ZERO; 11], 1.0),
            0
        );
        assert_eq!(mesh.triangle_count(), 18);
    }

    #[test]
    fn a_collapse_that_would_join_two_fan_centres_is_refused() {
        let mut mesh = flat_patch();
        // Make ring vertex 3 (a neighbour of crossing 9, not of centre 8) a second fan centre.
        let mut centre = vec![false; 11];
        centre[8] = true;
        centre[3] = true;
        let mut feature = centre.clone();
        assert_eq!(
            merge_flat_crossings(&mut mesh, &mut centre, &mut feature, &mut vec![Vec3::ZERO; 11], 1.0),
            0
        );
    }

    /// A grid of unit cells from the origin: z = 0 is one of its planes.
    const UNIT_GRID: (Vec3, Vec3) = (Vec3::ZERO, Vec3::ONE);

    /// Two fans either side of the plane z = 0, centres 0.02 apart, sharing the edge (a, b) in
    /// it: the fan above over (a, b, p), the one below over (b, a, r).
    fn back_to_back_fans() -> Mesh {
        // 0: a, 1: b, 2: p (above), 3: r (below), 4: centre above, 5: centre below.
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 1.0],
            [0.5, 1.0, -1.0],
            [0.5, 0.3, 0.01],
            [0.5, 0.3, -0.01],
        ];
        let triangles = [[4, 0, 1], [4, 1, 2], [4, 2, 0], [5, 1, 0], [5, 0, 3], [5, 3, 1]];
        fixtures::mesh(&positions, &triangles)
    }

    #[test]
    fn fan_centres_back_to_back_across_a_face_are_welded_on_it() {
        let mut mesh = back_to_back_fans();
        let before = topology(&mesh);
        let (mut centre, mut feature) = (vec![false, false, false, false, true, true], vec![false; 6]);
        feature[5] = true;
        let mut crease = vec![Vec3::ZERO; 6];
        assert_eq!(weld_facing_centres(&mut mesh, &mut centre, &mut feature, &mut crease, UNIT_GRID), 1);
        assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (5, 4));
        assert_eq!(centre, [false, false, false, false, true]);
        assert_eq!(feature, [false, false, false, false, true], "the weld keeps either's feature flag");
        assert_eq!(mesh.positions[4], Vec3::new(0.5, 0.3, 0.0), "the welded vertex lies on the face");
        assert!(mesh.triangles.iter().all(|t| t.contains(&4)), "one fan around it");
        let after = topology(&mesh);
        assert_eq!((after.euler, after.boundary_edges), (before.euler, before.boundary_edges));
        assert_eq!(after.non_manifold_edges, 0);
    }

    #[test]
    fn fan_centres_too_far_apart_aside_or_sharing_more_than_the_edge_stay() {
        let mut far = back_to_back_fans();
        far.positions[5].z = -0.2;
        let (mut centre, mut feature) = (vec![false, false, false, false, true, true], vec![false; 6]);
        assert_eq!(
            weld_facing_centres(&mut far, &mut centre, &mut feature, &mut vec![Vec3::ZERO; 6], UNIT_GRID),
            0
        );
        // Near, but not one point's two insets: they differ across the face too.
        let mut aside = back_to_back_fans();
        aside.positions[5].x += 0.01;
        let (mut centre, mut feature) = (vec![false, false, false, false, true, true], vec![false; 6]);
        let welded =
            weld_facing_centres(&mut aside, &mut centre, &mut feature, &mut vec![Vec3::ZERO; 6], UNIT_GRID);
        assert_eq!(welded, 0);
        // Both fans over the same triangle (a, b, p): welding would leave two triangles on one
        // edge pair, a closed pillow flattened.
        let mut pillow = fixtures::mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, 0.3, 0.01], [0.5, 0.3, -0.01]],
            &[[3, 0, 1], [3, 1, 2], [3, 2, 0], [4, 1, 0], [4, 2, 1], [4, 0, 2]],
        );
        let (mut centre, mut feature) = (vec![false, false, false, true, true], vec![false; 5]);
        let welded =
            weld_facing_centres(&mut pillow, &mut centre, &mut feature, &mut vec![Vec3::ZERO; 5], UNIT_GRID);
        assert_eq!((welded, pillow.triangle_count()), (0, 6));
    }
}

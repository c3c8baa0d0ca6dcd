//! Sliver collapse (§4 of the paper, in the form that needs no restricted QEF): a crossing that
//! root finding put within [`SNAP`] of a finest cell of one of its dual edge's ends is moved onto
//! that end, and all crossings moved onto one dual vertex become one mesh vertex. The triangles
//! between them shrink to nothing and are dropped; what they were is the fan of slivers Marching
//! Cubes makes around a dual vertex that lies almost on the surface (a crease vertex, most often).
//!
//! A dual vertex that close to the surface is within `SNAP` cells of it, so the distance bound
//! moves by at most that much. Collapsing can join two sheets that pass on either side of one
//! vertex (a wall thinner than `2 * SNAP` cells); the contour's topology is compared before and
//! after, and where it changed, nothing is collapsed.

use super::contour::{Contour, DualVertices};
use crate::mesh::analysis;

/// How close to a dual vertex (in finest cells) a crossing is moved onto it.
pub const SNAP: f32 = 0.1;

/// Collapses the slivers of `contour` (dual vertices in `vertices`, finest cells of side `h`);
/// how many triangles went.
pub fn collapse(contour: &mut Contour, vertices: &DualVertices, h: f32) -> usize {
    let reach = SNAP * h;
    let n = contour.crossings.len();
    let mut snapped_to = vec![u32::MAX; vertices.positions.len()];
    let mut remap: Vec<u32> = (0..n as u32).collect();
    let mut positions = contour.mesh.positions.clone();
    for (i, c) in contour.crossings.iter().enumerate() {
        let (a, b) = (vertices.positions[c.inside as usize], vertices.positions[c.outside as usize]);
        let length = (b - a).length();
        let end = if c.t * length < reach {
            c.inside
        } else if (1.0 - c.t) * length < reach {
            c.outside
        } else {
            continue;
        };
        let slot = &mut snapped_to[end as usize];
        if *slot == u32::MAX {
            *slot = i as u32;
            positions[i] = vertices.positions[end as usize];
        }
        remap[i] = *slot;
    }
    let mut triangles = Vec::with_capacity(contour.mesh.triangles.len());
    let mut cells = Vec::with_capacity(triangles.capacity());
    for (t, &c) in contour.mesh.triangles.iter().zip(&contour.cell_of_triangle) {
        let v = t.map(|v| remap[v as usize]);
        if v[0] != v[1] && v[1] != v[2] && v[0] != v[2] {
            triangles.push(v);
            cells.push(c);
        }
    }
    let removed = contour.mesh.triangles.len() - triangles.len();
    if removed == 0 {
        return 0;
    }
    let collapsed = crate::mesh::Mesh { positions, normals: Vec::new(), triangles };
    let (before, after) = (analysis::topology(&contour.mesh), analysis::topology(&collapsed));
    let same =
        |t: &analysis::Topology| (t.euler, t.components, t.is_closed_manifold(), t.degenerate_triangles);
    if same(&before) != same(&after) {
        return 0;
    }
    contour.mesh = collapsed;
    contour.cell_of_triangle = cells;
    removed
}

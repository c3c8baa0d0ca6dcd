//! Fans whose centre left its cell, checked against the triangles around them.
//!
//! A feature point may sit up to half a cell outside its cell where the planes meet just beyond it
//! (see [`super::placement`]); that keeps creases that skim a cell's corner on the crease. Inside
//! its cell a fan is the cone from its centre over a closed curve on the cell's boundary, so it
//! meets nothing outside the cell but its own polygon's edges, and extraction decides it against
//! the cell's other components; outside, it can cut a neighbour's triangles, as on the gyroid's
//! tightly curved sheets at res 24. Before the edge flips it also pokes through the neighbour's
//! triangles that the flips then replace by ones reaching its centre, so the check runs after the
//! flips: each such fan is tested against the triangles near it (see [`super::nearby`]), and one
//! that cuts any has its centre moved to its best point inside the cell. Only vertex positions
//! change, never the connectivity, so the mesh stays MC's topology.

use super::feature::FeatureKind;
use super::nearby::NearbyTriangles;
use super::placement::Placement;
use crate::mesh::analysis::bvh::Aabb;
use crate::mesh::Mesh;
use glam::Vec3;
use rustc_hash::FxHashMap as HashMap;

/// A fan whose centre lies outside its cell, and where it would go inside.
#[derive(Debug, Clone, Copy)]
pub struct OutsideFan {
    pub vertex: u32,
    pub cell: [usize; 3],
    pub kind: FeatureKind,
    pub inside: Placement,
}

/// Moves the centre of every fan in `fans` whose triangles (flipped ones included) cross a
/// triangle near them to its inside placement, and takes those fans out of `fans`: the moved
/// ones are returned. `spacing` is the grid's cell. Fans are tested in order against the mesh
/// as it stands, earlier moves included.
pub fn pull_back_crossing_fans(
    mesh: &mut Mesh,
    spacing: Vec3,
    fans: &mut Vec<OutsideFan>,
) -> Vec<OutsideFan> {
    if fans.is_empty() {
        return Vec::new();
    }
    let mut incident: HashMap<u32, Vec<u32>> = fans.iter().map(|f| (f.vertex, Vec::new())).collect();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for v in tri {
            if let Some(list) = incident.get_mut(v) {
                list.push(t as u32);
            }
        }
    }
    // Questions are about these fans' triangles, each corner where it is or, for a centre that
    // may move, where it would go.
    let moves: HashMap<u32, Vec3> = fans.iter().map(|f| (f.vertex, f.inside.position)).collect();
    let region: Vec<Aabb> = incident
        .values()
        .flatten()
        .map(|&t| {
            let tri = mesh.triangles[t as usize];
            let moved = tri.map(|v| moves.get(&v).copied().unwrap_or(mesh.positions[v as usize]));
            Aabb::of_points(&mesh.corners(t as usize)).union(Aabb::of_points(&moved))
        })
        .collect();
    let mut buckets = NearbyTriangles::around(mesh, spacing, &region);
    let mut moved = Vec::new();
    fans.retain(|fan| {
        let own = &incident[&fan.vertex];
        let triangles: Vec<([u32; 3], [Vec3; 3])> =
            own.iter().map(|&s| (mesh.triangles[s as usize], mesh.corners(s as usize))).collect();
        // A fan triangle tested against itself shares its three corners, which never counts.
        let cuts = buckets.any_crosses(mesh, &triangles, &[]);
        if cuts {
            mesh.positions[fan.vertex as usize] = fan.inside.position;
            for &s in own {
                buckets.insert(s, &mesh.corners(s as usize));
            }
            moved.push(*fan);
        }
        !cuts
    });
    moved
}

//! Hand-built meshes with known answers, shared by the analysis and export tests.

use crate::grid::Grid;
use crate::mc::{mesh_field, McOptions};
use crate::mesh::Mesh;
use crate::scenes::Sphere;
use glam::Vec3;

pub fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Mesh {
    Mesh {
        positions: positions.iter().map(|&p| Vec3::from(p)).collect(),
        normals: Vec::new(),
        triangles: triangles.to_vec(),
    }
}

/// The corner of the unit cube: volume 1/6, area 3/2 + sqrt(3)/2.
pub fn tetrahedron() -> Mesh {
    mesh(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

/// Vertices at the unit points of the axes: volume 4/3, area 4 sqrt(3).
pub fn octahedron() -> Mesh {
    let positions = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let mut triangles = Vec::new();
    for sx in [0u32, 1] {
        for sy in [0u32, 1] {
            for sz in [0u32, 1] {
                let (a, b, c) = (sx, 2 + sy, 4 + sz);
                // The octant's sign product decides which winding faces away from the origin.
                let negatives = sx + sy + sz;
                triangles.push(if negatives % 2 == 0 { [a, b, c] } else { [a, c, b] });
            }
        }
    }
    mesh(&positions, &triangles)
}

/// The unit cube `[0, 1]^3` as 12 triangles, vertex `i` at `(i & 1, (i >> 1) & 1, i >> 2)`.
pub fn cube() -> Mesh {
    let positions: Vec<[f32; 3]> =
        (0..8).map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32]).collect();
    mesh(
        &positions,
        &[
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
        ],
    )
}

pub fn translated(mesh: &Mesh, offset: Vec3) -> Mesh {
    let mut out = mesh.clone();
    for p in &mut out.positions {
        *p += offset;
    }
    out
}

/// Both meshes in one, `b`'s indices shifted past `a`'s vertices (nothing is welded).
pub fn merged(a: &Mesh, b: &Mesh) -> Mesh {
    let shift = a.positions.len() as u32;
    let mut out = a.clone();
    out.positions.extend_from_slice(&b.positions);
    out.normals.extend_from_slice(&b.normals);
    out.triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + shift)));
    out
}

pub const SPHERE_RADIUS: f32 = 0.8;

pub fn sphere_field() -> Sphere {
    Sphere { center: Vec3::new(0.013, -0.007, 0.021), radius: SPHERE_RADIUS }
}

/// Marching Cubes of [`sphere_field`] with `res` cells across `[-1, 1]`; the centre is off the grid
/// lattice so no sample sits exactly on the surface by symmetry.
pub fn mc_sphere(res: usize) -> (Mesh, Grid) {
    let grid = Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), res).unwrap();
    let (mesh, _) = mesh_field(&sphere_field(), &grid, &McOptions::default()).unwrap();
    (mesh, grid)
}

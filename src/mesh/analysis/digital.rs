//! An Euler characteristic computed from the samples alone, with no mesh: the independent count a
//! mesher's output is checked against.
//!
//! The inside samples span a cubical complex (points, plus every grid edge, square and cube whose
//! corners are all inside). Its Euler characteristic V - E + F - C is that of the sampled solid; the
//! boundary of a solid has twice its Euler characteristic, so a correct closed surface extracted with
//! the "inside corners stay separated" convention (Marching Cubes' fixed table) has `χ = 2 * this`.

use crate::grid::Grid;

/// Euler characteristic of the cubical complex of samples with `value < iso` (the library's inside
/// rule, see [`crate::mc`]).
///
/// # Panics
/// When `values` does not hold exactly one sample per grid point.
pub fn digital_euler(values: &[f32], grid: &Grid, iso: f32) -> i64 {
    assert_eq!(values.len(), grid.point_count(), "digital_euler needs one value per grid point");
    let [nx, ny, nz] = grid.points();
    let inside: Vec<bool> = values.iter().map(|&v| v < iso).collect();
    let (sx, sy, sz) = (1, nx, nx * ny);
    let mut chi = 0i64;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let n = grid.index(i, j, k);
                if !inside[n] {
                    continue;
                }
                chi += 1;
                // Count each edge, square and cube once, at its lowest corner.
                let ax = i + 1 < nx && inside[n + sx];
                let ay = j + 1 < ny && inside[n + sy];
                let az = k + 1 < nz && inside[n + sz];
                chi -= ax as i64 + ay as i64 + az as i64;
                let sq_xy = ax && ay && inside[n + sx + sy];
                let sq_xz = ax && az && inside[n + sx + sz];
                let sq_yz = ay && az && inside[n + sy + sz];
                chi += sq_xy as i64 + sq_xz as i64 + sq_yz as i64;
                let cube = sq_xy && sq_xz && sq_yz && inside[n + sx + sy + sz];
                chi -= cube as i64;
            }
        }
    }
    chi
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::sample_grid;
    use crate::mesh::analysis::fixtures::{mc_sphere, sphere_field};
    use crate::mesh::analysis::topology;
    use glam::Vec3;

    fn unit_grid(cells: usize) -> Grid {
        Grid::new(Vec3::ZERO, Vec3::splat(cells as f32), [cells; 3]).unwrap()
    }

    #[test]
    fn a_filled_block_is_contractible() {
        let grid = unit_grid(6);
        let block = |p: Vec3| {
            if p.cmpge(Vec3::ONE).all() && p.cmple(Vec3::splat(4.0)).all() {
                -1.0
            } else {
                1.0
            }
        };
        let values = sample_grid(&block, &grid).unwrap();
        assert_eq!(digital_euler(&values, &grid, 0.0), 1);
    }

    #[test]
    fn a_hollow_shell_counts_as_a_sphere_and_a_ring_as_a_circle() {
        let grid = unit_grid(8);
        // Solid 1..=6 minus the inner block 3..=4: a thick shell around a cavity, χ = 2.
        let shell = |p: Vec3| {
            let outer = p.cmpge(Vec3::ONE).all() && p.cmple(Vec3::splat(6.0)).all();
            let inner = p.cmpge(Vec3::splat(3.0)).all() && p.cmple(Vec3::splat(4.0)).all();
            if outer && !inner {
                -1.0
            } else {
                1.0
            }
        };
        let values = sample_grid(&shell, &grid).unwrap();
        assert_eq!(digital_euler(&values, &grid, 0.0), 2);
        // A square ring in the plane z = 2: χ = 0.
        let ring = |p: Vec3| {
            let square = p.x >= 1.0 && p.x <= 5.0 && p.y >= 1.0 && p.y <= 5.0;
            let hole = p.x > 1.5 && p.x < 4.5 && p.y > 1.5 && p.y < 4.5;
            if square && !hole && p.z == 2.0 {
                -1.0
            } else {
                1.0
            }
        };
        let values = sample_grid(&ring, &grid).unwrap();
        assert_eq!(digital_euler(&values, &grid, 0.0), 0);
        // The iso-level moves the inside: nothing is below -2.
        assert_eq!(digital_euler(&values, &grid, -2.0), 0);
        assert_eq!(digital_euler(&values, &grid, 2.0), 1, "everything inside");
    }

    #[test]
    fn mc_sphere_euler_is_twice_the_digital_one() {
        let (mesh, grid) = mc_sphere(20);
        let values = sample_grid(&sphere_field(), &grid).unwrap();
        let digital = digital_euler(&values, &grid, 0.0);
        assert_eq!(digital, 1);
        assert_eq!(topology(&mesh).euler, 2 * digital);
    }
}

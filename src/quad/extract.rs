//! Section 2 of the paper: the outside faces of the data leaves (finest-level cells the surface
//! cuts) as a quad mesh. Faces are connected through reversed edge keys, vertices are duplicated
//! where independent face sets meet, and the singular "platelet holds a vertex twice" case is
//! closed by re-pairing, so the result is always a closed 2-manifold.

use super::mesh::QuadMesh;
use crate::grid::Grid;
use glam::Vec3;
use std::collections::HashMap;

/// What the extraction found, for the stats.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ExtractCounts {
    pub data_leaves: usize,
    /// Grid points that became more than one mesh vertex (Fig. 2b).
    pub duplicated_vertices: usize,
    /// Edges where four faces met and the same-cell rule chose the pairing (Fig. 2a).
    pub four_face_edges: usize,
    /// Singular configurations re-paired to close a one-dimensional hole.
    pub singular_fixes: usize,
}

/// Extracts the quad mesh from samples of a field (inside where `value < 0`) on `grid`.
/// A face is an outside face when it separates a data leaf from a cell with no inside corner;
/// space beyond the grid counts as outside, so the mesh is closed even where the surface is clipped.
pub fn extract(values: &[f32], grid: &Grid) -> (QuadMesh, ExtractCounts) {
    let [cx, cy, cz] = grid.cells;
    let inside = |i: usize, j: usize, k: usize| values[grid.index(i, j, k)] < 0.0;
    // Per cell: number of inside corners (0 = outside cell, 8 = inside cell, else data leaf).
    let cell = |i: usize, j: usize, k: usize| -> u8 {
        (0..8).filter(|&c| inside(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))).count() as u8
    };
    let is_outside = |c: [i64; 3]| -> bool {
        if c.iter().zip(grid.cells).any(|(&x, n)| x < 0 || x >= n as i64) {
            return true;
        }
        cell(c[0] as usize, c[1] as usize, c[2] as usize) == 0
    };

    let mut faces: Vec<[u32; 4]> = Vec::new();
    let mut twin: Vec<u32> = Vec::new();
    let mut open: HashMap<(u32, u32), u32> = HashMap::new();
    let mut counts = ExtractCounts::default();
    for k in 0..cz {
        for j in 0..cy {
            for i in 0..cx {
                let n = cell(i, j, k);
                if n == 0 || n == 8 {
                    continue;
                }
                counts.data_leaves += 1;
                let first = faces.len();
                // All outside faces of this leaf first, then their keys (the paper's rule).
                for axis in 0..3 {
                    for dir in [-1i64, 1] {
                        let mut nb = [i as i64, j as i64, k as i64];
                        nb[axis] += dir;
                        if is_outside(nb) {
                            faces.push(leaf_face(grid, [i, j, k], axis, dir > 0));
                        }
                    }
                }
                twin.resize(faces.len() * 4, u32::MAX);
                for (f, face) in faces.iter().enumerate().skip(first) {
                    for c in 0..4 {
                        let key = (face[c], face[(c + 1) % 4]);
                        let h = (f * 4 + c) as u32;
                        // A used key is discarded, so unused keys stay unique (Fig. 2a).
                        match open.remove(&(key.1, key.0)) {
                            Some(t) => {
                                twin[h as usize] = t;
                                twin[t as usize] = h;
                            }
                            None => {
                                open.insert(key, h);
                            }
                        }
                    }
                }
            }
        }
    }
    debug_assert!(open.is_empty(), "the boundary of a union of cells is closed");
    counts.four_face_edges = count_four_face_edges(&faces);

    let mut corner_vertex;
    let mut fixes = 0;
    loop {
        corner_vertex = fans(&twin);
        match find_singular(&corner_vertex) {
            Some((h1, h2)) if fixes < faces.len() => {
                // Swap partners: h1 and h2 both run u→v; crossing their twins splits the fan.
                let (t1, t2) = (twin[h1], twin[h2]);
                twin[h1] = t2;
                twin[t2 as usize] = h1 as u32;
                twin[h2] = t1;
                twin[t1 as usize] = h2 as u32;
                fixes += 1;
            }
            _ => break,
        }
    }
    counts.singular_fixes = fixes;

    // One mesh vertex per fan, placed a little into its own fan so copies do not coincide.
    let fan_count = corner_vertex.iter().map(|&v| v + 1).max().unwrap_or(0) as usize;
    let mut grid_point = vec![u32::MAX; fan_count];
    let mut centre = vec![Vec3::ZERO; fan_count];
    let mut fans_at: HashMap<u32, u32> = HashMap::new();
    for (h, &v) in corner_vertex.iter().enumerate() {
        let f = &faces[h / 4];
        let g = f[h % 4];
        if grid_point[v as usize] == u32::MAX {
            grid_point[v as usize] = g;
            *fans_at.entry(g).or_default() += 1;
        }
        centre[v as usize] += f.iter().map(|&p| point(grid, p)).sum::<Vec3>() * 0.25;
    }
    counts.duplicated_vertices = fans_at.values().filter(|&&n| n > 1).count();
    let val = corner_vertex.iter().fold(vec![0u32; fan_count], |mut acc, &v| {
        acc[v as usize] += 1;
        acc
    });
    let positions = (0..fan_count)
        .map(|v| {
            let p = point(grid, grid_point[v]);
            if fans_at[&grid_point[v]] > 1 {
                p + (centre[v] / val[v] as f32 - p) * 0.25
            } else {
                p
            }
        })
        .collect();
    let quads = (0..faces.len()).map(|f| [0, 1, 2, 3].map(|c| corner_vertex[f * 4 + c])).collect();
    (QuadMesh { positions, quads }, counts)
}

fn point(grid: &Grid, index: u32) -> Vec3 {
    let [i, j, k] = grid.unindex(index as usize);
    grid.position(i, j, k)
}

/// The face of cell `c` normal to `axis` on its `positive` side, counter-clockwise seen from the
/// neighbour it faces (so the normal points out of the data leaf, away from the solid).
fn leaf_face(grid: &Grid, c: [usize; 3], axis: usize, positive: bool) -> [u32; 4] {
    let (b, d) = ((axis + 1) % 3, (axis + 2) % 3);
    let corner = |u: usize, w: usize| {
        let mut p = c;
        p[axis] += positive as usize;
        p[b] += u;
        p[d] += w;
        grid.index(p[0], p[1], p[2]) as u32
    };
    let f = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
    if positive {
        f
    } else {
        [f[0], f[3], f[2], f[1]]
    }
}

fn count_four_face_edges(faces: &[[u32; 4]]) -> usize {
    let mut n: HashMap<(u32, u32), u8> = HashMap::new();
    for f in faces {
        for c in 0..4 {
            let (a, b) = (f[c], f[(c + 1) % 4]);
            *n.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    n.values().filter(|&&c| c == 4).count()
}

/// Labels every corner (= the half-edge leaving it) with its fan: corners reached from each other
/// by turning around the vertex through paired edges. Each fan becomes one mesh vertex.
fn fans(twin: &[u32]) -> Vec<u32> {
    let mut label = vec![u32::MAX; twin.len()];
    let mut next_label = 0;
    for start in 0..twin.len() {
        if label[start] != u32::MAX {
            continue;
        }
        let mut h = start;
        while label[h] == u32::MAX {
            label[h] = next_label;
            let prev = h - h % 4 + (h + 3) % 4;
            h = twin[prev] as usize;
        }
        next_label += 1;
    }
    label
}

/// Two distinct half-edges joining the same pair of mesh vertices in the same direction: the
/// singular configuration of Fig. 2b (right), where a platelet contains a vertex twice.
fn find_singular(vertex: &[u32]) -> Option<(usize, usize)> {
    let mut seen: HashMap<(u32, u32), usize> = HashMap::new();
    for h in 0..vertex.len() {
        let next = h - h % 4 + (h + 1) % 4;
        if let Some(&other) = seen.get(&(vertex[h], vertex[next])) {
            return Some((other, h));
        }
        seen.insert((vertex[h], vertex[next]), h);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic xorshift: every sign pattern the tests try is reproducible.
    fn signs(seed: u64, n: usize, density: f64) -> Vec<f32> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                if ((s >> 11) as f64 / (1u64 << 53) as f64) < density {
                    -1.0
                } else {
                    1.0
                }
            })
            .collect()
    }

    #[test]
    fn one_inside_point_gives_a_closed_box_of_eight_leaves() {
        let grid = Grid::new(Vec3::ZERO, Vec3::splat(4.0), [4, 4, 4]).unwrap();
        let mut v = vec![1.0f32; grid.point_count()];
        v[grid.index(2, 2, 2)] = -1.0;
        let (m, counts) = extract(&v, &grid);
        assert_eq!(counts.data_leaves, 8);
        assert_eq!(m.quad_count(), 24, "the 2x2x2 block's outside: 6 sides of 4 faces");
        assert!(m.is_closed_manifold());
        assert_eq!(m.euler(), 2);
    }

    #[test]
    fn random_sign_patterns_always_give_closed_manifolds() {
        let grid = Grid::new(Vec3::ZERO, Vec3::splat(6.0), [6, 6, 6]).unwrap();
        let mut total = ExtractCounts::default();
        for seed in 1..300u64 {
            // Sparse inside points, away from the border, so leaves meet edge- and corner-wise.
            let mut v = signs(seed * 7919, grid.point_count(), 0.12);
            for (n, x) in v.iter_mut().enumerate() {
                let [i, j, k] = grid.unindex(n);
                if [i, j, k].iter().any(|&c| c == 0 || c == 6) {
                    *x = 1.0;
                }
            }
            let (m, c) = extract(&v, &grid);
            assert!(m.is_closed_manifold(), "seed {seed}: {c:?}");
            total.duplicated_vertices += c.duplicated_vertices;
            total.four_face_edges += c.four_face_edges;
            total.singular_fixes += c.singular_fixes;
        }
        assert!(total.four_face_edges > 0 && total.duplicated_vertices > 0, "{total:?}");
    }
}

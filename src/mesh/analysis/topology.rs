//! Combinatorial topology of a triangle mesh: is it a closed, consistently oriented 2-manifold, and
//! what are its Euler characteristic, components and genus?
//!
//! Everything here depends on the indices only, never on positions (except the degenerate-triangle
//! count), so the verdict cannot be blurred by floating point.
//!
//! Triangles that repeat an index ("collapsed" triangles) are not 2-cells: they are counted in
//! [`Topology::degenerate_triangles`] and otherwise ignored, as are vertices only they reference.

use crate::mesh::Mesh;
use glam::DVec3;
use serde::Serialize;

/// The combinatorial verdict on a mesh. The defect categories are disjoint per edge: an edge with
/// one use is a boundary edge, with three or more a non-manifold edge, and with exactly two uses in
/// the same direction a misoriented edge.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Topology {
    /// Vertices referenced by at least one (non-collapsed) triangle.
    pub vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Non-collapsed triangles.
    pub faces: usize,
    pub boundary_edges: usize,
    pub non_manifold_edges: usize,
    pub misoriented_edges: usize,
    /// Vertices whose incident triangles do not form one fan: see [`topology`] for the exact rule.
    pub non_manifold_vertices: usize,
    /// Triangles with a repeated index or zero area (see [`degenerate_triangles`]). They do not
    /// make a mesh non-manifold, but they break normals, angles and aspect ratios.
    pub degenerate_triangles: usize,
    /// Components connected through shared vertices (so two solids touching at one vertex are one).
    pub components: usize,
    /// V - E + F over the whole mesh.
    pub euler: i64,
    /// Sum of the component genera `(2 - χ) / 2`, when the mesh is a closed oriented manifold.
    pub genus: Option<i64>,
    /// V - E + F of each component, in the order of each component's lowest vertex index.
    pub component_euler: Vec<i64>,
}

impl Topology {
    /// True for a watertight, consistently oriented 2-manifold: what a solid's boundary must be.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.non_manifold_vertices == 0
            && self.misoriented_edges == 0
    }
}

/// Computes the combinatorial topology of `mesh`.
///
/// A vertex is manifold when its *link* (the opposite edges of its incident triangles) is a single
/// simple path (a boundary vertex, an open fan) or a single simple cycle (an interior vertex, a
/// closed umbrella). Two fans meeting at one vertex give a disconnected link; a non-manifold edge
/// gives a link vertex of degree three or more, so the end points of non-manifold edges are counted
/// as non-manifold vertices too: their neighbourhood is not a disc either.
///
/// Indices beyond `positions` are tolerated (the analysis is combinatorial); only the
/// degenerate-triangle count looks at positions.
pub fn topology(mesh: &Mesh) -> Topology {
    let faces: Vec<[u32; 3]> = mesh.triangles.iter().copied().filter(|t| !is_collapsed(t)).collect();
    let vertex_slots = faces.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);

    let mut referenced = vec![false; vertex_slots];
    let mut sets = UnionFind::new(vertex_slots);
    for &[a, b, c] in &faces {
        for v in [a, b, c] {
            referenced[v as usize] = true;
        }
        sets.union(a, b);
        sets.union(a, c);
    }

    // Dense component ids, numbered by each component's lowest vertex.
    let mut component_of = vec![u32::MAX; vertex_slots];
    let mut components = 0usize;
    for v in 0..vertex_slots {
        if referenced[v] {
            let root = sets.find(v as u32) as usize;
            if component_of[root] == u32::MAX {
                component_of[root] = components as u32;
                components += 1;
            }
            component_of[v] = component_of[root];
        }
    }
    let mut component_euler = vec![0i64; components];
    for v in 0..vertex_slots {
        if referenced[v] {
            component_euler[component_of[v] as usize] += 1;
        }
    }
    for t in &faces {
        component_euler[component_of[t[0] as usize] as usize] += 1;
    }

    let mut topo = Topology {
        vertices: referenced.iter().filter(|&&r| r).count(),
        faces: faces.len(),
        components,
        degenerate_triangles: degenerate_triangles(mesh),
        ..Topology::default()
    };
    let component = |v: u32| component_of[v as usize] as usize;
    count_edges_and_vertices(&faces, vertex_slots, &mut topo, component, &mut component_euler);
    topo.euler = topo.vertices as i64 - topo.edges as i64 + topo.faces as i64;
    if topo.is_closed_manifold() {
        topo.genus = Some(component_euler.iter().map(|chi| (2 - chi) / 2).sum());
    }
    topo.component_euler = component_euler;
    topo
}

/// Counts triangles that repeat an index or whose corners are collinear. The area test is exact
/// zero of the cross product in `f64`, where differences and products of `f32` coordinates are
/// (nearly always) exact, so it flags true collinearity and not merely thin slivers: those are the
/// business of [`super::aspect_ratios`]. Triangles with an index beyond `positions` count too.
pub fn degenerate_triangles(mesh: &Mesh) -> usize {
    let corner = |v: u32| mesh.positions.get(v as usize).map(|p| p.as_dvec3());
    mesh.triangles
        .iter()
        .filter(|t| {
            if is_collapsed(t) {
                return true;
            }
            match (corner(t[0]), corner(t[1]), corner(t[2])) {
                (Some(a), Some(b), Some(c)) => (b - a).cross(c - a) == DVec3::ZERO,
                _ => true,
            }
        })
        .count()
}

fn is_collapsed(t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2]
}

/// Incident faces per vertex, compressed rows: vertex `v`'s are `incident[start[v]..start[v + 1]]`.
struct Fans {
    start: Vec<u32>,
    incident: Vec<u32>,
}

impl Fans {
    fn new(faces: &[[u32; 3]], vertex_slots: usize) -> Fans {
        let mut start = vec![0u32; vertex_slots + 1];
        for &v in faces.iter().flatten() {
            start[v as usize + 1] += 1;
        }
        for v in 0..vertex_slots {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut incident = vec![0u32; faces.len() * 3];
        for (f, t) in faces.iter().enumerate() {
            for &v in t {
                incident[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        Fans { start, incident }
    }

    fn of(&self, v: usize) -> &[u32] {
        &self.incident[self.start[v] as usize..self.start[v + 1] as usize]
    }
}

/// An edge of a vertex's link: the side of one of its triangles opposite it.
type LinkEdge = (u32, u32);
/// One triangle's use of an edge from a vertex: the edge's other end, and whether the use runs
/// from the lower end to the upper.
type EdgeUse = (u32, bool);

/// Fans up to this many triangles are checked in arrays on the stack (a closed mesh's vertices
/// have six on average); larger ones in vectors.
const SMALL_FAN: usize = 24;

/// Counts and classifies the edges and applies the link rule of [`topology`] to every referenced
/// vertex, in one pass over the vertices' fans: an edge is counted at its lower end, from the
/// uses its fan's triangles make of it (a sort of all the directed edges and a vector per vertex
/// were most of the time of the stats on a 24 000-triangle mesh).
fn count_edges_and_vertices(
    faces: &[[u32; 3]],
    vertex_slots: usize,
    topo: &mut Topology,
    component: impl Fn(u32) -> usize,
    component_euler: &mut [i64],
) {
    let fans = Fans::new(faces, vertex_slots);
    let mut link_buffer = Vec::new();
    let mut uses_buffer = Vec::new();
    let mut nodes = Vec::new();
    for v in 0..vertex_slots {
        let fan = fans.of(v);
        if fan.is_empty() {
            continue;
        }
        let (mut small_link, mut small_uses) = ([(0u32, 0u32); SMALL_FAN], [(0u32, false); 2 * SMALL_FAN]);
        let (link, uses): (&mut [LinkEdge], &mut [EdgeUse]) = if fan.len() <= SMALL_FAN {
            (&mut small_link[..fan.len()], &mut small_uses[..2 * fan.len()])
        } else {
            link_buffer.resize(fan.len(), (0, 0));
            uses_buffer.resize(2 * fan.len(), (0, false));
            (&mut link_buffer[..], &mut uses_buffer[..])
        };
        // The link edge opposite `v` in each triangle, and the triangle's uses of the edges at
        // `v`: from `v` to the next corner (forward, as the edge's key runs from its lower end,
        // when that corner is above `v`) and from the previous corner to `v`.
        let mut owned = 0;
        for (i, &f) in fan.iter().enumerate() {
            let t = faces[f as usize];
            let k = t.iter().position(|&c| c as usize == v).unwrap_or(0);
            let (next, prev) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            link[i] = (next, prev);
            if next as usize > v {
                uses[owned] = (next, true);
                owned += 1;
            }
            if prev as usize > v {
                uses[owned] = (prev, false);
                owned += 1;
            }
        }
        let uses = &mut uses[..owned];
        uses.sort_unstable_by_key(|u| u.0);
        for run in uses.chunk_by(|x, y| x.0 == y.0) {
            topo.edges += 1;
            component_euler[component(v as u32)] -= 1;
            let forward = run.iter().filter(|e| e.1).count();
            match run.len() {
                1 => topo.boundary_edges += 1,
                2 if forward != 1 => topo.misoriented_edges += 1,
                2 => {}
                _ => topo.non_manifold_edges += 1,
            }
        }
        let manifold = if fan.len() <= SMALL_FAN {
            small_link_is_path_or_cycle(link)
        } else {
            link_is_path_or_cycle(link, &mut nodes)
        };
        if !manifold {
            topo.non_manifold_vertices += 1;
        }
    }
}

/// [`link_is_path_or_cycle`] for at most [`SMALL_FAN`] edges, on the stack: a path or a cycle
/// has at most as many nodes as edges plus one, each node's degree is counted where it is
/// found, and the components are joined in a union-find of the nodes' slots.
fn small_link_is_path_or_cycle(link: &[(u32, u32)]) -> bool {
    let mut nodes = [0u32; 2 * SMALL_FAN];
    let mut degree = [0u8; 2 * SMALL_FAN];
    let mut parent = [0u8; 2 * SMALL_FAN];
    let mut count = 0usize;
    let mut slot = |v: u32, nodes: &mut [u32], degree: &mut [u8], parent: &mut [u8]| -> usize {
        let s = nodes[..count].iter().position(|&n| n == v).unwrap_or_else(|| {
            nodes[count] = v;
            parent[count] = count as u8;
            count += 1;
            count - 1
        });
        degree[s] = degree[s].saturating_add(1);
        s
    };
    let find = |parent: &mut [u8], mut x: usize| {
        while parent[x] as usize != x {
            parent[x] = parent[parent[x] as usize];
            x = parent[x] as usize;
        }
        x
    };
    let mut merges = 0;
    for &(a, b) in link {
        let a = slot(a, &mut nodes, &mut degree, &mut parent);
        let b = slot(b, &mut nodes, &mut degree, &mut parent);
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb) as u8;
            merges += 1;
        }
    }
    merges + 1 == count && degree[..count].iter().all(|&d| d <= 2)
}

/// True when the edges form one connected graph whose nodes all have degree at most two: a simple
/// path or a simple cycle (a doubled edge counts as a two-cycle, as for a doubled triangle).
fn link_is_path_or_cycle(link: &[(u32, u32)], nodes: &mut Vec<u32>) -> bool {
    nodes.clear();
    nodes.extend(link.iter().flat_map(|&(a, b)| [a, b]));
    nodes.sort_unstable();
    nodes.dedup();
    let local = |v: u32| nodes.binary_search(&v).unwrap_or(0) as u32;
    let mut degree = vec![0u8; nodes.len()];
    let mut sets = UnionFind::new(nodes.len());
    let mut merges = 0;
    for &(a, b) in link {
        let (a, b) = (local(a), local(b));
        for x in [a, b] {
            degree[x as usize] = degree[x as usize].saturating_add(1);
        }
        if sets.union(a, b) {
            merges += 1;
        }
    }
    merges + 1 == nodes.len() && degree.iter().all(|&d| d <= 2)
}

/// Disjoint sets over `0..n` with path halving (union by index keeps it short enough here).
#[derive(Default)]
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        UnionFind { parent: (0..n as u32).collect() }
    }

    /// Back to `n` singletons, keeping the allocation (for callers that use one per query).
    pub(crate) fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// Joins the sets of `a` and `b`; false when they were already one.
    pub(crate) fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        // Lower root wins, so a component's root is its lowest vertex.
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        self.parent[hi as usize] = lo;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::analysis::digital_euler;
    use crate::mesh::analysis::fixtures::*;
    use glam::Vec3;

    fn assert_closed_sphere(mesh: &Mesh) {
        let t = topology(mesh);
        assert!(t.is_closed_manifold(), "{t:?}");
        assert_eq!(t.euler, 2);
        assert_eq!(t.genus, Some(0));
        assert_eq!(t.components, 1);
        assert_eq!(t.component_euler, vec![2]);
        assert_eq!(t.degenerate_triangles, 0);
    }

    #[test]
    fn tetrahedron_octahedron_and_cube_are_closed_spheres() {
        let tet = topology(&tetrahedron());
        assert_eq!((tet.vertices, tet.edges, tet.faces), (4, 6, 4));
        let oct = topology(&octahedron());
        assert_eq!((oct.vertices, oct.edges, oct.faces), (6, 12, 8));
        let box12 = topology(&cube());
        assert_eq!((box12.vertices, box12.edges, box12.faces), (8, 18, 12));
        for m in [tetrahedron(), octahedron(), cube()] {
            assert_closed_sphere(&m);
        }
    }

    #[test]
    fn a_missing_face_leaves_a_boundary_loop() {
        let mut m = octahedron();
        m.triangles.pop();
        let t = topology(&m);
        assert_eq!(t.boundary_edges, 3);
        assert_eq!(t.euler, 1);
        assert_eq!(t.non_manifold_vertices, 0, "open fans are manifold");
        assert!(!t.is_closed_manifold());
        assert_eq!(t.genus, None);
    }

    #[test]
    fn a_flipped_face_has_three_misoriented_edges() {
        let mut m = octahedron();
        m.triangles[3].swap(1, 2);
        let t = topology(&m);
        assert_eq!(t.misoriented_edges, 3);
        assert_eq!(t.boundary_edges, 0);
        assert!(!t.is_closed_manifold());
        assert_eq!(t.genus, None);
    }

    #[test]
    fn tetrahedra_sharing_a_vertex_make_one_non_manifold_vertex() {
        let a = tetrahedron();
        // Reflect through the origin (and re-wind) so only vertex 0 coincides; then weld it.
        let mut b = translated(&a, Vec3::ZERO);
        for p in &mut b.positions {
            *p = -*p;
        }
        for t in &mut b.triangles {
            t.swap(1, 2);
        }
        let mut m = merged(&a, &b);
        for t in &mut m.triangles[4..] {
            for v in t.iter_mut() {
                if *v == 4 {
                    *v = 0;
                }
            }
        }
        let t = topology(&m);
        assert_eq!(t.non_manifold_vertices, 1);
        assert_eq!(t.non_manifold_edges, 0);
        assert_eq!(t.boundary_edges, 0);
        assert_eq!(t.components, 1);
        assert_eq!(t.vertices, 7);
        assert_eq!(t.euler, 7 - 12 + 8);
        assert!(!t.is_closed_manifold());
    }

    #[test]
    fn three_faces_on_an_edge_are_non_manifold() {
        let mut m = tetrahedron();
        m.positions.push(Vec3::new(1.0, 1.0, -1.0));
        m.triangles.push([0, 4, 1]);
        let t = topology(&m);
        assert_eq!(t.non_manifold_edges, 1);
        assert_eq!(t.boundary_edges, 2);
        assert_eq!(t.non_manifold_vertices, 2, "both ends of the fin's edge");
    }

    #[test]
    fn disjoint_solids_are_separate_components() {
        let m = merged(&cube(), &translated(&octahedron(), Vec3::new(5.0, 0.0, 0.0)));
        let t = topology(&m);
        assert!(t.is_closed_manifold());
        assert_eq!(t.components, 2);
        assert_eq!(t.component_euler, vec![2, 2]);
        assert_eq!(t.euler, 4);
        assert_eq!(t.genus, Some(0));
    }

    #[test]
    fn degenerate_triangles_are_counted_and_collapsed_ones_ignored() {
        let mut m = octahedron();
        m.triangles.push([0, 0, 1]);
        m.positions.push(Vec3::new(2.0, 0.0, 0.0));
        // Collinear: +x, the origin side (-x) and (2, 0, 0) lie on the x axis.
        m.triangles.push([0, 1, 6]);
        assert_eq!(degenerate_triangles(&m), 2);
        let t = topology(&m);
        assert_eq!(t.degenerate_triangles, 2);
        assert_eq!(t.faces, 9, "the collinear triangle is a 2-cell, the collapsed one is not");
    }

    /// The edge and vertex counts as first written (all directed edges sorted; each vertex's
    /// link in vectors), kept as the reference the one-pass count must match.
    fn reference_counts(faces: &[[u32; 3]], vertex_slots: usize) -> [usize; 5] {
        let mut directed: Vec<(u64, bool)> = Vec::new();
        for t in faces {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                directed.push(((a.min(b) as u64) << 32 | a.max(b) as u64, a < b));
            }
        }
        directed.sort_unstable();
        let [mut edges, mut boundary, mut misoriented, mut non_manifold] = [0; 4];
        for run in directed.chunk_by(|x, y| x.0 == y.0) {
            edges += 1;
            let forward = run.iter().filter(|e| e.1).count();
            match run.len() {
                1 => boundary += 1,
                2 if forward != 1 => misoriented += 1,
                2 => {}
                _ => non_manifold += 1,
            }
        }
        let mut vertices = 0;
        let mut nodes = Vec::new();
        for v in 0..vertex_slots as u32 {
            let link: Vec<(u32, u32)> = faces
                .iter()
                .filter_map(|t| t.iter().position(|&c| c == v).map(|k| (t[(k + 1) % 3], t[(k + 2) % 3])))
                .collect();
            if !link.is_empty() && !link_is_path_or_cycle(&link, &mut nodes) {
                vertices += 1;
            }
        }
        [edges, boundary, misoriented, non_manifold, vertices]
    }

    /// Random meshes of every defect: a closed MC sphere with faces removed, flipped, doubled
    /// and vertices welded, and soups of triangles over a few vertices (fins, pinched fans, and
    /// half of them around one hub vertex whose fan outgrows the stack arrays).
    #[test]
    fn one_pass_counts_match_the_reference_on_random_meshes() {
        let mut rng = crate::expr::testutil::Rng::new(5);
        let (sphere, _) = mc_sphere(10);
        let mut largest_fan = 0;
        for case in 0..300 {
            let mut triangles = if case % 2 == 0 {
                let mut t = sphere.triangles.clone();
                for _ in 0..rng.below(6) {
                    let f = rng.below(t.len());
                    match rng.below(4) {
                        0 => {
                            t.remove(f);
                        }
                        1 => t[f].swap(1, 2),
                        2 => t.push(t[f]),
                        _ => {
                            let (a, b) = (t[f][0], t[rng.below(t.len())][1]);
                            for tri in t.iter_mut() {
                                for c in tri.iter_mut() {
                                    if *c == b {
                                        *c = a;
                                    }
                                }
                            }
                        }
                    }
                }
                t
            } else {
                let n = 3 + rng.below(12) as u32;
                let hub = rng.below(2) == 0;
                (0..1 + rng.below(60))
                    .map(|_| {
                        let mut c = || rng.below(n as usize) as u32;
                        [if hub { 0 } else { c() }, c(), c()]
                    })
                    .collect::<Vec<_>>()
            };
            triangles.retain(|t| !is_collapsed(t));
            let slots = triangles.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);
            let mesh = Mesh {
                positions: vec![Vec3::ZERO; slots],
                normals: Vec::new(),
                triangles: triangles.clone(),
            };
            let t = topology(&mesh);
            let got = [
                t.edges,
                t.boundary_edges,
                t.misoriented_edges,
                t.non_manifold_edges,
                t.non_manifold_vertices,
            ];
            assert_eq!(got, reference_counts(&triangles, slots), "case {case}: {triangles:?}");
            let fans = (0..slots as u32).map(|v| triangles.iter().filter(|t| t.contains(&v)).count());
            largest_fan = largest_fan.max(fans.max().unwrap_or(0));
        }
        assert!(largest_fan > SMALL_FAN, "no fan took the vectors' path ({largest_fan})");
    }

    #[test]
    fn mc_sphere_is_a_closed_sphere_at_several_resolutions() {
        for res in [12, 24, 40] {
            let (m, _) = mc_sphere(res);
            assert!(m.triangle_count() > 100);
            assert_closed_sphere(&m);
        }
    }

    #[test]
    fn mc_torus_has_genus_one_and_twice_the_digital_euler_number() {
        let torus = crate::scenes::Torus { major: 0.6, minor: 0.25 };
        let grid = crate::grid::Grid::with_resolution(Vec3::splat(-1.0), Vec3::splat(1.0), 40).unwrap();
        let (m, _) = crate::mc::mesh_field(&torus, &grid, &crate::mc::McOptions::default()).unwrap();
        let t = topology(&m);
        assert!(t.is_closed_manifold(), "{t:?}");
        assert_eq!(t.euler, 0);
        assert_eq!(t.genus, Some(1));
        let values = crate::field::sample_grid(&torus, &grid).unwrap();
        assert_eq!(t.euler, 2 * digital_euler(&values, &grid, 0.0));
    }
}

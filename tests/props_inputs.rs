//! Seeded random triangle meshes and oriented point clouds, remeshed by EMC and by MC on the
//! same grid: closed inputs (several overlapping shells, turned inside out), and damaged ones
//! (duplicated triangles, zero-area triangles, a hole). The source shapes are random CSG trees
//! (`common::csg`) meshed by MC; the inputs are what a stranger's exporter would hand over.
//!
//! `ISOFORGE_SEED=S` reruns one case, `ISOFORGE_SOAK=N` runs N per property.

mod common;

use common::csg::random_tree;
use common::{bare_request, boundary_edges, case_seeds, Rng};
use isoforge::emc::mesh_source::padded_grid;
use isoforge::expr;
use isoforge::input::PointCloud;
use isoforge::mesh::analysis;
use isoforge::pipeline::{self, Method, Output};
use isoforge::{Field, Grid, Mesh, Vec3};

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;
#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_dedicated_worker);

const CI_CASES: usize = 16;

/// A closed mesh of a random tree at least 0.05 across (trees whose parts all fall outside the
/// bounds are skipped by drawing again) at `coarsest` to `coarsest + 9` cells, and its
/// program's text.
fn source_mesh(rng: &mut Rng, coarsest: usize) -> (Mesh, String) {
    loop {
        let tree = random_tree(rng);
        let program = expr::compile(&tree.text).unwrap();
        let res = coarsest + rng.below(10) as usize;
        let out = pipeline::mesh_program(&program, &bare_request(Method::Mc, res)).unwrap();
        // A speck (a part grazing the bounds can leave one) is too small for f32 to grid at the
        // coordinates it sits at, which the pipeline refuses as it should: draw again.
        let (lo, hi) = isoforge::emc::mesh_source::mesh_bounds(&out.mesh);
        if out.stats.closed_manifold && out.mesh.triangle_count() > 0 && (hi - lo).max_element() > 0.05 {
            return (out.mesh, tree.text);
        }
    }
}

/// How a case damages or rearranges its source mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Damage {
    /// As exported: closed and outward.
    None,
    /// Every triangle wound the other way (an inside-out export).
    Inverted,
    /// A second closed shell overlapping the first (a union the exporter did not compute).
    Overlapping,
    /// Some triangles listed twice.
    Duplicated,
    /// Zero-area triangles (a corner repeated) added.
    Degenerate,
}

const DAMAGES: [Damage; 5] =
    [Damage::None, Damage::Inverted, Damage::Overlapping, Damage::Duplicated, Damage::Degenerate];

fn damaged(rng: &mut Rng, mesh: &Mesh, damage: Damage) -> Mesh {
    let mut out = mesh.clone();
    let n = mesh.triangles.len();
    match damage {
        Damage::None => {}
        Damage::Inverted => out.triangles.iter_mut().for_each(|t| t.swap(1, 2)),
        Damage::Overlapping => {
            let shift = Vec3::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), rng.range(-0.3, 0.3));
            let base = out.positions.len() as u32;
            out.positions.extend(mesh.positions.iter().map(|&p| p + shift));
            out.triangles.extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
        }
        Damage::Duplicated => {
            for _ in 0..1 + n / 20 {
                out.triangles.push(mesh.triangles[rng.below(n as u64) as usize]);
            }
        }
        Damage::Degenerate => {
            for _ in 0..1 + n / 20 {
                let t = mesh.triangles[rng.below(n as u64) as usize];
                out.triangles.push([t[0], t[0], t[1]]);
                out.triangles.push([t[2], t[1], t[2]]);
            }
        }
    }
    out.normals.clear();
    out
}

/// Finite, closed, manifold, outward (the grid is padded around the input, so nothing reaches
/// its bounds).
fn assert_closed(out: &Output, what: &str) -> analysis::Topology {
    assert!(out.mesh.positions.iter().all(|p| p.is_finite()), "{what}: non-finite vertex");
    let topo = analysis::topology(&out.mesh);
    assert!(topo.is_closed_manifold(), "{what}: not a closed manifold: {topo:?}");
    assert_eq!(topo.degenerate_triangles, 0, "{what}: degenerate triangles");
    if out.mesh.triangle_count() > 0 {
        assert!(analysis::signed_volume(&out.mesh) > 0.0, "{what}: not outward");
    }
    topo
}

/// Finite, an oriented manifold, every vertex inside the grid, and every border edge on one of
/// the grid's faces.
fn assert_open_only_on_the_grid(out: &Output, grid: &Grid, what: &str) -> analysis::Topology {
    let mesh = &out.mesh;
    assert!(mesh.positions.iter().all(|p| p.is_finite()), "{what}: non-finite vertex");
    let topo = analysis::topology(mesh);
    let manifold = (topo.non_manifold_edges, topo.non_manifold_vertices, topo.misoriented_edges);
    assert_eq!(manifold, (0, 0, 0), "{what}: {topo:?}");
    assert_eq!(topo.degenerate_triangles, 0, "{what}: degenerate triangles");
    let (lo, hi) = (grid.origin, grid.max());
    let slack = grid.cell_size() * 1e-4;
    for &p in &mesh.positions {
        assert!(
            p.cmpge(lo - slack).all() && p.cmple(hi + slack).all(),
            "{what}: vertex {p} outside the grid"
        );
    }
    let on_face = |p: Vec3| (0..3).any(|a| (p[a] - lo[a]).abs() < slack || (p[a] - hi[a]).abs() < slack);
    for [a, b] in boundary_edges(mesh) {
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        assert!(on_face(pa) && on_face(pb), "{what}: border edge {pa} {pb} inside the grid");
    }
    topo
}

/// Source meshes with fewer faces than this are drawn again for
/// [`prop_meshes_with_holes_remesh_with_the_closed_meshs_topology`].
const MIN_HOLED_TRIANGLES: usize = 64;

/// A closed mesh of at least [`MIN_HOLED_TRIANGLES`] triangles with 1–5 random ones removed
/// (punched holes), remeshed by MC, EMC and DMC at 16–27 cells: inside is where the generalised
/// winding number exceeds 1/2, so the holes are spanned and the output is closed with the topology
/// (Euler characteristic, components) of the same method's remesh of the mesh before the damage;
/// where a part thinner than a cell reads differently (the README's limit), at twice the cells.
/// The open edges are counted: those of the removed triangles that the rest of the mesh still
/// uses once (an edge two removed triangles share is gone entirely).
#[test]
fn prop_meshes_with_holes_remesh_with_the_closed_meshs_topology() {
    for seed in case_seeds(8_500_000, CI_CASES / 2) {
        check_holed_remesh(seed);
    }
}

/// Specks of a thin shell spread over the box, five faces punched out: the enclosed volume about
/// the box's middle was the missing faces' and negative, so the mesh was turned inside out and
/// refused as enclosing nothing (now the winding number decides, `MeshBvh::new`).
#[test]
fn holed_specks_far_apart_keep_their_winding_on_seed_8500046() {
    check_holed_remesh(8_500_046);
}

/// Found by a soak past CI's seeds (seeds 8500024–8500200): both are parts thinner than a cell,
/// where the README promises nothing. Seed 8500107: a shell wall 0.054 thick at cells of 0.057,
/// its flat bottom face on a grid plane (the padded grid's first plane lies on the mesh's
/// bounding box), so the wall is held only by grid points on the face; a removed triangle of that
/// face leaves its points at a winding number of 0.494, outside, and MC and EMC punch a tunnel
/// ((4, 3) for (6, 3): Euler characteristic, components). Seed 8500142: specks under a cell, of
/// which MC at 21 cells finds 6 and DMC 4 closed and 5 holed (the distances beside the removed
/// faces changed). Twice as fine, every method gives the closed mesh's topology.
#[test]
fn holed_thin_parts_keep_their_topology_twice_as_fine_on_seeds_8500107_8500142() {
    check_holed_remesh(8_500_107);
    check_holed_remesh(8_500_142);
}

fn check_holed_remesh(seed: u64) {
    let mut rng = Rng::new(seed);
    // Holes in a surface, not most of it gone: five faces punched out of a speck of eight
    // (seed 8500093) leave a sheet of three, whose winding number spans another shape.
    let (source, text) = loop {
        let (mesh, text) = source_mesh(&mut rng, 12);
        if mesh.triangle_count() >= MIN_HOLED_TRIANGLES {
            break (mesh, text);
        }
    };
    let res = 16 + rng.below(12) as usize;
    let mut holed = source.clone();
    let mut removed = Vec::new();
    for _ in 0..1 + rng.below(5) {
        removed.push(holed.triangles.swap_remove(rng.below(holed.triangles.len() as u64) as usize));
    }
    let mut edges = std::collections::HashMap::new();
    for t in &removed {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let open = edges.values().filter(|&&n| n == 1).count();
    let what = format!("seed {seed}, res {res}, {} triangles removed from the mesh of {text}", removed.len());
    assert_eq!(isoforge::emc::mesh_source::MeshBvh::new(&holed).unwrap().open_edges, open, "{what}");
    for method in [Method::Mc, Method::Emc, Method::Dmc] {
        let remesh_both = |res: usize| {
            let closed = pipeline::mesh_triangles(&source, &bare_request(method, res)).unwrap();
            let closed_topo =
                assert_closed(&closed, &format!("{}, closed source at {res}, {what}", method.name()));
            let out = pipeline::mesh_triangles(&holed, &bare_request(method, res))
                .unwrap_or_else(|e| panic!("{what}: {} refused it at {res}: {e}", method.name()));
            let topo = assert_closed(&out, &format!("{} at {res}, {what}", method.name()));
            ((topo.euler, topo.components), (closed_topo.euler, closed_topo.components))
        };
        let (holed_topo, closed_topo) = remesh_both(res);
        if holed_topo != closed_topo {
            // A part thinner than a cell (a wall held by the grid points on its face, a speck)
            // can be read differently once faces beside it are gone; twice as fine, a hole must
            // not matter any more.
            let (holed_topo, closed_topo) = remesh_both(2 * res);
            assert_eq!(holed_topo, closed_topo, "{} at {} and at twice that, {what}", method.name(), res);
        }
    }
}

/// Closed inputs and damaged ones alike: MC and EMC accept them and mesh a closed, outward
/// manifold; EMC has MC's Euler characteristic and components on the same grid; a duplicated or
/// zero-area triangle changes nothing but the input's face count; an inside-out mesh meshes like
/// the right way round.
#[test]
fn prop_meshes_remesh_closed_with_mcs_topology() {
    for seed in case_seeds(5_500_000, CI_CASES) {
        let mut rng = Rng::new(seed);
        let (source, text) = source_mesh(&mut rng, 12);
        let res = 16 + rng.below(12) as usize;
        let clean_mc = pipeline::mesh_triangles(&source, &bare_request(Method::Mc, res)).unwrap();
        for damage in DAMAGES {
            let input = damaged(&mut rng, &source, damage);
            let what = format!("seed {seed}, res {res}, {damage:?} mesh of {text}");
            let mc = pipeline::mesh_triangles(&input, &bare_request(Method::Mc, res))
                .unwrap_or_else(|e| panic!("{what}: mc refused it: {e}"));
            let emc = pipeline::mesh_triangles(&input, &bare_request(Method::Emc, res))
                .unwrap_or_else(|e| panic!("{what}: emc refused it: {e}"));
            let mc_topo = assert_closed(&mc, &format!("mc, {what}"));
            let emc_topo = assert_closed(&emc, &format!("emc, {what}"));
            assert_eq!(
                (emc_topo.euler, emc_topo.components),
                (mc_topo.euler, mc_topo.components),
                "emc vs mc, {what}"
            );
            if matches!(damage, Damage::Inverted | Damage::Duplicated | Damage::Degenerate) {
                assert_eq!(
                    mc.mesh.positions, clean_mc.mesh.positions,
                    "mc, {what}: differs from the clean mesh's"
                );
            }
        }
    }
}

/// Oriented point clouds sampled densely from a random tree's surface (the vertices of its MC mesh
/// at 40–49 cells, with the program's exact normals), reconstructed at 12–23 cells by MC and EMC:
/// closed (grid points more than a cell outside the samples' box are outside, and the grid reaches
/// two cells beyond it), an oriented manifold, EMC with MC's topology. The topology need not be
/// the tree's: where a part is thinner than the samples' spacing, the nearest sample to a grid
/// point outside may lie on the far sheet and face away from it.
#[test]
fn prop_point_clouds_reconstruct_closed_with_mcs_topology() {
    for seed in case_seeds(6_500_000, CI_CASES) {
        check_point_cloud(seed);
    }
}

/// Open, found by a soak past CI's seeds (`ISOFORGE_SEED=S` over seeds 6500048–6500399): where a
/// tree has parts thinner than the samples' spacing, orientation turns many of its exact normals
/// (seed 6500218: 152 of 958, 6500244: 633 of 1 574, 6500326: 3 173 of 9 976): pairs across
/// edges next to a thin part put each sample on another side of the other's plane, and pairs
/// 134° apart with one sample within 1° of the other's plane vote as one sheet with a normal
/// flipped (6500218). docs/inputs.md says so. Ignored until orientation tells a thin part from a
/// flipped patch.
#[test]
#[ignore]
fn exact_normals_of_thin_parts_are_kept_on_seeds_6500218_6500244_6500326() {
    for seed in [6_500_218, 6_500_244, 6_500_326] {
        check_point_cloud(seed);
    }
}

/// From the same soak: an 84-sample part of a thin shell was refused as unoriented (53 % of its
/// neighbouring normals disagreeing), until a pair with opposite normals whose points lie each
/// behind the other's plane, by however little, counted as a wall's two faces (no vote) rather
/// than as a flipped normal (`orient::agreement`).
#[test]
fn a_thin_shells_exact_normals_are_not_refused_on_seed_6500192() {
    check_point_cloud(6_500_192);
}

fn check_point_cloud(seed: u64) {
    let mut rng = Rng::new(seed);
    let (source, text) = source_mesh(&mut rng, 40);
    let program = expr::compile(&text).unwrap();
    let normals: Vec<Vec3> = source
        .positions
        .iter()
        .map(|&p| program.gradient(p).unwrap_or(Vec3::Z).normalize_or(Vec3::Z))
        .collect();
    let cloud = PointCloud { positions: source.positions.clone(), normals };
    // The normals are exact: orientation may turn a few where parts are thinner than the
    // samples' spacing (the two faces of a shell thinning to nothing read as flipped where
    // they meet), never a face. Measured over 100 trees: none in 86, at most 1.9 % of a cloud
    // of 748 (and 48 of a 232-sample speck, not asserted); over seeds 48-399, three trees with
    // thin parts break this (the ignored test above).
    let mut oriented = cloud.clone();
    let turned = isoforge::emc::orient::orient_normals(&mut oriented)
        .unwrap_or_else(|e| panic!("seed {seed}: exact normals refused: {e}"));
    if cloud.len() >= 500 {
        assert!(turned * 33 <= cloud.len(), "seed {seed}: {turned} of {} exact normals turned", cloud.len());
    }
    let res = 12 + rng.below(12) as usize;
    let what = format!("seed {seed}, res {res}, {} points of {text}", cloud.positions.len());
    let mc = pipeline::mesh_points(&cloud, &bare_request(Method::Mc, res))
        .unwrap_or_else(|e| panic!("{what}: mc refused it: {e}"));
    let emc = pipeline::mesh_points(&cloud, &bare_request(Method::Emc, res))
        .unwrap_or_else(|e| panic!("{what}: emc refused it: {e}"));
    let (lo, hi) = cloud.bounds();
    let grid = padded_grid(lo, hi, res).unwrap();
    let mc_topo = assert_open_only_on_the_grid(&mc, &grid, &format!("mc, {what}"));
    let emc_topo = assert_open_only_on_the_grid(&emc, &grid, &format!("emc, {what}"));
    assert_eq!(mc_topo.boundary_edges, 0, "mc, {what}: open");
    assert_eq!(emc_topo.boundary_edges, 0, "emc, {what}: open");
    assert_eq!(
        (emc_topo.euler, emc_topo.components),
        (mc_topo.euler, mc_topo.components),
        "emc vs mc, {what}"
    );
}

/// A convex part of a random shape: a ball or a box turned at random.
#[derive(Debug, Clone, Copy)]
enum Part {
    Ball { centre: Vec3, radius: f32 },
    Box { centre: Vec3, half: Vec3, rotation: glam::Quat },
}

impl Part {
    fn random(rng: &mut Rng, centre: Vec3) -> Part {
        if rng.below(2) == 0 {
            Part::Ball { centre, radius: rng.range(0.25, 0.45) }
        } else {
            let axis = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            Part::Box {
                centre,
                half: Vec3::new(rng.range(0.18, 0.35), rng.range(0.18, 0.35), rng.range(0.18, 0.35)),
                rotation: glam::Quat::from_axis_angle(axis.normalize_or(Vec3::Z), rng.range(0.0, 3.0)),
            }
        }
    }

    fn area(&self) -> f32 {
        match *self {
            Part::Ball { radius, .. } => 4.0 * std::f32::consts::PI * radius * radius,
            Part::Box { half: h, .. } => 8.0 * (h.x * h.y + h.y * h.z + h.z * h.x),
        }
    }

    /// Strictly inside, by more than `margin`.
    fn contains(&self, p: Vec3, margin: f32) -> bool {
        match *self {
            Part::Ball { centre, radius } => (p - centre).length() < radius - margin,
            Part::Box { centre, half, rotation } => {
                let local = rotation.inverse() * (p - centre);
                local.abs().cmplt(half - Vec3::splat(margin)).all()
            }
        }
    }

    /// A uniformly random point of the surface and its outward normal.
    fn sample(&self, rng: &mut Rng) -> (Vec3, Vec3) {
        match *self {
            Part::Ball { centre, radius } => {
                let z = rng.range(-1.0, 1.0);
                let a = rng.range(0.0, std::f32::consts::TAU);
                let rho = (1.0 - z * z).max(0.0).sqrt();
                let n = Vec3::new(rho * a.cos(), rho * a.sin(), z);
                (centre + n * radius, n)
            }
            Part::Box { centre, half, rotation } => {
                let areas = [half.y * half.z, half.z * half.x, half.x * half.y];
                let mut pick = rng.range(0.0, areas.iter().sum());
                let mut axis = 2;
                for (a, &area) in areas.iter().enumerate() {
                    if pick < area {
                        axis = a;
                        break;
                    }
                    pick -= area;
                }
                let side = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                let mut local =
                    Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * half;
                local[axis] = side * half[axis];
                let mut n = Vec3::ZERO;
                n[axis] = side;
                (centre + rotation * local, rotation * n)
            }
        }
    }
}

/// A random shape of one or two separate components, each a box, a ball, or the union of two
/// overlapping balls (a topological ball either way; a box and a part overlapping it can leave a
/// sliver thinner than a cell, which reconstruction splits off), sampled by about `density`
/// points per unit area on the surface of the union with exact outward normals. Returns the cloud,
/// the number of components and a description.
fn random_shape_cloud(rng: &mut Rng, density: f32) -> (PointCloud, usize, String) {
    let components = 1 + rng.below(2) as usize;
    let mut parts = Vec::new();
    for c in 0..components {
        let centre = Vec3::new(if components == 2 { c as f32 * 1.4 - 0.7 } else { 0.0 }, 0.0, 0.0)
            + Vec3::new(rng.range(-0.1, 0.1), rng.range(-0.1, 0.1), rng.range(-0.1, 0.1));
        let first = Part::random(rng, centre);
        parts.push(first);
        if matches!(first, Part::Ball { .. }) && rng.below(2) == 0 {
            let offset = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let distance = rng.range(0.1, 0.3);
            let radius = rng.range(0.25, 0.45);
            parts.push(Part::Ball { centre: centre + offset.normalize_or(Vec3::Y) * distance, radius });
        }
    }
    let mut cloud = PointCloud::default();
    for (k, part) in parts.iter().enumerate() {
        let count = (part.area() * density) as usize;
        for _ in 0..count {
            let (p, n) = part.sample(rng);
            // On the union's surface: inside no other part.
            if !parts.iter().enumerate().any(|(m, other)| m != k && other.contains(p, 0.0)) {
                cloud.positions.push(p);
                cloud.normals.push(n);
            }
        }
    }
    (cloud, components, format!("{parts:?}"))
}

/// Turns around a random 0–5 % of the normals: scattered single ones, and in some clouds also
/// compact clusters (a sample's nearest neighbours). Returns how many are turned.
fn flip_some(rng: &mut Rng, cloud: &mut PointCloud) -> usize {
    let n = cloud.positions.len();
    let target = (rng.range(0.0, 0.05) * n as f32) as usize;
    let mut flipped = vec![false; n];
    if rng.below(2) == 0 {
        // Up to three clusters taking half the budget.
        for _ in 0..1 + rng.below(3) {
            let centre = cloud.positions[rng.below(n as u64) as usize];
            let mut by_distance: Vec<usize> = (0..n).collect();
            by_distance.sort_by(|&a, &b| {
                (cloud.positions[a] - centre).length().total_cmp(&(cloud.positions[b] - centre).length())
            });
            for &i in by_distance.iter().take(target / 6) {
                flipped[i] = true;
            }
        }
    }
    while flipped.iter().filter(|&&f| f).count() < target {
        flipped[rng.below(n as u64) as usize] = true;
    }
    for (normal, _) in cloud.normals.iter_mut().zip(&flipped).filter(|(_, &f)| f) {
        *normal = -*normal;
    }
    flipped.iter().filter(|&&f| f).count()
}

/// Clouds sampled from random balls, boxes and unions of two, with 0–5 % of their normals turned
/// around (scattered, and in half the clouds partly in clusters): orientation turns those back
/// (all of them, or all but one in 2 000 samples: see below) and no others, and the reconstruction
/// (EMC, 16–27 cells) is closed with the topology of the undamaged cloud's, which for balls and
/// their unions is one component per shape component, Euler characteristic 2 each; where every
/// normal came back it is the same mesh as from the cloud before the damage.
#[test]
fn prop_flipped_normals_are_turned_back() {
    for seed in case_seeds(7_500_000, CI_CASES) {
        let mut rng = Rng::new(seed);
        let (truth, components, shape) = random_shape_cloud(&mut rng, 6000.0);
        let mut cloud = truth.clone();
        let flipped = flip_some(&mut rng, &mut cloud);
        let res = 16 + rng.below(12) as usize;
        let what = format!("seed {seed}, res {res}, {flipped} of {} normals flipped, {shape}", truth.len());
        let mut oriented = cloud.clone();
        let turned = isoforge::emc::orient::orient_normals(&mut oriented)
            .unwrap_or_else(|e| panic!("{what}: refused: {e}"));
        let wrong = oriented.normals.iter().zip(&truth.normals).filter(|(a, b)| a != b).count();
        // Exactly the flipped ones, but for the odd sample alone on a sliver of a face at a corner
        // (its only neighbours across two sharp edges at once, which cannot tell it either way).
        assert!(wrong * 2000 <= truth.len(), "{what}: {wrong} normals still wrong, {turned} turned");
        if wrong == 0 {
            assert_eq!(turned, flipped, "{what}: turned ones that were right");
        }
        let out = pipeline::mesh_points(&cloud, &bare_request(Method::Emc, res))
            .unwrap_or_else(|e| panic!("{what}: refused: {e}"));
        let topo = assert_closed(&out, &what);
        let clean = pipeline::mesh_points(&truth, &bare_request(Method::Emc, res)).unwrap();
        let clean_topo = assert_closed(&clean, &format!("undamaged, {what}"));
        assert_eq!((topo.components, topo.euler), (clean_topo.components, clean_topo.euler), "{what}");
        // Balls and their unions come back as what they are; a box now and then gains a bubble
        // off an edge or corner even from undamaged normals (a reconstruction limit, not
        // orientation's: seed 7_500_054 is one).
        if !shape.contains("Box") {
            assert_eq!((topo.components, topo.euler), (components, 2 * components as i64), "{what}");
        }
        if wrong == 0 {
            assert_eq!(
                out.mesh.positions, clean.mesh.positions,
                "{what}: differs from the undamaged cloud's"
            );
        }
    }
}

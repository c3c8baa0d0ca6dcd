//! Consistent normals for a point cloud: reconstruction reads the side of every grid point off the
//! nearest sample's normal, so one normal pointing into the solid makes a bubble or a hole, and a
//! scanner's or an estimator's output often has a few such normals (or whole patches of them).
//!
//! The cloud's normals are taken to be *mostly* right, and the minority that disagrees with its
//! neighbours is turned around:
//! 1. Every sample is joined to its [`NEIGHBOURS`] nearest, and each pair gets a vote on whether
//!    their normals agree ([`agreement`]): +1 for surely consistent, −1 for surely one of them
//!    flipped, near 0 for "cannot tell" (across a sharp edge, where the normals are orthogonal).
//! 2. Pairs on one smooth sheet whose normals clearly agree as given join into patches
//!    (union-find).
//! 3. Patches are joined into groups where the pairs between them clearly agree or clearly
//!    disagree on average, strongest summed evidence first (Kruskal's order, as in the
//!    minimum spanning tree of Hoppe et al. 1992, but over patches, so one unlucky pair cannot
//!    turn a large region around), each join recording whether one patch is turned relative to the
//!    other.
//! 4. In each group the orientation most of its samples already have wins; the others are turned.
//! 5. A region of patches to be turned is turned only where 3/4 of the evidence across its border
//!    agrees and there is at least the square root of its size of it (a sample alone on a sliver
//!    of a face at a corner has only votes across sharp edges, which can contradict each other,
//!    and the inside of a shell thinning to nothing meets the outside in a few pairs that read as
//!    flipped; both keep the normals they came with).
//! 6. A group holding one of the cloud's six extreme samples (largest and smallest x, y, z), whose
//!    outward normal must point away from the cloud along that axis, is turned around as a whole
//!    when those samples say it is inside out (a cloud exported with inward normals), as inside-out
//!    triangle meshes are.
//! 7. A group split nearly evenly that no extreme sample settles is an error where most of its
//!    neighbouring normals disagree (the cloud has no orientation to restore), and otherwise keeps
//!    its normals but for patches their own neighbours clearly overrule (the relations between
//!    patches went wrong, as they can across parts thinner than the samples' neighbourhoods).

use super::point_source::PointIndex;
use crate::error::Error;
use crate::input::PointCloud;
use glam::Vec3;
use std::collections::HashMap;

/// Neighbours each sample is compared with.
pub const NEIGHBOURS: usize = 10;

/// A pair whose vote is at least this joins one patch: consistent beyond doubt.
const AGREE: f32 = 0.5;

/// Patches are joined only on summed evidence of at least this (a single pair's clear vote).
const EVIDENCE: f32 = 0.5;

/// Patches are joined only where the mean vote of the pairs between them is at least this.
const CLEAR: f32 = 0.5;

/// A group whose minority holds more than this share of its samples is split too evenly for a
/// majority to mean anything.
const SPLIT: f64 = 0.4;

/// A group whose pairs' votes say "flipped" with more than this share of their weight has no
/// orientation to restore.
const DISORDER: f64 = 0.3;

/// Below this share of the cloud (or 20 samples), an evenly split group is left as it is rather
/// than refused: a handful of stray samples cannot make the whole cloud unusable.
const SIZEABLE: f64 = 0.01;

/// The least offset (as in [`agreement`]) at which two points each behind the other's plane are
/// read as a wall's two faces: 0.6°, far above rounding on a flat sheet.
const THIN_WALL: f32 = 0.01;

/// How strongly samples `i` (at `pi`, normal `ni`) and `j` agree that their normals point to the
/// same side of the surface, in −1..1, and whether that rests on the normals alone (the two lie
/// on one smooth sheet).
///
/// Two tests, each reliable where the other is not:
/// - on one smooth sheet the points lie (nearly) in each other's tangent planes, and consistent
///   normals are (nearly) parallel: the vote is `ni·nj`;
/// - across a sharp edge the points lie clearly off each other's tangent planes and `ni·nj` can be
///   0; consistent normals then put each point on the same side of the other's plane: both behind
///   it at a convex edge, both in front of it at a concave one, while a flipped normal puts them on
///   different sides. The vote is +1 or −1.
///
/// The offset that decides between them is the smaller of the two points' distances from the
/// other's plane over their distance: below 0.05 (within 3° of each other's planes) the first
/// test, above 0.2 (12°) the second, in between a blend. A sphere sampled at spacing `s` and
/// radius `r` has offsets near `s / 2r`, so the first test holds on any surface sampled finer than
/// a tenth of its radius of curvature.
///
/// Where the normals are (anti)parallel (`|ni·nj| ≥ 0.5`) but the points lie off each other's
/// planes, the two tests can contradict each other and neither is reliable: a step (a convex edge
/// and a concave one) with consistent normals reads as flipped to the second test, the two faces
/// of a wall thinner than the neighbourhood read as flipped to the first. Such a pair has no vote,
/// and neither has a pair with opposite normals each behind the other's plane by more than
/// 0.01 (`THIN_WALL`), however near the planes: a wall's two faces.
pub fn agreement(pi: Vec3, ni: Vec3, pj: Vec3, nj: Vec3) -> (f32, bool) {
    let parallel = ni.dot(nj);
    let d = pj - pi;
    let length = d.length();
    if length <= 0.0 || length.is_nan() {
        return (parallel, true);
    }
    let (ai, aj) = (ni.dot(d) / length, -nj.dot(d) / length);
    let offset = ai.abs().min(aj.abs());
    let w = ((offset - 0.05) / 0.15).clamp(0.0, 1.0);
    if w == 0.0 {
        // Opposite normals on points each behind the other's plane: the two faces of a wall
        // thinner than the neighbourhood however thin (a flipped normal on one curved sheet puts
        // the two on opposite sides of each other's planes).
        if parallel <= -0.5 && ai < -THIN_WALL && aj < -THIN_WALL {
            return (0.0, false);
        }
        return (parallel, true);
    }
    let sides = if ai * aj > 0.0 { 1.0 } else { -1.0 };
    if parallel.abs() >= 0.5 && parallel * sides < 0.0 {
        return (0.0, false);
    }
    ((1.0 - w) * parallel + w * sides, false)
}

/// Union-find whose elements carry a parity relative to their root: whether they are turned
/// around with respect to it.
struct Parity {
    parent: Vec<u32>,
    /// Parity relative to `parent`.
    flip: Vec<bool>,
    size: Vec<u32>,
}

impl Parity {
    fn new(n: usize) -> Parity {
        Parity { parent: (0..n as u32).collect(), flip: vec![false; n], size: vec![1; n] }
    }

    /// The root of `i` and `i`'s parity relative to it (path halving keeps the parities right by
    /// folding them in as it shortcuts).
    fn find(&mut self, mut i: u32) -> (u32, bool) {
        let mut path = Vec::new();
        while self.parent[i as usize] != i {
            path.push(i);
            i = self.parent[i as usize];
        }
        let root = i;
        // Compress: every node on the path points at the root with its total parity.
        let mut total = false;
        for &node in path.iter().rev() {
            total ^= self.flip[node as usize];
            self.flip[node as usize] = total;
            self.parent[node as usize] = root;
        }
        // Recompute from the stored parities now that each points at the root directly.
        let first = path.first().copied();
        match first {
            Some(node) => (root, self.flip[node as usize]),
            None => (root, false),
        }
    }

    /// Joins the sets of `a` and `b` so that their parities differ by `turned`; false when they
    /// were already one set.
    fn union(&mut self, a: u32, b: u32, turned: bool) -> bool {
        let ((ra, pa), (rb, pb)) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        let (big, small) = if self.size[ra as usize] >= self.size[rb as usize] { (ra, rb) } else { (rb, ra) };
        self.parent[small as usize] = big;
        // parity(b) = parity(a) ^ turned, with parity(x) = p_x ^ parity(root_x).
        self.flip[small as usize] = pa ^ pb ^ turned;
        self.size[big as usize] += self.size[small as usize];
        true
    }
}

/// Turns around the normals of `cloud` that disagree with their neighbours (module
/// documentation), and returns how many were turned. The cloud must pass
/// [`PointCloud::validate`]. Fails when a sizeable part of the cloud has no prevailing
/// orientation (its normals were estimated without one, or are random), naming how it is split.
pub fn orient_normals(cloud: &mut PointCloud) -> Result<usize, Error> {
    let index = PointIndex::new(cloud)?;
    let n = index.len();
    if n < 2 {
        return Ok(0);
    }
    // Pairs of (reordered) neighbours, each once, with their vote.
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(n * NEIGHBOURS);
    let mut near = Vec::with_capacity(NEIGHBOURS + 1);
    for i in 0..n as u32 {
        index.k_nearest(index.sample(i).0, NEIGHBOURS + 1, &mut near);
        pairs.extend(near.iter().filter(|&&(_, j)| j != i).map(|&(_, j)| (i.min(j), i.max(j))));
    }
    pairs.sort_unstable();
    pairs.dedup();
    let (votes, smooth): (Vec<f32>, Vec<bool>) = pairs
        .iter()
        .map(|&(i, j)| {
            let ((pi, ni), (pj, nj)) = (index.sample(i), index.sample(j));
            agreement(pi, ni, pj, nj)
        })
        .unzip();

    // Patches: samples joined by clear agreement of their normals on one smooth sheet. Votes
    // across sharp edges only count summed up, between patches.
    let mut patches = Parity::new(n);
    for ((&(i, j), &v), &smooth) in pairs.iter().zip(&votes).zip(&smooth) {
        if smooth && v >= AGREE {
            patches.union(i, j, false);
        }
    }
    let patch: Vec<u32> = (0..n as u32).map(|i| patches.find(i).0).collect();

    // Evidence between patches (summed votes, pairs), then Kruskal over it, strongest first. A
    // link joins two patches only where the pairs between them clearly agree on average: the two
    // faces of a wall about as thin as the samples' spacing are two patches with many pairs
    // between them that abstain and a few that read as flipped, which must not turn one face.
    let mut evidence: HashMap<(u32, u32), (f32, u32)> = HashMap::new();
    for (&(i, j), &v) in pairs.iter().zip(&votes) {
        let (a, b) = (patch[i as usize], patch[j as usize]);
        if a != b {
            let e = evidence.entry((a.min(b), a.max(b))).or_insert((0.0, 0));
            e.0 += v;
            e.1 += 1;
        }
    }
    let mut links: Vec<((u32, u32), f32, u32)> = evidence.into_iter().map(|(k, (e, c))| (k, e, c)).collect();
    links.sort_unstable_by(|a, b| b.1.abs().total_cmp(&a.1.abs()).then(a.0.cmp(&b.0)));
    let mut groups = Parity::new(n);
    for &((a, b), e, count) in &links {
        if e.abs() >= EVIDENCE && e.abs() >= CLEAR * count as f32 {
            groups.union(a, b, e < 0.0);
        }
    }

    // Per sample: its group and whether it is turned relative to the group's root.
    let mut group = vec![0u32; n];
    let mut turned = vec![false; n];
    // (samples with parity false, with parity true) per group root.
    let mut counts: HashMap<u32, (usize, usize)> = HashMap::new();
    for i in 0..n {
        let (root, parity) = groups.find(patch[i]);
        group[i] = root;
        turned[i] = parity;
        let c = counts.entry(root).or_insert((0, 0));
        if parity {
            c.1 += 1;
        } else {
            c.0 += 1;
        }
    }
    // The parity a group's samples should end with: the majority's.
    let mut keep: HashMap<u32, bool> = counts.iter().map(|(&g, &(even, odd))| (g, odd > even)).collect();

    // The six extreme samples vote on each group they belong to, with the majority applied.
    let mut extremes = [(f32::NEG_INFINITY, 0u32); 6];
    let directions = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for i in 0..n as u32 {
        let p = index.sample(i).0;
        for (e, d) in extremes.iter_mut().zip(directions) {
            if p.dot(d) > e.0 {
                *e = (p.dot(d), i);
            }
        }
    }
    let mut outward: HashMap<u32, f32> = HashMap::new();
    for ((_, i), d) in extremes.iter().zip(directions) {
        let i = *i as usize;
        let normal = index.sample(i as u32).1;
        let as_kept = if turned[i] == keep[&group[i]] { normal } else { -normal };
        let along = as_kept.dot(d);
        if along.abs() > 0.3 {
            *outward.entry(group[i]).or_insert(0.0) += along.signum();
        }
    }
    for (g, vote) in &outward {
        if *vote < 0.0 {
            let k = keep.get_mut(g).expect("every group has a count");
            *k = !*k;
        }
    }
    // How much of the pairs' vote weight within each group says "flipped" as the normals are given:
    // a few per cent for a cloud with stray normals (each has ~10 neighbours voting against it),
    // near half for one without an orientation.
    let mut against: HashMap<u32, (f64, f64)> = HashMap::new();
    for (&(i, _), &v) in pairs.iter().zip(&votes) {
        let a = against.entry(group[i as usize]).or_insert((0.0, 0.0));
        a.0 += (-v).max(0.0) as f64;
        a.1 += v.abs() as f64;
    }
    // Groups the majority cannot settle: split nearly evenly, with no extreme sample. Either the
    // normals have no orientation (most pairs disagree: an error), or they have one and the
    // relations between patches went wrong somewhere (across parts thinner than the samples'
    // neighbourhoods): then only patches their own neighbours overrule are turned (below).
    let mut unsettled = std::collections::HashSet::new();
    for (g, &(even, odd)) in &counts {
        let (size, minority) = (even + odd, even.min(odd));
        let settled = outward.get(g).is_some_and(|v| *v != 0.0);
        if settled || minority as f64 <= SPLIT * size as f64 {
            continue;
        }
        let (bad, total) = against.get(g).copied().unwrap_or((0.0, 0.0));
        if size >= 20 && size as f64 >= SIZEABLE * n as f64 && bad > DISORDER * total {
            return Err(Error::InvalidOption(format!(
                "the normals of a connected part of {size} of the {n} points are not oriented: \
                 {:.0} % of neighbouring normals disagree, {even} point one way and {odd} the \
                 other, and nothing tells which side is out; give normals that point out of the \
                 solid (most of them at least)",
                100.0 * bad / total.max(f64::MIN_POSITIVE)
            )));
        }
        unsettled.insert(*g);
    }

    // The proposal per patch (all its samples share it), checked against the patch's own links:
    // a patch is turned only if at least 3/4 of the evidence on its links, with its neighbours as
    // proposed, says so. A sample alone on a sliver of a face next to a corner has only votes
    // across sharp edges, some of them across two edges at once, which read a consistent pair as
    // flipped; where those contradict each other, the normal it came with stands. In an unsettled
    // group the proposal is the normals as given, and only patches their links overrule turn.
    let mut turn: HashMap<u32, bool> = HashMap::new();
    for i in 0..n {
        let proposed = turned[i] != keep[&group[i]];
        turn.insert(patch[i], proposed && !unsettled.contains(&group[i]));
    }
    // (evidence for turning, total evidence) per patch
    let mut support: HashMap<u32, (f32, f32)> = HashMap::new();
    for &((a, b), e, _) in &links {
        for (p, q) in [(a, b), (b, a)] {
            let other = if turn[&q] { -1.0 } else { 1.0 };
            let s = support.entry(p).or_insert((0.0, 0.0));
            s.0 -= e * other;
            s.1 += e.abs();
        }
    }
    // A turned patch's rim disagrees with its surroundings all round: a flipped disc of m samples
    // has some 3.5 √m on its rim and each of those about 5 pairs across it, so its evidence grows
    // like 17 √m. Asking for √m keeps a large region from being turned by a handful of pairs (the
    // two faces of a wall thinning to nothing, as the inside of a shell does, read as flipped
    // where they meet). Patches to be turned are judged together with the turned patches they
    // link to, by the evidence across the border of that region to patches that stay, since
    // within the region they agree with each other either way.
    let mut patch_size: HashMap<u32, f32> = HashMap::new();
    for &p in &patch {
        *patch_size.entry(p).or_insert(0.0) += 1.0;
    }
    let mut regions = Parity::new(n);
    for &((a, b), _, _) in &links {
        if turn[&a] && turn[&b] {
            regions.union(a, b, false);
        }
    }
    // (evidence for turning, total evidence, samples) per region, across its border
    let mut border: HashMap<u32, (f32, f32, f32)> = HashMap::new();
    for (&p, &t) in &turn {
        if t {
            border.entry(regions.find(p).0).or_insert((0.0, 0.0, 0.0)).2 += patch_size[&p];
        }
    }
    for &((a, b), e, _) in &links {
        for (p, q) in [(a, b), (b, a)] {
            if turn[&p] && !turn[&q] {
                let s = border.get_mut(&regions.find(p).0).expect("every turned patch has a region");
                s.0 -= e;
                s.1 += e.abs();
            }
        }
    }
    let clear = |(for_turning, total, size): (f32, f32, f32)| {
        for_turning >= 0.5 * total && for_turning >= size.sqrt()
    };
    let mut decided = HashMap::new();
    for (&p, &t) in &turn {
        let keep_turned = if unsettled.contains(&groups.find(p).0) {
            // Nothing proposed; turned only where its own neighbours overrule it.
            support.get(&p).is_some_and(|&(f, total)| total >= EVIDENCE && clear((f, total, patch_size[&p])))
        } else {
            // A region with no border at all is a whole group turned (inside out): no vote across.
            t && {
                let b = border[&regions.find(p).0];
                b.1 == 0.0 || clear(b)
            }
        };
        decided.insert(p, keep_turned);
    }
    let turn = decided;
    let mut changed = 0;
    for i in 0..n {
        if turn[&patch[i]] {
            let original = index.original(i as u32);
            cloud.normals[original] = -cloud.normals[original];
            changed += 1;
        }
    }
    Ok(changed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn votes_read_sharp_edges_and_abstain_where_unsure() {
        let vote = |pi, ni, pj, nj| agreement(pi, ni, pj, nj).0;
        // One smooth sheet: parallel normals agree, opposite ones do not.
        let (a, b) = (Vec3::ZERO, Vec3::new(0.1, 0.0, 0.0));
        assert_eq!(agreement(a, Vec3::Z, b, Vec3::Z), (1.0, true));
        assert_eq!(agreement(a, Vec3::Z, b, -Vec3::Z), (-1.0, true));
        // A convex 90° edge: orthogonal normals, each point behind the other's plane.
        let (top, side) = (Vec3::new(-0.05, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.05));
        assert_eq!(agreement(top, Vec3::Z, side, Vec3::X), (1.0, false));
        assert!(vote(top, Vec3::Z, side, -Vec3::X) < -0.99);
        // A concave one: each in front of the other's plane.
        assert!(vote(top, -Vec3::Z, side, -Vec3::X) > 0.99);
        // The two faces of a thin wall, or a step: opposite or parallel normals off each other's
        // planes. Either reading could be the flipped one, so no vote.
        let (up, down) = (Vec3::new(0.0, 0.0, 0.01), Vec3::new(0.03, 0.0, -0.01));
        assert_eq!(vote(up, Vec3::Z, down, -Vec3::Z), 0.0);
        assert_eq!(vote(up, Vec3::Z, down, Vec3::Z), 0.0);
        // Coincident samples: the normals alone.
        assert_eq!(agreement(a, Vec3::Z, a, Vec3::X), (0.0, true));
    }

    #[test]
    fn parity_union_find_composes_turns() {
        let mut p = Parity::new(5);
        assert!(p.union(0, 1, true));
        assert!(p.union(2, 3, true));
        assert!(p.union(1, 3, false));
        assert!(!p.union(0, 3, true));
        let parity = |p: &mut Parity, i| p.find(i).1;
        let root = p.find(0).0;
        assert!((0..4).all(|i| p.find(i).0 == root));
        assert_ne!(parity(&mut p, 0), parity(&mut p, 1));
        assert_eq!(parity(&mut p, 1), parity(&mut p, 3));
        assert_ne!(parity(&mut p, 2), parity(&mut p, 3));
        assert_eq!(p.find(4), (4, false));
    }

    /// `n` points on the unit sphere (a Fibonacci lattice), normals outward.
    fn sphere(n: usize) -> PointCloud {
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let mut cloud = PointCloud::default();
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let rho = (1.0 - z * z).sqrt();
            let p = Vec3::new(rho * (golden * i as f32).cos(), rho * (golden * i as f32).sin(), z);
            cloud.positions.push(p);
            cloud.normals.push(p);
        }
        cloud
    }

    #[test]
    fn stray_and_inward_normals_are_turned_out() {
        let truth = sphere(2000);
        let mut cloud = truth.clone();
        for i in (0..2000).step_by(37) {
            cloud.normals[i] = -cloud.normals[i];
        }
        assert_eq!(orient_normals(&mut cloud).unwrap(), 55);
        assert_eq!(cloud, truth);
        assert_eq!(orient_normals(&mut cloud).unwrap(), 0, "a consistent cloud is left alone");
        // Every normal inward: the extremes turn it all around.
        let mut inward = truth.clone();
        inward.normals.iter_mut().for_each(|n| *n = -*n);
        assert_eq!(orient_normals(&mut inward).unwrap(), 2000);
        assert_eq!(inward, truth);
    }

    #[test]
    fn unoriented_normals_are_an_error_where_nothing_settles_them() {
        // Two spheres nested: the inner one's extremes are not the cloud's, and its normals are
        // split evenly.
        let mut cloud = sphere(1500);
        let inner = sphere(1000);
        for (k, (p, n)) in inner.positions.iter().zip(&inner.normals).enumerate() {
            cloud.positions.push(*p * 0.5);
            cloud.normals.push(if k % 2 == 0 { -*n } else { *n });
        }
        let err = orient_normals(&mut cloud).unwrap_err().to_string();
        assert!(err.contains("not oriented") && err.contains("of the 2500 points"), "{err}");
    }
}

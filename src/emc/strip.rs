//! A narrow face between two creases inside one cell: two fan centres instead of one.
//!
//! One fan centre per component serves one feature. Where a face narrower than a cell runs
//! between two creases (the fandisk's 90° strip between its flat top and its cylinder, half a
//! cell wide and tapering out), a cell sees three sheets but no corner: the three planes meet far
//! away, or not at all, and no single point lies on both creases. Its centre then sat a quarter
//! of a cell off the part (the fandisk's largest error at 56–72 cells), and MC's polygon cuts
//! the strip off.
//!
//! Here the polygon's crossings are split into the two sides and the middle face, one centre is
//! put on each crease (each sheet pair's tangent planes, as an edge component's are solved), and
//! the polygon is fanned from both: a side's crossings to its crease's centre, the middle face's
//! to the centre of the side they follow, and one triangle at each end of the middle face's runs
//! joins the two centres, so the edge between them is shared by exactly two triangles. The
//! polygon is MC's, as for every fan, so the mesh stays closed whatever is decided inside. Where
//! one of the creases only skims the cell (its line misses the cell, or only off the surface),
//! the other crease's centre alone is fanned to the whole polygon.
//!
//! Where the face is so narrow that no grid edge of the cell crosses it, the cell sees only the
//! two sides and solves their planes' line, which lies off the face: the fan cuts it off, half a
//! cell deep on the fandisk at 68 cells. The walk that tells a crease from a smooth bend
//! ([`super::crease::fine_scale`]) crosses such a face on its way from one side to the other; where
//! one of its samples turns sharply against both, that sample stands for the middle face
//! ([`hidden`]).
//!
//! Taken only where the input can say how far a point is from the surface, both centres lie on
//! it, in the cell, and the triangles do not fold and lie nearer the surface than the one
//! centre's fan (or MC's triangles).

use super::edges::EdgeSampler;
use super::feature::{self, FeatureKind};
use super::placement::{line_in_box, Component, GROWTH, INSET};
use crate::grid::in_box;
use glam::Vec3;

/// Two centres, one on each crease (or one, where the other crease skims the cell), and the
/// triangles between them and the polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct Strip {
    /// On the crease between the first side and the middle face, and on the one between the
    /// middle face and the other side; only one where the other crease merely skims the cell.
    pub centres: Vec<Vec3>,
    /// The creases' directions (unit), one per centre.
    pub creases: Vec<Vec3>,
    /// The triangles, over the polygon's vertices `0..n` and the centres `n` and `n + 1`.
    pub triangles: Vec<[usize; 3]>,
}

impl Strip {
    /// Where vertex `v` of [`Strip::triangles`] lies, over the polygon's positions `pts`.
    pub fn corner(&self, pts: &[Vec3], v: usize) -> Vec3 {
        if v < pts.len() {
            pts[v]
        } else {
            self.centres[v - pts.len()]
        }
    }

    /// The triangles as positions, over the polygon's positions `pts`.
    pub fn positions<'a>(&'a self, pts: &'a [Vec3]) -> impl Iterator<Item = [Vec3; 3]> + 'a {
        self.triangles.iter().map(move |t| t.map(|v| self.corner(pts, v)))
    }
}

/// A side of the strip, the middle face, or the other side.
const FIRST: u8 = 0;
const MIDDLE: u8 = 1;
const OTHER: u8 = 2;

/// The strip of `component` where it is one (see the module doc), with both centres within
/// `on_surface` of the surface by `distance`; where several readings of which face is the middle
/// one fit, the one whose triangles lie nearest the surface. `theta_sharp` is the sharpness
/// test's cosine: each pair of the three sheets must be sharp, and each crossing must lie on one
/// of them within it.
pub fn solve(
    component: &Component,
    theta_sharp: f32,
    distance: &dyn Fn(Vec3) -> Option<f32>,
    on_surface: f32,
) -> Option<(Strip, f32)> {
    let (pts, nrm) = (component.pts, component.nrm);
    let sheets = feature::sharp_third_sheet(nrm, theta_sharp)?.map(|s| nrm[s]);
    let mut label = Vec::with_capacity(nrm.len());
    for n in nrm {
        let (s, fit) =
            (0..3).map(|s| (s as u8, n.dot(sheets[s]))).max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
        if fit < theta_sharp {
            return None;
        }
        label.push(s);
    }
    // Three planes that meet near the cell make a corner, which one centre serves.
    if meet_near(pts, &label, sheets, component.grown(GROWTH)) {
        return None;
    }
    let runs = runs(&label);
    let middles: Vec<u8> = match runs.as_slice() {
        // Every face meets both others: any may be the middle one.
        [_, _, _] if distinct(&runs) => vec![0, 1, 2],
        // x y z y: y is.
        [x, y, z, w] if y == w && x != z && x != y && z != y => vec![*y],
        [x, y, z, w] if x == z && y != w && x != y && w != x => vec![*x],
        _ => return None,
    };
    middles
        .into_iter()
        .filter_map(|middle| {
            let sides: Vec<u8> = (0..3).filter(|&s| s != middle).collect();
            let relabel = |s: u8| match s {
                s if s == middle => MIDDLE,
                s if s == sides[0] => FIRST,
                _ => OTHER,
            };
            let label: Vec<u8> = label.iter().map(|&s| relabel(s)).collect();
            let strip = place(component, &label, &[], distance, on_surface)?;
            let worst = worst_distance(&strip, pts, distance)?;
            Some((strip, worst))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// A strip for an edge component where a point of the surface between its two sides (`between`,
/// with its normal: see [`super::crease::fine_scale`]) turns sharply against both: the face a walk
/// from one side to the other met (see the module doc). The caller keeps it only where its
/// triangles lie nearer the surface than the one centre's fan.
pub fn hidden(
    component: &Component,
    between: (Vec3, Vec3),
    sampler: &dyn EdgeSampler,
    theta_sharp: f32,
    on_surface: f32,
) -> Option<(Strip, f32)> {
    let (pts, nrm) = (component.pts, component.nrm);
    let n = pts.len();
    let (i, j) = feature::widest_pair_indices(nrm)?;
    let sides = [nrm[i], nrm[j]];
    let (p, pn) = between;
    if !in_box(p, component.grown(GROWTH)) || sides.iter().any(|s| s.dot(pn) >= theta_sharp) {
        return None;
    }
    let mut label = Vec::with_capacity(n);
    for m in nrm {
        let (a, b) = (m.dot(sides[0]), m.dot(sides[1]));
        if a.max(b) < theta_sharp {
            return None;
        }
        label.push(if a >= b { FIRST } else { OTHER });
    }
    let distance = |p: Vec3| sampler.distance(p);
    let strip = place(component, &label, &[(p, pn)], &distance, on_surface)?;
    let worst = worst_distance(&strip, pts, &distance)?;
    Some((strip, worst))
}

/// The cyclic runs of equal labels, one entry per run.
fn runs(label: &[u8]) -> Vec<u8> {
    let n = label.len();
    let Some(start) = (0..n).find(|&q| label[q] != label[(q + n - 1) % n]) else { return vec![label[0]] };
    (0..n)
        .map(|q| (q + start) % n)
        .filter(|&q| q == start || label[q] != label[(q + n - 1) % n])
        .map(|q| label[q])
        .collect()
}

/// Whether the three sheets' planes (each through the mean of its crossings) meet in one point
/// inside `near`.
fn meet_near(pts: &[Vec3], label: &[u8], sheets: [Vec3; 3], near: (Vec3, Vec3)) -> bool {
    let mut offsets = [0.0f64; 3];
    for (s, offset) in offsets.iter_mut().enumerate() {
        let on: Vec<Vec3> = (0..pts.len()).filter(|&q| label[q] == s as u8).map(|q| pts[q]).collect();
        let mean = on.iter().sum::<Vec3>() / on.len().max(1) as f32;
        *offset = sheets[s].as_dvec3().dot(mean.as_dvec3());
    }
    let [a, b, c] = sheets.map(|n| n.as_dvec3());
    let det = a.dot(b.cross(c));
    if det.abs() < 1e-6 {
        return false;
    }
    // Cramer's rule for a·p = oa, b·p = ob, c·p = oc.
    let p = (b.cross(c) * offsets[0] + c.cross(a) * offsets[1] + a.cross(b) * offsets[2]) / det;
    in_box(p.as_vec3(), near)
}

fn distinct(runs: &[u8]) -> bool {
    runs[0] != runs[1] && runs[1] != runs[2] && runs[0] != runs[2]
}

/// Samples along each crease, in the cell, when searching for centres whose triangles do not fold.
const LINE_SAMPLES: usize = 16;

/// The two centres for one reading of the labels, on their creases, in the cell and on the
/// surface, and the triangles, which must face the way their sheets do. Each crease's point
/// nearest its crossings is tried first; where the triangles fold (a crease that leaves the cell
/// near where the polygon cuts it), points along both creases are, nearest first.
fn place(
    component: &Component,
    label: &[u8],
    middle: &[(Vec3, Vec3)],
    distance: &dyn Fn(Vec3) -> Option<f32>,
    on_surface: f32,
) -> Option<Strip> {
    let (pts, nrm) = (component.pts, component.nrm);
    let (lo, hi) = component.grown(-INSET);
    let triangulations: Vec<Vec<[usize; 3]>> =
        entering_choices(label).filter_map(|e| triangulate(label, e)).collect();
    if triangulations.is_empty() {
        return None;
    }
    let mut candidates: [Vec<Vec3>; 2] = Default::default();
    let mut creases = [Vec3::ZERO; 2];
    for (c, side) in [FIRST, OTHER].into_iter().enumerate() {
        let on = |q: &usize| label[*q] == side || label[*q] == MIDDLE;
        let (sp, sn): (Vec<Vec3>, Vec<Vec3>) =
            (0..pts.len()).filter(on).map(|q| (pts[q], nrm[q])).chain(middle.iter().copied()).unzip();
        let solved = feature::feature_point(&sp, &sn, FeatureKind::Edge);
        let dir = feature::crease_direction(&sn)?;
        creases[c] = dir;
        let Some((s0, s1)) = line_in_box(solved, dir, lo, hi) else { continue };
        let nearest = 0.0f32.clamp(s0, s1);
        let mut steps: Vec<f32> =
            (0..=LINE_SAMPLES).map(|q| s0 + (s1 - s0) * q as f32 / LINE_SAMPLES as f32).collect();
        steps.sort_by(|a, b| (a - nearest).abs().total_cmp(&(b - nearest).abs()));
        steps.insert(0, nearest);
        candidates[c] = steps
            .into_iter()
            .map(|s| (solved + dir * s).clamp(lo, hi))
            .filter(|&p| distance(p).is_some_and(|d| d <= on_surface))
            .collect();
    }
    let [first, other] = &candidates;
    let mut pairs: Vec<(usize, usize)> =
        (0..first.len()).flat_map(|a| (0..other.len()).map(move |b| (a, b))).collect();
    pairs.sort_by_key(|&(a, b)| (a + b, a.abs_diff(b)));
    let two = pairs.into_iter().find_map(|(a, b)| {
        triangulations.iter().find_map(|triangles| {
            let centres = vec![first[a], other[b]];
            let strip = Strip { centres, creases: creases.to_vec(), triangles: triangles.clone() };
            faces_its_sheets(&strip, pts, nrm, label, middle).then_some(strip)
        })
    });
    if two.is_some() {
        return two;
    }
    // Where one crease only skims the cell (its line misses the cell, or only off the surface),
    // the other crease's centre alone, fanned to the whole polygon.
    let n = pts.len();
    let fan: Vec<[usize; 3]> = (0..n).map(|q| [n, q, (q + 1) % n]).collect();
    let single = |c: usize| {
        candidates[c].iter().find_map(|&centre| {
            let strip = Strip { centres: vec![centre], creases: vec![creases[c]], triangles: fan.clone() };
            faces_its_sheets(&strip, pts, nrm, label, middle).then_some(strip)
        })
    };
    match (first.is_empty(), other.is_empty()) {
        (false, true) => single(0),
        (true, false) => single(1),
        _ => None,
    }
}

/// The two-centre fan over a polygon labelled by sheet: each polygon edge goes to the centre of
/// the side it leaves (where it leaves the middle face, of the side it enters; an edge within
/// the middle face, to the centre of the edge before it); where two consecutive edges go to
/// different centres, a triangle between their shared vertex and both centres closes the gap.
/// An edge straight from one side to the other (the middle face crosses the cell's face between
/// two crossings) may go to either: the k-th such edge goes to the side it enters where bit k of
/// `entering` is set (which one faces the right way depends on where the face crosses). `None`
/// unless the centre changes exactly twice around the polygon.
fn triangulate(label: &[u8], entering: u8) -> Option<Vec<[usize; 3]>> {
    let n = label.len();
    let centre = |s: u8| (s == OTHER) as usize;
    // The direct edges, in order, each with its bit of `entering`.
    let direct: Vec<usize> = (0..n).filter(|&q| is_direct(label[q], label[(q + 1) % n])).collect();
    let side = |q: usize| match (label[q], label[(q + 1) % n]) {
        (MIDDLE, MIDDLE) => None,
        (MIDDLE, v) => Some(centre(v)),
        (u, v) if is_direct(u, v) => {
            let k = direct.iter().position(|&d| d == q).unwrap_or(0);
            Some(if entering >> k & 1 == 1 { centre(v) } else { centre(u) })
        }
        (u, _) => Some(centre(u)),
    };
    let start = (0..n).find(|&q| side(q).is_some())?;
    let mut centre_of = vec![0usize; n];
    let mut current = side(start)?;
    for k in 0..n {
        let q = (start + k) % n;
        current = side(q).unwrap_or(current);
        centre_of[q] = current;
    }
    let mut triangles = Vec::with_capacity(n + 2);
    let mut changes = 0;
    for q in 0..n {
        let r = (q + 1) % n;
        triangles.push([n + centre_of[q], q, r]);
        if centre_of[r] != centre_of[q] {
            triangles.push([n + centre_of[q], r, n + centre_of[r]]);
            changes += 1;
        }
    }
    (changes == 2).then_some(triangles)
}

/// Every triangle is not degenerate and faces the way the normals at its polygon vertices do
/// (each of them, not only their sum: a triangle across a crease must not turn its back to
/// either face).
/// An edge straight from one side to the other, past the middle face.
fn is_direct(u: u8, v: u8) -> bool {
    u != v && u != MIDDLE && v != MIDDLE
}

/// Choices of [`triangulate`]'s `entering` worth trying: one bit per direct edge.
fn entering_choices(label: &[u8]) -> std::ops::Range<u8> {
    let n = label.len();
    let direct = (0..n).filter(|&q| is_direct(label[q], label[(q + 1) % n])).count().min(2);
    0..1 << direct
}

fn faces_its_sheets(
    strip: &Strip,
    pts: &[Vec3],
    nrm: &[Vec3],
    label: &[u8],
    middle: &[(Vec3, Vec3)],
) -> bool {
    let n = pts.len();
    let middle_normal: Vec3 = (0..n)
        .filter(|&q| label[q] == MIDDLE)
        .map(|q| nrm[q])
        .chain(middle.iter().map(|m| m.1))
        .sum::<Vec3>()
        .normalize_or_zero();
    strip.triangles.iter().zip(strip.positions(pts)).all(|(t, [a, b, c])| {
        let normal = (b - a).cross(c - a);
        let scale = (b - a).length() * (c - a).length();
        // Degenerate (or NaN: the comparison fails for it too).
        if normal.length().partial_cmp(&(1e-6 * scale)) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let references: Vec<Vec3> = t.iter().filter(|&&v| v < n).map(|&v| nrm[v]).collect();
        let bridge = t.iter().filter(|&&v| v >= n).count() == 2;
        references.iter().chain(bridge.then_some(&middle_normal)).all(|r| normal.dot(*r) > 0.0)
    })
}

/// The largest distance from the surface over the triangles' centroids; `None` where the input
/// cannot tell.
fn worst_distance(strip: &Strip, pts: &[Vec3], distance: &dyn Fn(Vec3) -> Option<f32>) -> Option<f32> {
    strip.positions(pts).try_fold(0.0f32, |worst, [a, b, c]| Some(worst.max(distance((a + b + c) / 3.0)?)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emc::placement::UNBOUNDED;

    #[test]
    fn runs_are_counted_around_the_polygon() {
        assert_eq!(runs(&[1, 0, 2, 2]), vec![1, 0, 2]);
        assert_eq!(runs(&[0, 0, 1, 2, 2, 1]), vec![0, 1, 2, 1]);
        assert_eq!(runs(&[1, 1]), vec![1]);
    }

    /// Each edge of the polygon is used once, each edge between the centres twice, both ways:
    /// the fan closes the polygon as one disc.
    #[test]
    fn the_two_centre_fan_is_a_disc_over_the_polygon() {
        let labels = [
            vec![FIRST, MIDDLE, OTHER, MIDDLE],
            vec![MIDDLE, FIRST, OTHER, OTHER],
            vec![FIRST, FIRST, MIDDLE, MIDDLE, OTHER, MIDDLE],
            vec![FIRST, FIRST, OTHER, OTHER, OTHER],
        ];
        let every_choice = labels.iter().flat_map(|l| entering_choices(l).map(move |e| (l.clone(), e)));
        for (label, entering) in every_choice {
            let n = label.len();
            let triangles = triangulate(&label, entering).unwrap();
            let mut directed = std::collections::HashMap::new();
            for t in &triangles {
                for k in 0..3 {
                    *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
                }
            }
            for q in 0..n {
                assert_eq!(directed.get(&(q, (q + 1) % n)), Some(&1), "{label:?}");
            }
            for (&(a, b), &count) in &directed {
                assert_eq!(count, 1, "{label:?}");
                let on_boundary = a < n && b < n && b == (a + 1) % n;
                assert!(on_boundary || directed.contains_key(&(b, a)), "{label:?}: {a}-{b} open");
            }
            // Euler characteristic of a disc: V - E + F = 1.
            let edges = directed.keys().filter(|&&(a, b)| a < b || !directed.contains_key(&(b, a))).count();
            assert_eq!((n + 2) as i64 - edges as i64 + triangles.len() as i64, 1, "{label:?}");
        }
    }

    /// A 90° face half a cell wide between a flat top and a face sloping at 33° from it (the
    /// fandisk's): both centres land on their creases, and on the surface.
    #[test]
    fn a_narrow_face_gets_a_centre_on_each_crease() {
        // Top z = 0 for y < 0 (normal +z); middle face y = 0 for z in [-0.5, 0] (normal +y);
        // lower face through (0, 0, -0.5) turned 33° about x from the top, for y > 0.
        let top = Vec3::Z;
        let side = Vec3::Y;
        let (s, c) = 33f32.to_radians().sin_cos();
        let low = Vec3::new(0.0, s, c);
        let distance = |p: Vec3| -> Option<f32> {
            let d_top = p.z;
            let d_side = p.y;
            let d_low = (p - Vec3::new(0.0, 0.0, -0.5)).dot(low);
            // The solid is below the top, behind the middle face, and below the lower face.
            Some(d_top.max(d_side.min(d_low)).abs())
        };
        let pts = [
            Vec3::new(0.0, -0.3, 0.0),
            Vec3::new(1.0, -0.3, 0.0),
            Vec3::new(1.0, 0.0, -0.2),
            Vec3::new(1.0, 0.6, -0.5 - 0.6 * s / c),
            Vec3::new(0.0, 0.6, -0.5 - 0.6 * s / c),
            Vec3::new(0.0, 0.0, -0.3),
        ];
        let nrm = [top, top, side, low, low, side];
        let component = Component {
            pts: &pts,
            nrm: &nrm,
            cell_min: Vec3::new(-0.01, -0.5, -1.0),
            cell_max: Vec3::new(1.01, 0.7, 0.1),
            domain: UNBOUNDED,
        };
        let (strip, worst) = solve(&component, 0.9, &distance, 1e-4).expect("a strip");
        // No farther off than the polygon's own chord across the upper crease, (1, -0.15, -0.1).
        assert!(worst <= 0.1 + 1e-4, "{worst}");
        let on_top_crease = |p: Vec3| p.y.abs() < 1e-4 && p.z.abs() < 1e-4;
        let on_low_crease = |p: Vec3| p.y.abs() < 1e-4 && (p.z + 0.5).abs() < 1e-4;
        let [a, b] = strip.centres[..] else { panic!("two centres: {:?}", strip.centres) };
        assert!(
            (on_top_crease(a) && on_low_crease(b)) || (on_top_crease(b) && on_low_crease(a)),
            "{:?}",
            strip.centres
        );
    }
}

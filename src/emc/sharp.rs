//! The feature point of one sharp component: §4.3's tangent planes, and where the input can be
//! sampled off the grid edges (functions, meshes), the surface itself.
//!
//! The tangent planes at a cell's crossings stand for the sheets they were taken on. Where a
//! sheet is curved they meet off the surface: a rounded edge tessellated in strips, each turning
//! under θ, meeting a flat face, looks like a corner, and the outer strips' planes and the face's
//! meet a fifth of a cell off the part (the fandisk at 64 cells). There the surface is walked from
//! one sheet to the other ([`crease::crease_between`]), which finds the crease that is really
//! there, and the point is resampled on it.

use super::crease::{self, Crease};
use super::edges::EdgeSampler;
use super::feature::{self, FeatureKind};
use super::placement::{self, Component, Placed};
use super::resample;
use super::EmcOptions;
use glam::Vec3;

/// What a sharp component comes to: its kind (smooth at the fine scale, or an edge where the
/// normals suggested a corner) and its placed feature point, `None` where no valid one was found.
pub struct Sharp {
    pub kind: FeatureKind,
    pub feature: Option<(Placed, FeatureKind)>,
    /// A point of the surface, with its normal, between two of the component's crossings that
    /// turns sharply against both: a face too narrow for a crossing (see [`super::strip`]).
    pub between: Option<(Vec3, Vec3)>,
}

/// The feature point of `component`, classified `kind` by §4.2's normal test. `on_surface` is how
/// far (in length units) a point on the feature may lie from the surface where the input can tell.
pub fn solve(
    mut kind: FeatureKind,
    component: &Component,
    sampler: &dyn EdgeSampler,
    options: &EmcOptions,
    on_surface: f32,
) -> Sharp {
    let (pts, nrm) = (component.pts, component.nrm);
    let theta = options.theta_sharp;
    let walk = options.resample_creases;
    // Where the input can be walked (a function, a closed mesh), a crease is kept only where the
    // surface still turns past θ next to it (see `crease`).
    let mut between = None;
    if kind != FeatureKind::Smooth && walk {
        let fine = crease::fine_scale(pts, nrm, sampler, theta);
        between = fine.between;
        if fine.smooth {
            kind = FeatureKind::Smooth;
        }
    }
    if kind == FeatureKind::Smooth {
        return Sharp { kind, feature: None, between: None };
    }
    // A third sheet that continues another one smoothly makes an edge, solved from a point on its
    // crease rather than from the tangent planes.
    if let Some(crease) = walk.then(|| crease::two_sheet_crease(pts, nrm, sampler, theta)).flatten() {
        let feature = place_on_crease(&crease, component, sampler, on_surface);
        return Sharp { kind: FeatureKind::Edge, feature, between };
    }
    let near = component.grown(placement::GROWTH);
    let (mut solved_kind, mut solved) = feature::sharp_point(pts, nrm, kind, near);
    if walk {
        if let Some(better) = resample::resample_component(solved, solved_kind, component, sampler, theta) {
            (solved_kind, solved) = better;
        }
    }
    let surface = walk.then_some((sampler, on_surface));
    Sharp { kind, feature: place(solved, solved_kind, component, surface), between }
}

/// An edge point on `crease`, resampled from its two sides, placed in the component's cell.
fn place_on_crease(
    crease: &Crease,
    component: &Component,
    sampler: &dyn EdgeSampler,
    on_surface: f32,
) -> Option<(Placed, FeatureKind)> {
    let cell = (component.cell_max - component.cell_min).min_element();
    let [(p0, n0), (p1, n1)] = crease.sides;
    // The two sides' planes meet on the crease (exactly, where they are flat), nearest to the
    // middle of the walk's last piece.
    let (pts, nrm) = ([p0, p1], [n0, n1]);
    let planes = feature::feature_point(&pts, &nrm, FeatureKind::Edge);
    let start = if planes.distance(crease.at) <= p0.distance(p1) { planes } else { crease.at };
    let point =
        resample::resample_feature(start, FeatureKind::Edge, &pts, &nrm, sampler, cell).unwrap_or(start);
    place(point, FeatureKind::Edge, component, Some((sampler, on_surface)))
}

/// `point` placed in the component's cell ([`placement::place`]), and where `surface` is given,
/// checked to lie within its distance of the sampler's surface ([`Placed::check_surface`]);
/// where that gives no feature vertex, [`placement::place_far`]'s point if it is one.
fn place(
    point: Vec3,
    kind: FeatureKind,
    component: &Component,
    surface: Option<(&dyn EdgeSampler, f32)>,
) -> Option<(Placed, FeatureKind)> {
    let placed = placement::place(point, kind, component);
    let Some((sampler, on_surface)) = surface else { return placed.map(|p| (p, kind)) };
    let checked = |mut placed: Placed| {
        placed.check_surface(|p| sampler.distance(p), on_surface);
        placed
    };
    let placed = placed.map(checked);
    if placed.is_some_and(|p| p.at.is_feature_vertex()) {
        return placed.map(|p| (p, kind));
    }
    // No centre on the feature near the cell: farther, where the input says it is on the surface
    // (not merely that it cannot tell: a flat field, as on samples at the level, says nothing).
    // (`place_far` gives only points on the feature, and one on the surface is not off it.)
    let on_it = |p: &Placed| sampler.distance(p.at.position).is_some_and(|d| d <= on_surface);
    let far = placement::place_far(point, kind, component).filter(on_it).map(checked);
    far.or(placed).map(|p| (p, kind))
}

//! One component of a cell on its way out: its polygon, and where sharp its feature point, with
//! the triangles either would emit (a fan, or MC's table / the per-cell rules): what the cell's
//! passes in [`super`] look at before anything is written to the mesh.

use super::feature::FeatureKind;
use super::placement;
use super::strip::Strip;
use crate::mc::{polygon_center, untangled};
use crate::mcq::polygon::triangulate_cell_polygon;
use crate::mcq::PolygonRules;
use crate::tables::{CellTriangles, CENTER};
use glam::{DVec3, Vec3};

/// What one component of a cell will become: its polygon and, where sharp, its feature point.
pub(super) struct Plan<'a> {
    pub by_edge: [u32; 13],
    /// The polygon's vertex ids and positions, in order.
    pub ids: Vec<u32>,
    pub pts: Vec<Vec3>,
    pub nrm: Vec<Vec3>,
    /// The cell edges its vertices sit on, in the same order.
    pub cell_edges: &'a [u8],
    /// Its triangles in the cell's MC triangulation (triangle indices).
    pub group: std::ops::Range<usize>,
    /// Where the fan centre goes, what the feature is, and, for a centre outside the cell, where
    /// it would go inside (see [`super::untangle`]).
    pub feature: Option<(placement::Placed, FeatureKind)>,
    /// Two centres instead of one, where two creases bound a face narrower than the cell (see
    /// [`super::strip`]), with the triangles' largest distance from the surface; `feature` is
    /// then `None`.
    pub strip: Option<(Strip, f32)>,
}

/// Stands for the one vertex a component without feature point may add (MC's centre vertex, or
/// the inner vertex of the per-cell rules) before it has an id.
pub(super) const EXTRA: u32 = u32::MAX;

impl Plan<'_> {
    /// The triangles of this component's fan, as positions, if it has a feature point or a strip.
    pub fn fan_triangles(&self) -> Option<Vec<[DVec3; 3]>> {
        if let Some((strip, _)) = &self.strip {
            return Some(strip.positions(&self.pts).map(|t| t.map(|p| p.as_dvec3())).collect());
        }
        self.feature_fan()
    }

    /// The fan around this component's feature point, as positions, if it has one.
    fn feature_fan(&self) -> Option<Vec<[DVec3; 3]>> {
        let (f, _) = self.feature?;
        let n = self.pts.len();
        let corner = |q: usize| [f.at.position, self.pts[q], self.pts[(q + 1) % n]].map(|p| p.as_dvec3());
        Some((0..n).map(corner).collect())
    }

    /// Whether this component's strip (see [`super::strip`]) lies nearer the surface, at its
    /// triangles' centroids by `distance`, than what it would be without: the fan around its
    /// feature point, or MC's triangles (a strip is taken only where the input can tell).
    pub fn strip_is_nearer(
        &self,
        positions: &[Vec3],
        table: &CellTriangles,
        rules: Option<&PolygonRules>,
        distance: impl Fn(Vec3) -> Option<f32>,
    ) -> bool {
        let Some((_, strip_worst)) = &self.strip else { return false };
        let without = self.feature_fan().unwrap_or_else(|| self.plain_triangles(positions, table, rules));
        *strip_worst < farthest_centroid(&without, distance)
    }

    /// Whether this component's fan centre is an approximate one (off its feature, or on its
    /// feature's line but off the surface: see [`placement`]) that lies farther from the
    /// surface, by `distance` (an estimate, `None` where the input cannot tell), than `slack`
    /// beyond the centroid of every one of MC's triangles of the polygon. Such a centre bends the patch away from the surface, not towards
    /// a feature: a crease or an apex in a grid plane that the cell sees only from one side (two
    /// boxes' faces on grid planes), where its fan stood up to 166° off the surface. On the scenes
    /// at 32–96 cells this changes the rocket and the gyroid only, each max distance the same or
    /// lower (the rocket at 32 and 64 cells: 0.0379 → 0.0327, 0.0169 → 0.0139).
    pub fn approximate_centre_is_worse_than_mc(
        &self,
        positions: &[Vec3],
        table: &CellTriangles,
        rules: Option<&PolygonRules>,
        distance: impl Fn(Vec3) -> Option<f32>,
        slack: f32,
    ) -> bool {
        let Some((placed, _)) = &self.feature else { return false };
        if placed.at.is_feature_vertex() {
            return false;
        }
        let Some(centre) = distance(placed.at.position) else { return false };
        let mc_worst = farthest_centroid(&self.plain_triangles(positions, table, rules), distance);
        centre > mc_worst + slack
    }

    /// The triangles of [`Plan::plain`], as positions.
    pub fn plain_triangles(
        &self,
        positions: &[Vec3],
        table: &CellTriangles,
        rules: Option<&PolygonRules>,
    ) -> Vec<[DVec3; 3]> {
        let (tris, extra) = self.plain(positions, table, rules);
        let at = |v: u32| match (v, extra) {
            (EXTRA, Some(c)) => c.as_dvec3(),
            _ => positions[v as usize].as_dvec3(),
        };
        tris.iter().map(|t| t.map(at)).collect()
    }

    /// The triangles of the component without a feature point, by vertex id ([`EXTRA`] for an
    /// added vertex, whose position comes along): MC's table, or with `rules` the per-cell polygon
    /// rules of [`crate::mcq`].
    pub fn plain(
        &self,
        positions: &[Vec3],
        table: &CellTriangles,
        rules: Option<&PolygonRules>,
    ) -> (Vec<[u32; 3]>, Option<Vec3>) {
        if let Some(rules) = rules {
            return triangulate_cell_polygon(&self.ids, &self.pts, self.cell_edges, rules, EXTRA);
        }
        let table_group = &table.edges[3 * self.group.start..3 * self.group.end];
        let fan = untangled(self.cell_edges, table_group, |e| positions[self.by_edge[e as usize] as usize]);
        let group = fan.as_deref().unwrap_or(table_group);
        let extra = group.contains(&CENTER).then(|| polygon_center(positions, group, &self.by_edge));
        let id = |e: u8| if e == CENTER { EXTRA } else { self.by_edge[e as usize] };
        (group.chunks_exact(3).map(|t| [id(t[0]), id(t[1]), id(t[2])]).collect(), extra)
    }
}

/// The largest of `distance` over the triangles' centroids (0 where it cannot tell).
fn farthest_centroid(triangles: &[[DVec3; 3]], distance: impl Fn(Vec3) -> Option<f32>) -> f32 {
    triangles.iter().filter_map(|t| distance(((t[0] + t[1] + t[2]) / 3.0).as_vec3())).fold(0.0f32, f32::max)
}

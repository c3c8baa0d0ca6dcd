//! Every option of a [`Request`] checked in one place, before any work, so the CLI, the wasm API
//! and the benches refuse the same inputs with the same words. Each method's knobs are checked by
//! one function of that method's; the request adds what every method shares (iso-level, bounds,
//! resolution, cell cap). A value is refused rather than clamped: a silently different request
//! would mesh a different surface.

use super::{Method, Request};
use crate::error::Error;
use crate::field::MAX_SAMPLE_MAGNITUDE;
use crate::grid::{Grid, MAX_CELLS_PER_AXIS};
use crate::quad::QuadOptions;

/// Most relaxation rounds, collapse passes and subdivision steps the quad method accepts: each
/// subdivision quadruples the mesh, so past a few the output, not the input, is the problem.
pub const MAX_QUAD_RELAX: usize = 100;
pub const MAX_QUAD_PASSES: usize = 8;
pub const MAX_QUAD_SUBDIVISIONS: usize = 3;

impl Request {
    /// Fails with [`Error::InvalidOption`] (or [`Error::InvalidGrid`] for bounds) naming the first
    /// option outside its meaningful range.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |msg: String| Err(Error::InvalidOption(msg));
        if !self.iso.is_finite() {
            return bad(format!("iso must be finite, got {}", self.iso));
        }
        if self.iso.abs() > MAX_SAMPLE_MAGNITUDE {
            return bad(format!(
                "iso must lie within ±{MAX_SAMPLE_MAGNITUDE:e}, as samples do, got {:e}",
                self.iso
            ));
        }
        if self.res == 0 || self.res > MAX_CELLS_PER_AXIS {
            return bad(format!("res must be a whole number in 1..={MAX_CELLS_PER_AXIS}, got {}", self.res));
        }
        if self.max_cells == 0 {
            return bad("maxCells must be at least 1".into());
        }
        if let Some((min, max)) = self.bounds {
            // Grid::new checks finiteness, max > min and that f32 can resolve one cell there.
            Grid::new(min, max, [1, 1, 1])?;
        }
        self.validate_refinement()?;
        match self.method {
            Method::Mc => self.mc_options().validate(),
            Method::Emc => self.emc_options().validate(),
            Method::Dmc => self.dmc_options().validate(),
            Method::Mcq => self.mcq_options().validate(),
            Method::Quad => validate_quad(&self.quad),
        }
    }
}

/// Most smoothing passes accepted: past a few dozen a surface only gets slower to smooth.
pub const MAX_SMOOTH_PASSES: usize = 100;

impl Request {
    /// Decimation and smoothing, shared by every method but the quad one, whose quads they would
    /// break up.
    fn validate_refinement(&self) -> Result<(), Error> {
        let bad = |msg: String| Err(Error::InvalidOption(msg));
        if self.method == Method::Quad && (self.decimate.is_some() || self.smooth > 0) {
            return bad(
                "decimate and smooth do not apply to the quad method (they would break its quads)".into()
            );
        }
        if self.decimate == Some(0) {
            return bad("decimate must be a target of at least 1 triangle, got 0".into());
        }
        if let Some(e) = self.decimate_error {
            if !(e.is_finite() && e > 0.0) {
                return bad(format!("decimateError must be a positive number of cells, got {e}"));
            }
        }
        if self.smooth > MAX_SMOOTH_PASSES {
            return bad(format!("smooth must lie in 0..={MAX_SMOOTH_PASSES}, got {}", self.smooth));
        }
        Ok(())
    }
}

/// The quad method's knobs (see [`QuadOptions`]).
fn validate_quad(options: &QuadOptions) -> Result<(), Error> {
    let limit = |name: &str, v: usize, max: usize| {
        if v <= max {
            Ok(())
        } else {
            Err(Error::InvalidOption(format!("{name} must lie in 0..={max}, got {v}")))
        }
    };
    limit("quad relaxation rounds", options.relax_iterations, MAX_QUAD_RELAX)?;
    limit("quad collapse passes", options.passes, MAX_QUAD_PASSES)?;
    limit("quad subdivisions", options.subdivisions, MAX_QUAD_SUBDIVISIONS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn refused(request: Request, needle: &str) {
        let err = request.validate().expect_err(needle).to_string();
        assert!(err.contains(needle), "expected '{needle}' in: {err}");
    }

    #[test]
    fn every_method_refuses_a_non_finite_iso_level() {
        for method in Method::NAMES.map(|m| Method::parse(m).unwrap()) {
            for iso in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                refused(Request { method, iso, ..Request::default() }, "iso must be finite");
            }
            assert_eq!(Request { method, ..Request::default() }.validate(), Ok(()));
        }
    }

    #[test]
    fn knobs_out_of_range_are_named() {
        let mcq = Request { method: Method::Mcq, ..Request::default() };
        let mut nan_cut = mcq.clone();
        nan_cut.mcq_rules.cut_angle_deg = f32::NAN;
        refused(nan_cut, "cutAngle");
        let mut ratio = mcq.clone();
        ratio.mcq_rules.quad_ratio = -1.0;
        refused(ratio, "quadRatio");
        refused(Request { mcq_snap: Some(0.7), ..mcq }, "snap");
        let emc = Request { method: Method::Emc, ..Request::default() };
        refused(Request { theta_sharp: f32::NAN, ..emc.clone() }, "thetaSharp");
        refused(Request { phi_corner: 2.0, ..emc }, "phiCorner");
        let dmc = Request { method: Method::Dmc, ..Request::default() };
        refused(Request { tolerance: -1.0, ..dmc.clone() }, "tolerance");
        refused(Request { samples_per_cell: 1, ..dmc }, "samplesPerCell");
        let mut quad = Request { method: Method::Quad, ..Request::default() };
        quad.quad.subdivisions = 9;
        refused(quad, "quad subdivisions");
        refused(Request { res: 0, ..Request::default() }, "res must be");
        refused(Request { max_cells: 0, ..Request::default() }, "maxCells");
    }

    #[test]
    fn bounds_must_be_finite_non_empty_and_resolvable() {
        let with = |min: Vec3, max: Vec3| Request { bounds: Some((min, max)), ..Request::default() };
        refused(with(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)), "max > min");
        refused(with(Vec3::splat(f32::NAN), Vec3::ONE), "finite");
        refused(with(Vec3::splat(-3e38), Vec3::splat(3e38)), "coordinates must lie within");
        refused(with(Vec3::splat(1e7), Vec3::splat(1e7 + 4.0)), "finer than f32");
    }
}

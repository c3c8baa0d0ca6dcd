//! Progress and cooperative cancellation for long jobs.
//!
//! The meshers call [`checkpoint`] between slabs of a grid, levels of an octree and passes of the
//! analysis, naming the phase (the keys of `phases_ms`) and how far it got. Whoever runs the job
//! may install a hook for its duration ([`with_hook`]) that sees each checkpoint and may ask the
//! job to stop; the job then returns [`Error::Cancelled`] from that checkpoint, having written
//! nothing anywhere. The web worker uses it to abandon a superseded request without killing the
//! worker (and its compiled module), and to post progress events; the core knows nothing of who
//! listens. Without a hook a checkpoint costs one thread-local read.
//!
//! The hook belongs to the thread that installed it: checkpoints are called from the job's own
//! thread, between pieces of work, never from inside a parallel section.

use crate::error::Error;
use std::cell::RefCell;

type Hook = Box<dyn FnMut(&'static str, f32) -> bool>;

thread_local! {
    static HOOK: RefCell<Option<Hook>> = const { RefCell::new(None) };
}

/// Runs `job` with `hook` seeing every checkpoint: `hook(phase, fraction)` returns `true` to stop
/// the job. The previous hook (if any) is restored afterwards, even if `job` panics.
pub fn with_hook<R>(hook: impl FnMut(&'static str, f32) -> bool + 'static, job: impl FnOnce() -> R) -> R {
    struct Restore(Option<Hook>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            HOOK.with(|h| *h.borrow_mut() = previous);
        }
    }
    let previous = HOOK.with(|h| h.borrow_mut().replace(Box::new(hook)));
    let _restore = Restore(previous);
    job()
}

/// Reports that `phase` is `fraction` (0 to 1) done; fails with [`Error::Cancelled`] if the hook
/// asks to stop.
pub fn checkpoint(phase: &'static str, fraction: f32) -> Result<(), Error> {
    let stop = HOOK.with(|h| match h.try_borrow_mut() {
        Ok(mut hook) => hook.as_mut().is_some_and(|f| f(phase, fraction.clamp(0.0, 1.0))),
        // A checkpoint reached from inside the hook itself: nothing to report.
        Err(_) => false,
    });
    if stop {
        Err(Error::Cancelled)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    #[test]
    fn a_hook_sees_checkpoints_and_can_stop_the_job() {
        let seen = Rc::new(RefCell::new(Vec::new()));
        let log = seen.clone();
        let result = with_hook(
            move |phase, fraction| {
                log.borrow_mut().push((phase, fraction));
                fraction >= 0.5
            },
            || -> Result<usize, Error> {
                for i in 0..10 {
                    checkpoint("work", i as f32 / 10.0)?;
                }
                Ok(10)
            },
        );
        assert_eq!(result, Err(Error::Cancelled));
        assert_eq!(seen.borrow().len(), 6, "stopped at the first checkpoint past half way");
        // Restored afterwards: no hook, nothing stops.
        assert_eq!(checkpoint("work", 1.0), Ok(()));
    }

    #[test]
    fn jobs_are_stopped_by_checkpoints_in_every_method() {
        use crate::pipeline::{mesh_scene, Method, Request};
        for method in [Method::Mc, Method::Emc, Method::Dmc, Method::Mcq, Method::Quad] {
            let request = Request { method, res: 24, ..Request::default() };
            let phases = Rc::new(RefCell::new(Vec::new()));
            let log = phases.clone();
            let result = with_hook(
                move |phase, _| {
                    log.borrow_mut().push(phase);
                    log.borrow().len() > 3
                },
                || mesh_scene("rocket", &request),
            );
            assert_eq!(result.err(), Some(Error::Cancelled), "{method:?}");
            assert_eq!(phases.borrow().len(), 4, "{method:?}: {:?}", phases.borrow());
            // And without a hook the same request runs to the end.
            assert!(mesh_scene("rocket", &request).is_ok());
        }
    }

    /// DMC's simplification, its longest stretch on deep octrees, checks in once per level, so a
    /// stop asked for during it comes before the contouring.
    #[test]
    fn dmc_stops_inside_its_simplification() {
        use crate::pipeline::{mesh_scene, Method, Request};
        let request = Request { method: Method::Dmc, max_depth: Some(6), ..Request::default() };
        let seen = Rc::new(RefCell::new(Vec::new()));
        let log = seen.clone();
        let result = with_hook(
            move |phase, fraction| {
                log.borrow_mut().push((phase, fraction));
                phase == "octree" && fraction > 0.7
            },
            || mesh_scene("fandisk", &request),
        );
        assert_eq!(result.err(), Some(Error::Cancelled));
        let seen = seen.borrow();
        assert!(seen.iter().any(|&(p, _)| p == "feature_isolation"), "stopped after the sampling: {seen:?}");
        assert!(!seen.iter().any(|&(p, _)| p == "contouring"), "stopped before the contouring: {seen:?}");
    }

    /// The surface measurement of a large mesh checks in every few thousand faces: a stop asked
    /// for half way ends it there, and without a hook it measures what `surface_error` does.
    #[test]
    fn the_surface_measurement_stops_part_way() {
        use crate::mesh::analysis::{surface_error, surface_error_cancellable};
        use crate::pipeline::{mesh_scene, Request};
        let out = mesh_scene("torus", &Request { res: 64, ..Request::default() }).unwrap();
        let field = crate::scenes::scene("torus").unwrap().field;
        assert!(out.mesh.triangle_count() > 4 * 4096, "{} triangles", out.mesh.triangle_count());
        let fractions = Rc::new(RefCell::new(Vec::new()));
        let log = fractions.clone();
        let stopped = with_hook(
            move |_, fraction| {
                log.borrow_mut().push(fraction);
                fraction >= 0.5
            },
            || surface_error_cancellable(&out.mesh, field.as_ref()),
        );
        assert_eq!(stopped, Err(Error::Cancelled));
        let fractions = fractions.borrow();
        assert!(fractions.len() >= 3 && fractions.windows(2).all(|w| w[0] < w[1]), "{fractions:?}");
        assert_eq!(
            surface_error_cancellable(&out.mesh, field.as_ref()),
            Ok(surface_error(&out.mesh, field.as_ref()))
        );
    }

    /// The crossing check of a large mesh checks in every few thousand box pairs: the page runs it
    /// after every mesh, and the next request stops it there instead of waiting for it. Without a
    /// hook it finds what `self_intersecting_pairs` does.
    #[test]
    fn the_crossing_check_stops_part_way() {
        use crate::mesh::analysis::{self_intersecting_pairs, self_intersecting_pairs_cancellable};
        use crate::pipeline::{mesh_scene, Request};
        let out = mesh_scene("torus", &Request { res: 64, ..Request::default() }).unwrap();
        let calls = Rc::new(RefCell::new(0));
        let count = calls.clone();
        let stopped = with_hook(
            move |phase, _| {
                assert_eq!(phase, "analysis");
                *count.borrow_mut() += 1;
                *count.borrow() == 2
            },
            || self_intersecting_pairs_cancellable(&out.mesh),
        );
        assert_eq!(stopped, Err(Error::Cancelled));
        assert_eq!(*calls.borrow(), 2, "stopped at the second checkpoint, not run to the end");
        assert_eq!(self_intersecting_pairs_cancellable(&out.mesh), Ok(self_intersecting_pairs(&out.mesh)));
    }
}

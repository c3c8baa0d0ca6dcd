//! JSON text → `Program::from_csg_json`. Malformed JSON, unknown ops, misplaced fields and
//! out-of-range parameters are errors; nothing may panic, recurse past the stack or allocate
//! without bound. A tree that compiles is evaluated once at a few points and over a box, the
//! calls every mesher makes first.
#![no_main]

use isoforge::expr::Program;
use isoforge::Vec3;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(program) = Program::from_csg_json(text) {
        for p in [Vec3::ZERO, Vec3::splat(0.5), Vec3::new(-1.0, 0.25, 0.9)] {
            let v = program.eval(p);
            let (g, _) = program.eval_grad(p);
            assert!(v == g || (v.is_nan() && g.is_nan()), "eval {v}, eval_grad {g}");
        }
        let (lo, hi) = program.eval_interval(Vec3::splat(-1.0), Vec3::splat(1.0));
        assert!(!lo.is_nan() && !hi.is_nan(), "NaN interval endpoint {lo}..{hi}");
    }
});

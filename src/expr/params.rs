//! The ranges of the shapes' parameters, checked where a shape is built (in the text compiler and
//! in the CSG JSON reader, the same function for both) so a negative radius or a blend of width
//! zero is an error pointing at the call, not a mesh of nonsense. Only parameters whose value is
//! known when the shape is built (constants) can be checked; one computed from the coordinates is
//! the program's own business.

use super::builtins::Builtin;

/// Why `f`'s arguments are out of range, or `None`. `args` holds one entry per argument of the
/// call in order, `Some` for each argument whose value is known (shape arguments are ignored).
pub fn check(f: Builtin, args: &[Option<f64>]) -> Option<String> {
    let name = f.name();
    let first = first_parameter(f)?;
    for (i, v) in args.iter().enumerate().skip(first) {
        if let Some(v) = v {
            if !v.is_finite() {
                return Some(format!(
                    "{name}: argument {} is {}; every parameter must be finite",
                    i + 1,
                    num(*v)
                ));
            }
        }
    }
    let arg = |i: usize| args.get(i).copied().flatten();
    let positive = |i: usize, what: &str| match arg(i) {
        Some(v) if v <= 0.0 => Some(format!("{name}: the {what} must be positive, got {}", num(v))),
        _ => None,
    };
    let at_least_zero = |i: usize, what: &str| match arg(i) {
        Some(v) if v < 0.0 => Some(format!("{name}: the {what} must not be negative, got {}", num(v))),
        _ => None,
    };
    match f {
        Builtin::Sphere => positive(0, "radius"),
        Builtin::Box => {
            (0..3).find_map(|i| positive(i, ["half extent x", "half extent y", "half extent z"][i]))
        }
        Builtin::RoundedBox => {
            let half =
                (0..3).find_map(|i| positive(i, ["half extent x", "half extent y", "half extent z"][i]));
            half.or_else(|| at_least_zero(3, "rounding radius")).or_else(|| {
                let smallest = (0..3).filter_map(arg).fold(f64::INFINITY, f64::min);
                match arg(3) {
                    Some(r) if r > smallest => Some(format!(
                        "{name}: the rounding radius {} is larger than the smallest half extent {}",
                        num(r),
                        num(smallest)
                    )),
                    _ => None,
                }
            })
        }
        Builtin::Cylinder => positive(0, "radius").or_else(|| positive(1, "half height")),
        Builtin::Cone => positive(0, "radius").or_else(|| positive(1, "height")),
        Builtin::Torus => at_least_zero(0, "major radius").or_else(|| positive(1, "minor radius")),
        Builtin::Capsule => positive(6, "radius"),
        Builtin::SmoothUnion | Builtin::SmoothIntersect | Builtin::SmoothSubtract => {
            positive(2, "blend width k")
        }
        Builtin::Shell => positive(1, "thickness"),
        Builtin::Scale => positive(1, "factor"),
        _ => None,
    }
}

/// Parameters are `f32` in the program: print them as such, not as the `f64` they widen to.
fn num(v: f64) -> String {
    format!("{}", v as f32)
}

/// The index of `f`'s first numeric parameter (after its shape arguments), or `None` for
/// functions whose arguments are all values (math, `union`, …), which any number may be.
fn first_parameter(f: Builtin) -> Option<usize> {
    Some(match f {
        Builtin::Sphere
        | Builtin::Box
        | Builtin::RoundedBox
        | Builtin::Cylinder
        | Builtin::Cone
        | Builtin::Torus
        | Builtin::Capsule
        | Builtin::Plane => 0,
        Builtin::Shell | Builtin::Offset | Builtin::Translate | Builtin::Rotate | Builtin::Scale => 1,
        Builtin::SmoothUnion | Builtin::SmoothIntersect | Builtin::SmoothSubtract => 2,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(f: Builtin, args: &[f64], needle: &str) {
        let args: Vec<Option<f64>> = args.iter().map(|&v| Some(v)).collect();
        let message = check(f, &args).unwrap_or_else(|| panic!("{} {args:?} accepted", f.name()));
        assert!(message.contains(needle), "'{needle}' not in: {message}");
    }

    #[test]
    fn out_of_range_parameters_are_named() {
        refused(Builtin::Sphere, &[-0.5], "radius must be positive");
        refused(Builtin::Box, &[0.3, -0.5, 0.2], "half extent y must be positive");
        refused(Builtin::RoundedBox, &[0.5, 0.4, 0.3, 0.35], "larger than the smallest half extent 0.3");
        refused(Builtin::SmoothUnion, &[0.0, 0.0, -1.0], "blend width k must be positive");
        refused(Builtin::SmoothSubtract, &[0.0, 0.0, 0.0], "blend width k");
        refused(Builtin::Rotate, &[0.0, 1.0, 0.0, 0.0, f64::NAN], "argument 5 is NaN");
        refused(Builtin::Scale, &[0.0, -2.0], "factor");
        refused(Builtin::Shell, &[0.0, 0.0], "thickness");
        refused(Builtin::Torus, &[0.5, 0.0], "minor radius");
    }

    #[test]
    fn good_and_unknown_parameters_pass() {
        let known = |v: &[f64]| v.iter().map(|&x| Some(x)).collect::<Vec<_>>();
        assert_eq!(check(Builtin::RoundedBox, &known(&[0.5, 0.4, 0.3, 0.3])), None);
        assert_eq!(check(Builtin::Torus, &known(&[0.0, 0.2])), None);
        assert_eq!(check(Builtin::Sphere, &[None]), None, "a radius computed from x is not checked");
        assert_eq!(check(Builtin::Min, &known(&[-1.0, f64::NAN])), None, "math takes any value");
        assert_eq!(check(Builtin::SmoothUnion, &[Some(-5.0), Some(-3.0), Some(0.1)]), None);
    }
}

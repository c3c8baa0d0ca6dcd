//! Random CSG trees written as programs in the expression language, for the property suites: every
//! primitive, transform and combinator (smooth ones and shells included), thin parts, and parts
//! that reach past the bounds [-1, 1]³. Each tree is a pure function of its seed.

use super::Rng;

/// A generated tree: its program text and facts the suites need about it.
#[derive(Debug, Clone)]
pub struct Tree {
    pub text: String,
    /// Primitives in the tree.
    pub primitives: usize,
    /// Upper bound on the field's Lipschitz constant: every primitive is an exact distance
    /// (1-Lipschitz) and min, max, negation, shells, offsets, rigid motions, uniform scaling and
    /// the polynomial smooth blends keep that, so |f(v)| ≤ distance(v, surface) for every v.
    pub lipschitz: f32,
}

/// A tree of `2..=12` primitives.
pub fn random_tree(rng: &mut Rng) -> Tree {
    let primitives = 2 + rng.below(11) as usize;
    Tree { text: node(rng, primitives), primitives, lipschitz: 1.0 }
}

fn num(v: f32) -> String {
    format!("{v:.3}")
}

/// A subtree with exactly `n` primitives.
fn node(rng: &mut Rng, n: usize) -> String {
    let inner = if n == 1 {
        primitive(rng)
    } else {
        let left = 1 + rng.below(n as u64 - 1) as usize;
        let (a, b) = (node(rng, left), node(rng, n - left));
        let k = num(rng.range(0.02, 0.2));
        match rng.below(7) {
            0 | 1 => format!("union({a}, {b})"),
            2 => format!("intersect({a}, {b})"),
            3 => format!("subtract({a}, {b})"),
            4 => format!("smooth_union({a}, {b}, {k})"),
            5 => format!("smooth_subtract({a}, {b}, {k})"),
            _ => format!("smooth_intersect({a}, {b}, {k})"),
        }
    };
    wrap(rng, inner)
}

/// Sometimes moves, shells or offsets a subtree.
fn wrap(rng: &mut Rng, shape: String) -> String {
    match rng.below(12) {
        0 => format!("shell({shape}, {})", num(rng.range(0.01, 0.08))),
        1 => format!("offset({shape}, {})", num(rng.range(-0.04, 0.06))),
        2 => format!(
            "rotate({shape}, {}, {}, {}, {})",
            num(rng.range(-1.0, 1.0)),
            num(rng.range(-1.0, 1.0)),
            num(rng.range(0.1, 1.0)),
            num(rng.range(-180.0, 180.0))
        ),
        3 => format!("scale({shape}, {})", num(rng.range(0.6, 1.4))),
        4 => format!("mirror_x({shape})"),
        5 => format!(
            "translate({shape}, {}, {}, {})",
            num(rng.range(-0.2, 0.2)),
            num(rng.range(-0.2, 0.2)),
            num(rng.range(-0.2, 0.2))
        ),
        _ => shape,
    }
}

fn primitive(rng: &mut Rng) -> String {
    let size = |rng: &mut Rng| rng.range(0.08, 0.45);
    // One part in eight is thin (a plate or a rod thinner than a typical cell), one in eight sits
    // near a face of the bounds so that it reaches past them.
    let thin = rng.below(8) == 0;
    let reach = rng.below(8) == 0;
    let centre: [f32; 3] = std::array::from_fn(|_| rng.range(-0.6, 0.6));
    let centre = if reach {
        let axis = rng.below(3) as usize;
        let mut c = centre;
        c[axis] = if rng.below(2) == 0 { -0.95 } else { 0.95 };
        c
    } else {
        centre
    };
    let shape = match rng.below(8) {
        0 => format!("sphere({})", num(size(rng))),
        1 => {
            let mut h: [f32; 3] = std::array::from_fn(|_| size(rng));
            if thin {
                h[rng.below(3) as usize] = rng.range(0.005, 0.02);
            }
            format!("box({}, {}, {})", num(h[0]), num(h[1]), num(h[2]))
        }
        2 => {
            let h: [f32; 3] = std::array::from_fn(|_| size(rng));
            let r = rng.range(0.0, 1.0) * h.iter().copied().fold(f32::MAX, f32::min);
            format!("rounded_box({}, {}, {}, {})", num(h[0]), num(h[1]), num(h[2]), num(r.max(0.001)))
        }
        3 => {
            let r = if thin { rng.range(0.005, 0.02) } else { size(rng) };
            format!("cylinder({}, {})", num(r), num(size(rng)))
        }
        4 => format!("cone({}, {})", num(size(rng)), num(size(rng))),
        5 => {
            let big = size(rng);
            let small = if thin { rng.range(0.005, 0.02) } else { rng.range(0.03, big.max(0.05)) };
            format!("torus({}, {})", num(big), num(small))
        }
        6 => {
            let a: [f32; 3] = std::array::from_fn(|_| rng.range(-0.3, 0.3));
            let b: [f32; 3] = std::array::from_fn(|_| rng.range(-0.3, 0.3));
            let r = if thin { rng.range(0.005, 0.02) } else { rng.range(0.04, 0.2) };
            format!(
                "capsule({}, {}, {}, {}, {}, {}, {})",
                num(a[0]),
                num(a[1]),
                num(a[2]),
                num(b[0]),
                num(b[1]),
                num(b[2]),
                num(r)
            )
        }
        _ => {
            // A half-space, cut down to a slab so the part stays bounded.
            let n: [f32; 3] = std::array::from_fn(|_| rng.range(-1.0, 1.0));
            let w = rng.range(0.05, 0.3);
            format!(
                "intersect(plane({}, {}, {}, 0), -plane({}, {}, {}, {}), sphere({}))",
                num(n[0]),
                num(n[1]),
                num(n[2] + 0.01),
                num(n[0]),
                num(n[1]),
                num(n[2] + 0.01),
                num(w),
                num(size(rng) + 0.1)
            )
        }
    };
    format!("translate({shape}, {}, {}, {})", num(centre[0]), num(centre[1]), num(centre[2]))
}

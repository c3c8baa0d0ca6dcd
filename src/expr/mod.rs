//! Implicit surfaces typed as text (or built as CSG JSON), compiled to a flat tape.
//!
//! ```
//! use isoforge::expr::compile;
//! use isoforge::Vec3;
//! let p = compile("body = rounded_box(1, 0.6, 0.4, 0.1);\n\
//!                  subtract(body, translate(cylinder(0.25, 2), 0.3, 0, 0))").unwrap();
//! assert!(p.eval(Vec3::new(-0.6, 0.0, 0.0)) < 0.0); // inside the body, beside the hole
//! let (value, gradient) = p.eval_grad(Vec3::new(2.0, 0.0, 0.0));
//! assert!((value - 1.0).abs() < 1e-5 && (gradient - Vec3::X).length() < 1e-5);
//! ```
//!
//! # The language
//!
//! ```text
//! program = { name "=" expr ";" } expr [ ";" ] ;
//! expr    = term { ("+" | "-") term } ;
//! term    = unary { ("*" | "/") unary } ;
//! unary   = ("-" | "+") unary | power ;
//! power   = atom [ "^" unary ] ;                       (* right-assoc; -x^2 = -(x^2) *)
//! atom    = number | name | name "(" [ expr { "," expr } ] ")" | "(" expr ")" ;
//! number  = digits [ "." [digits] ] [ exp ] | "." digits [ exp ] ;   exp = ("e"|"E") ["+"|"-"] digits
//! ```
//! Names are `x`, `y`, `z`, earlier bindings, and the functions below. Comments: `// …`, `# …`,
//! `/* … */`. Inside is negative; shapes are exact signed distances unless noted.
//!
//! - Math: `sin cos tan asin acos atan atan2(y,x) exp log sqrt abs floor pow(a,b) clamp(a,lo,hi)
//!   mix(a,b,t)`, and n-ary `min max length` (one or more arguments). `log` is natural.
//! - Shapes, at the current coordinates: `sphere(r)`, `box(hx,hy,hz)`, `rounded_box(hx,hy,hz,r)`
//!   (outer half extents), `cylinder(r,h)` (axis z, from -h to h), `cone(r,h)` (base radius r in
//!   the plane z = 0, apex at z = h), `torus(R,r)` (around z), `capsule(ax,ay,az,bx,by,bz,r)`,
//!   `plane(nx,ny,nz,d)` (n·p - d with n normalised).
//! - Combinators: `union(a,…)` = min, `intersect(a,…)` = max, `subtract(a,b)`,
//!   `smooth_union(a,b,k)`, `smooth_intersect(a,b,k)`, `smooth_subtract(a,b,k)` (polynomial blend
//!   of width k > 0; not exact distances inside the blend), `shell(a,t)` = |a| - t,
//!   `offset(a,d)` = a - d.
//! - Transforms: `translate(a,dx,dy,dz)`, `rotate(a,ax,ay,az,degrees)` (right-hand rule about the
//!   axis through the origin), `scale(a,s)` = s·a(p/s), `mirror_x(a)` = a(|x|,y,z), `mirror_y`,
//!   `mirror_z`. The first argument is evaluated at the moved coordinates, *all* of it: in
//!   `translate(sphere(x), 1, 0, 0)` the radius sees the moved `x` too. A binding means its
//!   expression wherever it is used, so a bound shape can be placed several times.
//!
//! # Pipeline
//! `lexer` → `parser` (names resolved; an [`ast`] with spans) → `compile` lowers it to a
//! hash-consed, constant-folded `graph` with the formulas of `shapes` → `tape` allocates
//! registers → `eval` and `interval` run it. [`csg`] is the JSON front end onto the same tree;
//! [`naive`] is the reference tree walk used by tests and benchmarks; [`speed`] times every mode
//! against it with a clock passed in (so browsers can time themselves). Each is one file here.
//!
//! # Evaluation modes
//! All in `f32`. [`Program::eval`] (a point), [`Program::eval_grad`] (value and exact gradient,
//! forward mode; at kinks min/max take the active branch's gradient, abs takes `+` at 0, and
//! `sqrt(0)` contributes a zero gradient), [`Program::eval_interval`] (conservative bounds over a
//! box), [`Program::eval_interval_with_choices`] + [`Program::simplify`] (prune min/max branches
//! that cannot win in a box), [`Program::eval_many`] (64-point columns).

pub mod ast;
mod builtins;
mod columns;
mod compile;
pub mod csg;
mod csg_json;
mod diag;
mod eval;
pub mod extent;
mod field;
mod graph;
mod interval;
mod lexer;
pub mod naive;
mod ops;
mod params;
mod parser;
mod program;
pub mod regions;
mod shapes;
pub mod speed;
mod tape;

#[cfg(test)]
pub(crate) mod testutil;

pub use ast::Script;
pub use builtins::{Arity, Builtin};
pub use csg::CsgNode;
pub use diag::Span;
pub use graph::{Node, NodeId};
pub use interval::Choice;
pub use ops::{BinaryOp, UnaryOp};
pub use program::Program;
pub use regions::{RegionalProgram, TapeLengths};

use crate::error::Error;

/// Parses and compiles a program. Errors name the problem and point at its line and column.
pub fn compile(text: &str) -> Result<Program, Error> {
    let script = parse(text)?;
    compile::compile_script(&script).map_err(|d| d.into_error(text))
}

/// Parses a program into its syntax tree (names resolved, argument counts checked).
pub fn parse(text: &str) -> Result<Script, Error> {
    parser::parse(text).map_err(|d| d.into_error(text))
}

#[cfg(test)]
mod tests {
    use super::testutil::{Rng, CASES};
    use super::*;
    use glam::Vec3;

    /// Whatever compiles must also evaluate in every mode without panicking.
    fn exercise(text: &str) {
        if let Ok(p) = compile(text) {
            let q = Vec3::new(0.3, -0.2, 0.7);
            let _ = (p.eval(q), p.eval_grad(q), p.eval_interval(-q, q));
            let (_, choices) = p.eval_interval_with_choices(Vec3::splat(-1.0), Vec3::ONE);
            let _ = p.simplify(&choices).eval(q);
            let mut out = [0.0; 3];
            p.eval_many(&[q, -q, q * 2.0], &mut out);
            let _ = p.to_string();
        } else if let Err(e) = compile(text) {
            let _ = e.to_string();
        }
    }

    #[test]
    fn no_input_makes_it_panic() {
        let mut rng = Rng::new(30);
        let alphabet: Vec<char> =
            "xyz0123456789.eE+-*/^(),;=#\n\t /*abcdefghijklmnopqrstuvw_é$[]{}".chars().collect();
        for _ in 0..3000 {
            let len = rng.below(40);
            let text: String = (0..len).map(|_| alphabet[rng.below(alphabet.len())]).collect();
            exercise(&text);
            let bytes: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
            exercise(&String::from_utf8_lossy(&bytes));
        }
        for case in CASES {
            for cut in 0..=case.len() {
                if case.is_char_boundary(cut) {
                    exercise(&case[..cut]);
                }
            }
            // Point mutations: a token dropped or swapped often still parses, with odd arities.
            let chars: Vec<char> = case.chars().collect();
            for _ in 0..100 {
                let mut m = chars.clone();
                let i = rng.below(m.len());
                if rng.below(2) == 0 {
                    m.remove(i);
                } else {
                    m[i] = alphabet[rng.below(alphabet.len())];
                }
                exercise(&m.into_iter().collect::<String>());
            }
        }
    }

    #[test]
    fn the_module_example_holds() {
        let p = compile(
            "body = rounded_box(1, 0.6, 0.4, 0.1);\nsubtract(body, translate(cylinder(0.25, 2), 0.3, 0, 0))",
        )
        .unwrap();
        assert!(p.eval(Vec3::new(-0.6, 0.0, 0.0)) < 0.0);
        assert!(p.eval(Vec3::new(0.3, 0.0, 0.0)) > 0.0, "in the hole");
    }
}

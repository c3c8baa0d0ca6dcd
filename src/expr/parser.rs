//! Tokens → [`Script`], resolving names as it goes (see [`super::ast`]).
//!
//! Recursive descent, one function per precedence level:
//! sum (`+ -`) < product (`* /`) < unary minus < power (`^`, right-associative) < atoms.
//! Unary minus sits *below* `^`, so `-x^2` is `-(x^2)`, and the exponent may itself be negated
//! (`2^-x`). Nesting is capped so that no input can exhaust the stack.

use super::ast::{Axis, Binding, ChainOp, Expr, ExprKind, Script};
use super::builtins::Builtin;
use super::diag::{suggest, Diag, Span};
use super::lexer::{tokenize, Token, TokenKind};

/// Deepest nesting of parentheses, calls, unary minus and powers. Generous for hand-written code,
/// and small enough that the parser and compiler recursion fit a browser's 1 MB stack.
pub const MAX_NESTING: usize = 100;

pub fn parse(source: &str) -> Result<Script, Diag> {
    let tokens = tokenize(source)?;
    let mut p = Parser { tokens, pos: 0, depth: 0, bindings: Vec::new() };
    p.script()
}

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    depth: usize,
    /// Names bound so far, in order; a later binding of the same name shadows an earlier one.
    bindings: Vec<Binding>,
}

impl Parser {
    fn peek(&self) -> &Token {
        // The token list always ends with Eof and `pos` never moves past it.
        &self.tokens[self.pos.min(self.tokens.len() - 1)]
    }

    fn peek_kind(&self, ahead: usize) -> &TokenKind {
        &self.tokens[(self.pos + ahead).min(self.tokens.len() - 1)].kind
    }

    fn bump(&mut self) -> Token {
        let t = self.peek().clone();
        if t.kind != TokenKind::Eof {
            self.pos += 1;
        }
        t
    }

    /// End of the previous token: where a missing `;` or `)` belongs.
    fn after_previous(&self) -> Span {
        let end = if self.pos == 0 { 0 } else { self.tokens[self.pos - 1].span.end };
        Span::new(end, end)
    }

    fn unexpected(&self, wanted: &str) -> Diag {
        let t = self.peek();
        Diag::new(t.span, format!("expected {wanted}, found {}", t.kind.describe()))
    }

    fn script(&mut self) -> Result<Script, Diag> {
        if self.peek().kind == TokenKind::Eof {
            return Err(Diag::new(self.peek().span, "the program is empty: expected an expression"));
        }
        loop {
            let is_binding =
                matches!(self.peek_kind(0), TokenKind::Ident(_)) && *self.peek_kind(1) == TokenKind::Assign;
            if !is_binding {
                break;
            }
            self.binding()?;
            if self.peek().kind == TokenKind::Eof {
                return Err(Diag::new(self.peek().span, "expected a final expression after the bindings"));
            }
        }
        let body = self.expr()?;
        if self.peek().kind == TokenKind::Semi {
            self.bump();
        }
        if self.peek().kind != TokenKind::Eof {
            let wanted = if matches!(self.peek().kind, TokenKind::Assign) {
                "an operator or the end of the program ('=' binds a plain name, before the final expression)"
            } else {
                "an operator or the end of the program"
            };
            return Err(self.unexpected(wanted));
        }
        Ok(Script { bindings: std::mem::take(&mut self.bindings), body })
    }

    fn binding(&mut self) -> Result<(), Diag> {
        let name_tok = self.bump();
        let TokenKind::Ident(name) = name_tok.kind else {
            return Err(Diag::new(name_tok.span, "expected a name to bind"));
        };
        if matches!(name.as_str(), "x" | "y" | "z") {
            return Err(Diag::new(name_tok.span, format!("cannot bind '{name}': it is a coordinate")));
        }
        if Builtin::lookup(&name).is_some() {
            return Err(Diag::new(
                name_tok.span,
                format!("cannot bind '{name}': it names a built-in function"),
            ));
        }
        self.bump(); // '='
        let value = self.expr()?;
        if self.peek().kind != TokenKind::Semi {
            return Err(Diag::new(
                self.after_previous(),
                format!("expected ';' after the binding of '{name}'"),
            ));
        }
        self.bump();
        self.bindings.push(Binding { name, span: name_tok.span, value });
        Ok(())
    }

    fn nested<T>(&mut self, at: Span, f: impl FnOnce(&mut Self) -> Result<T, Diag>) -> Result<T, Diag> {
        if self.depth >= MAX_NESTING {
            return Err(Diag::new(at, format!("expression nests deeper than {MAX_NESTING} levels")));
        }
        self.depth += 1;
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn expr(&mut self) -> Result<Expr, Diag> {
        let at = self.peek().span;
        self.nested(at, |p| p.chain(Level::Sum))
    }

    fn chain(&mut self, level: Level) -> Result<Expr, Diag> {
        let first = self.operand(level)?;
        let mut rest = Vec::new();
        loop {
            let op = match (level, &self.peek().kind) {
                (Level::Sum, TokenKind::Plus) => ChainOp::Add,
                (Level::Sum, TokenKind::Minus) => ChainOp::Sub,
                (Level::Product, TokenKind::Star) => ChainOp::Mul,
                (Level::Product, TokenKind::Slash) => ChainOp::Div,
                _ => break,
            };
            self.bump();
            rest.push((op, self.operand(level)?));
        }
        if rest.is_empty() {
            return Ok(first);
        }
        let span = first.span.to(rest.last().map_or(first.span, |r| r.1.span));
        Ok(Expr::new(ExprKind::Chain { first: Box::new(first), rest }, span))
    }

    fn operand(&mut self, level: Level) -> Result<Expr, Diag> {
        match level {
            Level::Sum => self.chain(Level::Product),
            Level::Product => self.unary(),
        }
    }

    fn unary(&mut self) -> Result<Expr, Diag> {
        let t = self.peek().clone();
        match t.kind {
            TokenKind::Minus | TokenKind::Plus => {
                self.bump();
                let inner = self.nested(t.span, |p| p.unary())?;
                if t.kind == TokenKind::Plus {
                    return Ok(inner);
                }
                let span = t.span.to(inner.span);
                // `-0.5` is one number, as it is in JSON: CSG trees and their text then match.
                if let ExprKind::Number(v) = inner.kind {
                    return Ok(Expr::new(ExprKind::Number(-v), span));
                }
                Ok(Expr::new(ExprKind::Neg(Box::new(inner)), span))
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Expr, Diag> {
        let base = self.atom()?;
        if self.peek().kind != TokenKind::Caret {
            return Ok(base);
        }
        let caret = self.bump();
        let exponent = self.nested(caret.span, |p| p.unary())?;
        let span = base.span.to(exponent.span);
        Ok(Expr::new(ExprKind::Power(Box::new(base), Box::new(exponent)), span))
    }

    fn atom(&mut self) -> Result<Expr, Diag> {
        let t = self.peek().clone();
        match t.kind {
            TokenKind::Number(v) => {
                self.bump();
                Ok(Expr::new(ExprKind::Number(v), t.span))
            }
            TokenKind::LParen => {
                self.bump();
                let inner = self.expr()?;
                self.expect_close(t.span)?;
                Ok(inner)
            }
            TokenKind::Ident(name) => {
                self.bump();
                if self.peek().kind == TokenKind::LParen {
                    self.call(name, t.span)
                } else {
                    self.identifier(&name, t.span)
                }
            }
            _ => Err(self.unexpected("an expression")),
        }
    }

    fn expect_close(&mut self, open: Span) -> Result<(), Diag> {
        match self.peek().kind {
            TokenKind::RParen => {
                self.bump();
                Ok(())
            }
            TokenKind::Eof => Err(Diag::new(open, "this '(' is never closed")),
            _ => Err(self.unexpected("')' or an operator")),
        }
    }

    fn identifier(&self, name: &str, span: Span) -> Result<Expr, Diag> {
        let kind = match name {
            "x" => ExprKind::Coord(Axis::X),
            "y" => ExprKind::Coord(Axis::Y),
            "z" => ExprKind::Coord(Axis::Z),
            _ => match self.bindings.iter().rposition(|b| b.name == name) {
                Some(i) => ExprKind::Binding(i),
                None if Builtin::lookup(name).is_some() => {
                    return Err(Diag::new(span, format!("'{name}' is a function; call it like {name}(…)")));
                }
                None => {
                    let known =
                        ["x", "y", "z"].into_iter().chain(self.bindings.iter().map(|b| b.name.as_str()));
                    let hint =
                        suggest(name, known).map(|s| format!("; did you mean '{s}'?")).unwrap_or_default();
                    return Err(Diag::new(span, format!("unknown identifier '{name}'{hint}")));
                }
            },
        };
        Ok(Expr::new(kind, span))
    }

    fn call(&mut self, name: String, name_span: Span) -> Result<Expr, Diag> {
        let Some(builtin) = Builtin::lookup(&name) else {
            let message = if self.bindings.iter().any(|b| b.name == name) {
                format!("'{name}' is a binding, not a function; use it without parentheses")
            } else if matches!(name.as_str(), "x" | "y" | "z") {
                format!("'{name}' is a coordinate, not a function")
            } else {
                let hint = suggest(&name, Builtin::names())
                    .map(|s| format!("; did you mean '{s}'?"))
                    .unwrap_or_default();
                format!("unknown function '{name}'{hint}")
            };
            return Err(Diag::new(name_span, message));
        };
        self.bump(); // '('
        let mut args = Vec::new();
        if self.peek().kind != TokenKind::RParen {
            loop {
                args.push(self.expr()?);
                match self.peek().kind {
                    TokenKind::Comma => {
                        self.bump();
                    }
                    TokenKind::RParen => break,
                    TokenKind::Eof => {
                        return Err(Diag::new(
                            name_span,
                            format!("this call of '{name}' is never closed with ')'"),
                        ));
                    }
                    _ => return Err(self.unexpected("',' or ')'")),
                }
            }
        }
        let close = self.bump();
        let span = name_span.to(close.span);
        if !builtin.arity().accepts(args.len()) {
            return Err(Diag::new(
                name_span,
                format!(
                    "'{name}' takes {} ({}), but was given {}",
                    builtin.arity(),
                    builtin.signature(),
                    args.len()
                ),
            ));
        }
        Ok(Expr::new(ExprKind::Call(builtin, args), span))
    }
}

#[derive(Clone, Copy)]
enum Level {
    Sum,
    Product,
}

#[cfg(test)]
mod tests {
    use super::super::compile;
    use crate::error::Error;
    use glam::Vec3;

    fn value(src: &str, p: Vec3) -> f32 {
        compile(src).unwrap_or_else(|e| panic!("{src}: {e}")).eval(p)
    }

    #[test]
    fn precedence_and_associativity() {
        let p = Vec3::new(3.0, 2.0, 0.5);
        let cases = [
            ("-x^2", -9.0),
            ("(-x)^2", 9.0),
            ("-2^2", -4.0),
            ("2^3^2", 512.0),
            ("2^-1", 0.5),
            ("x^-y", 1.0 / 9.0),
            ("1 - 2 - 3", -4.0),
            ("8 / 2 / 2", 2.0),
            ("2 * -3", -6.0),
            ("1 + 2 * 3 ^ 2", 19.0),
            ("- -x", 3.0),
            ("+x - +y", 1.0),
            ("x * y / z", 12.0),
            ("1e-3 * 1e3 + .5 + 2.", 3.5),
        ];
        for (src, want) in cases {
            assert_eq!(value(src, p), want, "{src}");
        }
    }

    #[test]
    fn bindings_comments_and_an_optional_final_semicolon() {
        let src = "# a comment\nr = 0.5; // another\n/* block\n comment */ d = r * 2;\nx - d;";
        assert_eq!(value(src, Vec3::new(3.0, 0.0, 0.0)), 2.0);
    }

    fn error_at(src: &str) -> (usize, usize, String, String) {
        match compile(src) {
            Err(Error::Parse { message, line, column, snippet }) => (line, column, message, snippet),
            other => panic!("{src}: expected a parse error, got {other:?}"),
        }
    }

    #[test]
    fn errors_point_at_the_right_line_and_column() {
        let cases: &[(&str, usize, usize, &str)] = &[
            ("", 1, 1, "empty"),
            ("sphere(1", 1, 1, "never closed"),
            ("(x + 1", 1, 1, "'(' is never closed"),
            ("x +", 1, 4, "expected an expression, found the end of the input"),
            ("x + * 2", 1, 5, "expected an expression, found '*'"),
            ("sphre(1)", 1, 1, "unknown function 'sphre'; did you mean 'sphere'?"),
            ("sphere(1, 2)", 1, 1, "'sphere' takes 1 argument (sphere(r)), but was given 2"),
            ("box(1)", 1, 1, "'box' takes 3 arguments (box(hx, hy, hz)), but was given 1"),
            ("min()", 1, 1, "'min' takes at least 1 argument"),
            ("x + foo", 1, 5, "unknown identifier 'foo'"),
            ("r = 1;\nsphere(q)", 2, 8, "unknown identifier 'q'"),
            ("a = 1;\nb = 2\nc = 3;\na", 2, 6, "expected ';' after the binding of 'b'"),
            ("r = 1;\n\n   sphere(r) + sin", 3, 16, "'sin' is a function"),
            ("x = 1; x", 1, 1, "cannot bind 'x'"),
            ("a = 1;", 1, 7, "expected a final expression"),
            ("sphere(1) sphere(2)", 1, 11, "expected an operator or the end of the program, found 'sphere'"),
            ("y(2)", 1, 1, "'y' is a coordinate"),
            ("a = 2; a(1)", 1, 8, "'a' is a binding, not a function"),
            ("translate(sphere(1), 1, 2,)", 1, 27, "expected an expression, found ')'"),
            ("// only\n/* comments */\n\t2x", 3, 2, "malformed number '2x'"),
            ("a = 1;\n/* never\nclosed", 2, 1, "never closed"),
            ("union(sphere(1)\n, box(1, 1, 1) $)", 2, 16, "unexpected character '$'"),
        ];
        for &(src, line, column, words) in cases {
            let (l, c, message, _) = error_at(src);
            assert_eq!((l, c), (line, column), "{src:?}: {message}");
            assert!(message.contains(words), "{src:?}: {message}");
        }
    }

    #[test]
    fn error_display_quotes_the_line_with_a_caret() {
        let err = compile("r = 0.5;\nsphere(r) + boxx(1, 1, 1)").unwrap_err().to_string();
        assert_eq!(
            err,
            "2:13: unknown function 'boxx'; did you mean 'box'?\nsphere(r) + boxx(1, 1, 1)\n            ^"
        );
    }
}

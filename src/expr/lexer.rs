//! Text → tokens. Comments and whitespace vanish here, so the parser never sees them.

use super::diag::{Diag, Span};

#[derive(Debug, Clone, PartialEq)]
pub enum TokenKind {
    Number(f64),
    Ident(String),
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    LParen,
    RParen,
    Comma,
    Semi,
    Assign,
    Eof,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    pub kind: TokenKind,
    pub span: Span,
}

impl TokenKind {
    /// How the token reads in an error message.
    pub fn describe(&self) -> String {
        match self {
            TokenKind::Number(_) => "a number".to_string(),
            TokenKind::Ident(name) => format!("'{name}'"),
            TokenKind::Eof => "the end of the input".to_string(),
            other => format!("'{}'", other.symbol()),
        }
    }

    fn symbol(&self) -> &'static str {
        match self {
            TokenKind::Plus => "+",
            TokenKind::Minus => "-",
            TokenKind::Star => "*",
            TokenKind::Slash => "/",
            TokenKind::Caret => "^",
            TokenKind::LParen => "(",
            TokenKind::RParen => ")",
            TokenKind::Comma => ",",
            TokenKind::Semi => ";",
            TokenKind::Assign => "=",
            _ => "",
        }
    }
}

/// Splits `source` into tokens, ending with one [`TokenKind::Eof`] whose span is the end of the text.
pub fn tokenize(source: &str) -> Result<Vec<Token>, Diag> {
    let bytes = source.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        let kind = match c {
            b' ' | b'\t' | b'\r' | b'\n' => None,
            b'#' => {
                i = skip_line(bytes, i);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = skip_line(bytes, i);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                match source[i + 2..].find("*/") {
                    Some(end) => i += 2 + end + 2,
                    None => {
                        return Err(Diag::new(
                            Span::new(i, i + 2),
                            "this block comment is never closed with '*/'",
                        ))
                    }
                }
                continue;
            }
            b'0'..=b'9' | b'.' => {
                let (kind, end) = number(source, i)?;
                i = end;
                tokens.push(Token { kind, span: Span::new(start, end) });
                continue;
            }
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                let end = ident_end(bytes, i);
                tokens.push(Token {
                    kind: TokenKind::Ident(source[i..end].to_string()),
                    span: Span::new(i, end),
                });
                i = end;
                continue;
            }
            b'*' if bytes.get(i + 1) == Some(&b'*') => {
                return Err(Diag::new(Span::new(i, i + 2), "'**' is not an operator; write powers with '^'"));
            }
            b'+' => Some(TokenKind::Plus),
            b'-' => Some(TokenKind::Minus),
            b'*' => Some(TokenKind::Star),
            b'/' => Some(TokenKind::Slash),
            b'^' => Some(TokenKind::Caret),
            b'(' => Some(TokenKind::LParen),
            b')' => Some(TokenKind::RParen),
            b',' => Some(TokenKind::Comma),
            b';' => Some(TokenKind::Semi),
            b'=' => Some(TokenKind::Assign),
            _ => {
                let ch = source[i..].chars().next().unwrap_or('?');
                let hint = if matches!(ch, '{' | '[') { "; group with '(' and ')'" } else { "" };
                return Err(Diag::new(
                    Span::new(i, i + ch.len_utf8()),
                    format!("unexpected character '{ch}'{hint}"),
                ));
            }
        };
        i += 1;
        if let Some(kind) = kind {
            tokens.push(Token { kind, span: Span::new(start, i) });
        }
    }
    tokens.push(Token { kind: TokenKind::Eof, span: Span::new(source.len(), source.len()) });
    Ok(tokens)
}

fn skip_line(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && bytes[i] != b'\n' {
        i += 1;
    }
    i
}

fn ident_end(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
        i += 1;
    }
    i
}

fn digits_end(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && bytes[i].is_ascii_digit() {
        i += 1;
    }
    i
}

/// `digits [. digits] [e [+-] digits]` or `. digits [...]`. Anything glued to the end of a number
/// (`2x`, `1.2.3`, `1e`) is one malformed number rather than two tokens, which reads better.
fn number(source: &str, start: usize) -> Result<(TokenKind, usize), Diag> {
    let bytes = source.as_bytes();
    let int_end = digits_end(bytes, start);
    let mut end = int_end;
    let mut has_digits = int_end > start;
    if bytes.get(end) == Some(&b'.') {
        let frac_end = digits_end(bytes, end + 1);
        has_digits |= frac_end > end + 1;
        end = frac_end;
    }
    if !has_digits {
        return Err(Diag::new(Span::new(start, start + 1), "unexpected character '.'"));
    }
    if matches!(bytes.get(end), Some(b'e' | b'E')) {
        let mut j = end + 1;
        if matches!(bytes.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let exp_end = digits_end(bytes, j);
        if exp_end == j {
            let bad_end = ident_end(bytes, j);
            return Err(Diag::new(
                Span::new(start, bad_end),
                format!("malformed number '{}': the exponent needs digits", &source[start..bad_end]),
            ));
        }
        end = exp_end;
    }
    if end < bytes.len() && (bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_' || bytes[end] == b'.') {
        let mut bad_end = end;
        while bad_end < bytes.len()
            && (bytes[bad_end].is_ascii_alphanumeric() || bytes[bad_end] == b'_' || bytes[bad_end] == b'.')
        {
            bad_end += 1;
        }
        let text = &source[start..bad_end];
        let hint = if bytes[end].is_ascii_alphabetic() { "; multiplication needs '*'" } else { "" };
        return Err(Diag::new(Span::new(start, bad_end), format!("malformed number '{text}'{hint}")));
    }
    let text = &source[start..end];
    let value: f64 =
        text.parse().map_err(|_| Diag::new(Span::new(start, end), format!("malformed number '{text}'")))?;
    // Evaluation is in f32: a literal that only fits in f64 would silently become infinity.
    if !(value as f32).is_finite() {
        return Err(Diag::new(
            Span::new(start, end),
            format!("number '{text}' is too large (the limit is about 3.4e38)"),
        ));
    }
    Ok((TokenKind::Number(value), end))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(src: &str) -> Vec<TokenKind> {
        tokenize(src).unwrap().into_iter().map(|t| t.kind).collect()
    }

    #[test]
    fn numbers_in_every_accepted_form() {
        use TokenKind::Number as N;
        assert_eq!(
            kinds(".5 1e-3 2. 3.25E+2 7 1.e1"),
            vec![N(0.5), N(1e-3), N(2.0), N(325.0), N(7.0), N(10.0), TokenKind::Eof]
        );
    }

    #[test]
    fn comments_and_whitespace_disappear() {
        let k = kinds("x # note\n+ /* block\n * still */ y // end\n");
        assert_eq!(
            k,
            vec![TokenKind::Ident("x".into()), TokenKind::Plus, TokenKind::Ident("y".into()), TokenKind::Eof]
        );
    }

    #[test]
    fn spans_are_byte_ranges() {
        let t = tokenize("ab + 12.5").unwrap();
        assert_eq!(t[0].span, Span::new(0, 2));
        assert_eq!(t[2].span, Span::new(5, 9));
        assert_eq!(t[3].span, Span::new(9, 9));
    }

    #[test]
    fn malformed_input_is_reported_where_it_starts() {
        let cases = [
            ("x + 1e", 4, "exponent needs digits"),
            ("2x", 0, "multiplication needs '*'"),
            ("1.2.3", 0, "malformed number '1.2.3'"),
            ("x /* open", 2, "never closed"),
            ("x $ y", 2, "unexpected character '$'"),
            ("1e39", 0, "too large"),
            ("x ** 2", 2, "write powers with '^'"),
            ("é", 0, "unexpected character 'é'"),
        ];
        for (src, at, words) in cases {
            let err = tokenize(src).unwrap_err();
            assert_eq!(err.span.start, at, "{src}: {}", err.message);
            assert!(err.message.contains(words), "{src}: {}", err.message);
        }
    }
}

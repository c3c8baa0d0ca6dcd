//! Where in the source something went wrong, and how that becomes the crate's [`Error`].
//!
//! Everything before the final conversion works with byte spans, which are cheap to carry; line,
//! column and the quoted line are only computed once, for the one error that is reported.

use crate::error::Error;

/// A byte range in the program text. Trees built from CSG JSON have no text and use `0..0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    pub start: usize,
    pub end: usize,
}

impl Span {
    pub fn new(start: usize, end: usize) -> Span {
        Span { start, end }
    }

    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span { start: self.start.min(other.start), end: self.end.max(other.end) }
    }
}

/// An error that knows its span but not yet its source text.
#[derive(Debug, Clone, PartialEq)]
pub struct Diag {
    pub message: String,
    pub span: Span,
}

impl Diag {
    pub fn new(span: Span, message: impl Into<String>) -> Diag {
        Diag { message: message.into(), span }
    }

    /// Locates the span in `source` and quotes its line.
    pub fn into_error(self, source: &str) -> Error {
        let (line, column, snippet) = locate(source, self.span.start);
        Error::Parse { message: self.message, line, column, snippet }
    }

    /// For trees that never had text (built from CSG): no position to point at.
    pub fn into_error_without_source(self) -> Error {
        Error::InvalidOption(format!("shape tree: {}", self.message))
    }
}

/// 1-based line and character column of byte offset `at` (clamped into the text), and that line
/// without its line terminator.
pub fn locate(source: &str, at: usize) -> (usize, usize, String) {
    let mut at = at.min(source.len());
    while !source.is_char_boundary(at) {
        at -= 1;
    }
    let line_start = source[..at].rfind('\n').map_or(0, |i| i + 1);
    let line_end = source[at..].find('\n').map_or(source.len(), |i| at + i);
    let line = source[..line_start].matches('\n').count() + 1;
    let column = source[line_start..at].chars().count() + 1;
    let snippet = source[line_start..line_end].trim_end_matches('\r').to_string();
    (line, column, snippet)
}

/// The closest of `candidates` to `name` when it is close enough to be a plausible typo.
pub fn suggest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (edit_distance(name, c), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1).min(row[j] + 1).min(diagonal + usize::from(ca != cb));
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locates_lines_and_character_columns() {
        let src = "a = 1;\r\nbé = 2;\nb + c";
        assert_eq!(locate(src, 0), (1, 1, "a = 1;".to_string()));
        let at = src.find('=').unwrap();
        assert_eq!(locate(src, at), (1, 3, "a = 1;".to_string()));
        let at = src.find("= 2").unwrap();
        assert_eq!(locate(src, at), (2, 4, "bé = 2;".to_string()), "é is one column, two bytes");
        assert_eq!(locate(src, src.len()), (3, 6, "b + c".to_string()));
    }

    #[test]
    fn display_puts_the_caret_under_the_column() {
        let err = Diag::new(Span::new(12, 13), "unknown identifier 'q'").into_error("x + 1;\n\tx + q");
        assert_eq!(err.to_string(), "2:6: unknown identifier 'q'\n\tx + q\n\t    ^");
    }

    #[test]
    fn suggests_near_misses_only() {
        let names = ["sphere", "smooth_union", "sin"];
        assert_eq!(suggest("sphre", names), Some("sphere"));
        assert_eq!(suggest("sine", names), Some("sin"));
        assert_eq!(suggest("banana", names), None);
    }
}

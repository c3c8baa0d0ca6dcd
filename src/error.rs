//! One error type for the whole library, so bindings can turn any failure into one readable message.

use std::fmt;

/// Everything that can go wrong before or while meshing. Messages are written for the person who
/// passed the input: they name the offending sample, option or value.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A sample was NaN or infinite; meshing it would silently produce garbage.
    NonFiniteSample { index: [usize; 3], position: [f32; 3], value: f32 },
    /// The grid has no cells, mismatched buffer sizes, or bad bounds.
    InvalidGrid(String),
    /// The grid is larger than the configured cap (protects browsers from freezing or running out of memory).
    GridTooLarge { cells: u64, max_cells: u64 },
    /// An option had a value outside its meaningful range.
    InvalidOption(String),
    /// An unknown scene, method or other name.
    UnknownName { kind: &'static str, name: String, known: Vec<String> },
    /// Reading or writing a file failed.
    Io(String),
    /// Text the user typed (an expression program, a CSG JSON document) is malformed or names
    /// something unknown. `line` and `column` are 1-based (column counts characters); `snippet`
    /// is the whole offending source line, so the message stands alone.
    Parse { message: String, line: usize, column: usize, snippet: String },
    /// A vertex came out infinite or NaN although every input was finite: the samples or
    /// coordinates are so large that the method's `f32` arithmetic overflowed.
    NonFiniteOutput { method: &'static str, index: usize, position: [f32; 3] },
    /// A user-supplied field function (see [`crate::field::BatchFn`]) failed or returned a batch
    /// of the wrong size.
    FieldFunction(String),
    /// The job's progress hook asked it to stop (see [`crate::progress`]).
    Cancelled,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NonFiniteSample { index, position, value } => write!(
                f,
                "sample ({}, {}, {}) at position ({}, {}, {}) is {}; every sample must be finite",
                index[0], index[1], index[2], position[0], position[1], position[2], value
            ),
            Error::InvalidGrid(msg) => write!(f, "invalid grid: {msg}"),
            Error::GridTooLarge { cells, max_cells } => write!(
                f,
                "grid of {cells} cells is larger than the limit of {max_cells} cells; lower the resolution or raise maxCells"
            ),
            Error::InvalidOption(msg) => write!(f, "invalid option: {msg}"),
            Error::UnknownName { kind, name, known } => {
                write!(f, "unknown {kind} '{name}'; known: {}", known.join(", "))
            }
            Error::Io(msg) => write!(f, "{msg}"),
            Error::FieldFunction(msg) => write!(f, "field function: {msg}"),
            Error::Cancelled => write!(f, "meshing cancelled"),
            Error::NonFiniteOutput { method, index, position } => write!(
                f,
                "{method} produced vertex {index} at ({}, {}, {}): the input's values or coordinates are too \
                 large for f32 arithmetic; scale them down",
                position[0], position[1], position[2]
            ),
            Error::Parse { message, line, column, snippet } => {
                write!(f, "{line}:{column}: {message}\n{snippet}\n")?;
                // Copy tabs from the line so the caret lands under the same column in a terminal.
                for c in snippet.chars().take(column.saturating_sub(1)) {
                    f.write_str(if c == '\t' { "\t" } else { " " })?;
                }
                f.write_str("^")
            }
        }
    }
}

impl std::error::Error for Error {}

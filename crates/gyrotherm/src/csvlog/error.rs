//! The error of a log that cannot be read or written: file, line, column, kind and the fix.
//!
//! Displayed like a compiler or ripgrep message, so an editor can jump to it:
//! `run2.csv:1834: column temp_c: "4,5" is not a number; fix the value or ...`.

use std::path::PathBuf;

/// What is wrong with a log. The message of the [`LogError`] carrying it says how to fix it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LogErrorKind {
    /// The file could not be opened, read or written.
    Io,
    /// The output's reader went away (a closed pipe, as `| head` leaves): not a fault of the
    /// log; a command-line program ends quietly.
    OutputClosed,
    /// The CSV syntax itself is broken (reported by the `csv` parser).
    Csv,
    /// No header row: the file is empty or holds only comments.
    NoHeader,
    /// A header row but no data rows.
    NoData,
    /// A required (or explicitly mapped) column is not in the header.
    MissingColumn,
    /// A mapped column name appears more than once in the header.
    DuplicateColumn,
    /// A numeric field does not parse as a number.
    NotANumber,
    /// A numeric field is NaN or infinite (or overflows f64).
    NonFinite,
    /// The last line has fewer fields than the header: the file was cut mid-write.
    TruncatedLine,
    /// A line (not the last) has a different number of fields than the header.
    FieldCount,
    /// A line longer than the reader's limit (a stream caps its lines so that one line
    /// cannot take unbounded memory).
    LineTooLong,
    /// Time goes backwards.
    TimeNotIncreasing,
    /// The same timestamp appears on two consecutive rows.
    DuplicateTime,
    /// A gap of more than 1.5 nominal sample periods, and gap filling is off.
    Gap,
    /// A gap longer than the `fill_gaps_max_s` limit.
    GapTooLong,
    /// A pass-through field or a header name is not UTF-8 text.
    NotUtf8,
    /// The read options themselves are invalid (e.g. a negative gap limit).
    BadOptions,
    /// `write_log` was given an inconsistent or non-finite log.
    BadLog,
    /// The log is sampled more sparsely than the model steps (compensation).
    SampledTooSparsely,
    /// A binary log's bytes do not decode: not the format read, or damaged (the message
    /// names the byte offset).
    Corrupt,
}

/// A log that cannot be read: file, line, column and what to do.
#[derive(Debug)]
pub struct LogError {
    /// The file (`<stdin>` for a stream).
    pub path: PathBuf,
    /// 1-based physical line of the file, comments included (None: not tied to a line).
    pub line: Option<u64>,
    /// The column's header name, where one is at fault.
    pub column: Option<String>,
    /// What is wrong and how to fix it.
    pub message: String,
    /// The class of the problem, for programs.
    pub kind: LogErrorKind,
}

impl LogError {
    /// A new error; `line` and `column` may be None.
    pub fn new(
        kind: LogErrorKind,
        path: impl Into<PathBuf>,
        line: Option<u64>,
        column: Option<&str>,
        message: impl Into<String>,
    ) -> Self {
        LogError {
            path: path.into(),
            line,
            column: column.map(str::to_owned),
            message: message.into(),
            kind,
        }
    }
}

impl LogError {
    /// A binary log `path` damaged at byte `at` (the autopilot formats have no lines).
    pub(crate) fn corrupt_at(path: &std::path::Path, at: u64, what: String) -> Self {
        LogError::new(
            LogErrorKind::Corrupt,
            path,
            None,
            None,
            format!("byte {at}: {what}"),
        )
    }

    /// A line of `path` longer than [`MAX_LINE_BYTES`](super::MAX_LINE_BYTES) at `line`.
    pub(crate) fn line_too_long(path: impl Into<PathBuf>, line: u64) -> Self {
        LogError::new(
            LogErrorKind::LineTooLong,
            path,
            Some(line),
            None,
            format!(
                "line longer than {} bytes; a log line holds a few numbers: check that this \
                 is a log with one record per line",
                super::MAX_LINE_BYTES
            ),
        )
    }
}

/// Most characters of a field quoted in a message: enough to recognise it, while a message
/// about a huge field stays one line.
pub(crate) const QUOTED_FIELD_CHARS: usize = 40;

/// A field as a message quotes it: in double quotes with escapes (no control character reaches
/// the terminal), cut to its first [`QUOTED_FIELD_CHARS`] characters and its length in bytes
/// when longer.
pub(crate) fn quoted_field(raw: &[u8]) -> String {
    let text = String::from_utf8_lossy(raw);
    match text.char_indices().nth(QUOTED_FIELD_CHARS) {
        None => format!("{text:?}"),
        Some((at, _)) => format!("{:?}… ({} bytes)", &text[..at], raw.len()),
    }
}

impl std::fmt::Display for LogError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        if let Some(c) = &self.column {
            write!(f, ": column {c}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for LogError {}

impl From<std::io::Error> for LogError {
    fn from(e: std::io::Error) -> Self {
        LogError::new(LogErrorKind::Io, PathBuf::new(), None, None, e.to_string())
    }
}

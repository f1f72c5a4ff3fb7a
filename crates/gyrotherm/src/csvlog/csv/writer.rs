//! Streaming CSV writer for logs and per-sample outputs: a header, then rows of numbers and
//! raw pass-through fields.
//!
//! Numbers are written shortest-round-trip: Rust's `{}` for ordinary magnitudes and `{:e}`
//! below 1e-5 or from 1e16 on (where `{}` would print long runs of zeros); both parse back
//! to the same f64.

use std::io::{self, Write};

pub(crate) use crate::number_text::format_f64;
pub(crate) use crate::number_text::short_f64;

/// Rows are handed to the inner writer once this many bytes are buffered (unless flushing
/// every row).
const CHUNK_BYTES: usize = 64 * 1024;

/// Writes a CSV header and rows, buffering internally.
///
/// ```
/// use gyrotherm::csvlog::LogWriter;
/// let mut out = Vec::new();
/// let mut w = LogWriter::new(&mut out, ["time_s", "rate_dps", "note"]).unwrap();
/// w.push_f64(1.0);
/// w.push_f64(0.25);
/// w.push_raw(b"a,b");
/// w.end_row().unwrap();
/// w.flush().unwrap();
/// drop(w);
/// assert_eq!(out, b"time_s,rate_dps,note\n1,0.25,\"a,b\"\n");
/// ```
///
/// Buffered rows are flushed on [`LogWriter::flush`] and, ignoring errors, on drop; call
/// `flush` to see write errors.
pub struct LogWriter<W: Write> {
    out: W,
    buf: Vec<u8>,
    columns: usize,
    fields: usize,
    row_start: usize,
    flush_each_row: bool,
    delimiter: u8,
}

impl<W: Write> LogWriter<W> {
    /// Write the header row (names quoted where CSV needs it), fields separated by commas.
    pub fn new<I>(out: W, header: I) -> io::Result<Self>
    where
        I: IntoIterator,
        I::Item: AsRef<str>,
    {
        Self::with_delimiter(out, header, b',')
    }

    /// [`new`](Self::new) with another field separator (`b';'` or `b'\t'`, as
    /// [`ReadOptions::delimiter`](super::ReadOptions::delimiter)): a field holding it is quoted.
    /// Numbers are still written with a decimal point, which the reader accepts beside the
    /// decimal comma.
    pub(crate) fn with_delimiter<I>(out: W, header: I, delimiter: u8) -> io::Result<Self>
    where
        I: IntoIterator,
        I::Item: AsRef<str>,
    {
        let mut w = LogWriter {
            out,
            buf: Vec::with_capacity(CHUNK_BYTES + 1024),
            columns: usize::MAX,
            fields: 0,
            row_start: 0,
            flush_each_row: false,
            delimiter,
        };
        for name in header {
            w.push_raw(name.as_ref().as_bytes());
        }
        w.columns = w.fields;
        if w.columns == 0 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "a CSV header needs at least one column",
            ));
        }
        w.end_row()?;
        Ok(w)
    }

    /// Hand every row to the inner writer and flush it as soon as it ends (for
    /// `compensate --stream`, where each input line must give its output line at once).
    pub fn set_flush_each_row(&mut self, on: bool) {
        self.flush_each_row = on;
    }

    /// Number of columns of the header.
    pub fn columns(&self) -> usize {
        self.columns
    }

    #[inline]
    fn sep(&mut self) {
        if self.fields > 0 {
            self.buf.push(self.delimiter);
        }
        self.fields += 1;
    }

    /// Append a number (shortest round-trip text; NaN and inf are written as `NaN`, `inf`,
    /// which the reader rejects).
    #[inline]
    pub fn push_f64(&mut self, v: f64) {
        self.sep();
        format_f64(&mut self.buf, v);
    }

    /// Append a field as given, quoted if it holds the delimiter, `"`, CR or LF (or, as the first field,
    /// starts with `#` or is empty, which a reader would take for a comment or a blank line).
    #[inline]
    pub fn push_raw(&mut self, field: &[u8]) {
        let first = self.fields == 0;
        self.sep();
        let needs_quotes = field
            .iter()
            .any(|&b| b == self.delimiter || matches!(b, b'"' | b'\n' | b'\r'))
            || (first && (field.first() == Some(&b'#') || field.is_empty()));
        if needs_quotes {
            self.buf.push(b'"');
            for &b in field {
                if b == b'"' {
                    self.buf.push(b'"');
                }
                self.buf.push(b);
            }
            self.buf.push(b'"');
        } else {
            self.buf.extend_from_slice(field);
        }
    }

    /// Append pass-through fields, e.g. [`LogReader::extra_fields`](super::LogReader::extra_fields).
    #[inline]
    pub fn push_extras<'a>(&mut self, fields: impl IntoIterator<Item = &'a [u8]>) {
        for f in fields {
            self.push_raw(f);
        }
    }

    /// End the row. A row with another number of fields than the header is dropped and
    /// reported as `InvalidInput`.
    #[inline]
    pub fn end_row(&mut self) -> io::Result<()> {
        if self.fields != self.columns && self.columns != usize::MAX {
            let n = self.fields;
            self.buf.truncate(self.row_start);
            self.fields = 0;
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("row has {n} fields, the header has {}", self.columns),
            ));
        }
        self.buf.push(b'\n');
        self.fields = 0;
        self.row_start = self.buf.len();
        if self.flush_each_row {
            self.flush()?;
        } else if self.buf.len() >= CHUNK_BYTES {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
            self.row_start = 0;
        }
        Ok(())
    }

    /// Write out the complete rows buffered so far and flush the inner writer.
    pub fn flush(&mut self) -> io::Result<()> {
        let done = self.row_start;
        self.out.write_all(&self.buf[..done])?;
        self.buf.drain(..done);
        self.row_start = 0;
        self.out.flush()
    }
}

impl<W: Write> Drop for LogWriter<W> {
    fn drop(&mut self) {
        let _ = self.flush();
    }
}

//! Fast path of the reader: newline-aligned blocks of plain rows (no quotes, no lone CR),
//! split in two at a newline and parsed on two threads.
//!
//! The fast parser only accepts what it can judge exactly as the CSV path would: comment
//! lines (`#` at the start), blank lines, and rows of exactly the header's field count whose
//! mapped fields are finite numbers in increasing time order. At the first line it cannot
//! accept it stops, and the reader hands that line and everything after it to the CSV path,
//! which reports the error (or parses the quoted record) with its exact line and column.
//! So the first error in file order is always the one reported, and its text is the CSV
//! path's.

use memchr::memchr;

use super::gaps::Sample;
use super::number::{parse_decimal_prefix, parse_f64, parse_f64_decimal_comma};

/// Blocks at least this long are split in two and parsed on two threads.
pub(super) const PARALLEL_MIN_BYTES: usize = 256 * 1024;

/// What the fast parser needs to know of the layout.
#[derive(Debug, Clone)]
pub(super) struct Layout {
    /// Field separator.
    pub(super) delimiter: u8,
    /// Numbers may use a decimal comma (the separator is not a comma).
    pub(super) decimal_comma: bool,
    /// Fields per row (the header's count).
    pub(super) ncols: usize,
    /// Role of each field: 0 time, 1 gyro, 2 temperature, 3 table rate, 4 passed through.
    pub(super) roles: Vec<u8>,
    pub(super) has_table: bool,
    pub(super) gyro_scale: f64,
}

impl Layout {
    /// Roles of `ncols` fields.
    pub(super) fn roles(
        ncols: usize,
        time: usize,
        gyro: usize,
        temp: usize,
        table: Option<usize>,
    ) -> Vec<u8> {
        (0..ncols)
            .map(|k| {
                if k == time {
                    0
                } else if k == gyro {
                    1
                } else if k == temp {
                    2
                } else if Some(k) == table {
                    3
                } else {
                    4
                }
            })
            .collect()
    }
}

/// One accepted row: its sample, 1-based line and the byte range of its text (without the
/// line terminator) in the block.
#[derive(Debug, Clone, Copy)]
pub(super) struct Row {
    pub(super) sample: Sample,
    pub(super) line: u64,
    pub(super) start: usize,
    pub(super) end: usize,
}

/// Outcome of parsing a run of complete lines.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Parsed {
    /// Offset (in the block) of the first line not accepted, or the end of the run.
    pub(super) stop: usize,
    /// Line number of the line at `stop`.
    pub(super) stop_line: u64,
    /// Whether the parser stopped early (the CSV path takes over at `stop`).
    pub(super) stopped: bool,
}

/// Parse the complete lines in `block[from..to]` (`to` just after a `\n`) into `rows`;
/// `line` is the line number at `from`, `prev_time` the time of the row before.
pub(super) fn parse_lines(
    block: &[u8],
    from: usize,
    to: usize,
    mut line: u64,
    mut prev_time: Option<f64>,
    lay: &Layout,
    rows: &mut Vec<Row>,
) -> Parsed {
    let mut pos = from;
    let mut fields = [0.0f64; 4];
    while pos < to {
        let nl = match memchr(b'\n', &block[pos..to]) {
            Some(k) => pos + k,
            None => break,
        };
        let mut end = nl;
        if end > pos && block[end - 1] == b'\r' {
            end -= 1;
        }
        let text = &block[pos..end];
        let stop = Parsed {
            stop: pos,
            stop_line: line,
            stopped: true,
        };
        match text.first() {
            // Blank line: the CSV path skips it.
            None => {}
            // A comment runs to the newline whatever it holds.
            Some(b'#') => {}
            Some(_) => {
                let Some(s) = parse_row(text, lay, &mut fields) else {
                    return stop;
                };
                if prev_time.is_some_and(|t0| s.time_s <= t0) {
                    return stop;
                }
                prev_time = Some(s.time_s);
                rows.push(Row {
                    sample: s,
                    line,
                    start: pos,
                    end,
                });
            }
        }
        line += 1;
        pos = nl + 1;
    }
    Parsed {
        stop: pos,
        stop_line: line,
        stopped: false,
    }
}

/// Split `text` (one line, no terminator) and parse its mapped fields; None for anything
/// the CSV path must judge (quote, CR, wrong field count, a field that is not a finite
/// number). One pass: a number is parsed where it starts and must end at a delimiter.
#[inline]
fn parse_row(text: &[u8], lay: &Layout, vals: &mut [f64; 4]) -> Option<Sample> {
    let d = lay.delimiter;
    let last = lay.roles.len() - 1;
    let mut pos = 0;
    for (k, &role) in lay.roles.iter().enumerate() {
        let end = if role < 4 {
            let (v, end) = number_at(text, pos, d, lay.decimal_comma)?;
            vals[usize::from(role)] = v;
            end
        } else {
            let end = memchr(d, &text[pos..]).map_or(text.len(), |j| pos + j);
            if memchr::memchr2(b'"', b'\r', &text[pos..end]).is_some() {
                return None;
            }
            end
        };
        if k < last {
            if end == text.len() {
                return None;
            }
            pos = end + 1;
        } else if end != text.len() {
            return None;
        }
    }
    Some(Sample {
        time_s: vals[0],
        gyro_dps: vals[1] * lay.gyro_scale,
        temp_c: vals[2],
        table_dps: lay.has_table.then_some(vals[3]),
    })
}

/// The finite number in the field starting at `pos`, and where the field ends; the same
/// value the CSV path's number check gives (a decimal comma only where `decimal_comma`).
#[inline(always)]
fn number_at(text: &[u8], pos: usize, d: u8, decimal_comma: bool) -> Option<(f64, usize)> {
    let rest = &text[pos..];
    if let Some((v, n)) = parse_decimal_prefix(rest, b'.') {
        if rest.get(n).is_none_or(|&b| b == d) {
            return Some((v, pos + n));
        }
    }
    if decimal_comma {
        if let Some((v, n)) = parse_decimal_prefix(rest, b',') {
            if rest.get(n).is_none_or(|&b| b == d) {
                return Some((v, pos + n));
            }
        }
    }
    let end = memchr(d, rest).map_or(text.len(), |j| pos + j);
    let field = &text[pos..end];
    if memchr::memchr2(b'"', b'\r', field).is_some() {
        return None;
    }
    let v = match parse_f64(field) {
        None if decimal_comma => parse_f64_decimal_comma(field),
        v => v,
    };
    v.filter(|v| v.is_finite()).map(|v| (v, end))
}

/// Field `i` of a fast-path row's text.
pub(super) fn field(text: &[u8], delimiter: u8, i: usize) -> &[u8] {
    text.split(|&b| b == delimiter).nth(i).unwrap_or(b"")
}

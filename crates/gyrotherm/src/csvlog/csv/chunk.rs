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
use super::number::{parse_decimal_prefix, parse_number};

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

/// One accepted row: its numbers (time, gyro in °/s, temperature, table rate or 0), 1-based
/// line and the byte range of its text (without the line terminator) in the block. 48
/// bytes: the rows of a block are written by two threads and read back by one.
#[derive(Debug, Clone, Copy)]
pub(super) struct Row {
    pub(super) vals: [f64; 4],
    pub(super) line: u64,
    pub(super) start: u32,
    pub(super) end: u32,
}

impl Row {
    #[inline(always)]
    pub(super) fn time_s(&self) -> f64 {
        self.vals[0]
    }

    #[inline(always)]
    pub(super) fn sample(&self, has_table: bool) -> Sample {
        Sample {
            time_s: self.vals[0],
            gyro_dps: self.vals[1],
            temp_c: self.vals[2],
            table_dps: has_table.then_some(self.vals[3]),
        }
    }
}

/// Most bytes a block may hold: row offsets are `u32`.
pub(super) const MAX_BLOCK_BYTES: usize = u32::MAX as usize;

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

/// Parse the complete lines in `block[from..to]` (`to` just after a `\n`, at most
/// [`MAX_BLOCK_BYTES`]) into `rows`; `line` is the line number at `from`, `prev_time` the
/// time of the row before.
pub(super) fn parse_lines(
    block: &[u8],
    from: usize,
    to: usize,
    mut line: u64,
    mut prev_time: Option<f64>,
    lay: &Layout,
    rows: &mut Vec<Row>,
) -> Parsed {
    let block = &block[..to];
    let mut pos = from;
    let mut vals = [0.0f64; 4];
    while pos < to {
        let stop = Parsed {
            stop: pos,
            stop_line: line,
            stopped: true,
        };
        // The usual row, parsed straight through to its newline.
        if let Some(([t, g, c, r], end, next)) = direct_row(block, pos, lay) {
            let g = g * lay.gyro_scale;
            // A gyro value that overflows in °/s is the CSV path's error to tell.
            if prev_time.is_some_and(|t0| t <= t0) || !g.is_finite() {
                return stop;
            }
            prev_time = Some(t);
            rows.push(Row {
                vals: [t, g, c, r],
                line,
                start: pos as u32,
                end: end as u32,
            });
            line += 1;
            pos = next;
            continue;
        }
        let nl = match memchr(b'\n', &block[pos..to]) {
            Some(k) => pos + k,
            None => break,
        };
        let mut end = nl;
        if end > pos && block[end - 1] == b'\r' {
            end -= 1;
        }
        let text = &block[pos..end];
        match text.first() {
            // Blank line: the CSV path skips it.
            None => {}
            // A comment runs to the newline whatever it holds.
            Some(b'#') => {}
            Some(_) => {
                let Some(s) = parse_row(text, lay, &mut vals) else {
                    return stop;
                };
                if prev_time.is_some_and(|t0| s.time_s <= t0) {
                    return stop;
                }
                prev_time = Some(s.time_s);
                rows.push(Row {
                    vals: [s.time_s, s.gyro_dps, s.temp_c, s.table_dps.unwrap_or(0.0)],
                    line,
                    start: pos as u32,
                    end: end as u32,
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

/// The row starting at `pos`, parsed in one pass when it is plain: every mapped field a
/// plain decimal ([`parse_decimal_prefix`]) ended by the delimiter (the last field by the
/// line's `\n` or `\r\n`), pass-through fields free of quotes, CR and newline (the last one
/// also of delimiters), and no `#` at the start. Gives time, gyro (unscaled), temperature,
/// table rate (0 without one), the end of the row's text and the start of the next line;
/// None for anything else, which [`parse_row`] then judges.
#[inline(always)]
fn direct_row(block: &[u8], pos: usize, lay: &Layout) -> Option<([f64; 4], usize, usize)> {
    if block.get(pos) == Some(&b'#') {
        return None;
    }
    let d = lay.delimiter;
    let last = lay.roles.len() - 1;
    let mut p = pos;
    // Scalars, not an array indexed by role: that would live on the stack, and the row's
    // wide copy of it would stall on the narrow stores.
    let (mut t, mut g, mut c, mut r) = (0.0, 0.0, 0.0, 0.0);
    for (k, &role) in lay.roles.iter().enumerate() {
        let sep = if k < last { d } else { b'\n' };
        if role < 4 {
            let rest = &block[p..];
            let mut parsed = parse_decimal_prefix(rest, b'.');
            if lay.decimal_comma && parsed.is_some_and(|(_, n)| rest.get(n) == Some(&b',')) {
                parsed = parse_decimal_prefix(rest, b',');
            }
            let (v, n) = parsed?;
            match role {
                0 => t = v,
                1 => g = v,
                2 => c = v,
                _ => r = v,
            }
            p += n;
        } else {
            while let Some(&b) = block.get(p) {
                if b == sep || b == b'\r' && sep == b'\n' {
                    break;
                }
                // (A delimiter here is one in the last field: too many fields.)
                if b == b'"' || b == b'\r' || b == b'\n' || b == d {
                    return None;
                }
                p += 1;
            }
        }
        match block.get(p) {
            Some(&b) if b == sep => p += 1,
            Some(b'\r') if sep == b'\n' && block.get(p + 1) == Some(&b'\n') => p += 2,
            _ => return None,
        }
    }
    let end = if block[p - 2] == b'\r' { p - 2 } else { p - 1 };
    Some(([t, g, c, r], end, p))
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
    let gyro_dps = vals[1] * lay.gyro_scale;
    if !gyro_dps.is_finite() {
        return None;
    }
    Some(Sample {
        time_s: vals[0],
        gyro_dps,
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
    let v = parse_number(field, decimal_comma);
    v.filter(|v| v.is_finite()).map(|v| (v, end))
}

/// Field `i` of a fast-path row's text.
pub(super) fn field(text: &[u8], delimiter: u8, i: usize) -> &[u8] {
    text.split(|&b| b == delimiter).nth(i).unwrap_or(b"")
}

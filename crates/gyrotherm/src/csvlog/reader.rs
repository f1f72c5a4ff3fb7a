//! Streaming, validating reader: one CSV record in, one checked [`Sample`] out.
//!
//! The reader keeps a single reused [`csv::ByteRecord`] for the current row, so reading a log
//! costs no allocation per row; pass-through fields are handed out as raw bytes of that record.
//!
//! # Nominal sample period and gaps
//! The nominal period is the median (the lower middle value for an even count) of the first
//! [`PERIOD_ESTIMATE_STEPS`] time steps (fewer if the log is shorter), unless [`ReadOptions::sample_period_s`] gives it. The median ignores
//! a few gaps or jittered stamps among those steps. To know it before the first sample goes
//! out, the reader reads up to `PERIOD_ESTIMATE_STEPS + 1` rows ahead at the start (a live
//! 1 Hz stream therefore starts answering after 100 s unless the period is given).
//! A step larger than [`GAP_FACTOR`] periods is a gap: an error, or, with
//! [`ReadOptions::fill_gaps_max_s`], filled by linear interpolation (see [`LogReader`]).

use std::collections::VecDeque;
use std::io::Read;
use std::path::{Path, PathBuf};

use csv::ByteRecord;

use super::error::{LogError, LogErrorKind as Kind};
use super::{GyroUnit, ReadOptions, ReadReport, DEFAULT_TABLE_COL};

/// Number of leading time steps whose median is the nominal sample period.
pub const PERIOD_ESTIMATE_STEPS: usize = 100;

/// A step longer than this many nominal periods is a gap (issue 2: "a gap larger than 1.5
/// sample periods").
pub const GAP_FACTOR: f64 = 1.5;

/// Most samples one gap may be filled with; beyond it the gap is reported as too long, so
/// that a tiny period and a large limit cannot exhaust memory.
pub const MAX_FILL_SAMPLES_PER_GAP: usize = 10_000_000;

/// One validated row: finite numbers, gyro converted to °/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s (strictly increasing along the log).
    pub time_s: f64,
    /// Gyro output, °/s (converted from the file's unit).
    pub gyro_dps: f64,
    /// Temperature, °C.
    pub temp_c: f64,
    /// Rate-table input rate, °/s (None: the log has no table column).
    pub table_dps: Option<f64>,
}

/// Where the mapped columns sit in the header.
#[derive(Debug, Clone)]
struct Columns {
    time: usize,
    gyro: usize,
    temp: usize,
    table: Option<usize>,
    /// Every other column, in file order.
    extra: Vec<usize>,
}

/// The CSV side: parses and validates one record at a time (numbers, field count, time order).
struct Source<R> {
    csv: csv::Reader<Tail<R>>,
    path: PathBuf,
    headers: Vec<String>,
    header_line: u64,
    header_end_byte: u64,
    cols: Columns,
    gyro_scale: f64,
    /// Time and line of the last row read, for the order checks.
    last: Option<(f64, u64)>,
    rows: u64,
    /// Scratch record for looking one row ahead after a short row.
    peek: ByteRecord,
}

/// Gap filling in progress: `n` samples between `from` and `to`, `k` already handed out.
#[derive(Debug, Clone, Copy)]
struct Fill {
    from: Sample,
    to: Sample,
    to_line: u64,
    n: usize,
    k: usize,
}

/// Streaming reader of a test log.
///
/// ```no_run
/// # fn main() -> Result<(), gyrotherm::csvlog::LogError> {
/// use gyrotherm::csvlog::{LogReader, ReadOptions};
/// let stdin = std::io::stdin().lock();
/// let mut rdr = LogReader::new(stdin, "<stdin>", &ReadOptions::default())?;
/// while let Some(s) = rdr.next_sample()? {
///     let extras: Vec<&[u8]> = rdr.extra_fields().collect();
///     println!("{} {} {} {:?}", s.time_s, s.gyro_dps, s.temp_c, extras);
/// }
/// # Ok(()) }
/// ```
///
/// Gap filling: a gap of `dt` seconds between real samples `a` and `b` (time from `a` to `b`)
/// gets `n = round(dt / period) - 1` samples at equal steps `dt / (n + 1)`; gyro and
/// temperature are interpolated linearly, the table rate holds `a`'s value, pass-through fields
/// are empty ([`LogReader::is_filled`] is true and [`LogReader::record`] is None for them).
///
/// After an error the reader's state is unspecified: stop reading.
pub struct LogReader<R> {
    src: Source<R>,
    /// The raw record of the current (real) sample.
    record: ByteRecord,
    period_s: Option<f64>,
    warmed_up: bool,
    /// Rows read ahead during warm-up: record, sample, line.
    pending: VecDeque<(ByteRecord, Sample, u64)>,
    fill_max_s: Option<f64>,
    prev: Option<Sample>,
    fill: Option<Fill>,
    line: u64,
    filled: bool,
    report: ReadReport,
}

impl<R: Read> LogReader<R> {
    /// Read the header of `reader` and map the columns. `source` names the input in errors
    /// (a path, or `<stdin>`).
    pub fn new(
        reader: R,
        source: impl Into<PathBuf>,
        opts: &ReadOptions,
    ) -> Result<Self, LogError> {
        let path: PathBuf = source.into();
        check_options(&path, opts)?;
        let mut csv = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .buffer_capacity(64 * 1024)
            .from_reader(Tail {
                inner: reader,
                total: 0,
                last: b'\n',
                crlf: false,
                crlf_known: false,
            });
        let mut header = ByteRecord::new();
        let got = csv
            .read_byte_record(&mut header)
            .map_err(|e| csv_error(&path, e))?;
        if !got {
            return Err(LogError::new(
                Kind::NoHeader,
                &path,
                None,
                None,
                "empty file: no header row; the first line that is not a '#' comment must name \
                 the columns, e.g. time_s,gyro_dps,temp_c",
            ));
        }
        let header_line = record_line(&csv, &header);
        let header_end_byte = csv.position().byte();
        let mut headers = Vec::with_capacity(header.len());
        for (i, raw) in header.iter().enumerate() {
            let raw = if i == 0 {
                raw.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(raw)
            } else {
                raw
            };
            let name = std::str::from_utf8(raw).map_err(|_| {
                LogError::new(
                    Kind::NotUtf8,
                    &path,
                    Some(header_line),
                    None,
                    format!(
                        "header field {} is not UTF-8 text; re-save the file as UTF-8",
                        i + 1
                    ),
                )
            })?;
            headers.push(name.trim().to_owned());
        }
        let cols = map_columns(&path, header_line, &headers, opts)?;
        let gyro_scale = match opts.gyro_unit {
            GyroUnit::Dps => 1.0,
            // 1 °/h = 1/3600 °/s.
            GyroUnit::Dph => 1.0 / 3600.0,
            // 1 rad = 180/π °.
            GyroUnit::RadPerS => 180.0 / std::f64::consts::PI,
        };
        let ncols = headers.len();
        Ok(LogReader {
            src: Source {
                csv,
                path,
                headers,
                header_line,
                header_end_byte,
                cols,
                gyro_scale,
                last: None,
                rows: 0,
                peek: ByteRecord::new(),
            },
            record: ByteRecord::with_capacity(64, ncols),
            period_s: opts.sample_period_s,
            warmed_up: false,
            pending: VecDeque::new(),
            fill_max_s: opts.fill_gaps_max_s,
            prev: None,
            fill: None,
            line: header_line,
            filled: false,
            report: ReadReport::default(),
        })
    }

    /// The next sample, real or gap-filled; `Ok(None)` at the end of the input.
    /// A log without any data row is an error ([`Kind::NoData`]).
    #[inline]
    pub fn next_sample(&mut self) -> Result<Option<Sample>, LogError> {
        if let Some(f) = self.fill.as_mut() {
            if f.k < f.n {
                f.k += 1;
                let a = f.k as f64 / (f.n + 1) as f64;
                let s = Sample {
                    time_s: lerp(f.from.time_s, f.to.time_s, a),
                    gyro_dps: lerp(f.from.gyro_dps, f.to.gyro_dps, a),
                    temp_c: lerp(f.from.temp_c, f.to.temp_c, a),
                    table_dps: f.from.table_dps,
                };
                self.filled = true;
                return Ok(Some(s));
            }
            let (to, to_line) = (f.to, f.to_line);
            self.fill = None;
            return Ok(Some(self.accept(to, to_line)));
        }
        let Some((s, line)) = self.next_row()? else {
            self.report.rows = self.src.rows;
            return Ok(None);
        };
        if let (Some(p), Some(period)) = (self.prev, self.period_s) {
            let dt = s.time_s - p.time_s;
            if dt > GAP_FACTOR * period {
                return self.gap(p, s, line, dt, period);
            }
        }
        Ok(Some(self.accept(s, line)))
    }

    /// Hand out a real sample.
    #[inline]
    fn accept(&mut self, s: Sample, line: u64) -> Sample {
        self.filled = false;
        self.line = line;
        self.prev = Some(s);
        s
    }

    #[cold]
    fn gap(
        &mut self,
        p: Sample,
        s: Sample,
        line: u64,
        dt: f64,
        period: f64,
    ) -> Result<Option<Sample>, LogError> {
        let t_col = &self.src.headers[self.src.cols.time];
        let how = if self.period_s_estimated() {
            format!("median of the first {PERIOD_ESTIMATE_STEPS} steps")
        } else {
            "given".to_owned()
        };
        let what = format!(
            "gap of {dt} s from {} s to {} s, more than {GAP_FACTOR} sample periods \
             (period {period} s, {how})",
            p.time_s, s.time_s
        );
        let n_f = (dt / period).round() - 1.0;
        match self.fill_max_s {
            Some(max) if dt <= max && n_f <= MAX_FILL_SAMPLES_PER_GAP as f64 => {
                // dt > 1.5 period, so n_f >= 1.
                let n = (n_f as usize).max(1);
                self.report.filled_gaps += 1;
                self.report.filled_samples += n;
                self.fill = Some(Fill {
                    from: p,
                    to: s,
                    to_line: line,
                    n,
                    k: 0,
                });
                self.next_sample()
            }
            Some(max) => Err(LogError::new(
                Kind::GapTooLong,
                &self.src.path,
                Some(line),
                Some(t_col),
                format!(
                    "{what}, longer than the --fill-gaps limit of {max} s; split the log at \
                     this line or raise --fill-gaps if interpolating {dt} s is acceptable"
                ),
            )),
            None => Err(LogError::new(
                Kind::Gap,
                &self.src.path,
                Some(line),
                Some(t_col),
                format!(
                    "{what}; split the log at this line, or pass --fill-gaps MAX_S to \
                     interpolate gaps up to MAX_S seconds"
                ),
            )),
        }
    }

    fn period_s_estimated(&self) -> bool {
        self.report.sample_period_estimated
    }

    /// Next validated row from the read-ahead queue or the file; sets `self.record`.
    #[inline]
    fn next_row(&mut self) -> Result<Option<(Sample, u64)>, LogError> {
        if !self.warmed_up {
            self.warm_up()?;
        }
        if let Some((mut rec, s, line)) = self.pending.pop_front() {
            std::mem::swap(&mut self.record, &mut rec);
            return Ok(Some((s, line)));
        }
        self.src.read(&mut self.record).map_err(|e| *e)
    }

    /// Read ahead to estimate the period (unless given) and check there is data at all.
    #[cold]
    fn warm_up(&mut self) -> Result<(), LogError> {
        self.warmed_up = true;
        let want = if self.period_s.is_some() {
            1
        } else {
            PERIOD_ESTIMATE_STEPS + 1
        };
        while self.pending.len() < want {
            let mut rec = ByteRecord::with_capacity(64, self.src.headers.len());
            match self.src.read(&mut rec).map_err(|e| *e)? {
                Some((s, line)) => self.pending.push_back((rec, s, line)),
                None => break,
            }
        }
        if self.pending.is_empty() {
            return Err(LogError::new(
                Kind::NoData,
                &self.src.path,
                None,
                None,
                format!(
                    "no data rows after the header (line {}); the log is empty or holds only \
                     comments",
                    self.src.header_line
                ),
            ));
        }
        if self.period_s.is_none() {
            let mut steps: Vec<f64> = self
                .pending
                .iter()
                .zip(self.pending.iter().skip(1))
                .map(|(a, b)| b.1.time_s - a.1.time_s)
                .collect();
            if !steps.is_empty() {
                steps.sort_by(f64::total_cmp);
                // Lower median: for an even count the smaller middle step, so that gaps
                // (long steps) never raise the period (3 rows with steps 1 s, 2 s: 1 s).
                let median = steps[(steps.len() - 1) / 2];
                self.period_s = Some(median);
                self.report.sample_period_estimated = true;
            }
        }
        self.report.sample_period_s = self.period_s;
        Ok(())
    }

    /// The header names (trimmed), in file order.
    pub fn headers(&self) -> &[String] {
        &self.src.headers
    }

    /// Names of the pass-through columns, in file order.
    pub fn extra_names(&self) -> impl Iterator<Item = &str> + '_ {
        self.src
            .cols
            .extra
            .iter()
            .map(|&i| self.src.headers[i].as_str())
    }

    /// Number of pass-through columns.
    pub fn extra_count(&self) -> usize {
        self.src.cols.extra.len()
    }

    /// Whether the log has the table-rate column.
    pub fn has_table(&self) -> bool {
        self.src.cols.table.is_some()
    }

    /// Raw pass-through fields of the current sample, in file order (empty for a gap-filled
    /// sample). The bytes are as parsed by the CSV reader (quotes removed, spaces kept).
    pub fn extra_fields(&self) -> impl Iterator<Item = &[u8]> + '_ {
        let filled = self.filled;
        self.src
            .cols
            .extra
            .iter()
            .map(move |&i| if filled { &b""[..] } else { &self.record[i] })
    }

    /// The raw record of the current sample (None for a gap-filled sample).
    pub fn record(&self) -> Option<&ByteRecord> {
        (!self.filled).then_some(&self.record)
    }

    /// Whether the current sample was made by gap filling.
    pub fn is_filled(&self) -> bool {
        self.filled
    }

    /// 1-based physical line of the current real sample (for a filled one: of the last real
    /// sample handed out before it).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// The nominal sample period, s (known after the first `next_sample`; None for a log of
    /// one row without a given period).
    pub fn sample_period_s(&self) -> Option<f64> {
        self.period_s
    }

    /// What reading did so far (filled gaps and samples; `rows` is final at the end).
    pub fn report(&self) -> &ReadReport {
        &self.report
    }

    /// The name given for the input.
    pub fn source(&self) -> &Path {
        &self.src.path
    }

    /// Bytes consumed by the parser so far, and the bytes per data row seen so far (for
    /// sizing buffers; None before any row).
    pub fn bytes_per_row(&self) -> Option<f64> {
        let rows = self.src.rows;
        (rows > 0).then(|| {
            (self.src.csv.position().byte() - self.src.header_end_byte) as f64 / rows as f64
        })
    }

    /// Convert the current sample's `k`-th pass-through field to text, with a located error
    /// if it is not UTF-8.
    pub fn extra_text(&self, k: usize) -> Result<&str, LogError> {
        if self.filled {
            return Ok("");
        }
        let i = self.src.cols.extra[k];
        std::str::from_utf8(&self.record[i]).map_err(|_| {
            LogError::new(
                Kind::NotUtf8,
                &self.src.path,
                Some(self.line),
                Some(&self.src.headers[i]),
                "field is not UTF-8 text; re-save the file as UTF-8",
            )
        })
    }
}

impl<R: Read> Source<R> {
    /// Read and check one data row into `rec`.
    #[inline]
    fn read(&mut self, rec: &mut ByteRecord) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        let more = self
            .csv
            .read_byte_record(rec)
            .map_err(|e| Box::new(csv_error(&self.path, e)))?;
        if !more {
            return Ok(None);
        }
        let line = record_line(&self.csv, rec);
        if rec.len() != self.headers.len() {
            return Err(Box::new(self.field_count_error(rec.len(), line)));
        }
        let time_s = self.number(rec, self.cols.time, line)?;
        let gyro_dps = self.number(rec, self.cols.gyro, line)? * self.gyro_scale;
        let temp_c = self.number(rec, self.cols.temp, line)?;
        let table_dps = match self.cols.table {
            Some(i) => Some(self.number(rec, i, line)?),
            None => None,
        };
        if let Some((t0, line0)) = self.last {
            // Written so that it holds for the common case; NaN cannot occur (checked above).
            if time_s <= t0 {
                return Err(Box::new(self.order_error(time_s, t0, line, line0)));
            }
        }
        self.last = Some((time_s, line));
        self.rows += 1;
        Ok(Some((
            Sample {
                time_s,
                gyro_dps,
                temp_c,
                table_dps,
            },
            line,
        )))
    }

    #[inline(always)]
    fn number(&self, rec: &ByteRecord, i: usize, line: u64) -> Result<f64, Box<LogError>> {
        match parse_f64(&rec[i]) {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(Box::new(self.number_error(&rec[i], i, line))),
        }
    }

    #[cold]
    fn number_error(&self, raw: &[u8], i: usize, line: u64) -> LogError {
        let text = String::from_utf8_lossy(raw);
        let (kind, message) = if parse_f64(raw).is_some() {
            (
                Kind::NonFinite,
                format!(
                    "{text:?} is not a finite number (NaN, infinite or out of range); \
                     fix the value or comment the line out with '#'"
                ),
            )
        } else if text.trim().is_empty() {
            (
                Kind::NotANumber,
                "empty field where a number is required; fill in the value or comment the \
                 line out with '#'"
                    .to_owned(),
            )
        } else {
            let hint = if text.contains(',') {
                " (use '.' as the decimal point)"
            } else {
                ""
            };
            (
                Kind::NotANumber,
                format!(
                    "{text:?} is not a number; fix the value{hint} or comment the line out \
                     with '#'"
                ),
            )
        };
        LogError::new(
            kind,
            &self.path,
            Some(line),
            Some(&self.headers[i]),
            message,
        )
    }

    #[cold]
    fn field_count_error(&mut self, found: usize, line: u64) -> LogError {
        let want = self.headers.len();
        // A short row followed by nothing is a file cut mid-write.
        let is_last =
            found < want && matches!(self.csv.read_byte_record(&mut self.peek), Ok(false));
        if is_last {
            LogError::new(
                Kind::TruncatedLine,
                &self.path,
                Some(line),
                Some(&self.headers[found]),
                format!(
                    "truncated last line: {found} of {want} fields (was the file cut while \
                     being written?); delete the incomplete last line or copy the log again"
                ),
            )
        } else {
            LogError::new(
                Kind::FieldCount,
                &self.path,
                Some(line),
                None,
                format!(
                    "{found} fields, but the header (line {}) has {want}; fix the line (a \
                     missing or extra ',') or comment it out with '#'",
                    self.header_line
                ),
            )
        }
    }

    #[cold]
    fn order_error(&self, t: f64, t0: f64, line: u64, line0: u64) -> LogError {
        let col = Some(self.headers[self.cols.time].as_str());
        if t == t0 {
            LogError::new(
                Kind::DuplicateTime,
                &self.path,
                Some(line),
                col,
                format!(
                    "duplicate timestamp {t} s (also on line {line0}); remove one of the two \
                     rows"
                ),
            )
        } else {
            LogError::new(
                Kind::TimeNotIncreasing,
                &self.path,
                Some(line),
                col,
                format!(
                    "time is not strictly increasing: {t} s comes after {t0} s (line {line0}); \
                     sort the log by time or remove the out-of-order row"
                ),
            )
        }
    }
}

/// Parse a numeric field: ASCII spaces around it allowed, Rust float syntax (which also
/// accepts `NaN` and `inf`; the caller rejects those). Gives the same f64 as `str::parse`.
#[inline(always)]
pub(crate) fn parse_f64(raw: &[u8]) -> Option<f64> {
    match parse_plain_decimal(raw) {
        Some(v) => Some(v),
        None => parse_f64_std(raw),
    }
}

#[cold]
#[inline(never)]
fn parse_f64_std(raw: &[u8]) -> Option<f64> {
    let t = raw.trim_ascii();
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// Exact powers of ten representable in f64 (10^22 is the largest, Clinger 1990).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Fast path for the usual log field `[+-]digits[.digits]`: when the digits form an integer
/// `m ≤ 2^53` and there are at most 22 decimals, `m` and `10^d` are exact f64 values and one
/// IEEE division rounds `m / 10^d` correctly, so the result equals `str::parse`'s (Clinger's
/// fast path: W. D. Clinger, "How to read floating point numbers accurately", PLDI 1990).
/// Anything else (exponent, spaces, 20+ digits, NaN, inf) gives None.
#[inline(always)]
pub(crate) fn parse_plain_decimal(s: &[u8]) -> Option<f64> {
    let (neg, s) = match s.first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    let mut m: u64 = 0;
    let mut i = digits(s, 0, &mut m);
    let int_digits = i;
    let mut frac_digits = 0;
    if i < s.len() && s[i] == b'.' {
        let start = i + 1;
        i = digits(s, start, &mut m);
        frac_digits = i - start;
    }
    let digits = int_digits + frac_digits;
    // 19 digits cannot overflow u64, so `m` is exact when digits <= 19.
    if i != s.len() || digits == 0 || digits > 19 || m > (1 << 53) || frac_digits > 22 {
        return None;
    }
    let v = m as f64 / POW10[frac_digits];
    Some(if neg { -v } else { v })
}

/// 1-based physical line where `rec`, just read, starts.
///
/// The csv crate stamps a record with the position where reading began, which is before
/// any comment or blank lines it skipped (and, in a CRLF file, before the previous line's
/// LF). So count back from the line after the record: less the newlines inside quoted
/// fields, less one for the record's own LF terminator (a CRLF record ends at its CR, and
/// the last record of a file may have no terminator).
#[inline]
fn record_line<R: Read>(csv: &csv::Reader<Tail<R>>, rec: &ByteRecord) -> u64 {
    let start = rec.position().map_or(1, |p| p.line());
    let pos = csv.position();
    let end = pos.line();
    let tail = csv.get_ref();
    let unterminated = pos.byte() == tail.total && tail.last != b'\n';
    let terminator = u64::from(!unterminated && !tail.crlf);
    if end <= start + terminator {
        return start;
    }
    let inside = rec.as_slice().iter().filter(|&&b| b == b'\n').count() as u64;
    end.saturating_sub(inside + terminator).max(start)
}

/// The input, remembering how many bytes were read, the last one (to tell whether the
/// last record ended with a newline) and whether lines end in CRLF (judged by the first
/// line; a file mixing LF and CRLF lines may get line numbers off by one in errors).
struct Tail<R> {
    inner: R,
    total: u64,
    last: u8,
    crlf: bool,
    crlf_known: bool,
}

impl<R: Read> Read for Tail<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if n > 0 {
            if !self.crlf_known {
                if let Some(k) = buf[..n].iter().position(|&b| b == b'\n') {
                    let before = if k > 0 { buf[k - 1] } else { self.last };
                    self.crlf = before == b'\r';
                    self.crlf_known = true;
                }
            }
            self.total += n as u64;
            self.last = buf[n - 1];
        }
        Ok(n)
    }
}

/// Accumulate the decimal digits of `s` from `i` into `m` (wrapping; the caller bounds the
/// count), eight at a time where it can; returns the index after the last digit.
#[inline(always)]
fn digits(s: &[u8], mut i: usize, m: &mut u64) -> usize {
    while let Some(chunk) = s.get(i..i + 8) {
        let mut word = [0u8; 8];
        word.copy_from_slice(chunk);
        let v = u64::from_le_bytes(word);
        // All eight bytes in b'0'..=b'9' (SWAR test as in simdjson / fast_float).
        let all_digits = (v.wrapping_add(0x4646_4646_4646_4646)
            | v.wrapping_sub(0x3030_3030_3030_3030))
            & 0x8080_8080_8080_8080
            == 0;
        if !all_digits {
            break;
        }
        *m = m.wrapping_mul(100_000_000).wrapping_add(eight_digits(v));
        i += 8;
    }
    while i < s.len() && s[i].is_ascii_digit() {
        *m = m.wrapping_mul(10).wrapping_add(u64::from(s[i] - b'0'));
        i += 1;
    }
    i
}

/// Value of eight ASCII digits packed little-endian in `v` (first digit in the low byte).
#[inline(always)]
fn eight_digits(v: u64) -> u64 {
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    const MUL1: u64 = 0x000F_4240_0000_0064; // 100 + (1_000_000 << 32)
    const MUL2: u64 = 0x0000_2710_0000_0001; // 1 + (10_000 << 32)
    let v = v.wrapping_sub(0x3030_3030_3030_3030);
    let v = v.wrapping_mul(10).wrapping_add(v >> 8);
    (((v & MASK).wrapping_mul(MUL1)).wrapping_add(((v >> 16) & MASK).wrapping_mul(MUL2))) >> 32
}

#[inline]
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

fn csv_error(path: &Path, e: csv::Error) -> LogError {
    let line = e.position().map(|p| p.line());
    if let csv::ErrorKind::Io(io) = e.kind() {
        LogError::new(Kind::Io, path, line, None, format!("cannot read: {io}"))
    } else {
        LogError::new(Kind::Csv, path, line, None, format!("malformed CSV: {e}"))
    }
}

fn check_options(path: &Path, opts: &ReadOptions) -> Result<(), LogError> {
    let bad = |what: &str, v: f64| {
        LogError::new(
            Kind::BadOptions,
            path,
            None,
            None,
            format!("{what} must be a positive number of seconds, got {v}"),
        )
    };
    if let Some(v) = opts.fill_gaps_max_s {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad("--fill-gaps", v));
        }
    }
    if let Some(v) = opts.sample_period_s {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad("the sample period", v));
        }
    }
    Ok(())
}

/// Find the mapped columns; a missing one names the columns found and the option to use.
fn map_columns(
    path: &Path,
    line: u64,
    headers: &[String],
    opts: &ReadOptions,
) -> Result<Columns, LogError> {
    let find = |name: &str, flag: &str, what: &str| -> Result<Option<usize>, LogError> {
        let mut hits = headers
            .iter()
            .enumerate()
            .filter(|(_, h)| *h == name)
            .map(|(i, _)| i);
        let first = hits.next();
        if let (Some(a), Some(b)) = (first, hits.next()) {
            return Err(LogError::new(
                Kind::DuplicateColumn,
                path,
                Some(line),
                Some(name),
                format!(
                    "the header names this column twice (fields {} and {}); rename one, or \
                     pick the {what} column with {flag} NAME",
                    a + 1,
                    b + 1
                ),
            ));
        }
        Ok(first)
    };
    let require = |name: &str, flag: &str, what: &str| -> Result<usize, LogError> {
        find(name, flag, what)?.ok_or_else(|| missing_column(path, line, headers, name, flag, what))
    };
    let time = require(&opts.time_col, "--time-col", "time")?;
    let gyro = require(&opts.gyro_col, "--gyro-col", "gyro")?;
    let temp = require(&opts.temp_col, "--temp-col", "temperature")?;
    let table = find(&opts.table_col, "--table-col", "table-rate")?;
    if table.is_none() && opts.table_col != DEFAULT_TABLE_COL {
        // Mapped explicitly, so its absence is not a static test but a mistake.
        return Err(missing_column(
            path,
            line,
            headers,
            &opts.table_col,
            "--table-col",
            "table-rate",
        ));
    }
    let roles = [
        (time, &opts.time_col),
        (gyro, &opts.gyro_col),
        (temp, &opts.temp_col),
    ];
    for (k, (i, name)) in roles.iter().enumerate() {
        let clash = roles[k + 1..]
            .iter()
            .map(|(j, n)| (*j, *n))
            .chain(table.map(|j| (j, &opts.table_col)))
            .find(|(j, _)| j == i);
        if let Some((_, other)) = clash {
            return Err(LogError::new(
                Kind::BadOptions,
                path,
                Some(line),
                Some(name),
                format!("column {name} is mapped to two roles (also as {other}); map each role to its own column"),
            ));
        }
    }
    let extra = (0..headers.len())
        .filter(|&i| i != time && i != gyro && i != temp && Some(i) != table)
        .collect();
    Ok(Columns {
        time,
        gyro,
        temp,
        table,
        extra,
    })
}

#[cold]
fn missing_column(
    path: &Path,
    line: u64,
    headers: &[String],
    name: &str,
    flag: &str,
    what: &str,
) -> LogError {
    let found = headers
        .iter()
        .map(|h| format!("{h:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    let mut message =
        format!("required column not found; the header (line {line}) has: {found}; name the {what} column with {flag} NAME");
    if headers.len() == 1 {
        for (sep, sep_name) in [(';', "';'"), ('\t', "tabs")] {
            if headers[0].contains(sep) {
                message.push_str(&format!(
                    " (the file seems to separate fields with {sep_name}; gyrotherm reads \
                     comma-separated files)"
                ));
            }
        }
    }
    if !headers.is_empty() && headers.iter().all(|h| parse_f64(h.as_bytes()).is_some()) {
        message.push_str(
            " (the first line looks like data: add a header row such as time_s,gyro_dps,temp_c)",
        );
    }
    LogError::new(Kind::MissingColumn, path, Some(line), Some(name), message)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The fast path must agree bit for bit with `str::parse` (the independent reference).
    fn same_as_std(s: &str) {
        let want: Option<f64> = s.trim_ascii().parse().ok();
        let got = parse_f64(s.as_bytes());
        assert_eq!(
            got.map(f64::to_bits),
            want.map(f64::to_bits),
            "{s:?}: want {want:?} got {got:?}"
        );
    }

    #[test]
    fn decimal_parse_edge_cases() {
        for s in [
            "0",
            "-0",
            "+0",
            "1.",
            ".5",
            ".",
            "-",
            "",
            " 1.5 ",
            "12345.000",
            "0.0012345678901",
            "23.4375",
            "9007199254740993",
            "9007199254740992",
            "0.1",
            "1e5",
            "nan",
            "inf",
            "-infinity",
            "1,5",
            "00000000000000000001.5",
            "1.00000000000000000000001",
            "123456789012345678901234",
            "4.9e-324",
            "1.7976931348623157e308",
            "0x10",
            "1_0",
        ] {
            same_as_std(s);
        }
    }

    proptest! {
        #[test]
        fn decimal_parse_matches_std(s in "[+-]?[0-9]{0,20}(\\.[0-9]{0,25})?") {
            same_as_std(&s);
        }

        #[test]
        fn decimal_parse_of_printed_f64_round_trips(v in any::<f64>().prop_filter("finite", |v| v.is_finite()), d in 0usize..17) {
            same_as_std(&format!("{v}"));
            same_as_std(&format!("{v:.d$}"));
        }
    }
}

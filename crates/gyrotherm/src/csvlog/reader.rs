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

use super::columns::{check_options, map_columns, Columns};
use super::error::{LogError, LogErrorKind as Kind};
use super::gaps::{gap_verdict, Fill, GapVerdict, Sample};
use super::number::{parse_f64, parse_f64_decimal_comma};
use super::{GyroUnit, ReadOptions, ReadReport};

/// Number of leading time steps whose median is the nominal sample period.
pub const PERIOD_ESTIMATE_STEPS: usize = 100;

/// A step longer than this many nominal periods is a gap: one missing sample (a step of two
/// periods) must be caught, while jitter of half a period must not be.
pub const GAP_FACTOR: f64 = 1.5;

/// Most samples gap filling may make in one log, all gaps together.
pub const MAX_FILLED_SAMPLES: usize = 10_000_000;

/// A given sample period is checked against this many leading time steps of the log.
pub const PERIOD_CHECK_STEPS: usize = 10;

/// That many of those steps more than [`GAP_FACTOR`] times longer or shorter than the given
/// period mean the period is wrong (one or two may be real gaps).
const PERIOD_CHECK_MISMATCHES: usize = 3;

/// The CSV side: parses and validates one record at a time (numbers, field count, time order).
struct Source<R> {
    csv: csv::Reader<Tail<R>>,
    path: PathBuf,
    headers: Vec<String>,
    header_line: u64,
    header_end_byte: u64,
    cols: Columns,
    gyro_scale: f64,
    /// Numbers may use a decimal comma (the separator is not a comma).
    decimal_comma: bool,
    /// Time and line of the last row read, for the order checks.
    last: Option<(f64, u64)>,
    rows: u64,
    /// Scratch record for looking one row ahead after a short row.
    peek: ByteRecord,
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
    /// Leading steps kept to check a given period (emptied once checked).
    given_period_steps: Vec<f64>,
    /// Steps checked against a given period so far.
    period_checked: usize,
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
            .delimiter(opts.delimiter)
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
                decimal_comma: opts.delimiter != b',',
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
            given_period_steps: Vec::with_capacity(if opts.sample_period_s.is_some() {
                PERIOD_CHECK_STEPS
            } else {
                0
            }),
            period_checked: 0,
        })
    }

    /// The next sample, real or gap-filled; `Ok(None)` at the end of the input.
    /// A log without any data row is an error ([`Kind::NoData`]).
    #[inline]
    pub fn next_sample(&mut self) -> Result<Option<Sample>, LogError> {
        if let Some(f) = self.fill.as_mut() {
            if let Some(s) = f.next_filled() {
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
            if !self.report.sample_period_estimated && self.period_checked < PERIOD_CHECK_STEPS {
                self.check_given_period(dt, period, line)?;
            }
            if dt > GAP_FACTOR * period {
                return self.gap(p, s, line, dt, period);
            }
            let jitter = (dt / period - 1.0).abs();
            if jitter > self.report.max_step_jitter {
                self.report.max_step_jitter = jitter;
                self.report.max_jitter_line = Some(line);
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
        match gap_verdict(dt, period, self.fill_max_s) {
            GapVerdict::Fill(n) if self.report.filled_samples + n > MAX_FILLED_SAMPLES => {
                Err(LogError::new(
                    Kind::GapTooLong,
                    &self.src.path,
                    Some(line),
                    Some(t_col),
                    format!(
                        "{what}: filling it would bring the samples made by gap filling to \
                         more than {MAX_FILLED_SAMPLES}; check the sample period and the time \
                         column, or split the log"
                    ),
                ))
            }
            GapVerdict::Fill(n) => {
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
            GapVerdict::TooLong(max) => Err(LogError::new(
                Kind::GapTooLong,
                &self.src.path,
                Some(line),
                Some(t_col),
                format!(
                    "{what}, longer than the --fill-gaps limit of {max} s; split the log at \
                     this line or raise --fill-gaps if interpolating {dt} s is acceptable"
                ),
            )),
            GapVerdict::NotAllowed => Err(LogError::new(
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

    /// A given period must match the log's own steps: a period far off would make every
    /// step a gap (runaway gap filling) or hide real gaps.
    #[cold]
    fn check_given_period(&mut self, dt: f64, period: f64, line: u64) -> Result<(), LogError> {
        self.period_checked += 1;
        self.given_period_steps.push(dt);
        let off = |d: &f64| *d > GAP_FACTOR * period || *d < period / GAP_FACTOR;
        let mismatches = self.given_period_steps.iter().filter(|d| off(d)).count();
        if mismatches >= PERIOD_CHECK_MISMATCHES {
            let mut steps = self.given_period_steps.clone();
            steps.sort_by(f64::total_cmp);
            let median = steps[(steps.len() - 1) / 2];
            return Err(LogError::new(
                Kind::BadOptions,
                &self.src.path,
                Some(line),
                Some(&self.src.headers[self.src.cols.time]),
                format!(
                    "the given sample period {period} s disagrees with the log's time steps: \
                     {mismatches} of its first {} steps are more than {GAP_FACTOR} times longer \
                     or shorter (median step {median} s); give the log's own period or leave \
                     --sample-period out",
                    steps.len()
                ),
            ));
        }
        if self.given_period_steps.len() >= PERIOD_CHECK_STEPS {
            self.given_period_steps = Vec::new();
        }
        Ok(())
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
        let parsed = match parse_f64(&rec[i]) {
            None if self.decimal_comma => parse_f64_decimal_comma(&rec[i]),
            v => v,
        };
        match parsed {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(Box::new(self.number_error(&rec[i], i, line))),
        }
    }

    #[cold]
    fn number_error(&self, raw: &[u8], i: usize, line: u64) -> LogError {
        let text = String::from_utf8_lossy(raw);
        let parses = parse_f64(raw).is_some()
            || (self.decimal_comma && parse_f64_decimal_comma(raw).is_some());
        let (kind, message) = if parses {
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
            let hint = if text.contains(',') && !self.decimal_comma {
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

fn csv_error(path: &Path, e: csv::Error) -> LogError {
    let line = e.position().map(|p| p.line());
    if let csv::ErrorKind::Io(io) = e.kind() {
        LogError::new(Kind::Io, path, line, None, format!("cannot read: {io}"))
    } else {
        LogError::new(Kind::Csv, path, line, None, format!("malformed CSV: {e}"))
    }
}

//! Streaming, validating reader: one CSV record in, one checked [`Sample`] out.
//!
//! Rows are read in newline-aligned blocks of plain rows parsed on two threads (the fast
//! path, [`super::chunk`]); at the first line the fast path cannot judge (a quote, a lone
//! CR, an error) the csv crate takes over from that line, so errors keep their exact line,
//! column and text. Either way reading costs no allocation per row; pass-through fields are
//! handed out as raw bytes of the row. A line longer than [`MAX_LINE_BYTES`] is an error
//! ([`LogErrorKind::LineTooLong`](super::LogErrorKind::LineTooLong)) before it is held in
//! memory, and a bad field is quoted in a message by at most its first characters.
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

use std::cell::OnceCell;

use super::chunk::{self, parse_lines, Layout, Row, MAX_BLOCK_BYTES, PARALLEL_MIN_BYTES};
use super::columns::{check_options, map_columns, Columns};
use super::error::{quoted_field, LogError, LogErrorKind as Kind};
use super::gaps::{gap_verdict, Fill, GapVerdict, Sample, MAX_FILL_SAMPLES_PER_GAP};
use super::number::parse_number;
use super::MAX_LINE_BYTES;
use super::{ReadOptions, ReadReport};

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

mod fast;
mod source;

use fast::*;
use source::*;

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
    src: Source<LineCap<R>>,
    /// The raw record of the current sample when it came from the read-ahead queue.
    record: ByteRecord,
    from_pending: bool,
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
        Self::with_path(reader, source.into(), opts, true)
    }

    /// `fast: false` reads everything down the CSV path (the reference for the fast path).
    fn with_path(
        reader: R,
        path: PathBuf,
        opts: &ReadOptions,
        fast: bool,
    ) -> Result<Self, LogError> {
        check_options(&path, opts)?;
        let mut inner = LineCap::new(reader);
        // Read until the header line is complete, then parse it with the csv crate; a
        // header the fast path cannot judge (quotes, lone CR) sends the whole input
        // down the CSV path.
        let mut buf = vec![0u8; BLOCK_BYTES];
        let mut len = 0;
        let mut eof = false;
        let header_end = loop {
            match find_header(&buf[..len]) {
                HeaderScan::Found(end) if fast && len <= MAX_BLOCK_BYTES / 2 => break Some(end),
                HeaderScan::Found(_) => break None,
                HeaderScan::Hard => break None,
                HeaderScan::NeedMore if eof => break None,
                HeaderScan::NeedMore => {
                    if len == buf.len() {
                        buf.resize(2 * buf.len(), 0);
                    }
                    let n =
                        read_retry(&mut inner, &mut buf[len..]).map_err(|e| io_error(&path, e))?;
                    eof = n == 0;
                    len += n;
                }
            }
        };
        let crlf = memchr::memchr(b'\n', &buf[..len]).map(|k| k > 0 && buf[k - 1] == b'\r');
        let (mode, header, header_line, csv_skip) = match header_end {
            Some(end) => {
                let mut csv = csv_reader(&buf[..end], crlf, opts.delimiter);
                let (header, header_line) = read_header(&mut csv, &path)?;
                let line = buf[..end].iter().filter(|&&b| b == b'\n').count() as u64 + 1;
                let fast = Fast {
                    inner,
                    buf,
                    len,
                    parsed_end: end,
                    line,
                    eof,
                    parts: [Vec::new(), Vec::new()],
                    part: 0,
                    next: 0,
                    switch_at: None,
                    record: OnceCell::new(),
                    threads: std::thread::available_parallelism().is_ok_and(|n| n.get() > 1),
                };
                (Mode::Fast(Box::new(fast)), header, header_line, 0)
            }
            None => {
                buf.truncate(len);
                let mut csv =
                    csv_reader(std::io::Cursor::new(buf).chain(inner), crlf, opts.delimiter);
                let (header, header_line) = read_header(&mut csv, &path)?;
                let skip = csv.position().byte();
                let part = CsvPart {
                    csv,
                    line_offset: 0,
                    rec: ByteRecord::new(),
                };
                (Mode::Csv(Box::new(part)), header, header_line, skip)
            }
        };
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
        let gyro_scale = opts.gyro_unit.dps_per_unit();
        let ncols = headers.len();
        let lay = Layout {
            delimiter: opts.delimiter,
            decimal_comma: opts.delimiter != b',',
            ncols,
            has_table: cols.table.is_some(),
            gyro_scale,
            roles: Layout::roles(ncols, cols.time, cols.gyro, cols.temp, cols.table),
        };
        Ok(LogReader {
            src: Source {
                path,
                headers,
                header_line,
                cols,
                lay,
                decimal_comma: opts.delimiter != b',',
                last: None,
                rows: 0,
                crlf,
                mode,
                fast_bytes: 0,
                csv_skip,
                peek: ByteRecord::new(),
            },
            record: ByteRecord::with_capacity(64, ncols),
            from_pending: false,
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
        // The usual case: the next row of the fast path's block, handed straight on.
        if self.warmed_up && self.pending.is_empty() {
            if let Some(row) = self.src.fast_row() {
                self.from_pending = false;
                return self.real(row.sample(self.src.lay.has_table), row.line);
            }
        }
        let Some((s, line)) = self.next_row()? else {
            self.report.rows = self.src.rows;
            return Ok(None);
        };
        self.real(s, line)
    }

    /// Check the step to a real sample (given period, gap, jitter) and hand it out.
    #[inline(always)]
    fn real(&mut self, s: Sample, line: u64) -> Result<Option<Sample>, LogError> {
        // Only the time of the sample before is read here (not a copy of all of it: that
        // stalls on the store that wrote it a moment ago).
        let prev_time = self.prev.as_ref().map(|p| p.time_s);
        if let (Some(prev_time), Some(period)) = (prev_time, self.period_s) {
            let dt = s.time_s - prev_time;
            if !self.report.sample_period_estimated && self.period_checked < PERIOD_CHECK_STEPS {
                self.check_given_period(dt, period, line)?;
            }
            if dt > GAP_FACTOR * period {
                if let Some(p) = self.prev {
                    return self.gap(p, s, line, dt, period);
                }
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
                    "{what}, longer than the --fill-gaps-max-s limit of {max} s; split the log at \
                     this line or raise --fill-gaps-max-s if interpolating {dt} s is acceptable"
                ),
            )),
            GapVerdict::TooManySamples(n) => Err(LogError::new(
                Kind::GapTooLong,
                &self.src.path,
                Some(line),
                Some(t_col),
                format!(
                    "{what}: filling it would take {n} samples, more than the \
                     {MAX_FILL_SAMPLES_PER_GAP} one gap may be filled with, whatever the fill \
                     limit; check the sample period and the time column, or split the log at \
                     this line"
                ),
            )),
            GapVerdict::NotAllowed => Err(LogError::new(
                Kind::Gap,
                &self.src.path,
                Some(line),
                Some(t_col),
                format!(
                    "{what}; split the log at this line, or pass --fill-gaps-max-s MAX_S to \
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
                     --sample-period-s out",
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
            self.from_pending = true;
            return Ok(Some((s, line)));
        }
        self.from_pending = false;
        self.src.read().map_err(|e| *e)
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
            match self.src.read().map_err(|e| *e)? {
                Some((s, line)) => {
                    let rec = self.src.record().clone();
                    self.pending.push_back((rec, s, line));
                }
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
    pub(crate) fn extra_count(&self) -> usize {
        self.src.cols.extra.len()
    }

    /// Whether the log has the table-rate column.
    pub(crate) fn has_table(&self) -> bool {
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
            .map(move |&i| if filled { &b""[..] } else { self.field(i) })
    }

    /// The raw record of the current sample (None for a gap-filled sample).
    pub fn record(&self) -> Option<&ByteRecord> {
        if self.filled {
            None
        } else if self.from_pending {
            Some(&self.record)
        } else {
            Some(self.src.record())
        }
    }

    /// Field `i` of the current real sample's record.
    fn field(&self, i: usize) -> &[u8] {
        if self.from_pending {
            &self.record[i]
        } else {
            self.src.field(i)
        }
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
    pub(crate) fn bytes_per_row(&self) -> Option<f64> {
        let rows = self.src.rows;
        (rows > 0).then(|| self.src.bytes_consumed() as f64 / rows as f64)
    }

    /// Convert the current sample's `k`-th pass-through field to text, with a located error
    /// if it is not UTF-8.
    pub(crate) fn extra_text(&self, k: usize) -> Result<&str, LogError> {
        if self.filled {
            return Ok("");
        }
        let i = self.src.cols.extra[k];
        std::str::from_utf8(self.field(i)).map_err(|_| {
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

#[cfg(test)]
mod tests;

//! Streaming, validating reader: one CSV record in, one checked [`Sample`] out.
//!
//! Rows are read in newline-aligned blocks of plain rows parsed on two threads (the fast
//! path, [`super::chunk`]); at the first line the fast path cannot judge (a quote, a lone
//! CR, an error) the csv crate takes over from that line, so errors keep their exact line,
//! column and text. Either way reading costs no allocation per row; pass-through fields are
//! handed out as raw bytes of the row.
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

/// Where rows come from: the fast path (plain rows in newline-aligned blocks, parsed on two
/// threads, see [`super::chunk`]) until it meets a line it cannot judge, then the CSV path
/// from that line on. Both check numbers, field count and time order.
struct Source<R> {
    path: PathBuf,
    headers: Vec<String>,
    header_line: u64,
    cols: Columns,
    lay: Layout,
    /// Numbers may use a decimal comma (the separator is not a comma).
    decimal_comma: bool,
    /// Time and line of the last row read, for the order checks.
    last: Option<(f64, u64)>,
    rows: u64,
    /// Whether lines end in CRLF (judged by the first line; None: not known yet).
    crlf: Option<bool>,
    mode: Mode<R>,
    /// Bytes of the log consumed by the fast path, and where the CSV path's byte count
    /// starts (for [`LogReader::bytes_per_row`]).
    fast_bytes: u64,
    csv_skip: u64,
    /// Scratch record for looking one row ahead after a short row.
    peek: ByteRecord,
}

/// The input with the bytes already read in front of it.
type Resume<R> = std::io::Chain<std::io::Cursor<Vec<u8>>, R>;

enum Mode<R> {
    Fast(Box<Fast<R>>),
    Csv(Box<CsvPart<R>>),
    /// Only while switching.
    Gone,
}

/// The CSV path: the csv crate over the rest of the input; its line numbers are offset by
/// the lines before the point where it took over.
struct CsvPart<R> {
    csv: csv::Reader<Tail<Resume<R>>>,
    line_offset: u64,
    /// The current record.
    rec: ByteRecord,
}

/// The fast path's block and the rows parsed from it.
struct Fast<R> {
    inner: R,
    /// The block (its length is its capacity; `len` bytes are valid).
    buf: Vec<u8>,
    len: usize,
    /// Offset after the last complete line parsed, and its line number.
    parsed_end: usize,
    line: u64,
    eof: bool,
    /// Rows of the two halves of the block, and the next one to hand out.
    parts: [Vec<Row>; 2],
    part: usize,
    next: usize,
    /// Where the CSV path takes over once the parsed rows are out (offset, line).
    switch_at: Option<(usize, u64)>,
    /// The current row's record, built on demand.
    record: OnceCell<ByteRecord>,
    threads: bool,
}

/// Block size of the fast path.
const BLOCK_BYTES: usize = 2 << 20;

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
        let mut inner = reader;
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
        let gyro_scale = match opts.gyro_unit {
            GyroUnit::Dps => 1.0,
            // 1 °/h = 1/3600 °/s.
            GyroUnit::Dph => 1.0 / 3600.0,
            // 1 rad = 180/π °.
            GyroUnit::RadPerS => 180.0 / std::f64::consts::PI,
        };
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
    pub fn bytes_per_row(&self) -> Option<f64> {
        let rows = self.src.rows;
        (rows > 0).then(|| self.src.bytes_consumed() as f64 / rows as f64)
    }

    /// Convert the current sample's `k`-th pass-through field to text, with a located error
    /// if it is not UTF-8.
    pub fn extra_text(&self, k: usize) -> Result<&str, LogError> {
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

impl<R: Read> Source<R> {
    /// Read and check one data row; it becomes the current record.
    #[inline]
    fn read(&mut self) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        if let Some(row) = self.fast_row() {
            return Ok(Some((row.sample(self.lay.has_table), row.line)));
        }
        if let Mode::Fast(_) = self.mode {
            return self.refill();
        }
        self.read_csv()
    }

    /// The next row already parsed by the fast path, if there is one; it becomes the
    /// current record.
    #[inline(always)]
    fn fast_row(&mut self) -> Option<Row> {
        let Mode::Fast(f) = &mut self.mode else {
            return None;
        };
        let row = *f.parts[f.part].get(f.next)?;
        f.next += 1;
        f.record = OnceCell::new();
        self.last = Some((row.time_s(), row.line));
        self.rows += 1;
        Some(row)
    }

    /// The fast path's rows are all out: go to the second half of the block, parse the
    /// next block, or hand over to the CSV path.
    #[cold]
    fn refill(&mut self) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        loop {
            let Mode::Fast(f) = &mut self.mode else {
                return self.read_csv();
            };
            if f.next < f.parts[f.part].len() {
                return self.read();
            }
            if f.part == 0 && !f.parts[1].is_empty() {
                f.part = 1;
                f.next = 0;
                continue;
            }
            if let Some((at, line)) = f.switch_at {
                self.switch_to_csv(at, line);
                continue;
            }
            // Keep the unparsed tail (a partial line), read more behind it.
            f.buf.copy_within(f.parsed_end..f.len, 0);
            f.len -= f.parsed_end;
            self.fast_bytes += f.parsed_end as u64;
            f.parsed_end = 0;
            f.parts[0].clear();
            f.parts[1].clear();
            f.part = 0;
            f.next = 0;
            let end = memchr::memrchr(b'\n', &f.buf[..f.len]).map_or(0, |k| k + 1);
            if end > 0 {
                f.parse(end, self.last.map(|l| l.0), &self.lay);
                continue;
            }
            if f.eof {
                // An unterminated last line (or nothing): the CSV path judges it.
                let line = f.line;
                self.switch_to_csv(0, line);
                continue;
            }
            if f.len == f.buf.len() {
                let n = f.buf.len();
                if 2 * n > MAX_BLOCK_BYTES {
                    // A line of gigabytes: the CSV path judges it.
                    let line = f.line;
                    self.switch_to_csv(0, line);
                    continue;
                }
                f.buf.resize(2 * n, 0);
            }
            let n = read_retry(&mut f.inner, &mut f.buf[f.len..])
                .map_err(|e| Box::new(io_error(&self.path, e)))?;
            f.eof = n == 0;
            f.len += n;
        }
    }

    /// Hand the input from `at` in the block (line `line`) on to the CSV path.
    #[cold]
    fn switch_to_csv(&mut self, at: usize, line: u64) {
        let Mode::Fast(f) = std::mem::replace(&mut self.mode, Mode::Gone) else {
            unreachable!("switch_to_csv is only called in fast mode")
        };
        let Fast {
            inner,
            mut buf,
            len,
            ..
        } = *f;
        self.fast_bytes += at as u64;
        buf.truncate(len);
        buf.drain(..at);
        let csv = csv_reader(
            std::io::Cursor::new(buf).chain(inner),
            self.crlf,
            self.lay.delimiter,
        );
        self.csv_skip = 0;
        self.mode = Mode::Csv(Box::new(CsvPart {
            csv,
            line_offset: line - 1,
            rec: ByteRecord::with_capacity(64, self.headers.len()),
        }));
    }

    /// Bytes of data rows consumed so far (after the header).
    fn bytes_consumed(&self) -> u64 {
        match &self.mode {
            Mode::Fast(f) => {
                let at = f.parts[f.part]
                    .get(f.next)
                    .map_or(f.parsed_end, |r| r.start as usize);
                self.fast_bytes + at as u64
            }
            Mode::Csv(c) => self.fast_bytes + c.csv.position().byte() - self.csv_skip,
            Mode::Gone => self.fast_bytes,
        }
    }

    /// The current record.
    fn record(&self) -> &ByteRecord {
        match &self.mode {
            Mode::Fast(f) => f.record.get_or_init(|| {
                let text = f.current_text();
                let mut rec = ByteRecord::with_capacity(text.len(), self.lay.ncols);
                for field in text.split(|&b| b == self.lay.delimiter) {
                    rec.push_field(field);
                }
                rec
            }),
            Mode::Csv(c) => &c.rec,
            Mode::Gone => unreachable!("no record while switching"),
        }
    }

    /// Field `i` of the current record.
    fn field(&self, i: usize) -> &[u8] {
        match &self.mode {
            Mode::Fast(f) => chunk::field(f.current_text(), self.lay.delimiter, i),
            Mode::Csv(c) => &c.rec[i],
            Mode::Gone => unreachable!("no record while switching"),
        }
    }

    /// The CSV path: read and check one row into the current record.
    fn read_csv(&mut self) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        let Mode::Csv(c) = &mut self.mode else {
            unreachable!("read_csv is only called in CSV mode")
        };
        let more = c
            .csv
            .read_byte_record(&mut c.rec)
            .map_err(|e| Box::new(csv_error(&self.path, e, c.line_offset)))?;
        if !more {
            return Ok(None);
        }
        let line = record_line(&c.csv, &c.rec) + c.line_offset;
        // Taken out while the checks borrow `self`; put back below (after an error the
        // reader's state does not matter).
        let taken = std::mem::take(&mut c.rec);
        let rec = &taken;
        if rec.len() != self.headers.len() {
            let found = rec.len();
            return Err(Box::new(self.field_count_error(found, line)));
        }
        let time_s = self.number(rec, self.cols.time, line)?;
        let gyro_dps = self.number(rec, self.cols.gyro, line)? * self.lay.gyro_scale;
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
        if let Mode::Csv(c) = &mut self.mode {
            c.rec = taken;
        }
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
        let is_last = found < want
            && match &mut self.mode {
                Mode::Csv(c) => matches!(c.csv.read_byte_record(&mut self.peek), Ok(false)),
                _ => false,
            };
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

fn csv_error(path: &Path, e: csv::Error, line_offset: u64) -> LogError {
    let line = e.position().map(|p| p.line() + line_offset);
    if let csv::ErrorKind::Io(io) = e.kind() {
        LogError::new(Kind::Io, path, line, None, format!("cannot read: {io}"))
    } else {
        LogError::new(Kind::Csv, path, line, None, format!("malformed CSV: {e}"))
    }
}

impl<R: Read> Fast<R> {
    /// Parse the complete lines `buf[..end]` (`end` just after a newline), in two parts
    /// on two threads when the block is long; `prev_time` is the time of the row before.
    fn parse(&mut self, end: usize, prev_time: Option<f64>, lay: &Layout) {
        let buf = &self.buf[..end];
        let split = if self.threads && end >= PARALLEL_MIN_BYTES {
            // Halves: the other thread runs only while this one parses its half (reading
            // and handing rows out happen between blocks, on this thread alone), so equal
            // halves finish together. (Shifting work to the other thread to cover this
            // thread's reading measured slower: that work does not overlap.)
            let mid = end / 2;
            memchr::memchr(b'\n', &buf[mid..end]).map_or(end, |k| mid + k + 1)
        } else {
            end
        };
        let [rows_a, rows_b] = &mut self.parts;
        let (a, b) = if split < end {
            let (a, b) = std::thread::scope(|s| {
                let hb = s.spawn(|| parse_lines(buf, split, end, 0, None, lay, rows_b));
                let a = parse_lines(buf, 0, split, self.line, prev_time, lay, rows_a);
                (
                    a,
                    hb.join().unwrap_or_else(|p| std::panic::resume_unwind(p)),
                )
            });
            (a, Some(b))
        } else {
            (
                parse_lines(buf, 0, end, self.line, prev_time, lay, rows_a),
                None,
            )
        };
        if a.stopped {
            rows_b.clear();
            self.switch_at = Some((a.stop, a.stop_line));
            self.parsed_end = a.stop;
            return;
        }
        let Some(b) = b else {
            self.parsed_end = end;
            self.line = a.stop_line;
            return;
        };
        // The second half counted lines from 0: shift them, and check the order across
        // the split (the first half's last row, or the row before the block).
        let base = a.stop_line;
        for r in rows_b.iter_mut() {
            r.line += base;
        }
        let before = rows_a.last().map(Row::time_s).or(prev_time);
        if let (Some(t0), Some(first)) = (before, rows_b.first()) {
            if first.time_s() <= t0 {
                self.switch_at = Some((first.start as usize, first.line));
                self.parsed_end = first.start as usize;
                rows_b.clear();
                return;
            }
        }
        if b.stopped {
            self.switch_at = Some((b.stop, b.stop_line + base));
            self.parsed_end = b.stop;
            return;
        }
        self.parsed_end = end;
        self.line = b.stop_line + base;
    }

    /// Text of the current row (the last one handed out).
    fn current_text(&self) -> &[u8] {
        match self.next.checked_sub(1) {
            Some(k) => {
                let r = &self.parts[self.part][k];
                &self.buf[r.start as usize..r.end as usize]
            }
            // Before the first row.
            None => b"",
        }
    }
}

/// What the start of the input says about the header line.
enum HeaderScan {
    /// The header line ends just before this offset (after its newline).
    Found(usize),
    /// Not all of it read yet.
    NeedMore,
    /// Something only the CSV path judges (quote, lone CR).
    Hard,
}

/// Skip comment and blank lines to the header line, as the CSV path does.
fn find_header(bytes: &[u8]) -> HeaderScan {
    // A byte-order mark is skipped, as the csv crate does when it reads the header from the
    // block (which holds the mark and at least the newline after it).
    let mut pos = if bytes.starts_with(b"\xEF\xBB\xBF") {
        3
    } else {
        0
    };
    while let Some(k) = memchr::memchr(b'\n', &bytes[pos..]) {
        let nl = pos + k;
        let mut text = &bytes[pos..nl];
        if let [rest @ .., b'\r'] = text {
            text = rest;
        }
        match text.first() {
            None | Some(b'#') => {}
            Some(_) => {
                return if text.iter().any(|&b| b == b'"' || b == b'\r') {
                    HeaderScan::Hard
                } else {
                    HeaderScan::Found(nl + 1)
                };
            }
        }
        pos = nl + 1;
    }
    HeaderScan::NeedMore
}

/// `read`, retried on `Interrupted`.
fn read_retry<R: Read>(r: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    loop {
        match r.read(buf) {
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            other => return other,
        }
    }
}

fn io_error(path: &Path, e: std::io::Error) -> LogError {
    LogError::new(Kind::Io, path, None, None, format!("cannot read: {e}"))
}

/// The csv crate set up as the CSV path reads: no header handling, any field count, `#`
/// comments.
fn csv_reader<S: Read>(input: S, crlf: Option<bool>, delimiter: u8) -> csv::Reader<Tail<S>> {
    csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .buffer_capacity(64 * 1024)
        .from_reader(Tail {
            inner: input,
            total: 0,
            last: b'\n',
            crlf: crlf.unwrap_or(false),
            crlf_known: crlf.is_some(),
        })
}

/// Read the header record and its line.
fn read_header<S: Read>(
    csv: &mut csv::Reader<Tail<S>>,
    path: &Path,
) -> Result<(ByteRecord, u64), LogError> {
    let mut header = ByteRecord::new();
    let got = csv
        .read_byte_record(&mut header)
        .map_err(|e| csv_error(path, e, 0))?;
    if !got {
        return Err(LogError::new(
            Kind::NoHeader,
            path,
            None,
            None,
            "empty file: no header row; the first line that is not a '#' comment must name \
             the columns, e.g. time_s,gyro_dps,temp_c",
        ));
    }
    let line = record_line(csv, &header);
    Ok((header, line))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// One sample as handed out: the bits of time, gyro, temperature, table rate; line;
    /// whether filled; the raw record.
    type Out = (u64, u64, u64, Option<u64>, u64, bool, Vec<Vec<u8>>);

    /// The report at the end: rows, period bits, filled samples and gaps, jitter bits and
    /// line.
    type End = (u64, Option<u64>, usize, usize, u64, Option<u64>);

    /// Everything a reader hands out, and how it ends.
    #[derive(Debug, PartialEq)]
    struct Run {
        samples: Vec<Out>,
        end: Result<End, String>,
    }

    fn run<R: Read>(input: R, opts: &ReadOptions, fast: bool) -> Run {
        let mut samples = Vec::new();
        let mut rdr = match LogReader::with_path(input, "<t>".into(), opts, fast) {
            Ok(r) => r,
            Err(e) => {
                return Run {
                    samples,
                    end: Err(e.to_string()),
                }
            }
        };
        let end = loop {
            match rdr.next_sample() {
                Ok(Some(s)) => samples.push((
                    s.time_s.to_bits(),
                    s.gyro_dps.to_bits(),
                    s.temp_c.to_bits(),
                    s.table_dps.map(f64::to_bits),
                    rdr.line(),
                    rdr.is_filled(),
                    rdr.record()
                        .map(|r| r.iter().map(<[u8]>::to_vec).collect())
                        .unwrap_or_default(),
                )),
                Ok(None) => {
                    let r = rdr.report();
                    break Ok((
                        r.rows,
                        r.sample_period_s.map(f64::to_bits),
                        r.filled_samples,
                        r.filled_gaps,
                        r.max_step_jitter.to_bits(),
                        r.max_jitter_line,
                    ));
                }
                Err(e) => break Err(e.to_string()),
            }
        };
        Run { samples, end }
    }

    /// A reader that hands out at most `step` bytes per call (block edges everywhere).
    struct Dribble<'a> {
        data: &'a [u8],
        step: usize,
    }

    impl Read for Dribble<'_> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.step.min(buf.len()).min(self.data.len());
            buf[..n].copy_from_slice(&self.data[..n]);
            self.data = &self.data[n..];
            Ok(n)
        }
    }

    /// Whether the last record of `text` runs inside an open quote to the end of the input
    /// (csv-core's quoting: a quote opens only at a field's start, `""` inside is a quote,
    /// `#` at a record's start is a comment line). There the CSV path's line number is
    /// approximate (`record_line` cannot tell the file's last newline, inside the quote,
    /// from a terminator); from a later starting point, as after the fast path hands over,
    /// it comes out right. The comparisons close such a quote first.
    fn ends_in_open_quote(text: &[u8], d: u8) -> bool {
        let (mut i, mut record_start, mut field_start, mut quoted) = (0, true, true, false);
        while i < text.len() {
            let b = text[i];
            i += 1;
            if quoted {
                if b == b'"' {
                    if text.get(i) == Some(&b'"') {
                        i += 1;
                    } else {
                        quoted = false;
                    }
                }
            } else if record_start && b == b'#' {
                i = memchr::memchr(b'\n', &text[i..]).map_or(text.len(), |k| i + k + 1);
            } else if b == b'\n' || b == b'\r' {
                (record_start, field_start) = (true, true);
            } else {
                record_start = false;
                quoted = field_start && b == b'"';
                field_start = b == d;
            }
        }
        quoted
    }

    /// The fast path (whole input, and in small pieces) gives what the CSV path gives.
    fn same_as_csv(text: &[u8], opts: &ReadOptions) {
        let want = run(text, opts, false);
        assert_eq!(
            run(text, opts, true),
            want,
            "fast path, {:?}",
            String::from_utf8_lossy(text)
        );
        for step in [1, 7] {
            let got = run(Dribble { data: text, step }, opts, true);
            assert_eq!(
                got,
                want,
                "fast path in {step}-byte reads, {:?}",
                String::from_utf8_lossy(text)
            );
        }
    }

    fn log(rows: usize, table: bool) -> String {
        let mut s = String::from("# bench\ntime_s,gyro_dps,temp_c");
        s += if table { ",table_dps,id\n" } else { ",id\n" };
        for i in 0..rows {
            let gyro = 0.0012 + 1e-7 * ((i * 7919) % 1000) as f64;
            s += &format!(
                "{:.3},{gyro:.13},{}",
                i as f64 * 0.01,
                20.0 + (i % 16) as f64 * 0.0625
            );
            if table {
                s += ",20";
            }
            s += &format!(",r{i}\n");
        }
        s
    }

    #[test]
    fn fast_path_matches_csv_path_on_edge_cases() {
        let opts = ReadOptions::default();
        let gaps = ReadOptions {
            fill_gaps_max_s: Some(10.0),
            ..ReadOptions::default()
        };
        for text in [
            "time_s,gyro_dps,temp_c\n0,1,2\n1,1,2\n",
            "time_s,gyro_dps,temp_c\r\n0,1,2\r\n\r\n# c\r\n1,1,2\r\n2,1,2",
            "time_s,gyro_dps,temp_c\n0,1,2\n1,1\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n1,1,2,3\n2,1,2\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n\"1\",1,2\n2,\"1\n\",2\n3,x,2\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n1\r,1,2\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n0,1,2\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n 1 , 1e0 ,2\n2,nan,2\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n1,1,2\n5,1,2\n6,1,2\n",
            "\u{feff}time_s,gyro_dps,temp_c\n0,1,2\n",
            "\u{feff}# c\ntime_s,gyro_dps,temp_c\n0,1,2\n1,1,2\n",
            "\u{feff}\r\n\r\ntime_s,gyro_dps,temp_c\r\n0,1,2\r\n",
            "time_s,gyro_dps,temp_c\n0,1.5,2\n1,-.5,2.\n2,+1.25,2\n3,1.2.3,2\n",
            "time_s,gyro_dps,temp_c\n0,1,2\n1.25,1,2\n2,1,2\n3,1,2\n3.5,1,2\n",
            "# only\n",
            "time_s,gyro_dps,temp_c\n",
            "time_s,gyro_dps,temp_c\n#0,1,2\n 1,1,2\n",
        ] {
            same_as_csv(text.as_bytes(), &opts);
            same_as_csv(text.as_bytes(), &gaps);
            same_in_every_layout(text);
        }
    }

    /// `text` (written with commas and decimal points) read with `;` and tab separators,
    /// with decimal points and with decimal commas, and with a given sample period: the
    /// fast path gives what the CSV path gives; and with the gyro in °/h.
    fn same_in_every_layout(text: &str) {
        let semicolon = ReadOptions {
            delimiter: b';',
            ..ReadOptions::default()
        };
        let tab = ReadOptions {
            delimiter: b'\t',
            ..ReadOptions::default()
        };
        let given = ReadOptions {
            sample_period_s: Some(1.0),
            fill_gaps_max_s: Some(10.0),
            ..ReadOptions::default()
        };
        same_as_csv(text.replace(',', ";").as_bytes(), &semicolon);
        same_as_csv(
            text.replace(',', ";").replace('.', ",").as_bytes(),
            &semicolon,
        );
        same_as_csv(text.replace(',', "\t").replace('.', ",").as_bytes(), &tab);
        same_as_csv(text.as_bytes(), &given);
        let dph = ReadOptions {
            gyro_unit: GyroUnit::Dph,
            ..ReadOptions::default()
        };
        same_as_csv(text.as_bytes(), &dph);
    }

    #[test]
    fn fast_path_matches_csv_path_across_the_parallel_split() {
        let opts = ReadOptions::default();
        let text = log(20_000, true);
        assert!(text.len() > PARALLEL_MIN_BYTES, "the log must be split");
        let want = run(text.as_bytes(), &opts, false);
        assert_eq!(want.samples.len(), 20_000);
        assert_eq!(run(text.as_bytes(), &opts, true), want);
        // An error in each half, near the split, and an order break across it.
        let lines: Vec<&str> = text.lines().collect();
        for (at, bad) in [
            (3_000, "x"),
            (10_000, "1,2"),
            (10_003, "\"5\",1,2,3,4"),
            (15_000, "1e9,1,2,3,4"),
            (19_999, "1,1,1,1,1"),
        ] {
            let mut l = lines.clone();
            l[at] = bad;
            let t = l.join("\n") + "\n";
            let want = run(t.as_bytes(), &opts, false);
            assert_eq!(run(t.as_bytes(), &opts, true), want, "bad line {at}");
        }
        for k in 9_990..10_010 {
            let mut l = lines.clone();
            l.swap(k, k + 1);
            let t = l.join("\n") + "\n";
            assert_eq!(
                run(t.as_bytes(), &opts, true),
                run(t.as_bytes(), &opts, false)
            );
        }
    }

    proptest! {
        // No lone CR here: the CSV path's line numbers are approximate in a file that mixes
        // line endings (see `Tail`), the fast path's count newlines.
        #[test]
        fn fast_path_matches_csv_path_on_any_input(
            body in prop::collection::vec(
                prop::sample::select(b"0123456789.,-e#\n\" ".to_vec()), 0..200),
        ) {
            let mut text = b"time_s,gyro_dps,temp_c\n".to_vec();
            text.extend(body);
            if ends_in_open_quote(&text, b',') {
                text.push(b'"');
            }
            same_as_csv(&text, &ReadOptions::default());
        }

        #[test]
        fn fast_path_matches_csv_path_on_any_input_with_decimal_commas(
            body in prop::collection::vec(
                prop::sample::select(b"0123456789.,;-+e#\n\" ".to_vec()), 0..200),
        ) {
            let mut text = b"time_s;gyro_dps;temp_c\n".to_vec();
            text.extend(body);
            if ends_in_open_quote(&text, b';') {
                text.push(b'"');
            }
            let opts = ReadOptions { delimiter: b';', ..ReadOptions::default() };
            same_as_csv(&text, &opts);
        }

        #[test]
        fn fast_path_matches_csv_path_on_logs_with_a_fault(
            at in 0usize..60,
            fault in prop::sample::select(vec!["", "x", ",", "\r", "\"", "#", "\n", "1e999", "-"]),
        ) {
            let mut text = log(60, false).into_bytes();
            let pos = (at * text.len() / 60).min(text.len());
            text.splice(pos..pos, fault.bytes());
            same_as_csv(&text, &ReadOptions::default());
        }
    }
}

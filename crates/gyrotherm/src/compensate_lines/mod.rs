//! Compensate a CSV log line by line, with a status per line: what `gyrotherm compensate`
//! and `compensate --stream` run.
//!
//! One output line per input data line (comment lines starting with `#` and blank lines are
//! not data lines and are dropped): every input field as it was, then `bias_dps`, `scale`,
//! `gyro_comp_dps` (°/s), `status` (`ok`, `held`, `degraded`, `invalid`; see
//! [`gyrotherm_core::compensator`]), `coverage` (`inside`, `edge`, `outside`) and `sigma_dph`
//! (the verdict of the latest step's T and dT against the model's coverage map, see
//! [`crate::coverage`]; both empty before the first step, on a malformed line, and when the
//! model file has no map). The flight [`Compensator`](gyrotherm_core::Compensator)
//! runs sample by sample, so the numbers are those of flight code.
//!
//! Temperature faults never stop the run: an empty, non-numeric, NaN or implausible temperature
//! is handed to the compensator as a fault and the line is `held` (or `degraded`). A gyro field
//! that is NaN or infinite gives `invalid` with an empty `gyro_comp_dps`. Malformed lines
//! (wrong field count, a time or gyro field that is not a number, a time that is not finite or
//! does not increase) depend on the [`Mode`]: [`Mode::Strict`] (batch files) stops with an
//! error naming the file, line and column; [`Mode::Stream`] writes the line as `invalid` (its
//! fields, or empty fields when their count is wrong, and empty outputs) and reads the next
//! line, except a time that is a number but NaN, infinite or out of order, which goes to the
//! compensator's time axis (`held` or `degraded`, see [`gyrotherm_core::compensator`]). Time
//! gaps are bridged by the compensator (no gap filling, no period estimate: the first output
//! line follows the first input line at once). Quoted fields may hold the separator and quotes
//! but not line breaks. The separator is
//! [`ReadOptions::delimiter`](crate::csvlog::ReadOptions::delimiter); with `;` or tab, numbers
//! may use a decimal comma, and the output uses the same separator (numbers with a decimal
//! point, which the reader accepts beside the comma). A line longer than [`MAX_LINE_BYTES`] is
//! malformed (its bytes are skipped, not kept).
//!
//! An inertial unit's model runs the same line loop (`run_lines`) in [`unit`](mod@unit), with the
//! columns of each of its axes.

use std::io::{BufRead, Write};
use std::path::Path;

use gyrotherm_core::compensator::{Corrected, Status};

use crate::csvlog::{
    parse_number, read_line_capped, record, Fields, LineRead, LogError, LogErrorKind, LogReader,
    LogWriter, ReadOptions,
};
use crate::model::ModelFile;

/// Longest line read, bytes (line break included): the log reader's cap. A longer line is
/// malformed: in [`Mode::Stream`] it gives one `invalid` output line and its bytes are skipped
/// without being kept, so one endless line cannot take the memory of a flight computer.
pub use crate::csvlog::MAX_LINE_BYTES;

pub mod unit;

/// Columns appended to every row, in order.
pub(crate) const OUTPUT_COLUMNS: [&str; 6] = [
    "bias_dps",
    "scale",
    "gyro_comp_dps",
    "status",
    "coverage",
    "sigma_dph",
];

/// What to do with a malformed line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Stop with an error (batch files: the file is to be fixed).
    Strict,
    /// Write it as `invalid` and go on (a live feed must never stop).
    Stream,
}

/// Counts of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinesSummary {
    /// Data lines written (= data lines read).
    pub rows: u64,
    /// Lines per status: ok, held, degraded, invalid (malformed lines included).
    pub ok: u64,
    pub held: u64,
    pub degraded: u64,
    pub invalid: u64,
    /// Malformed lines written as invalid ([`Mode::Stream`] only).
    pub malformed: u64,
    /// Extrapolation warnings (temperature or its rate outside the training range).
    pub warnings: Vec<String>,
    /// Lines per coverage verdict: inside, edge, outside (all 0 without a coverage map).
    pub coverage: [u64; 3],
}

impl LinesSummary {
    fn count(&mut self, s: Status) {
        match s {
            Status::Ok => self.ok += 1,
            Status::Held => self.held += 1,
            Status::Degraded => self.degraded += 1,
            Status::Invalid => self.invalid += 1,
            // Only an axis with further sensors and a fallback gives it, never one model on
            // one sensor: counted as ok would hide it, so it is counted with held.
            Status::Fallback => self.held += 1,
        }
    }

    /// `N lines: ok a, held b, degraded c, invalid d (m malformed)`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "{} lines: ok {}, held {}, degraded {}, invalid {}",
            self.rows, self.ok, self.held, self.degraded, self.invalid
        );
        if self.malformed > 0 {
            s.push_str(&format!(" ({} malformed)", self.malformed));
        }
        if self.coverage.iter().any(|c| *c > 0) {
            let [i, e, o] = self.coverage;
            s.push_str(&format!("; coverage: inside {i}, edge {e}, outside {o}"));
        }
        s
    }
}

/// Why a run stopped.
#[derive(Debug)]
#[non_exhaustive]
pub enum LinesError {
    /// The model cannot be turned into a compensator.
    Model(crate::compensate::CompensateError),
    /// An inertial-unit model cannot be turned into the flight unit, or the log lacks one of
    /// its columns.
    Unit(crate::model::unit::ImuError),
    /// The input (header, or a malformed line in [`Mode::Strict`]): file, line, column, fix.
    Log(LogError),
    /// Reading the input or writing the output failed.
    Io(std::io::Error),
}

impl std::fmt::Display for LinesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinesError::Model(_) => f.write_str("model"),
            LinesError::Unit(e) => write!(f, "inertial-unit model: {e}"),
            LinesError::Log(e) => write!(f, "{e}"),
            LinesError::Io(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for LinesError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Log and I/O errors are transparent: their message is their own.
            LinesError::Io(e) => e.source(),
            LinesError::Log(e) => e.source(),
            LinesError::Model(e) => Some(e),
            LinesError::Unit(e) => e.source(),
        }
    }
}

impl From<std::io::Error> for LinesError {
    fn from(e: std::io::Error) -> Self {
        LinesError::Io(e)
    }
}

/// Compensate the log `input` into the CSV file `out` ([`Mode::Strict`]), written to a
/// temporary file and renamed into place: what `gyrotherm compensate --input --out` does.
pub fn compensate_file(
    model: &ModelFile,
    input: &Path,
    out: &Path,
    opts: &ReadOptions,
) -> Result<LinesSummary, FileError> {
    lines_to_file(input, out, opts, |r, w, opts| {
        compensate_lines(model, r, input, opts, w, Mode::Strict, false)
    })
}

/// Run `lines` from the file `input` into the CSV file `out`, written to a temporary file
/// and renamed into place (the batch form of a stream). A log whose format holds a unit (an
/// autopilot's) is read first and handed to `lines` as the CSV of its unit, with the read
/// options of that CSV.
pub(crate) fn lines_to_file<S>(
    input: &Path,
    out: &Path,
    opts: &ReadOptions,
    lines: impl FnOnce(
        &mut dyn std::io::BufRead,
        &mut std::io::BufWriter<std::fs::File>,
        &ReadOptions,
    ) -> Result<S, LinesError>,
) -> Result<S, FileError> {
    let (mut source, opts): (Box<dyn std::io::BufRead>, ReadOptions) =
        if opts.format_of(input).holds_unit() {
            let (log, _) = crate::csvlog::read_imu_log(input, opts, None)
                .map_err(|e| FileError::Lines(LinesError::Log(e)))?;
            let mut text = Vec::new();
            crate::csvlog::write_imu_csv(&mut text, &log).map_err(|source| FileError::Open {
                path: input.to_path_buf(),
                source,
            })?;
            let csv = ReadOptions {
                format: Some(crate::csvlog::LogFormat::Csv),
                ..ReadOptions::default()
            };
            (
                Box::new(std::io::Cursor::new(text)),
                ReadOptions {
                    gyro_col: opts.gyro_col.clone(),
                    temp_col: opts.temp_col.clone(),
                    ..csv
                },
            )
        } else {
            let file = std::fs::File::open(input).map_err(|source| FileError::Open {
                path: input.to_path_buf(),
                source,
            })?;
            (Box::new(std::io::BufReader::new(file)), opts.clone())
        };
    crate::atomic_file::write_atomically(out, |w: &mut std::io::BufWriter<std::fs::File>| {
        let s = lines(&mut source, w, &opts)?;
        w.flush()?;
        Ok::<_, LinesError>(s)
    })
    .map_err(|e| match e {
        LinesError::Io(source) => FileError::Write {
            path: out.to_path_buf(),
            source,
        },
        other => FileError::Lines(other),
    })
}

/// Why [`compensate_file`] failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum FileError {
    /// The input log could not be opened.
    Open {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    /// Reading the input or writing the output failed; the output was not replaced.
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    /// The model or the log: see [`LinesError`].
    Lines(LinesError),
}

impl std::fmt::Display for FileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FileError::Open { path, .. } => write!(f, "cannot open {}", path.display()),
            FileError::Write { path, .. } => {
                write!(f, "cannot compensate into {}", path.display())
            }
            FileError::Lines(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for FileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            FileError::Open { source, .. } | FileError::Write { source, .. } => Some(source),
            // Transparent: the message is the lines' own.
            FileError::Lines(e) => e.source(),
        }
    }
}

/// What [`split_and_time`] checks a line against.
pub(crate) struct LineCheck<'a> {
    pub source: &'a Path,
    pub headers: &'a [String],
    pub delimiter: u8,
    /// The time column's index.
    pub time_index: usize,
    pub mode: Mode,
}

/// The checks every stream makes before its own columns: split `line` into `fields` (as many
/// as the header has) and read its time, finite and (in strict mode) after `last_time`'s; a
/// live feed (stream mode) hands a NaN or infinite time on, and the compensator's time axis
/// gives it a status.
pub(crate) fn split_and_time(
    fields: &mut Fields,
    line: &[u8],
    c: &LineCheck<'_>,
    line_no: u64,
    last_time: Option<(f64, u64)>,
) -> Result<f64, LinesError> {
    let (headers, delimiter, ti, mode) = (c.headers, c.delimiter, c.time_index, c.mode);
    let decimal_comma = delimiter != b',';
    let err = |kind, line, column: Option<&str>, message: String| {
        LinesError::Log(LogError::new(kind, c.source, Some(line), column, message))
    };
    if !fields.split(line, delimiter) || fields.len() != headers.len() {
        return Err(err(
            LogErrorKind::FieldCount,
            line_no,
            None,
            format!(
                "{} fields, but the header has {}; fix the line (a missing or extra \
                 {}) or comment it out with '#'",
                fields.len(),
                headers.len(),
                match delimiter {
                    b'\t' => "tab".to_string(),
                    d => format!("'{}'", char::from(d)),
                }
            ),
        ));
    }
    let time_s = match parse_number(fields.get(line, ti), decimal_comma) {
        Some(t) if t.is_finite() => t,
        Some(t) if mode == Mode::Stream => t,
        _ => {
            return Err(err(
                LogErrorKind::NotANumber,
                line_no,
                Some(&headers[ti]),
                format!(
                    "{:?} is not a finite time; fix the value or comment the line out \
                     with '#'",
                    String::from_utf8_lossy(fields.get(line, ti))
                ),
            ))
        }
    };
    if let (Some((t0, line0)), Mode::Strict) = (last_time, mode) {
        if time_s <= t0 {
            return Err(err(
                LogErrorKind::TimeNotIncreasing,
                line_no,
                Some(&headers[ti]),
                format!(
                    "time is not strictly increasing: {time_s} s comes after {t0} s \
                     (line {line0}); sort the log by time or remove the row"
                ),
            ));
        }
    }
    Ok(time_s)
}

/// A line over [`MAX_LINE_BYTES`] at `line` of `source`.
pub(crate) fn too_long_error(source: &Path, line: u64) -> LinesError {
    LinesError::Log(LogError::new(
        LogErrorKind::LineTooLong,
        source,
        Some(line),
        None,
        format!(
            "line longer than {MAX_LINE_BYTES} bytes; a log line holds a few numbers: check \
             that this is a log with one record per line"
        ),
    ))
}

/// The header: everything up to the first line that is neither blank nor a comment (and its
/// continuation lines, when a quoted name holds a line break), parsed and checked
/// by the log reader with `opts` (column mapping and its messages). Returns the column names
/// and the number of lines read.
pub(crate) fn read_header<R: BufRead>(
    input: &mut R,
    source: &Path,
    opts: &ReadOptions,
) -> Result<(Vec<String>, u64), LinesError> {
    let mut head = Vec::new();
    let mut line_no = 0u64;
    let mut buf = Vec::new();
    // Where the header line starts in `head`, once found: a quoted name may hold a line
    // break, so the header ends at the first line break outside quotes, as the log reader
    // (which parses it below) sees it.
    let mut header_start: Option<usize> = None;
    let mut fields = Fields::default();
    loop {
        match read_line_capped(input, &mut buf, MAX_LINE_BYTES)? {
            LineRead::Eof => break,
            LineRead::TooLong => return Err(too_long_error(source, line_no + 1)),
            LineRead::Line => {}
        }
        line_no += 1;
        if head.len() + buf.len() > MAX_LINE_BYTES {
            // Comments before the header count too: they are kept for the header check.
            return Err(too_long_error(source, line_no));
        }
        let start = header_start.unwrap_or(head.len());
        head.extend_from_slice(&buf);
        let t = buf.trim_ascii();
        if header_start.is_none() && (t.is_empty() || t.starts_with(b"#")) {
            continue;
        }
        header_start = Some(start);
        let header = &head[start..];
        let header = header.strip_suffix(b"\n").unwrap_or(header);
        let header = header.strip_suffix(b"\r").unwrap_or(header);
        if fields.split(header, opts.delimiter) {
            break;
        }
    }
    let r = LogReader::new(&head[..], source, opts).map_err(LinesError::Log)?;
    Ok((r.headers().to_vec(), line_no))
}

/// Steps a file's cadence is judged on: the median of the first ones, so that a gap or two
/// (which the compensator bridges) does not count.
const CADENCE_STEPS: usize = 10;

/// The time steps of a run, against the longest sample period the compensator runs at
/// ([`crate::features::max_sample_period_s`], and at most its `degraded_after_s`): a log
/// sampled more sparsely is held or degraded on almost every line, which would read as
/// temperature faults.
#[derive(Debug)]
pub(crate) struct Cadence {
    max_s: f64,
    rate_lag_s: f64,
    first: Vec<f64>,
    judged: bool,
    steps: u64,
    slow: u64,
}

impl Cadence {
    pub(crate) fn new(spec: &gyrotherm_core::features::FeatureSpec, degraded_after_s: f64) -> Self {
        Cadence {
            max_s: crate::features::max_sample_period_s(spec).min(degraded_after_s),
            rate_lag_s: spec.rate_lag_s,
            first: Vec::with_capacity(CADENCE_STEPS),
            judged: false,
            steps: 0,
            slow: 0,
        }
    }

    /// A step of `dt` s between two lines; in [`Mode::Strict`], the error once the first
    /// steps show the log is sampled too sparsely.
    pub(crate) fn step(
        &mut self,
        dt: f64,
        mode: Mode,
        source: &Path,
        line: u64,
    ) -> Result<(), LinesError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Ok(());
        }
        self.steps += 1;
        self.slow += u64::from(dt > self.max_s);
        if self.first.len() < CADENCE_STEPS {
            self.first.push(dt);
            if self.first.len() == CADENCE_STEPS && mode == Mode::Strict {
                return self.judge(source, line);
            }
        }
        Ok(())
    }

    /// At the end of a file: the judgement, if fewer than [`CADENCE_STEPS`] steps came.
    pub(crate) fn finish(
        &mut self,
        mode: Mode,
        source: &Path,
        line: u64,
    ) -> Result<(), LinesError> {
        if mode == Mode::Strict && !self.first.is_empty() {
            return self.judge(source, line);
        }
        Ok(())
    }

    fn judge(&mut self, source: &Path, line: u64) -> Result<(), LinesError> {
        if std::mem::replace(&mut self.judged, true) {
            return Ok(());
        }
        let mid = self.first.len() / 2;
        let period = *self.first.select_nth_unstable_by(mid, f64::total_cmp).1;
        if period <= self.max_s {
            return Ok(());
        }
        Err(LinesError::Log(LogError::new(
            LogErrorKind::SampledTooSparsely,
            source,
            Some(line),
            None,
            format!(
                "one sample every {period} s ({} Hz, median of the first steps); the model \
                 steps every second and reads dT over {} s, so it needs at least one sample \
                 every {} s ({} Hz); every line would be held or degraded: log faster, or \
                 resample",
                1.0 / period,
                self.rate_lag_s,
                self.max_s,
                1.0 / self.max_s
            ),
        )))
    }

    /// The warning for a stream with steps longer than the compensator runs at.
    pub(crate) fn warning(&self) -> Option<String> {
        (self.slow > 0).then(|| {
            format!(
                "{} of {} time steps are longer than {} s, more sparsely than the model runs \
                 (it reads dT over {} s): the lines after them are held or degraded for that, \
                 not for a temperature fault",
                self.slow, self.steps, self.max_s, self.rate_lag_s
            )
        })
    }
}

/// The part of the line loop that belongs to the model: a single gyro's compensator, or a
/// unit's axes. [`run_lines`] does the rest, alike for both.
pub(crate) trait LineModel {
    /// Read the model's gyro and temperature fields of a line already split (its time read);
    /// an error makes the line malformed.
    fn parse(
        &mut self,
        fields: &Fields,
        line: &[u8],
        check: &LineCheck<'_>,
        line_no: u64,
    ) -> Result<(), LinesError>;
    /// Step at `time_s` with what [`LineModel::parse`] read, and write the columns it adds.
    fn step<W: Write>(&mut self, time_s: f64, writer: &mut LogWriter<W>);
    /// Write the columns it adds to a line with no usable output (all `invalid`).
    fn malformed<W: Write>(&mut self, writer: &mut LogWriter<W>);
}

/// Lines read after the header.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LineCounts {
    /// Data lines written (= data lines read).
    pub rows: u64,
    /// Lines written as malformed ([`Mode::Stream`] only).
    pub malformed: u64,
}

/// The data lines after the header (ending at line `line_no`) into `output`, whose header is
/// the input's and the model's `added` columns (refused when the input has one of them
/// already): each line split and its time read ([`split_and_time`]), the model's fields
/// parsed and stepped, and written with every input field as it was, then the model's columns; a malformed line stops a [`Mode::Strict`] run
/// and is written as `invalid` in a [`Mode::Stream`] one. `cadence` judges the time steps;
/// its warning is the caller's to take.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_lines<'a, R: BufRead, W: Write, M: LineModel>(
    input: &mut R,
    output: W,
    flush_each_row: bool,
    check: &LineCheck<'a>,
    added: impl IntoIterator<Item = &'a str> + Clone,
    mut line_no: u64,
    cadence: &mut Cadence,
    model: &mut M,
) -> Result<LineCounts, LinesError> {
    let (source, mode, n_fields) = (check.source, check.mode, check.headers.len());
    check_added_columns(check.headers, added.clone(), source, line_no)?;
    let mut writer = LogWriter::with_delimiter(
        output,
        check.headers.iter().map(String::as_str).chain(added),
        check.delimiter,
    )?;
    writer.set_flush_each_row(flush_each_row);
    let writer = &mut writer;
    let mut counts = LineCounts::default();
    let mut fields = Fields::default();
    let mut buf = Vec::new();
    let mut last_time: Option<(f64, u64)> = None;
    loop {
        let read = read_line_capped(input, &mut buf, MAX_LINE_BYTES)?;
        if read == LineRead::Eof {
            break;
        }
        line_no += 1;
        let line = match read {
            LineRead::TooLong if mode == Mode::Strict => {
                return Err(too_long_error(source, line_no))
            }
            LineRead::TooLong => None,
            _ => match record(&buf) {
                Some(line) => Some(line),
                None => continue,
            },
        };
        counts.rows += 1;
        let parsed = line.map(|line| {
            split_and_time(&mut fields, line, check, line_no, last_time)
                .and_then(|t| model.parse(&fields, line, check, line_no).map(|()| t))
        });
        match parsed {
            Some(Ok(time_s)) => {
                if let Some((t0, _)) = last_time {
                    cadence.step(time_s - t0, mode, source, line_no)?;
                }
                last_time = Some((time_s, line_no));
                let line = line.unwrap_or_default();
                for k in 0..fields.len() {
                    writer.push_raw(fields.get(line, k));
                }
                model.step(time_s, writer);
            }
            Some(Err(e)) if mode == Mode::Strict => return Err(e),
            // A line too long keeps none of its fields; one that does not split into the
            // header's fields keeps them empty.
            _ => {
                let keep = line.filter(|_| fields.len() == n_fields);
                for k in 0..n_fields {
                    writer.push_raw(keep.map_or(&[][..], |line| fields.get(line, k)));
                }
                model.malformed(writer);
                counts.malformed += 1;
            }
        }
        writer.end_row()?;
    }
    writer.flush()?;
    if counts.rows == 0 {
        return Err(LinesError::Log(LogError::new(
            LogErrorKind::NoData,
            source,
            Some(line_no),
            None,
            "no data rows after the header; the log is empty or holds only comments",
        )));
    }
    cadence.finish(mode, source, line_no)?;
    Ok(counts)
}

/// A gyro field of `line` that is not a number: the error naming its column.
pub(crate) fn gyro_not_a_number(
    check: &LineCheck<'_>,
    fields: &Fields,
    line: &[u8],
    line_no: u64,
    k: usize,
) -> LinesError {
    LinesError::Log(LogError::new(
        LogErrorKind::NotANumber,
        check.source,
        Some(line_no),
        Some(&check.headers[k]),
        format!(
            "{:?} is not a number; fix the value or comment the line out with '#'",
            String::from_utf8_lossy(fields.get(line, k))
        ),
    ))
}

/// Refuses a log whose header already has a column compensation adds (a log compensated
/// before): the output would hold two columns of one name, and a reader would take either.
pub(crate) fn check_added_columns<'a>(
    headers: &[String],
    added: impl IntoIterator<Item = &'a str>,
    source: &Path,
    line_no: u64,
) -> Result<(), LinesError> {
    let clash: Vec<&str> = added
        .into_iter()
        .filter(|a| headers.iter().any(|h| h == a))
        .collect();
    if clash.is_empty() {
        return Ok(());
    }
    Err(LinesError::Log(LogError::new(
        LogErrorKind::DuplicateColumn,
        source,
        Some(line_no),
        Some(clash[0]),
        format!(
            "the log already has the column{} {} that compensation adds (was it compensated \
             before?); compensate the raw log, or rename those columns",
            if clash.len() == 1 { "" } else { "s" },
            clash
                .iter()
                .map(|c| format!("`{c}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    )))
}

/// Compensate `input` (CSV with a header) into `output`; see the module doc. `source` names
/// the input in errors. With `flush_each_row` every line is flushed as soon as it is written.
pub fn compensate_lines<R: BufRead, W: Write>(
    model: &ModelFile,
    mut input: R,
    source: &Path,
    opts: &ReadOptions,
    output: W,
    mode: Mode,
    flush_each_row: bool,
) -> Result<LinesSummary, LinesError> {
    let comp = crate::compensate::compensator(model).map_err(LinesError::Model)?;
    let (headers, line_no) = read_header(&mut input, source, opts)?;
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(ti), Some(gi), Some(ci)) = (
        col(&opts.time_col),
        col(&opts.gyro_col),
        col(&opts.temp_col),
    ) else {
        // The log reader checked the mapping above; this cannot happen.
        return Err(LinesError::Log(LogError::new(
            LogErrorKind::MissingColumn,
            source,
            Some(line_no),
            None,
            "a mapped column is missing from the header",
        )));
    };
    let check = LineCheck {
        source,
        headers: &headers,
        delimiter: opts.delimiter,
        time_index: ti,
        mode,
    };
    let mut cadence = Cadence::new(comp.spec(), comp.limits().degraded_after_s);
    let mut gyro = OneGyro {
        // The file's map was checked when it was loaded.
        cover: model.coverage.as_ref().and_then(|c| c.to_core().ok()),
        comp,
        columns: (gi, ci),
        gyro_scale: opts.gyro_unit.dps_per_unit(),
        read: (0.0, 0.0),
        summary: LinesSummary::default(),
        temp_seen: (f64::INFINITY, f64::NEG_INFINITY),
        rate_seen: (f64::INFINITY, f64::NEG_INFINITY),
    };
    let counts = run_lines(
        &mut input,
        output,
        flush_each_row,
        &check,
        OUTPUT_COLUMNS,
        line_no,
        &mut cadence,
        &mut gyro,
    )?;
    let OneGyro {
        mut summary,
        temp_seen,
        rate_seen,
        ..
    } = gyro;
    (summary.rows, summary.malformed) = (counts.rows, counts.malformed);
    if temp_seen.0 <= temp_seen.1 {
        summary.warnings = crate::compensate::range_warnings(model, temp_seen, rate_seen);
    }
    summary.warnings.extend(cadence.warning());
    Ok(summary)
}

/// A single gyro's part of the line loop: one compensator, its coverage verdict per line, and
/// the temperatures and rates it ran on (for the extrapolation warnings).
struct OneGyro {
    comp: crate::flight_size::FlightCompensator,
    cover: Option<gyrotherm_core::coverage::CoverageMap>,
    /// The gyro and temperature columns' indices.
    columns: (usize, usize),
    gyro_scale: f64,
    /// The line's gyro (°/s) and temperature, as parsed.
    read: (f64, f64),
    summary: LinesSummary,
    temp_seen: (f64, f64),
    rate_seen: (f64, f64),
}

impl LineModel for OneGyro {
    fn parse(
        &mut self,
        fields: &Fields,
        line: &[u8],
        check: &LineCheck<'_>,
        line_no: u64,
    ) -> Result<(), LinesError> {
        let decimal_comma = check.delimiter != b',';
        let (gi, ci) = self.columns;
        let Some(gyro) = parse_number(fields.get(line, gi), decimal_comma) else {
            return Err(gyro_not_a_number(check, fields, line, line_no, gi));
        };
        // A temperature that is not a number is a sensor fault: NaN, held.
        let temp = parse_number(fields.get(line, ci), decimal_comma).unwrap_or(f64::NAN);
        self.read = (gyro * self.gyro_scale, temp);
        Ok(())
    }

    fn step<W: Write>(&mut self, time_s: f64, writer: &mut LogWriter<W>) {
        let c = self.comp.step(time_s, self.read.0, self.read.1);
        push_corrected(writer, &c);
        self.summary.count(c.status);
        let verdict = self
            .cover
            .as_ref()
            .and_then(|m| m.verdict_of(self.comp.features()));
        if let Some(v) = verdict {
            self.summary.coverage[v.coverage as usize] += 1;
        }
        push_verdict(writer, verdict);
        if c.status == Status::Ok {
            if let Some([t, r, ..]) = self.comp.features().map(|f| f.as_slice()) {
                self.temp_seen = (self.temp_seen.0.min(*t), self.temp_seen.1.max(*t));
                self.rate_seen = (self.rate_seen.0.min(*r), self.rate_seen.1.max(*r));
            }
        }
    }

    fn malformed<W: Write>(&mut self, writer: &mut LogWriter<W>) {
        push_invalid(writer);
        push_verdict(writer, None);
        self.summary.count(Status::Invalid);
    }
}

/// The `bias_dps` (or `G_bias`), `scale`, compensated rate and `status` fields of a step.
pub(crate) fn push_corrected<W: Write>(writer: &mut LogWriter<W>, c: &Corrected) {
    writer.push_f64(c.bias_dps);
    writer.push_f64(c.scale);
    match c.rate() {
        Some(r) => writer.push_f64(r),
        None => writer.push_raw(b""),
    }
    writer.push_raw(c.status.as_str().as_bytes());
}

/// The same four fields of a line with no usable output: empty, and `invalid`.
pub(crate) fn push_invalid<W: Write>(writer: &mut LogWriter<W>) {
    for _ in 0..3 {
        writer.push_raw(b"");
    }
    writer.push_raw(Status::Invalid.as_str().as_bytes());
}

/// The `coverage` and `sigma_dph` fields of an output row (both empty without a verdict).
pub(crate) fn push_verdict<W: std::io::Write>(
    writer: &mut crate::csvlog::LogWriter<W>,
    verdict: Option<gyrotherm_core::coverage::Verdict>,
) {
    match verdict {
        Some(v) => {
            writer.push_raw(v.coverage.as_str().as_bytes());
            writer.push_f64(v.sigma_dph);
        }
        None => {
            writer.push_raw(b"");
            writer.push_raw(b"");
        }
    }
}

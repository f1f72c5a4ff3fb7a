//! Logs: the log in memory ([`repr`]: [`ImuLog`], N gyro axes and M temperature sensors, and
//! [`TestLog`], one axis with one temperature) apart from the file formats that read and write
//! it ([`LogFormat`], listed in `format.rs`: CSV in `csv/`, PX4 ULog in `ulog.rs`,
//! ArduPilot DataFlash in `dataflash.rs`), and the one entry point every job reads through
//! ([`read_log_set`], in `log_set.rs`). Here: the read options and report every format shares.
//!
//! The CSV format, read and written by every command (`csv/`):
//!
//! A header row, then one row per sample. Required columns `time_s` (s), `gyro_dps` (°/s),
//! `temp_c` (°C); optional `table_dps` (rate-table input rate, °/s; absent means a static
//! test). Every other column is kept and passed through as raw text. Lines starting with `#`
//! are comments, before the header too. Fields are comma-separated; numbers may carry spaces
//! around them. [`ReadOptions`] maps other header names and converts the gyro unit.
//!
//! - [`read_log`]: a whole file into a [`TestLog`] (columns of f64), validated.
//! - [`LogReader`]: the same checks, one [`Sample`] at a time, for streams of any length.
//! - [`write_log`] / [`LogWriter`]: the same layout back out, numbers round-trip exact.
//!
//! Checks (each a [`LogError`] naming file, 1-based physical line, column and the fix, see
//! [`LogErrorKind`]): missing columns, non-numeric or non-finite fields, empty file, short
//! or long rows (a short last row is a truncated file), time not strictly increasing,
//! duplicate timestamps, and gaps longer than [`GAP_FACTOR`] nominal sample periods (the
//! period is the median of the first [`PERIOD_ESTIMATE_STEPS`] steps; see [`LogReader`]).

mod column_list;
mod csv;
mod dataflash;
mod error;
mod format;
mod log_set;
pub mod repr;
mod step_means;
mod ulog;

pub use csv::gaps::{Sample, MAX_FILL_SAMPLES_PER_GAP};
pub(crate) use csv::line::{read_line_capped, record, Fields, LineRead};
pub(crate) use csv::number::parse_number;
pub use csv::reader::{
    LogReader, GAP_FACTOR, MAX_FILLED_SAMPLES, PERIOD_CHECK_STEPS, PERIOD_ESTIMATE_STEPS,
};
pub use csv::unit::{read_imu_log, read_imu_logs};
pub(crate) use csv::write_imu_csv;
pub(crate) use csv::writer::short_f64;
pub use csv::writer::LogWriter;
pub use csv::{write_imu_log, write_log, write_log_with, WriteOptions};
pub use error::{LogError, LogErrorKind};
pub use format::{read_unit_from, LogFormat, LOG_FORMATS, LOG_FORMAT_NAMES};
pub(crate) use log_set::{read_in_form, read_one, LogSetForm, OneLog};
pub use log_set::{
    read_log_columns, read_log_set, read_log_sets, ColumnValues, FileRead, LogColumns, LogSet,
    LogSetError, SetRead,
};
pub use repr::{
    ColumnError, ExtraColumn, ImuLog, NamedSeries, TestLog, DEFAULT_TABLE_COL, GYRO_COL, NOISE_COL,
    TEMP_COL, TIME_COL, TRUE_BIAS_COL, TRUE_SCALE_COL,
};
pub use step_means::{SAMPLES_COL, SENSOR_GYRO_COLS};

use std::path::Path;

/// Longest line of a log, bytes (line break included), for every reader (the batch reader,
/// the compensator's stream): a log line holds a few numbers, and one endless line (a file
/// without line breaks, `/dev/zero`) must not take unbounded memory.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// Factor from a rate column's unit, read from its name suffix, to °/h: `*_dps` 3600,
/// `*_dph` 1, `*_rad_s` / `*_rps` 3600·180/π; None for a name without a rate unit.
pub fn rate_column_to_dph(column: &str) -> Option<f64> {
    if column.ends_with("_dps") {
        Some(3600.0)
    } else if column.ends_with("_dph") {
        Some(1.0)
    } else if column.ends_with("_rad_s") || column.ends_with("_rps") {
        Some(3600.0 * 180.0 / std::f64::consts::PI)
    } else {
        None
    }
}

/// Unit of the gyro column in the file; converted to °/s on read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GyroUnit {
    /// °/s
    #[default]
    Dps,
    /// °/h (1 °/h = 1/3600 °/s)
    Dph,
    /// rad/s (1 rad/s = 180/π °/s)
    RadPerS,
}

impl GyroUnit {
    /// °/s per unit of the file: the factor a gyro field is multiplied by on reading.
    pub(crate) fn dps_per_unit(self) -> f64 {
        match self {
            GyroUnit::Dps => 1.0,
            // 1 °/h = 1/3600 °/s.
            GyroUnit::Dph => 1.0 / 3600.0,
            // 1 rad = 180/π °.
            GyroUnit::RadPerS => 180.0 / std::f64::consts::PI,
        }
    }
}

impl std::str::FromStr for GyroUnit {
    type Err = String;
    /// `dps`, `dph` or `rad/s`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "dps" => Ok(GyroUnit::Dps),
            "dph" => Ok(GyroUnit::Dph),
            "rad/s" => Ok(GyroUnit::RadPerS),
            _ => Err(format!(
                "unknown gyro unit {s:?}; use dps (°/s), dph (°/h) or rad/s"
            )),
        }
    }
}

/// How to read a log: column names, unit, gap policy.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Header of the time column (s).
    pub time_col: String,
    /// Header of the gyro column (unit: `gyro_unit`), or of several, comma-separated (an
    /// inertial unit's log: [`read_imu_log`]; see `split_columns`).
    pub gyro_col: String,
    /// Header of the temperature column (°C), or of several, comma-separated.
    pub temp_col: String,
    /// Header of the table-rate column (°/s). Optional when left at `table_dps`; a column
    /// mapped to another name must exist.
    pub table_col: String,
    /// Unit of the gyro column.
    pub gyro_unit: GyroUnit,
    /// Interpolate gaps up to this many seconds (None: a gap is an error). A gap's length is
    /// the time between the real samples on either side of it.
    pub fill_gaps_max_s: Option<f64>,
    /// Nominal sample period, s (None: median of the first [`PERIOD_ESTIMATE_STEPS`] steps,
    /// which the streaming reader reads ahead before its first sample).
    pub sample_period_s: Option<f64>,
    /// Field separator: `b','` (default), `b';'` or `b'\t'`. With any separator but the
    /// comma, numbers may use a decimal comma (`0,5`), as European loggers write them.
    pub delimiter: u8,
    /// The file format (None: by the file's extension, `LogFormat::of_path`).
    pub format: Option<LogFormat>,
    /// Which of an autopilot's sensors of the same kind to read (PX4's multi-instance,
    /// ArduPilot's `I`); CSV logs ignore it.
    pub instance: u8,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            time_col: TIME_COL.into(),
            gyro_col: GYRO_COL.into(),
            temp_col: TEMP_COL.into(),
            table_col: DEFAULT_TABLE_COL.into(),
            gyro_unit: GyroUnit::Dps,
            fill_gaps_max_s: None,
            sample_period_s: None,
            delimiter: b',',
            format: None,
            instance: 0,
        }
    }
}

/// What reading did besides returning data.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadReport {
    /// Samples made by gap filling.
    pub filled_samples: usize,
    /// Gaps filled.
    pub filled_gaps: usize,
    /// Data rows read from the file (final once reading has ended).
    pub rows: u64,
    /// Nominal sample period used for the gap check, s (None: fewer than two rows).
    pub sample_period_s: Option<f64>,
    /// Whether that period was estimated from the data (false: given in the options).
    pub sample_period_estimated: bool,
    /// Largest |step / period − 1| over the steps that are not gaps: 0 for an evenly sampled
    /// log, 0.4 for steps 40 % off the period.
    pub max_step_jitter: f64,
    /// Line of the step with that jitter.
    pub max_jitter_line: Option<u64>,
    /// The table-rate column holds only zeros: an inertial unit's log read as a static run
    /// ([`read_imu_log`] leaves its `table` out).
    pub zero_table: bool,
    /// A binary log cut off mid-message: the byte where its last whole message ends (what
    /// follows was not read).
    pub truncated_at_byte: Option<u64>,
}

impl ReadReport {
    /// A warning about a log cut off mid-message, if it was.
    pub fn truncation_warning(&self, source: &Path) -> Option<String> {
        self.truncated_at_byte.map(|at| {
            format!(
                "{}: the log is cut off in a message at byte {at}; read up to there (a log \
                 copied before the autopilot closed it ends so)",
                source.display()
            )
        })
    }

    /// Jitter above which a log is reported as irregularly sampled (the figures assume
    /// even sampling).
    pub(crate) const JITTER_WARNING: f64 = 0.05;

    /// A warning about irregular steps, with the measured jitter, if above
    /// `JITTER_WARNING`.
    pub fn jitter_warning(&self, source: &Path) -> Option<String> {
        let period = self.sample_period_s?;
        (self.max_step_jitter > Self::JITTER_WARNING).then(|| {
            format!(
                "{}{}: time steps are irregular: up to {:.0} % off the {period} s period; the \
                 figures assume even sampling (resample the log if that matters)",
                source.display(),
                self.max_jitter_line
                    .map_or(String::new(), |l| format!(":{l}")),
                100.0 * self.max_step_jitter
            )
        })
    }
}

/// Read and validate a whole log. The file is read once, streaming; the columns are sized
/// from the file length and the bytes per row of the first rows.
pub fn read_log(path: &Path, opts: &ReadOptions) -> Result<(TestLog, ReadReport), LogError> {
    match opts.format_of(path) {
        LogFormat::Csv => {
            csv::read_log_numbers(path, opts, &[]).map(|(log, report, _)| (log, report))
        }
        _ => format::read_axis(path, opts),
    }
}

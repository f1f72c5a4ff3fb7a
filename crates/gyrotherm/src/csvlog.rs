//! The test-log CSV format, read and written by every command.
//!
//! Required columns `time_s` (s), `gyro_dps` (°/s), `temp_c` (°C); optional `table_dps`
//! (rate-table input rate, °/s; absent means a static test). Every other column is kept and
//! passed through. Lines starting with `#` are comments.
//!
//! NOTE: interface placeholder; the full validating, streaming reader is issue 2's.

use std::path::{Path, PathBuf};

/// Names of the simulator's truth columns (written with `simulate --truth`).
pub const TRUE_BIAS_COL: &str = "true_bias_dps";
/// True scale factor K (dimensionless, 1.0 nominal) in Ĝ = B + K·G.
pub const TRUE_SCALE_COL: &str = "true_scale";
/// Noise-only part of the gyro output, °/s.
pub const NOISE_COL: &str = "noise_dps";

/// One test log in memory. `gyro_dps` is always in °/s, whatever the file's unit.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TestLog {
    /// Time, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Gyro output, °/s.
    pub gyro_dps: Vec<f64>,
    /// Temperature, °C.
    pub temp_c: Vec<f64>,
    /// Rate-table input rate, °/s (None: static test).
    pub table_dps: Option<Vec<f64>>,
    /// Other columns, passed through to outputs unchanged (raw text of each field).
    pub extra: Vec<ExtraColumn>,
}

/// A pass-through column.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExtraColumn {
    pub name: String,
    pub values: Vec<String>,
}

impl TestLog {
    pub fn len(&self) -> usize {
        self.time_s.len()
    }
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }
    /// Median of the time steps, s (NaN for fewer than two samples).
    pub fn sample_period_s(&self) -> f64 {
        let mut d: Vec<f64> = self.time_s.windows(2).map(|w| w[1] - w[0]).collect();
        if d.is_empty() {
            return f64::NAN;
        }
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    }
    /// A pass-through column parsed as numbers (None if absent or not all numeric).
    pub fn extra_f64(&self, name: &str) -> Option<Vec<f64>> {
        let col = self.extra.iter().find(|c| c.name == name)?;
        col.values.iter().map(|v| v.trim().parse().ok()).collect()
    }
}

/// Unit of the gyro column in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GyroUnit {
    /// °/s
    #[default]
    Dps,
    /// °/h
    Dph,
    /// rad/s
    RadPerS,
}

/// How to read a log: column names, unit, gap policy.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    pub time_col: String,
    pub gyro_col: String,
    pub temp_col: String,
    pub table_col: String,
    pub gyro_unit: GyroUnit,
    /// Interpolate gaps up to this many seconds (None: a gap is an error).
    pub fill_gaps_max_s: Option<f64>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            time_col: "time_s".into(),
            gyro_col: "gyro_dps".into(),
            temp_col: "temp_c".into(),
            table_col: "table_dps".into(),
            gyro_unit: GyroUnit::Dps,
            fill_gaps_max_s: None,
        }
    }
}

/// What reading did besides returning data (e.g. samples made by gap filling).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadReport {
    pub filled_samples: usize,
    pub filled_gaps: usize,
}

/// A log that cannot be read: file, line, column and what to do.
#[derive(Debug)]
pub struct LogError {
    pub path: PathBuf,
    pub line: Option<u64>,
    pub column: Option<String>,
    pub message: String,
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
        LogError {
            path: PathBuf::new(),
            line: None,
            column: None,
            message: e.to_string(),
        }
    }
}

/// Read a whole log (placeholder: no validation yet).
pub fn read_log(path: &Path, opts: &ReadOptions) -> Result<(TestLog, ReadReport), LogError> {
    let err = |line: Option<u64>, column: Option<&str>, message: String| LogError {
        path: path.to_path_buf(),
        line,
        column: column.map(str::to_owned),
        message,
    };
    let mut rdr = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| err(None, None, e.to_string()))?;
    let headers = rdr
        .headers()
        .map_err(|e| err(None, None, e.to_string()))?
        .clone();
    let find = |name: &str| headers.iter().position(|h| h.trim() == name);
    let ti =
        find(&opts.time_col).ok_or_else(|| err(Some(1), Some(&opts.time_col), "missing".into()))?;
    let gi =
        find(&opts.gyro_col).ok_or_else(|| err(Some(1), Some(&opts.gyro_col), "missing".into()))?;
    let ci =
        find(&opts.temp_col).ok_or_else(|| err(Some(1), Some(&opts.temp_col), "missing".into()))?;
    let tab = find(&opts.table_col);
    let scale = match opts.gyro_unit {
        GyroUnit::Dps => 1.0,
        GyroUnit::Dph => 1.0 / 3600.0,
        GyroUnit::RadPerS => 180.0 / std::f64::consts::PI,
    };
    let mut log = TestLog::default();
    let extra_idx: Vec<usize> = (0..headers.len())
        .filter(|&i| i != ti && i != gi && i != ci && Some(i) != tab)
        .collect();
    log.extra = extra_idx
        .iter()
        .map(|&i| ExtraColumn {
            name: headers[i].to_owned(),
            values: Vec::new(),
        })
        .collect();
    let mut table = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| err(None, None, e.to_string()))?;
        let line = rec.position().map(|p| p.line());
        let num = |i: usize| -> Result<f64, LogError> {
            rec.get(i).unwrap_or("").trim().parse::<f64>().map_err(|_| {
                err(
                    line,
                    Some(&headers[i]),
                    format!("{:?} is not a number", rec.get(i).unwrap_or("")),
                )
            })
        };
        log.time_s.push(num(ti)?);
        log.gyro_dps.push(num(gi)? * scale);
        log.temp_c.push(num(ci)?);
        if let Some(t) = tab {
            table.push(num(t)?);
        }
        for (k, &i) in extra_idx.iter().enumerate() {
            log.extra[k]
                .values
                .push(rec.get(i).unwrap_or("").to_owned());
        }
    }
    if tab.is_some() {
        log.table_dps = Some(table);
    }
    Ok((log, ReadReport::default()))
}

/// Write a log as CSV (`time_s,gyro_dps,temp_c[,table_dps],extra...`), atomically.
pub fn write_log(path: &Path, log: &TestLog) -> Result<(), LogError> {
    crate::atomic_file::write_atomically(path, |w| {
        use std::io::Write;
        write!(w, "time_s,gyro_dps,temp_c")?;
        if log.table_dps.is_some() {
            write!(w, ",table_dps")?;
        }
        for c in &log.extra {
            write!(w, ",{}", c.name)?;
        }
        writeln!(w)?;
        for i in 0..log.len() {
            write!(w, "{},{},{}", log.time_s[i], log.gyro_dps[i], log.temp_c[i])?;
            if let Some(t) = &log.table_dps {
                write!(w, ",{}", t[i])?;
            }
            for c in &log.extra {
                write!(w, ",{}", c.values[i])?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
    .map_err(|e: std::io::Error| LogError {
        path: path.to_path_buf(),
        line: None,
        column: None,
        message: e.to_string(),
    })
}

//! The logs of one job, read through one entry point ([`read_log_set`]): a single gyro's (one
//! gyro and one temperature column, [`TestLog`]) or an inertial unit's (column lists, or an
//! autopilot log: [`ImuLog`]). The set remembers the form it was read in, so that a job runs
//! that form's own code; callers never ask which form they hold.

use std::path::{Path, PathBuf};

use super::{
    read_imu_logs, read_log, ColumnError, ImuLog, LogError, ReadOptions, ReadReport, TestLog,
    DEFAULT_TABLE_COL, TIME_COL,
};
use crate::told::Told;

/// The logs of one job, each with the name it is told by (its path as given).
#[derive(Debug, Clone)]
pub struct LogSet {
    form: LogSetForm,
    gap_warnings: Vec<String>,
}

/// The form a [`LogSet`] was read in: for the library's jobs, which run each form's own code.
#[derive(Debug, Clone)]
pub(crate) enum LogSetForm {
    Single(Vec<(String, TestLog)>),
    Unit(Vec<(String, ImuLog)>),
}

/// What reading one file of a set gave: the lines to tell about it, or why it cannot be used.
#[derive(Debug)]
pub struct FileRead {
    pub path: PathBuf,
    pub told: Vec<Told>,
    /// What reading did (None when the file could not be read).
    pub report: Option<ReadReport>,
    pub error: Option<LogError>,
}

/// Some logs of a set could not be read (each is told by its [`FileRead`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LogSetError {
    pub failed: usize,
    pub of: usize,
}

impl std::fmt::Display for LogSetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} input logs could not be read (see above)",
            self.failed, self.of
        )
    }
}

impl std::error::Error for LogSetError {}

/// Every file of a set as read: what to tell of each file, and the set when every file was
/// read.
#[derive(Debug)]
pub struct SetRead {
    pub files: Vec<FileRead>,
    pub set: Result<LogSet, LogSetError>,
}

/// Read every path with the same options: as a unit's logs when the options name several
/// gyro or temperature columns or a file's format holds a unit
/// ([`ReadOptions::reads_unit`]), else as a single gyro's. `table_axis` names the gyro
/// column a unit's rate table turns (None: found from the data). A unit's files are read
/// at once, each on its own thread.
pub fn read_log_set(paths: &[PathBuf], opts: &ReadOptions, table_axis: Option<&str>) -> SetRead {
    read_in_form(paths, opts, table_axis, opts.reads_unit(paths))
}

/// [`read_log_set`] for the sets of one job (training and held-out logs): all in one form,
/// a unit's when any set reads as a unit's.
pub fn read_log_sets(
    sets: &[&[PathBuf]],
    opts: &ReadOptions,
    table_axis: Option<&str>,
) -> Vec<SetRead> {
    let unit = opts.reads_unit(&sets.concat());
    sets.iter()
        .map(|paths| read_in_form(paths, opts, table_axis, unit))
        .collect()
}

pub(crate) fn read_in_form(
    paths: &[PathBuf],
    opts: &ReadOptions,
    table_axis: Option<&str>,
    unit: bool,
) -> SetRead {
    let mut files = Vec::with_capacity(paths.len());
    // A single gyro's gap-filling lines again, for a report that lists what reading did.
    let mut gap_warnings = Vec::new();
    let form = if unit {
        let read = read_imu_logs(paths, opts, table_axis);
        LogSetForm::Unit(keep(paths, read, &mut files, |p, report| {
            let mut told: Vec<Told> = filled_gaps(p, report).map(Told::Line).into_iter().collect();
            told.extend(report.truncation_warning(p).map(Told::Warning));
            if report.zero_table {
                told.push(Told::Line(format!(
                    "{}: the table-rate column {} is all zeros: read as a static run",
                    p.display(),
                    opts.table_col
                )));
            }
            told
        }))
    } else {
        let read = paths.iter().map(|p| read_log(p, opts));
        LogSetForm::Single(keep(paths, read, &mut files, |p, report| {
            let gap = filled_gaps(p, report);
            gap_warnings.extend(gap.clone());
            let mut told: Vec<Told> = gap.map(Told::Line).into_iter().collect();
            told.extend(report.jitter_warning(p).map(Told::Warning));
            told.extend(report.truncation_warning(p).map(Told::Warning));
            told
        }))
    };
    let failed = files.iter().filter(|f| f.error.is_some()).count();
    let set = if failed > 0 {
        Err(LogSetError {
            failed,
            of: files.len(),
        })
    } else {
        Ok(LogSet { form, gap_warnings })
    };
    SetRead { files, set }
}

/// The logs read, named by their paths as given; each file's lines to tell (`told`, from its
/// report) or its error into `files`, in the order of `paths`.
fn keep<L>(
    paths: &[PathBuf],
    read: impl IntoIterator<Item = Result<(L, ReadReport), LogError>>,
    files: &mut Vec<FileRead>,
    mut told: impl FnMut(&Path, &ReadReport) -> Vec<Told>,
) -> Vec<(String, L)> {
    let mut logs = Vec::new();
    for (p, r) in paths.iter().zip(read) {
        let (told, report, error) = match r {
            Ok((log, report)) => {
                logs.push((p.display().to_string(), log));
                (told(p, &report), Some(report), None)
            }
            Err(e) => (Vec::new(), None, Some(e)),
        };
        files.push(FileRead {
            path: p.clone(),
            told,
            report,
            error,
        });
    }
    logs
}

/// The line about the samples gap filling made, if it made any.
fn filled_gaps(path: &Path, report: &ReadReport) -> Option<String> {
    (report.filled_gaps > 0).then(|| {
        format!(
            "{}: filled {} gap(s) with {} interpolated sample(s) (--fill-gaps-max-s)",
            path.display(),
            report.filled_gaps,
            report.filled_samples
        )
    })
}

impl LogSet {
    /// A single gyro's logs made in memory (simulated runs, for example), with their names.
    pub fn of_logs(logs: Vec<(String, TestLog)>) -> LogSet {
        LogSet {
            form: LogSetForm::Single(logs),
            gap_warnings: Vec::new(),
        }
    }

    /// An inertial unit's logs made in memory (simulated runs, for example), with their
    /// names.
    pub fn of_unit_logs(logs: Vec<(String, ImuLog)>) -> LogSet {
        LogSet {
            form: LogSetForm::Unit(logs),
            gap_warnings: Vec::new(),
        }
    }

    /// How many logs.
    pub fn len(&self) -> usize {
        match &self.form {
            LogSetForm::Single(l) => l.len(),
            LogSetForm::Unit(l) => l.len(),
        }
    }

    /// Whether the set holds no log.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The names of the logs, in the order given.
    pub fn names(&self) -> Vec<&str> {
        match &self.form {
            LogSetForm::Single(l) => l.iter().map(|(n, _)| n.as_str()).collect(),
            LogSetForm::Unit(l) => l.iter().map(|(n, _)| n.as_str()).collect(),
        }
    }

    /// Per log, in order: whether it is a static run (no non-zero table rate).
    pub fn is_static(&self) -> Vec<bool> {
        match &self.form {
            LogSetForm::Single(l) => l.iter().map(|(_, l)| l.is_static()).collect(),
            LogSetForm::Unit(l) => l
                .iter()
                .map(|(_, l)| {
                    l.table
                        .as_ref()
                        .is_none_or(|t| t.values.iter().all(|v| *v == 0.0))
                })
                .collect(),
        }
    }

    /// The lines about gap filling, for a report that lists what reading did.
    pub fn gap_warnings(&self) -> &[String] {
        &self.gap_warnings
    }

    pub(crate) fn form(&self) -> &LogSetForm {
        &self.form
    }

    pub(crate) fn into_form(self) -> LogSetForm {
        self.form
    }
}

/// A column of a log as read: numbers, or the text of a pass-through column that is not all
/// numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnValues {
    Numbers(Vec<f64>),
    Text(Vec<String>),
}

/// One log as named columns, for a caller that wants a table (Python's `read_log`): time, the
/// gyro columns (°/s), the temperature columns (°C), the table rate, then the pass-through
/// columns (numbers when every field is one).
#[derive(Debug, Clone, PartialEq)]
pub struct LogColumns {
    pub columns: Vec<(String, ColumnValues)>,
    /// The gyro and temperature columns, in order.
    pub gyro_cols: Vec<String>,
    pub temp_cols: Vec<String>,
    /// The gyro column the table rate turns (None without a table column; a unit's all-zero
    /// table column is read as none).
    pub table_axis: Option<String>,
    /// Whether the log was read as a unit's (column lists, or a file format that holds one).
    pub unit: bool,
    /// Median time step, s (None for fewer than two samples).
    pub sample_period_s: Option<f64>,
    pub report: ReadReport,
    /// What reading did, to tell (gaps filled, irregular steps, a cut-off file).
    pub told: Vec<Told>,
}

impl LogColumns {
    /// The numbers of column `name`, moved out (left empty here).
    pub fn take_numbers(&mut self, name: &str) -> Result<Vec<f64>, ColumnError> {
        let Some(k) = self.columns.iter().position(|(n, _)| n == name) else {
            return Err(ColumnError::Missing {
                name: name.to_owned(),
                available: self.columns.iter().map(|(n, _)| n.clone()).collect(),
            });
        };
        match &mut self.columns[k].1 {
            ColumnValues::Numbers(v) => Ok(std::mem::take(v)),
            ColumnValues::Text(_) => Err(ColumnError::NotNumeric {
                name: name.to_owned(),
            }),
        }
    }
}

fn pass_through(extra: Vec<super::ExtraColumn>) -> impl Iterator<Item = (String, ColumnValues)> {
    extra.into_iter().map(|c| {
        let numbers: Option<Vec<f64>> = c.values.iter().map(|v| v.trim().parse().ok()).collect();
        let values = match numbers {
            Some(v) => ColumnValues::Numbers(v),
            None => ColumnValues::Text(c.values),
        };
        (c.name, values)
    })
}

/// Read one log through the one entry ([`read_log_set`]) and give its columns by name: a
/// single gyro's under the file's names (`opts`' columns), a unit's as [`ImuLog`] names them
/// (time as `time_s`, the table rate as `table_dps`).
pub fn read_log_columns(
    path: &Path,
    opts: &ReadOptions,
    table_axis: Option<&str>,
) -> Result<LogColumns, LogError> {
    let ReadOne { log, report, told } = read_one(path, opts, table_axis, opts.reads_unit(&[path]))?;
    // A single gyro's log is the unit of one axis, keyed by the file's names; a unit's keys
    // its time and table rate by their standard names.
    let (log, unit, time_name, table_name) = match log {
        OneLog::Single(l) => (
            ImuLog::of_axis(l, &opts.gyro_col, &opts.temp_col, &opts.table_col),
            false,
            opts.time_col.as_str(),
            opts.table_col.as_str(),
        ),
        OneLog::Unit(l) => (l, true, TIME_COL, DEFAULT_TABLE_COL),
    };
    let (gyro_cols, temp_cols) = log.column_names();
    let sample_period_s = Some(super::repr::median_step_s(&log.time_s)).filter(|p| p.is_finite());
    let ImuLog {
        time_s,
        gyro,
        temp,
        table,
        table_axis,
        extra,
    } = log;
    let mut columns = vec![(time_name.to_owned(), ColumnValues::Numbers(time_s))];
    columns.extend(
        gyro.into_iter()
            .chain(temp)
            .map(|s| (s.name, ColumnValues::Numbers(s.values))),
    );
    columns.extend(table.map(|t| (table_name.to_owned(), ColumnValues::Numbers(t.values))));
    columns.extend(pass_through(extra));
    Ok(LogColumns {
        columns,
        gyro_cols,
        temp_cols,
        table_axis,
        unit,
        sample_period_s,
        report,
        told,
    })
}

/// One log read through the one entry, in the form it was read in.
#[derive(Debug)]
pub(crate) enum OneLog {
    Single(TestLog),
    Unit(ImuLog),
}

/// What [`read_one`] gives: the log, what reading did, and what to tell of it.
#[derive(Debug)]
pub(crate) struct ReadOne {
    pub log: OneLog,
    pub report: ReadReport,
    pub told: Vec<Told>,
}

/// [`read_in_form`] of one path: its log, or the file's error.
pub(crate) fn read_one(
    path: &Path,
    opts: &ReadOptions,
    table_axis: Option<&str>,
    unit: bool,
) -> Result<ReadOne, LogError> {
    let read = read_in_form(&[path.to_path_buf()], opts, table_axis, unit);
    let mut file = read.files.into_iter().next();
    if let Some(e) = file.as_mut().and_then(|f| f.error.take()) {
        return Err(e);
    }
    let log = match read.set.map(LogSet::into_form) {
        Ok(LogSetForm::Single(l)) => l.into_iter().next().map(|(_, l)| OneLog::Single(l)),
        Ok(LogSetForm::Unit(l)) => l.into_iter().next().map(|(_, l)| OneLog::Unit(l)),
        Err(_) => None,
    };
    match (log, file) {
        (Some(log), Some(f)) => Ok(ReadOne {
            log,
            report: f.report.unwrap_or_default(),
            told: f.told,
        }),
        // A set of one path holds its log or its error: reaching here is the reader's fault.
        _ => Err(LogError::new(
            super::LogErrorKind::Io,
            path,
            None,
            None,
            "internal: reading gave neither the log nor an error; please report it",
        )),
    }
}

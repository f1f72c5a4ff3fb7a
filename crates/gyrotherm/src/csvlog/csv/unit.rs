//! An inertial unit's CSV log ([`ImuLog`] in memory): several gyro and temperature columns in one file
//! ([`super::column_list`] says how they are named).
//!
//! Reading goes through [`read_log`](crate::csvlog::read_log) with the first gyro and the first
//! temperature column, so time, gaps, separators and those two columns get every check of a
//! single-axis log; the further columns are then parsed as strictly (a number, finite; the
//! gyro unit converted; a decimal comma with `;` or tab separators) and named in their errors.
//! Rows made by gap filling get the further columns interpolated linearly in time, as the
//! reader interpolates the first ones.

use std::path::Path;

use super::column_list::{parse_table_axis, TABLE_AXIS_SLOPE_RANGE};
use super::error::{LogError, LogErrorKind as Kind};
use super::number::parse_number;
use super::{ExtraColumn, ImuLog, NamedSeries, ReadOptions, ReadReport, TIME_COL};

/// The gyro the table turns: the one whose output has a slope on the table rate within
/// [`TABLE_AXIS_SLOPE_RANGE`] (least squares over the samples, table rate and output
/// centred); None when none or several do.
pub(crate) fn detect_table_axis(gyro: &[NamedSeries], table_dps: &[f64]) -> Option<usize> {
    let n = table_dps.len() as f64;
    let mt = table_dps.iter().sum::<f64>() / n;
    let stt: f64 = table_dps.iter().map(|t| (t - mt) * (t - mt)).sum();
    if stt <= 0.0 || !stt.is_finite() {
        return None;
    }
    let (lo, hi) = TABLE_AXIS_SLOPE_RANGE;
    let mut hits = gyro.iter().enumerate().filter(|(_, g)| {
        let mg = g.values.iter().sum::<f64>() / n;
        let sgt: f64 = g
            .values
            .iter()
            .zip(table_dps)
            .map(|(y, t)| (y - mg) * (t - mt))
            .sum();
        let slope = sgt / stt;
        slope.abs() >= lo && slope.abs() <= hi
    });
    match (hits.next(), hits.next()) {
        (Some((k, _)), None) => Some(k),
        _ => None,
    }
}

/// Read an inertial unit's log: the gyro and temperature columns of `opts` (lists, or one
/// name each), the table column, and the axis it turns (`table_axis`, a gyro column, or
/// found by `detect_table_axis`; a table log where no single axis follows the table is an
/// error that says to name it).
pub fn read_imu_log(
    path: &Path,
    opts: &ReadOptions,
    table_axis: Option<&str>,
) -> Result<(ImuLog, ReadReport), LogError> {
    if opts.format_of(path).holds_unit() {
        return super::format::read_unit(path, opts);
    }
    let options = |e: crate::setting_rule::SettingError| {
        LogError::new(Kind::BadOptions, path, None, None, e.to_string())
    };
    let gyro_cols = opts.gyro_cols().map_err(options)?;
    let temp_cols = opts.temp_cols().map_err(options)?;
    opts.validate_columns().map_err(options)?;
    let first = ReadOptions {
        gyro_col: gyro_cols[0].clone(),
        temp_col: temp_cols[0].clone(),
        ..opts.clone()
    };
    let decimal_comma = opts.delimiter != b',';
    let further: Vec<&str> = gyro_cols[1..]
        .iter()
        .chain(&temp_cols[1..])
        .map(String::as_str)
        .collect();
    let (mut log, report, mut parsed) = super::read_log_numbers(path, &first, &further)?;
    let gyro_scale = opts.gyro_unit.dps_per_unit();
    let mut take = |name: &str, scale: f64, what: &str| -> Result<Vec<f64>, LogError> {
        let k = log
            .extra
            .iter()
            .position(|c| c.name == name)
            .ok_or_else(|| {
                let mut found = vec![
                    TIME_COL.to_owned(),
                    first.gyro_col.clone(),
                    first.temp_col.clone(),
                ];
                found.extend(log.extra.iter().map(|c| c.name.clone()));
                LogError::new(
                    Kind::MissingColumn,
                    path,
                    None,
                    Some(name),
                    format!(
                        "{what} column not found; the header has: {}",
                        found.join(", ")
                    ),
                )
            })?;
        let col = log.extra.remove(k);
        match parsed.remove(k) {
            Some(numbers) => numbers.finish(path, &col.name, &log.time_s, scale),
            None => parse_column(path, &col, &log.time_s, scale, decimal_comma),
        }
    };
    let mut gyro = Vec::with_capacity(gyro_cols.len());
    gyro.push(NamedSeries {
        name: gyro_cols[0].clone(),
        values: std::mem::take(&mut log.gyro_dps),
    });
    for g in &gyro_cols[1..] {
        gyro.push(NamedSeries {
            name: g.clone(),
            values: take(g, gyro_scale, "gyro")?,
        });
    }
    let mut temp = Vec::with_capacity(temp_cols.len());
    temp.push(NamedSeries {
        name: temp_cols[0].clone(),
        values: std::mem::take(&mut log.temp_c),
    });
    for t in &temp_cols[1..] {
        temp.push(NamedSeries {
            name: t.clone(),
            values: take(t, 1.0, "temperature")?,
        });
    }
    // A table column of zeros is a static run, as a single-axis log's is
    // ([`super::TestLog::is_static`]): no table turned, so no axis to find.
    let zero_table = log
        .table_dps
        .as_ref()
        .is_some_and(|t| t.iter().all(|v| *v == 0.0));
    let table = log
        .table_dps
        .take()
        .filter(|_| !zero_table)
        .map(|values| NamedSeries {
            name: opts.table_col.clone(),
            values,
        });
    let report = ReadReport {
        zero_table,
        ..report
    };
    let table_axis = match (&table, table_axis) {
        (None, _) => None,
        (Some(_), Some(a)) => Some(parse_table_axis(a, &gyro_cols).map_err(options)?),
        (Some(_), None) if gyro.len() == 1 => Some(0),
        (Some(t), None) => Some(detect_table_axis(&gyro, &t.values).ok_or_else(|| {
            LogError::new(
                Kind::BadOptions,
                path,
                None,
                Some(&t.name),
                format!(
                    "no single gyro column follows the table rate (slope {} to {}); name the \
                     axis the table turns with --table-axis GYRO_COL",
                    TABLE_AXIS_SLOPE_RANGE.0, TABLE_AXIS_SLOPE_RANGE.1
                ),
            )
        })?),
    };
    Ok((
        ImuLog {
            time_s: log.time_s,
            table_axis: table_axis.map(|k| gyro[k].name.clone()),
            gyro,
            temp,
            table,
            extra: log.extra,
        },
        report,
    ))
}

/// [`read_imu_log`] of each path with the same options, one thread per file (the files are
/// independent; a unit's training reads several, and much of a read is one thread's work):
/// the results in the order of `paths`, each as [`read_imu_log`] gives it.
pub fn read_imu_logs<P: AsRef<Path> + Sync>(
    paths: &[P],
    opts: &ReadOptions,
    table_axis: Option<&str>,
) -> Vec<Result<(ImuLog, ReadReport), LogError>> {
    std::thread::scope(|scope| {
        let handles: Vec<_> = paths
            .iter()
            .map(|p| scope.spawn(move || read_imu_log(p.as_ref(), opts, table_axis)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// Parse a further column: every field a finite number (times `scale`); empty fields, which
/// only gap filling makes, interpolated linearly in time between the real rows around them.
fn parse_column(
    path: &Path,
    col: &ExtraColumn,
    time_s: &[f64],
    scale: f64,
    decimal_comma: bool,
) -> Result<Vec<f64>, LogError> {
    let mut numbers = NumberColumn::default();
    for text in &col.values {
        numbers.push(text, decimal_comma);
        if numbers.bad.is_some() {
            break;
        }
    }
    numbers.finish(path, &col.name, time_s, scale)
}

/// A further column's fields parsed as they are read: NaN where a field is empty, and the first
/// field that is no number or not finite (data row index, text, what is wrong).
#[derive(Debug, Default)]
pub(crate) struct NumberColumn {
    pub(crate) values: Vec<f64>,
    bad: Option<(usize, String, Kind)>,
}

impl NumberColumn {
    /// The next field.
    pub(crate) fn push(&mut self, text: &str, decimal_comma: bool) {
        let row = self.values.len();
        if text.is_empty() {
            self.values.push(f64::NAN);
            return;
        }
        let raw = text.as_bytes();
        let v = parse_number(raw, decimal_comma);
        let v = match v {
            Some(v) if v.is_finite() => v,
            Some(_) => {
                self.bad
                    .get_or_insert((row, text.to_owned(), Kind::NonFinite));
                f64::NAN
            }
            None => {
                self.bad
                    .get_or_insert((row, text.to_owned(), Kind::NotANumber));
                f64::NAN
            }
        };
        self.values.push(v);
    }

    /// The column (times `scale`), its empty fields interpolated, or the error of its first
    /// bad field (named `name` in `path`).
    fn finish(
        self,
        path: &Path,
        name: &str,
        time_s: &[f64],
        scale: f64,
    ) -> Result<Vec<f64>, LogError> {
        if let Some((row, text, kind)) = self.bad {
            let what = match kind {
                Kind::NonFinite => "is not a finite number",
                _ => "is not a number",
            };
            return Err(LogError::new(
                kind,
                path,
                None,
                Some(name),
                format!(
                    "data row {}: {} {what}",
                    row + 1,
                    super::error::quoted_field(text.as_bytes())
                ),
            ));
        }
        let mut out = self.values;
        let mut filled = Vec::new();
        for (row, v) in out.iter_mut().enumerate() {
            if v.is_nan() {
                filled.push(row);
            } else {
                *v *= scale;
                if !v.is_finite() {
                    return Err(LogError::new(
                        Kind::NonFinite,
                        path,
                        None,
                        Some(name),
                        format!(
                            "data row {}: the value is beyond any number once converted to \
                             °/s; check it and --gyro-unit",
                            row + 1
                        ),
                    ));
                }
            }
        }
        for row in filled {
            let before = (0..row).rev().find(|&i| out[i].is_finite());
            let after = (row + 1..out.len()).find(|&i| out[i].is_finite());
            out[row] = match (before, after) {
                (Some(a), Some(b)) => {
                    let w = (time_s[row] - time_s[a]) / (time_s[b] - time_s[a]);
                    out[a] + w * (out[b] - out[a])
                }
                _ => {
                    return Err(LogError::new(
                        Kind::NotANumber,
                        path,
                        None,
                        Some(name),
                        format!("data row {}: the field is empty", row + 1),
                    ))
                }
            };
        }
        Ok(out)
    }
}

//! Column mapping: which header field holds time, gyro output, temperature and table rate
//! ([`ReadOptions`] names them), and which are passed through.

use std::path::Path;

use super::error::{LogError, LogErrorKind as Kind};
use super::number::parse_f64;
use super::{ReadOptions, DEFAULT_TABLE_COL};

/// Where the mapped columns sit in the header.
#[derive(Debug, Clone)]
pub(super) struct Columns {
    pub(super) time: usize,
    pub(super) gyro: usize,
    pub(super) temp: usize,
    pub(super) table: Option<usize>,
    /// Every other column, in file order.
    pub(super) extra: Vec<usize>,
}

pub(super) fn check_options(path: &Path, opts: &ReadOptions) -> Result<(), LogError> {
    let bad = |what: &str, v: f64| {
        LogError::new(
            Kind::BadOptions,
            path,
            None,
            None,
            format!("{what} must be a positive number of seconds, got {v}"),
        )
    };
    if opts.is_multi_column() {
        // Column lists are read by `read_imu_log`; this reader holds one gyro and one
        // temperature, and a list is no column name.
        return Err(LogError::new(
            Kind::BadOptions,
            path,
            None,
            None,
            format!(
                "this reads one gyro and one temperature column, not the lists {:?} and {:?}; \
                 name one of each (column lists are for the jobs on an inertial unit: train, \
                 compensate, evaluate, compare, report, plan, lot and allan)",
                opts.gyro_col, opts.temp_col
            ),
        ));
    }
    if let Some(v) = opts.fill_gaps_max_s {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad("--fill-gaps-max-s", v));
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
pub(super) fn map_columns(
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
        find(name, flag, what)?
            .ok_or_else(|| missing_column(path, line, headers, name, flag, what, opts.delimiter))
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
            opts.delimiter,
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
    opts_delimiter: u8,
) -> LogError {
    let found = headers
        .iter()
        .map(|h| format!("{h:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    let mut message =
        format!("required column not found; the header (line {line}) has: {found}; name the {what} column with {flag} NAME");
    // Which separator the header seems to use, when it is not the one being read with.
    let header = headers.join(&*String::from(char::from(opts_delimiter)));
    for (sep, sep_name, flag) in [
        (',', "commas", ","),
        (';', "';'", ";"),
        ('\t', "tabs", "tab"),
    ] {
        if sep as u8 != opts_delimiter && header.contains(sep) {
            message.push_str(&format!(
                " (the header seems to separate fields with {sep_name}: give --delimiter {flag})"
            ));
            break;
        }
    }
    let looks_like_data =
        !headers.is_empty() && headers.iter().all(|h| parse_f64(h.as_bytes()).is_some());
    if flag == "--time-col" && !looks_like_data {
        // A sample period cannot stand in for time stamps: the stamps are how a dropped
        // sample or a logger stall is seen (and ridden through) rather than silently closed up.
        message.push_str(
            " (time stamps cannot be replaced by --sample-period-s: they are how dropped \
             samples and stalls are found; if the logger wrote none, add a column of sample \
             index × period and say so in the test record)",
        );
    }
    if looks_like_data {
        message.push_str(
            " (the first line looks like data: add a header row such as time_s,gyro_dps,temp_c)",
        );
    }
    LogError::new(Kind::MissingColumn, path, Some(line), Some(name), message)
}

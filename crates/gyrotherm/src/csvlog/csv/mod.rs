//! The CSV format, read and written by every command (the format is described in
//! [`super`]'s docs): the log reader ([`reader`], one sample at a time, with its fast path
//! [`chunk`]), the header's column mapping ([`columns`]), number parsing ([`number`]), gap
//! filling ([`gaps`]), one line at a time for the line-by-line compensation ([`line`]), the
//! writer ([`writer`]), and an inertial unit's columns ([`unit`]).

pub(crate) mod chunk;
pub(crate) mod columns;
pub(crate) mod gaps;
pub(crate) mod line;
pub(crate) mod number;
pub(crate) mod reader;
pub(crate) mod unit;
pub(crate) mod writer;

use std::fs::File;
use std::path::Path;

// What the files here read from the rest of the log module, under their old `super::` names.
use super::{
    column_list, error, format, ExtraColumn, ImuLog, LogError, LogErrorKind, LogReader, LogWriter,
    NamedSeries, ReadOptions, ReadReport, TestLog, DEFAULT_TABLE_COL, GYRO_COL, MAX_LINE_BYTES,
    TEMP_COL, TIME_COL,
};

/// [`read_log`], the pass-through columns named in `numbers` (the first of each name) parsed
/// as they are read ([`unit::NumberColumn`]) instead of kept as text: such a column stays in
/// [`TestLog::extra`] by name only (no values), its numbers at the same index of the list
/// returned. A log read with several gyro or temperature columns parses them without holding
/// every field as a string first.
pub(crate) fn read_log_numbers(
    path: &Path,
    opts: &ReadOptions,
    numbers: &[&str],
) -> Result<(TestLog, ReadReport, Vec<Option<unit::NumberColumn>>), LogError> {
    let decimal_comma = opts.delimiter != b',';
    let file = File::open(path).map_err(|e| {
        LogError::new(
            LogErrorKind::Io,
            path,
            None,
            None,
            format!("cannot open: {e}"),
        )
    })?;
    let file_len = file.metadata().map(|m| m.len()).unwrap_or(0);
    let mut rdr = LogReader::new(file, path, opts)?;
    let mut log = TestLog::default();
    let mut table: Vec<f64> = Vec::new();
    let mut extra: Vec<Vec<String>> = vec![Vec::new(); rdr.extra_count()];
    let names: Vec<&str> = rdr.extra_names().collect();
    let mut parsed: Vec<Option<unit::NumberColumn>> = names
        .iter()
        .enumerate()
        .map(|(k, n)| {
            let first = names.iter().position(|m| m == n) == Some(k);
            (first && numbers.contains(n)).then(unit::NumberColumn::default)
        })
        .collect();
    drop(names);
    let mut sized = false;
    while let Some(s) = rdr.next_sample()? {
        if !sized {
            sized = true;
            // Rows = file length / bytes per row, +1 % for longer rows later on.
            let rows = rdr
                .bytes_per_row()
                .filter(|b| *b > 0.0)
                .map_or(0, |b| (file_len as f64 / b * 1.01) as usize + 16)
                .min(usize::MAX / 64);
            log.time_s.reserve_exact(rows);
            log.gyro_dps.reserve_exact(rows);
            log.temp_c.reserve_exact(rows);
            if rdr.has_table() {
                table.reserve_exact(rows);
            }
            for (col, num) in extra.iter_mut().zip(&mut parsed) {
                match num {
                    Some(n) => n.values.reserve_exact(rows),
                    None => col.reserve_exact(rows),
                }
            }
        }
        log.time_s.push(s.time_s);
        log.gyro_dps.push(s.gyro_dps);
        log.temp_c.push(s.temp_c);
        if let Some(t) = s.table_dps {
            table.push(t);
        }
        for (k, (col, num)) in extra.iter_mut().zip(&mut parsed).enumerate() {
            let text = rdr.extra_text(k)?;
            match num {
                Some(n) => n.push(text, decimal_comma),
                None => col.push(text.to_owned()),
            }
        }
    }
    if rdr.has_table() {
        log.table_dps = Some(table);
    }
    log.extra = rdr
        .extra_names()
        .zip(extra)
        .map(|(name, values)| ExtraColumn {
            name: name.to_owned(),
            values,
        })
        .collect();
    Ok((log, rdr.report().clone(), parsed))
}

/// Write a log as CSV (`time_s,gyro_dps,temp_c[,table_dps],extra...`), atomically (a
/// temporary file renamed into place). Numbers round-trip exactly: [`read_log`](super::read_log) of the
/// file gives back an equal [`TestLog`] (for a valid log: at least one row, time strictly
/// increasing without gaps). Refuses columns of unequal length, non-finite values and
/// extra columns named like a standard one.
pub fn write_log(path: &Path, log: &TestLog) -> Result<(), LogError> {
    write_log_with(path, log, WriteOptions::default())
}

/// What [`write_log_with`] lets through that [`write_log`] refuses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Write a NaN temperature as `NaN` (a simulated temperature-sensor fault; the flight
    /// compensator rides through it, the strict reader refuses it). Infinities are refused
    /// all the same.
    pub allow_nan_temperature: bool,
}

/// [`write_log`] with [`WriteOptions`].
pub fn write_log_with(path: &Path, log: &TestLog, opts: WriteOptions) -> Result<(), LogError> {
    let mut numeric = vec![
        Written::rate(GYRO_COL, &log.gyro_dps),
        Written::temperature(TEMP_COL, &log.temp_c),
    ];
    numeric.extend(
        log.table_dps
            .as_deref()
            .map(|t| Written::rate(DEFAULT_TABLE_COL, t)),
    );
    write_columns(path, &log.time_s, &numeric, &log.extra, opts)
}

/// Write an inertial unit's log (`time_s`, the gyro columns, the temperature columns, the
/// table column, the pass-through columns), atomically, with the checks of [`write_log`]; a
/// NaN temperature is written as `NaN` (a simulated sensor fault). A single gyro's log is
/// the unit of one axis: [`write_log`] writes the same bytes for it.
pub fn write_imu_log(path: &Path, log: &ImuLog) -> Result<(), LogError> {
    let opts = WriteOptions {
        allow_nan_temperature: true,
    };
    write_columns(path, &log.time_s, &unit_columns(log), &log.extra, opts)
}

/// A numeric column as written: its header, its values, and whether it is a temperature
/// (which [`WriteOptions::allow_nan_temperature`] lets hold NaN).
struct Written<'a> {
    name: &'a str,
    values: &'a [f64],
    temperature: bool,
}

impl<'a> Written<'a> {
    fn rate(name: &'a str, values: &'a [f64]) -> Self {
        Written {
            name,
            values,
            temperature: false,
        }
    }
    fn temperature(name: &'a str, values: &'a [f64]) -> Self {
        Written {
            name,
            values,
            temperature: true,
        }
    }
}

/// A unit's numeric columns in the order they are written: gyros, temperatures, table.
fn unit_columns(log: &ImuLog) -> Vec<Written<'_>> {
    let gyro = log.gyro.iter().map(|s| Written::rate(&s.name, &s.values));
    let temp = log
        .temp
        .iter()
        .map(|s| Written::temperature(&s.name, &s.values));
    let table = log.table.iter().map(|s| Written::rate(&s.name, &s.values));
    gyro.chain(temp).chain(table).collect()
}

/// The CSV of a unit's log, as [`write_imu_log`] writes it, into `w` (for a log the reader
/// gave: its columns' lengths are not checked again).
pub(crate) fn write_imu_csv<W: std::io::Write>(w: W, log: &ImuLog) -> std::io::Result<()> {
    write_csv(w, &log.time_s, &unit_columns(log), &log.extra)
}

fn write_csv<W: std::io::Write>(
    w: W,
    time_s: &[f64],
    numeric: &[Written],
    extra: &[ExtraColumn],
) -> std::io::Result<()> {
    let header = std::iter::once(TIME_COL)
        .chain(numeric.iter().map(|c| c.name))
        .chain(extra.iter().map(|c| c.name.as_str()));
    let mut out = LogWriter::new(w, header)?;
    for (i, t) in time_s.iter().enumerate() {
        out.push_f64(*t);
        for c in numeric {
            out.push_f64(c.values[i]);
        }
        for c in extra {
            out.push_raw(c.values[i].as_bytes());
        }
        out.end_row()?;
    }
    out.flush()
}

/// One writer for every log, a single gyro's and a unit's, atomically, after its checks:
/// every column as long as the time column; every number finite (a temperature may be NaN
/// when `opts` allows it); no pass-through column named like time, the table rate or a
/// numeric column, which would read back as that column.
fn write_columns(
    path: &Path,
    time_s: &[f64],
    numeric: &[Written],
    extra: &[ExtraColumn],
    opts: WriteOptions,
) -> Result<(), LogError> {
    let bad = |column: Option<&str>, message: String| {
        LogError::new(LogErrorKind::BadLog, path, None, column, message)
    };
    let n = time_s.len();
    let time = Written::rate(TIME_COL, time_s);
    for c in numeric.iter().chain(std::iter::once(&time)) {
        if c.values.len() != n {
            return Err(bad(
                Some(c.name),
                format!("{} values but {n} timestamps; not written", c.values.len()),
            ));
        }
        // A sensor fault reads as NaN; an infinity is a computation gone wrong, never written.
        let may_be_nan = c.temperature && opts.allow_nan_temperature;
        if let Some(i) = c
            .values
            .iter()
            .position(|x| !(x.is_finite() || may_be_nan && x.is_nan()))
        {
            return Err(bad(
                Some(c.name),
                format!(
                    "row {} holds {}, not a finite number; not written",
                    i + 1,
                    c.values[i]
                ),
            ));
        }
    }
    for c in extra {
        if c.values.len() != n {
            return Err(bad(
                Some(&c.name),
                format!("{} values but {n} timestamps; not written", c.values.len()),
            ));
        }
        let mut taken = [TIME_COL, DEFAULT_TABLE_COL]
            .into_iter()
            .chain(numeric.iter().map(|c| c.name));
        if taken.any(|name| name == c.name) {
            return Err(bad(
                Some(&c.name),
                "a pass-through column has a standard column's name; rename it".to_owned(),
            ));
        }
    }
    crate::atomic_file::write_atomically(path, |w| write_csv(w, time_s, numeric, extra)).map_err(
        |e| {
            let kind = if e.kind() == std::io::ErrorKind::BrokenPipe {
                LogErrorKind::OutputClosed
            } else {
                LogErrorKind::Io
            };
            LogError::new(kind, path, None, None, format!("cannot write: {e}"))
        },
    )
}

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
    check_log(path, log, opts)?;
    crate::atomic_file::write_atomically(path, |w| -> std::io::Result<()> {
        let mut header = vec![TIME_COL, GYRO_COL, TEMP_COL];
        if log.table_dps.is_some() {
            header.push(DEFAULT_TABLE_COL);
        }
        header.extend(log.extra.iter().map(|c| c.name.as_str()));
        let mut out = LogWriter::new(w, header)?;
        for i in 0..log.len() {
            out.push_f64(log.time_s[i]);
            out.push_f64(log.gyro_dps[i]);
            out.push_f64(log.temp_c[i]);
            if let Some(t) = &log.table_dps {
                out.push_f64(t[i]);
            }
            for c in &log.extra {
                out.push_raw(c.values[i].as_bytes());
            }
            out.end_row()?;
        }
        out.flush()
    })
    .map_err(|e| {
        let kind = if e.kind() == std::io::ErrorKind::BrokenPipe {
            LogErrorKind::OutputClosed
        } else {
            LogErrorKind::Io
        };
        LogError::new(kind, path, None, None, format!("cannot write: {e}"))
    })
}

fn check_log(path: &Path, log: &TestLog, opts: WriteOptions) -> Result<(), LogError> {
    let bad = |column: Option<&str>, message: String| {
        LogError::new(LogErrorKind::BadLog, path, None, column, message)
    };
    let n = log.len();
    let mut numeric = vec![
        (GYRO_COL, &log.gyro_dps),
        (TEMP_COL, &log.temp_c),
        (TIME_COL, &log.time_s),
    ];
    if let Some(t) = &log.table_dps {
        numeric.push((DEFAULT_TABLE_COL, t));
    }
    for (name, v) in numeric {
        if v.len() != n {
            return Err(bad(
                Some(name),
                format!("{} values but {n} timestamps; not written", v.len()),
            ));
        }
        // A sensor fault reads as NaN; an infinity is a computation gone wrong, never written.
        let may_be_nan = name == TEMP_COL && opts.allow_nan_temperature;
        if let Some(i) = v
            .iter()
            .position(|x| !(x.is_finite() || may_be_nan && x.is_nan()))
        {
            return Err(bad(
                Some(name),
                format!(
                    "row {} holds {}, not a finite number; not written",
                    i + 1,
                    v[i]
                ),
            ));
        }
    }
    for c in &log.extra {
        if c.values.len() != n {
            return Err(bad(
                Some(&c.name),
                format!("{} values but {n} timestamps; not written", c.values.len()),
            ));
        }
        if [TIME_COL, GYRO_COL, TEMP_COL, DEFAULT_TABLE_COL].contains(&c.name.as_str()) {
            return Err(bad(
                Some(&c.name),
                "a pass-through column has a standard column's name; rename it".to_owned(),
            ));
        }
    }
    Ok(())
}

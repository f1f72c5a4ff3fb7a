//! Compensate an inertial unit's CSV log line by line: what `gyrotherm compensate --stream`
//! runs with a unit model ([`crate::imu_model`]).
//!
//! The line handling is the single-axis stream's ([`compensate_lines`](mod@crate::compensate_lines)): the header
//! (comments and blank lines before it), the line cap [`MAX_LINE_BYTES`], the separator and
//! decimal comma, comment and blank lines dropped, one output line per data line, and
//! [`Mode::Strict`] (stop on a malformed line, naming file, line and column) or
//! [`Mode::Stream`] (write it as `invalid` and go on; a time that is a number but NaN,
//! infinite or out of order goes to the time axes). Every input field is written as it was,
//! then for each gyro column G of the model, in the model's order, the columns of batch
//! `compensate`: `G_bias` (°/s), `G_scale`, `G_comp` (°/s; empty when the axis is
//! `invalid`) and `G_status`.
//!
//! The numbers are those of flight code: the flight [`Unit`](gyrotherm_core::unit::Unit) of
//! [`gyrotherm_core::unit`] steps every axis with the line's time, gyro fields and all the
//! model's temperature fields, and each axis reads its own sensors (one, or several with a
//! model whose axes read further sensors), so a temperature field that is empty, not a number
//! or implausible holds only the axes that read it, and a gyro field
//! that is not a number (or NaN, infinite) makes only its own axis `invalid` (in
//! [`Mode::Strict`] a gyro field that is not a number stops the run, as a malformed line). A
//! bad time stamp reaches every axis alike. An axis whose further sensor is given up on runs
//! on its fallback model, if the model file has one, with status `fallback`
//! ([`gyrotherm_core::multi`]). The columns are looked up by the model's names;
//! the log must hold every gyro column and every temperature column an axis reads (the error
//! names the first missing); a column no axis reads is not looked for. Coverage columns and
//! extrapolation warnings are the single-axis stream's only.

use std::io::{BufRead, Write};
use std::path::Path;

use gyrotherm_core::compensator::{Corrected, Status};

use crate::compensate_lines::{
    check_added_columns, lines_to_file, parse_number, read_header, read_line_capped, record,
    split_and_time, too_long_error, Cadence, Fields, FileError, LineCheck, LineRead, LinesError,
    Mode, MAX_LINE_BYTES,
};
use crate::csvlog::{LogError, LogErrorKind, LogWriter, ReadOptions};
pub use crate::imu_model::MAX_STREAM_AXES;
use crate::imu_model::{imu_axis_compensators, ImuError, ImuModel};

pub use crate::flight_size::StreamUnit;

/// Suffixes of the columns added per gyro column, in order.
pub const AXIS_SUFFIXES: [&str; 4] = ["bias", "scale", "comp", "status"];

/// The names of the columns added for `model`: `G_bias`, `G_scale`, `G_comp`, `G_status`
/// per gyro column G.
pub fn output_columns(model: &ImuModel) -> Vec<String> {
    model
        .gyro_cols
        .iter()
        .flat_map(|g| AXIS_SUFFIXES.iter().map(move |s| format!("{g}_{s}")))
        .collect()
}

/// The flight unit of `model`: axis `i` runs axis `i`'s model on its sensors' indices among
/// the model's temperature columns (the first sensor's compensator and any further sensors'
/// parts, [`imu_axis_compensators`]), the same axes as batch [`crate::imu_model::compensate_imu`].
pub fn flight_unit(model: &ImuModel) -> Result<Box<StreamUnit>, ImuError> {
    let comps = imu_axis_compensators(model)?;
    // Boxed: a unit of 16 axes, each with its fallback, is some 370 KB (more with larger
    // LSTMs), more than a thread's stack holds in the copies a return by value can make.
    let unit = StreamUnit::of_axes(model.temp_cols.len(), comps).map_err(|(i, e)| {
        let gyro = model.axes.get(i).map_or("?", |a| a.gyro.as_str());
        ImuError::Layout(format!(
            "axis {gyro}: {e} (a unit runs at most {MAX_STREAM_AXES} axes)"
        ))
    })?;
    Ok(Box::new(unit))
}

/// Counts of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ImuLinesSummary {
    /// Data lines written (= data lines read).
    pub rows: u64,
    /// Malformed lines written as invalid on every axis ([`Mode::Stream`] only).
    pub malformed: u64,
    /// Per axis, in the model's order: lines ok, held, degraded, invalid, fallback (the
    /// codes of [`Status`]).
    pub per_axis: Vec<[u64; 5]>,
    /// What the lines do not show: time steps longer than the compensator runs at.
    pub warnings: Vec<String>,
}

impl ImuLinesSummary {
    /// `N lines (m malformed); gyro_x: ok a, held b, degraded c, invalid d; ...`, with
    /// `, fallback e` for an axis that ran on its fallback.
    pub fn describe(&self, gyro_cols: &[String]) -> String {
        let mut s = format!("{} lines", self.rows);
        if self.malformed > 0 {
            s.push_str(&format!(" ({} malformed)", self.malformed));
        }
        for (g, [ok, held, degraded, invalid, fallback]) in gyro_cols.iter().zip(&self.per_axis) {
            s.push_str(&format!(
                "; {g}: ok {ok}, held {held}, degraded {degraded}, invalid {invalid}"
            ));
            if *fallback > 0 {
                s.push_str(&format!(", fallback {fallback}"));
            }
        }
        s
    }
}

/// Compensate `input` (CSV with a header) with the unit model into `output`; see the module
/// doc. The columns are the model's: `opts` gives the time column, separator, gyro unit and
/// the rest; its gyro and temperature columns are not used. `source` names the input in
/// errors. With `flush_each_row` every line is flushed as soon as it is written.
pub fn compensate_imu_lines<R: BufRead, W: Write>(
    model: &ImuModel,
    mut input: R,
    source: &Path,
    opts: &ReadOptions,
    output: W,
    mode: Mode,
    flush_each_row: bool,
) -> Result<ImuLinesSummary, LinesError> {
    let mut unit = flight_unit(model).map_err(LinesError::Unit)?;
    let n_axes = model.gyro_cols.len();
    let read = model.temps_read();
    let (Some(gyro0), Some(temp0)) = (model.gyro_cols.first(), read.first()) else {
        return Err(LinesError::Unit(ImuError::Layout(
            "the model lists no gyro or no temperature column".into(),
        )));
    };
    // The log reader checks the header with the first gyro and sensor (its messages); the
    // other columns are looked up below.
    let first = ReadOptions {
        gyro_col: gyro0.clone(),
        temp_col: (*temp0).to_owned(),
        ..opts.clone()
    };
    let (headers, mut line_no) = read_header(&mut input, source, &first)?;
    let err = |kind, line, column: Option<&str>, message: String| {
        LinesError::Log(LogError::new(kind, source, Some(line), column, message))
    };
    let find = |name: &str, what: &str| {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            err(
                LogErrorKind::MissingColumn,
                line_no,
                Some(name),
                format!(
                    "{what} column not found, and the model needs it; the header has: {}",
                    headers.join(", ")
                ),
            )
        })
    };
    let ti = find(&opts.time_col, "time")?;
    let gi = model
        .gyro_cols
        .iter()
        .map(|g| find(g, "gyro"))
        .collect::<Result<Vec<_>, _>>()?;
    // A column no axis reads is not looked for: its channel stays NaN, which no axis sees.
    let ci = model
        .temp_cols
        .iter()
        .map(|t| {
            read.contains(&t.as_str())
                .then(|| find(t, "temperature"))
                .transpose()
        })
        .collect::<Result<Vec<_>, _>>()?;
    let gyro_scale = opts.gyro_unit.dps_per_unit();
    let delimiter = opts.delimiter;
    let decimal_comma = delimiter != b',';
    let added = output_columns(model);
    check_added_columns(&headers, added.iter().map(String::as_str), source, line_no)?;
    let mut writer = LogWriter::with_delimiter(
        output,
        headers
            .iter()
            .map(String::as_str)
            .chain(added.iter().map(String::as_str)),
        delimiter,
    )?;
    writer.set_flush_each_row(flush_each_row);
    let mut summary = ImuLinesSummary {
        per_axis: vec![[0; 5]; n_axes],
        ..ImuLinesSummary::default()
    };
    let mut fields = Fields::default();
    let mut buf = Vec::new();
    let mut last_time: Option<(f64, u64)> = None;
    // The axes share one time axis; the first axis's compensator steps as they all do.
    let mut cadence = unit
        .axis(0)
        .map(|a| Cadence::new(a.first().spec(), a.first().limits().degraded_after_s));
    let mut gyro = vec![0.0; n_axes];
    let mut temps = vec![0.0; ci.len()];
    // A line with no usable output: its fields (or empty ones), every axis invalid.
    let malformed = |writer: &mut LogWriter<W>,
                     summary: &mut ImuLinesSummary,
                     keep: Option<(&Fields, &[u8])>|
     -> std::io::Result<()> {
        for k in 0..headers.len() {
            writer.push_raw(keep.map_or(&[][..], |(f, line)| f.get(line, k)));
        }
        for counts in &mut summary.per_axis {
            for _ in 0..3 {
                writer.push_raw(b"");
            }
            writer.push_raw(Status::Invalid.as_str().as_bytes());
            counts[Status::Invalid as usize] += 1;
        }
        summary.malformed += 1;
        writer.end_row()
    };
    let check = LineCheck {
        source,
        headers: &headers,
        delimiter,
        time_index: ti,
        mode,
    };
    loop {
        let read = read_line_capped(&mut input, &mut buf, MAX_LINE_BYTES)?;
        if read == LineRead::Eof {
            break;
        }
        line_no += 1;
        if read == LineRead::TooLong {
            if mode == Mode::Strict {
                return Err(too_long_error(source, line_no));
            }
            summary.rows += 1;
            malformed(&mut writer, &mut summary, None)?;
            continue;
        }
        let Some(line) = record(&buf) else {
            continue;
        };
        summary.rows += 1;
        let parsed: Result<f64, LinesError> = (|| {
            let time_s = split_and_time(&mut fields, line, &check, line_no, last_time)?;
            for (g, &k) in gyro.iter_mut().zip(&gi) {
                *g = match parse_number(fields.get(line, k), decimal_comma) {
                    Some(v) => v * gyro_scale,
                    // One axis's fault: the others go on.
                    None if mode == Mode::Stream => f64::NAN,
                    None => {
                        return Err(err(
                            LogErrorKind::NotANumber,
                            line_no,
                            Some(&headers[k]),
                            format!(
                                "{:?} is not a number; fix the value or comment the line out \
                                 with '#'",
                                String::from_utf8_lossy(fields.get(line, k))
                            ),
                        ))
                    }
                };
            }
            // A temperature that is not a number is a sensor fault: NaN, held.
            for (c, k) in temps.iter_mut().zip(&ci) {
                *c = k
                    .and_then(|k| parse_number(fields.get(line, k), decimal_comma))
                    .unwrap_or(f64::NAN);
            }
            Ok(time_s)
        })();
        let time_s = match parsed {
            Ok(t) => t,
            Err(e) if mode == Mode::Strict => return Err(e),
            Err(_) => {
                let keep = fields.len() == headers.len();
                malformed(&mut writer, &mut summary, keep.then_some((&fields, line)))?;
                continue;
            }
        };
        if let (Some((t0, _)), Some(c)) = (last_time, cadence.as_mut()) {
            c.step(time_s - t0, mode, source, line_no)?;
        }
        last_time = Some((time_s, line_no));
        let out: [Corrected; MAX_STREAM_AXES] = unit.step(time_s, &gyro, &temps);
        for k in 0..fields.len() {
            writer.push_raw(fields.get(line, k));
        }
        for (c, counts) in out.iter().zip(&mut summary.per_axis) {
            writer.push_f64(c.bias_dps);
            writer.push_f64(c.scale);
            match c.rate() {
                Some(r) => writer.push_f64(r),
                None => writer.push_raw(b""),
            }
            writer.push_raw(c.status.as_str().as_bytes());
            counts[c.status as usize] += 1;
        }
        writer.end_row()?;
    }
    writer.flush()?;
    if summary.rows == 0 {
        return Err(err(
            LogErrorKind::NoData,
            line_no,
            None,
            "no data rows after the header; the log is empty or holds only comments".into(),
        ));
    }
    if let Some(c) = cadence.as_mut() {
        c.finish(mode, source, line_no)?;
        summary.warnings.extend(c.warning());
    }
    Ok(summary)
}

/// Compensate the unit log `input` into the CSV file `out` ([`Mode::Strict`]), written to a
/// temporary file and renamed into place: what `gyrotherm compensate --input --out` does with
/// a unit model. The same lines as the stream for every log the strict mode accepts.
pub fn compensate_imu_file(
    model: &ImuModel,
    input: &Path,
    out: &Path,
    opts: &ReadOptions,
) -> Result<ImuLinesSummary, FileError> {
    lines_to_file(input, out, opts, |r, w, opts| {
        compensate_imu_lines(model, r, input, opts, w, Mode::Strict, false)
    })
}

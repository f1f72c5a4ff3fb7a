//! Compensate an inertial unit's CSV log line by line: what `gyrotherm compensate --stream`
//! runs with a unit model ([`crate::model::unit`]).
//!
//! The line loop is the single-axis stream's ([`compensate_lines`](mod@crate::compensate_lines)):
//! the header (comments and blank lines before it), the line cap
//! [`MAX_LINE_BYTES`](crate::csvlog::MAX_LINE_BYTES), the separator and decimal comma, comment
//! and blank lines dropped, one output line per data line, and
//! [`Mode::Strict`] (stop on a malformed line, naming file, line and column) or
//! [`Mode::Stream`] (write it as `invalid` and go on; a time that is a number but NaN,
//! infinite or out of order goes to the time axes). Every input field is written as it was,
//! then for each gyro column G of the model, in the model's order, the columns of batch
//! `compensate`: `G_bias` (°/s), `G_scale`, `G_comp` (°/s; empty when the axis is
//! `invalid`), `G_status`, `G_coverage` and `G_sigma_dph` (the verdict of the axis's
//! coverage map on the latest step's T and dT of its first sensor, or of its fallback's while
//! it runs on it; empty without a verdict, as the single-axis stream's `coverage` and
//! `sigma_dph`).
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
//! names the first missing); a column no axis reads is not looked for. Extrapolation warnings
//! are the single-axis stream's only.

use std::io::{BufRead, Write};
use std::path::Path;

use gyrotherm_core::compensator::{Corrected, Status};

use super::{
    gyro_not_a_number, lines_to_file, push_corrected, push_invalid, push_verdict, read_header,
    run_lines, Cadence, FileError, LineCheck, LineModel, LinesError, Mode,
};
use crate::compensate::unit::imu_axis_compensators;
use crate::csvlog::{parse_number, Fields, LogError, LogErrorKind, LogWriter, ReadOptions};
pub use crate::model::unit::MAX_STREAM_AXES;
use crate::model::unit::{ImuError, ImuModel};
use gyrotherm_core::coverage::CoverageMap;

pub use crate::flight_size::StreamUnit;

/// Suffixes of the columns added per gyro column, in order.
pub(crate) const AXIS_SUFFIXES: [&str; 6] =
    ["bias", "scale", "comp", "status", "coverage", "sigma_dph"];

/// The names of the columns added for `model`: `G_bias`, `G_scale`, `G_comp`, `G_status`,
/// `G_coverage`, `G_sigma_dph` per gyro column G.
pub(crate) fn output_columns(model: &ImuModel) -> Vec<String> {
    model
        .gyro_cols
        .iter()
        .flat_map(|g| AXIS_SUFFIXES.iter().map(move |s| format!("{g}_{s}")))
        .collect()
}

/// The flight unit of `model`: axis `i` runs axis `i`'s model on its sensors' indices among
/// the model's temperature columns (the first sensor's compensator and any further sensors'
/// parts, [`imu_axis_compensators`]), the same axes as batch [`crate::compensate::unit::compensate_imu`].
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
    /// Per axis: lines per coverage verdict, inside, edge, outside (all 0 without a map).
    pub coverage: Vec<[u64; 3]>,
    /// What the lines do not show: time steps longer than the compensator runs at.
    pub warnings: Vec<String>,
}

impl ImuLinesSummary {
    /// `N lines (m malformed); gyro_x: ok a, held b, degraded c, invalid d; ...`, with
    /// `, fallback e` for an axis that ran on its fallback and `, coverage: inside i, edge j,
    /// outside k` for an axis with verdicts.
    pub fn describe(&self, gyro_cols: &[String]) -> String {
        let mut s = format!("{} lines", self.rows);
        if self.malformed > 0 {
            s.push_str(&format!(" ({} malformed)", self.malformed));
        }
        for (k, (g, [ok, held, degraded, invalid, fallback])) in
            gyro_cols.iter().zip(&self.per_axis).enumerate()
        {
            s.push_str(&format!(
                "; {g}: ok {ok}, held {held}, degraded {degraded}, invalid {invalid}"
            ));
            if *fallback > 0 {
                s.push_str(&format!(", fallback {fallback}"));
            }
            s.push_str(&self.coverage_counts(k));
        }
        s
    }

    /// `, coverage: inside i, edge j, outside k` for axis `k`, or nothing when it had no
    /// verdict.
    pub(crate) fn coverage_counts(&self, k: usize) -> String {
        match self.coverage.get(k) {
            Some([i, e, o]) if i + e + o > 0 => {
                format!(", coverage: inside {i}, edge {e}, outside {o}")
            }
            _ => String::new(),
        }
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
    let unit = flight_unit(model).map_err(LinesError::Unit)?;
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
    let (headers, line_no) = read_header(&mut input, source, &first)?;
    let find = |name: &str, what: &str| {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            LinesError::Log(LogError::new(
                LogErrorKind::MissingColumn,
                source,
                Some(line_no),
                Some(name),
                format!(
                    "{what} column not found, and the model needs it; the header has: {}",
                    headers.join(", ")
                ),
            ))
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
    // The axes share one time axis; the first axis's compensator steps as they all do.
    let Some(mut cadence) = unit
        .axis(0)
        .map(|a| Cadence::new(a.first().spec(), a.first().limits().degraded_after_s))
    else {
        return Err(LinesError::Unit(ImuError::Layout(
            "the model lists no gyro column".into(),
        )));
    };
    let check = LineCheck {
        source,
        headers: &headers,
        delimiter: opts.delimiter,
        time_index: ti,
        mode,
    };
    // The files' maps were checked when they were loaded.
    let map = |m: &crate::model::ModelFile| m.coverage.as_ref().and_then(|c| c.to_core().ok());
    let mut axes = Axes {
        maps: model
            .axes
            .iter()
            .map(|a| (map(&a.model), a.fallback.as_ref().and_then(map)))
            .collect(),
        coverage: vec![[0; 3]; n_axes],
        gyro: vec![0.0; n_axes],
        temps: vec![0.0; ci.len()],
        unit,
        gyro_columns: gi,
        temp_columns: ci,
        gyro_scale: opts.gyro_unit.dps_per_unit(),
        per_axis: vec![[0; 5]; n_axes],
    };
    let added = output_columns(model);
    let counts = run_lines(
        &mut input,
        output,
        flush_each_row,
        &check,
        added.iter().map(String::as_str),
        line_no,
        &mut cadence,
        &mut axes,
    )?;
    Ok(ImuLinesSummary {
        rows: counts.rows,
        malformed: counts.malformed,
        per_axis: axes.per_axis,
        coverage: axes.coverage,
        warnings: cadence.warning().into_iter().collect(),
    })
}

/// A unit's part of the line loop: every axis steps on the line's time, its gyro field and
/// the temperature fields it reads.
struct Axes {
    unit: Box<StreamUnit>,
    /// The gyro columns' indices, in the model's order.
    gyro_columns: Vec<usize>,
    /// Per model temperature column, its index (none when no axis reads it).
    temp_columns: Vec<Option<usize>>,
    gyro_scale: f64,
    /// The line's gyro rates (°/s) and temperatures, as parsed.
    gyro: Vec<f64>,
    temps: Vec<f64>,
    per_axis: Vec<[u64; 5]>,
    /// Per axis, its coverage map and its fallback's (None without one).
    maps: Vec<(Option<CoverageMap>, Option<CoverageMap>)>,
    coverage: Vec<[u64; 3]>,
}

impl LineModel for Axes {
    fn parse(
        &mut self,
        fields: &Fields,
        line: &[u8],
        check: &LineCheck<'_>,
        line_no: u64,
    ) -> Result<(), LinesError> {
        let decimal_comma = check.delimiter != b',';
        for (g, &k) in self.gyro.iter_mut().zip(&self.gyro_columns) {
            *g = match parse_number(fields.get(line, k), decimal_comma) {
                Some(v) => v * self.gyro_scale,
                // One axis's fault: the others go on.
                None if check.mode == Mode::Stream => f64::NAN,
                None => return Err(gyro_not_a_number(check, fields, line, line_no, k)),
            };
        }
        // A temperature that is not a number is a sensor fault: NaN, held.
        for (c, k) in self.temps.iter_mut().zip(&self.temp_columns) {
            *c = k
                .and_then(|k| parse_number(fields.get(line, k), decimal_comma))
                .unwrap_or(f64::NAN);
        }
        Ok(())
    }

    fn step<W: Write>(&mut self, time_s: f64, writer: &mut LogWriter<W>) {
        let out: [Corrected; MAX_STREAM_AXES] = self.unit.step(time_s, &self.gyro, &self.temps);
        for (k, (c, counts)) in out.iter().zip(&mut self.per_axis).enumerate() {
            push_corrected(writer, c);
            counts[c.status as usize] += 1;
            // On its fallback the axis runs the fallback's model: its map, on its features.
            let verdict = self.unit.axis(k).and_then(|axis| {
                let (map, fallback_map) = &self.maps[k];
                match axis.fallback() {
                    Some(f) if axis.on_fallback() => {
                        fallback_map.as_ref()?.verdict_of(f.features())
                    }
                    _ => map.as_ref()?.verdict_of(axis.features()),
                }
            });
            if let Some(v) = verdict {
                self.coverage[k][v.coverage as usize] += 1;
            }
            push_verdict(writer, verdict);
        }
    }

    fn malformed<W: Write>(&mut self, writer: &mut LogWriter<W>) {
        for counts in &mut self.per_axis {
            push_invalid(writer);
            push_verdict(writer, None);
            counts[Status::Invalid as usize] += 1;
        }
    }
}

/// Compensate the unit log `input` into the CSV file `out` ([`Mode::Strict`]), written to a
/// temporary file and renamed into place: what `gyrotherm compensate --input --out` does with
/// a unit model. The same lines as the stream for every log the strict mode accepts.
pub(crate) fn compensate_imu_file(
    model: &ImuModel,
    input: &Path,
    out: &Path,
    opts: &ReadOptions,
) -> Result<ImuLinesSummary, FileError> {
    lines_to_file(input, out, opts, |r, w, opts| {
        compensate_imu_lines(model, r, input, opts, w, Mode::Strict, false)
    })
}

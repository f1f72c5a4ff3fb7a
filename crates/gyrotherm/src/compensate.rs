//! Apply a fitted model to a log: the ground side of the flight [`Compensator`].
//!
//! Batch compensation runs the same `gyrotherm-core` compensator sample by sample that
//! `compensate --stream` and flight code run, so the numbers are identical by construction.

use gyrotherm_core::compensator::{Compensator, NormalisedLstm, TargetModel, HIDDEN, LSTM_INPUTS};

use crate::csvlog::LogError;
use crate::csvlog::TestLog;
use crate::model::{ModelFile, SubModel};
use crate::model::{ModelFileError, Target};
use crate::nn::params::{LstmParams, ParamsError};
use crate::nn::zscore::ZScore;
use gyrotherm_core::baseline::BaselineError;
use gyrotherm_core::compensator::ModelError as FlightModelError;
use gyrotherm_core::error::InputError;
use std::path::PathBuf;

/// Compensated series of one log, one value per sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Compensated {
    /// Predicted bias B, °/s.
    pub bias_dps: Vec<f64>,
    /// Predicted scale factor K, dimensionless.
    pub scale: Vec<f64>,
    /// G = (Ĝ - B) / K, °/s.
    pub gyro_comp_dps: Vec<f64>,
}

/// Widen an LSTM to the flight input count: input columns beyond `input_size` get weight 0.
fn padded_core_lstm(
    params: &LstmParams,
) -> Result<gyrotherm_core::lstm::LstmWeights<LSTM_INPUTS, HIDDEN>, CompensateError> {
    let i = params.input_size;
    if i > LSTM_INPUTS {
        return Err(CompensateError::LstmInputs { inputs: i });
    }
    let mut wide = params.clone();
    wide.input_size = LSTM_INPUTS;
    wide.w_ih = params
        .w_ih
        .chunks(i.max(1))
        .flat_map(|row| {
            let mut r = row.to_vec();
            r.resize(LSTM_INPUTS, 0.0);
            r
        })
        .collect();
    wide.to_core::<LSTM_INPUTS, HIDDEN>()
        .map_err(CompensateError::Params)
}

fn core_lstm(
    params: &LstmParams,
    input_norm: &ZScore,
    target_norm: &ZScore,
) -> Result<NormalisedLstm, CompensateError> {
    let w = padded_core_lstm(params)?;
    NormalisedLstm::new(
        &w,
        &input_norm.mean,
        &input_norm.std,
        target_norm.mean[0],
        target_norm.std[0],
    )
    .map_err(CompensateError::Flight)
}

/// The flight model of one target (`None`: the constant `absent`).
pub fn target_model(sub: Option<&SubModel>, absent: f64) -> Result<TargetModel, CompensateError> {
    let Some(sub) = sub else {
        return Ok(TargetModel::constant(absent));
    };
    let baseline = sub
        .baseline_core()
        .transpose()
        .map_err(CompensateError::Baseline)?;
    let lstm = match sub {
        SubModel::Lstm {
            params,
            input_norm,
            target_norm,
        }
        | SubModel::Residual {
            params,
            input_norm,
            target_norm,
            ..
        } => Some(core_lstm(params, input_norm, target_norm)?),
        SubModel::Baseline { .. } => None,
    };
    let lstm_reads_base = matches!(
        sub,
        SubModel::Residual {
            lstm_reads_base: true,
            ..
        }
    );
    Ok(TargetModel {
        offset: 0.0,
        baseline,
        lstm,
        lstm_reads_base,
    })
}

/// The flight compensator of a model file (bias 0 °/s and K = 1 where a target is absent).
pub fn compensator(model: &ModelFile) -> Result<Compensator, CompensateError> {
    let spec = model.feature_spec().map_err(CompensateError::Model)?;
    let in_target = |target| {
        move |e| CompensateError::InTarget {
            target,
            source: Box::new(e),
        }
    };
    let bias = target_model(model.bias.as_ref(), 0.0).map_err(in_target(Target::Bias))?;
    let scale = target_model(model.scale.as_ref(), 1.0).map_err(in_target(Target::Scale))?;
    Compensator::new(spec, bias, scale).map_err(CompensateError::Flight)
}

/// Compensate a whole log with the flight compensator. The error names the sample.
pub fn compensate_log(model: &ModelFile, log: &TestLog) -> Result<Compensated, CompensateError> {
    let mut comp = compensator(model)?;
    let n = log.len();
    let mut out = Compensated {
        bias_dps: Vec::with_capacity(n),
        scale: Vec::with_capacity(n),
        gyro_comp_dps: Vec::with_capacity(n),
    };
    for i in 0..n {
        let c = comp
            .step(log.time_s[i], log.gyro_dps[i], log.temp_c[i])
            .map_err(|source| CompensateError::Sample {
                sample: i + 1,
                time_s: log.time_s[i],
                source,
            })?;
        out.bias_dps.push(c.bias_dps);
        out.scale.push(c.scale);
        out.gyro_comp_dps.push(c.rate_dps);
    }
    Ok(out)
}

/// Warnings, with the numbers, when `log` leaves the model's training temperature or
/// temperature-rate range (the model then extrapolates).
pub fn extrapolation_warnings(model: &ModelFile, log: &TestLog) -> Vec<String> {
    let Ok(spec) = model.feature_spec() else {
        return Vec::new();
    };
    let Ok(table) = crate::features::extract(log, &spec) else {
        return Vec::new();
    };
    match (table.range(0), table.range(1)) {
        (Some(t), Some(r)) => range_warnings(model, t, r),
        _ => Vec::new(),
    }
}

/// Warnings for a seen temperature range (°C) and temperature-rate range (°C/s) outside the
/// model's training ranges. A margin of 2 % of the training span absorbs sensor noise.
pub(crate) fn range_warnings(
    model: &ModelFile,
    temp_c: (f64, f64),
    rate_c_per_s: (f64, f64),
) -> Vec<String> {
    let t = &model.training;
    let checks = [
        ("temperature", "°C", temp_c, t.temp_range_c, 1.0),
        (
            "temperature rate",
            "°C/min",
            rate_c_per_s,
            t.rate_range_c_per_s,
            60.0,
        ),
    ];
    let mut out = Vec::new();
    for (what, unit, (lo, hi), range, scale) in checks {
        let margin = 0.02 * (range.max - range.min);
        if lo < range.min - margin || hi > range.max + margin {
            out.push(format!(
                "{what} {:.3} to {:.3} {unit} leaves the training range {:.3} to {:.3} {unit}; the model extrapolates there",
                lo * scale,
                hi * scale,
                range.min * scale,
                range.max * scale
            ));
        }
    }
    out
}

/// Columns appended by [`compensate_stream`].
pub const OUTPUT_COLUMNS: [&str; 3] = ["bias_dps", "scale", "gyro_comp_dps"];

/// What a streaming compensation saw.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StreamSummary {
    /// Rows written.
    pub rows: u64,
    /// Rows made by gap filling.
    pub filled_rows: u64,
    /// Extrapolation warnings (temperature or its rate outside the training range).
    pub warnings: Vec<String>,
}

/// Compensate a CSV log from `input` to `output`, one output row per input row: every input
/// column as it was, then `bias_dps`, `scale` and `gyro_comp_dps` (°/s). Runs the flight
/// [`Compensator`] sample by sample, so batch files and `--stream` give identical numbers.
/// With `flush_each_row` every row is flushed as soon as it is written.
pub fn compensate_stream<R: std::io::Read, W: std::io::Write>(
    model: &ModelFile,
    input: R,
    source: &std::path::Path,
    opts: &crate::csvlog::ReadOptions,
    output: W,
    flush_each_row: bool,
) -> Result<StreamSummary, CompensateError> {
    use crate::csvlog::{LogReader, LogWriter};
    let mut comp = compensator(model)?;
    let mut reader = LogReader::new(input, source, opts).map_err(CompensateError::Log)?;
    let headers: Vec<String> = reader.headers().to_vec();
    let mut writer = LogWriter::new(
        output,
        headers.iter().map(String::as_str).chain(OUTPUT_COLUMNS),
    )
    .map_err(|e| CompensateError::Write {
        what: "the header",
        source: e,
    })?;
    writer.set_flush_each_row(flush_each_row);
    let col = |name: &str| headers.iter().position(|h| h.trim() == name);
    let (ti, gi, ci, tabi) = (
        col(&opts.time_col),
        col(&opts.gyro_col),
        col(&opts.temp_col),
        col(&opts.table_col),
    );
    let mut summary = StreamSummary::default();
    let mut temp_seen = (f64::INFINITY, f64::NEG_INFINITY);
    let mut rate_seen = (f64::INFINITY, f64::NEG_INFINITY);
    while let Some(s) = reader.next_sample().map_err(CompensateError::Log)? {
        let c = comp
            .step(s.time_s, s.gyro_dps, s.temp_c)
            .map_err(|e| CompensateError::Line {
                path: source.to_path_buf(),
                line: reader.line(),
                source: e,
            })?;
        if let Some(f) = comp.features() {
            let f = f.as_slice();
            if let [t, r, ..] = f {
                temp_seen = (temp_seen.0.min(*t), temp_seen.1.max(*t));
                rate_seen = (rate_seen.0.min(*r), rate_seen.1.max(*r));
            }
        }
        match reader.record() {
            Some(rec) if !reader.is_filled() => {
                for field in rec.iter() {
                    writer.push_raw(field);
                }
            }
            _ => {
                summary.filled_rows += 1;
                for k in 0..headers.len() {
                    let v = if Some(k) == ti {
                        Some(s.time_s)
                    } else if Some(k) == gi {
                        // The filled value in the file's own unit is not kept; write °/s.
                        Some(s.gyro_dps)
                    } else if Some(k) == ci {
                        Some(s.temp_c)
                    } else if Some(k) == tabi {
                        s.table_dps
                    } else {
                        None
                    };
                    match v {
                        Some(v) => writer.push_f64(v),
                        None => writer.push_raw(b""),
                    }
                }
            }
        }
        writer.push_f64(c.bias_dps);
        writer.push_f64(c.scale);
        writer.push_f64(c.rate_dps);
        writer.end_row().map_err(|e| CompensateError::Write {
            what: "output",
            source: e,
        })?;
        summary.rows += 1;
    }
    writer.flush().map_err(|e| CompensateError::Write {
        what: "output",
        source: e,
    })?;
    if temp_seen.0 <= temp_seen.1 {
        summary.warnings = range_warnings(model, temp_seen, rate_seen);
    }
    summary
        .warnings
        .extend(reader.report().jitter_warning(source));
    Ok(summary)
}

/// Why a model could not be turned into the flight compensator, or a log not compensated: the
/// target, sample, line or value at fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum CompensateError {
    /// The model file's feature definition.
    Model(ModelFileError),
    /// The LSTM reads more inputs than flight code takes.
    LstmInputs { inputs: usize },
    /// The LSTM parameters cannot be exported.
    Params(ParamsError),
    /// The least-squares part cannot be evaluated in flight.
    Baseline(BaselineError),
    /// The flight crate refused the model.
    Flight(FlightModelError),
    /// In the bias or scale-factor model.
    InTarget {
        target: Target,
        source: Box<CompensateError>,
    },
    /// The compensator refused sample `sample` (counted from 1) of a log.
    Sample {
        sample: usize,
        time_s: f64,
        source: InputError,
    },
    /// The compensator refused the sample on line `line` of file `path`.
    Line {
        path: PathBuf,
        line: u64,
        source: InputError,
    },
    /// The input log cannot be read.
    Log(LogError),
    /// Writing `what` failed.
    Write {
        what: &'static str,
        source: std::io::Error,
    },
}

impl std::fmt::Display for CompensateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CompensateError::Model(e) => e.fmt(f),
            CompensateError::LstmInputs { inputs } => write!(
                f,
                "the LSTM reads {inputs} inputs; flight code takes at most {LSTM_INPUTS}"
            ),
            CompensateError::Params(e) => e.fmt(f),
            CompensateError::Baseline(e) => e.fmt(f),
            CompensateError::Flight(e) => e.fmt(f),
            CompensateError::InTarget { target, source } => {
                write!(f, "{}: {source}", target.as_str())
            }
            CompensateError::Sample {
                sample,
                time_s,
                source,
            } => write!(f, "sample {sample} (time {time_s} s): {source}"),
            CompensateError::Line { path, line, source } => {
                write!(f, "{}:{line}: {source}", path.display())
            }
            CompensateError::Log(e) => e.fmt(f),
            CompensateError::Write { what, source } => write!(f, "writing {what}: {source}"),
        }
    }
}

impl std::error::Error for CompensateError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CompensateError::Model(e) => Some(e),
            CompensateError::Params(e) => Some(e),
            CompensateError::Baseline(e) => Some(e),
            CompensateError::InTarget { source, .. } => Some(source.as_ref()),
            CompensateError::Sample { source, .. } | CompensateError::Line { source, .. } => {
                Some(source)
            }
            CompensateError::Log(e) => Some(e),
            CompensateError::Write { source, .. } => Some(source),
            CompensateError::LstmInputs { .. } | CompensateError::Flight(_) => None,
        }
    }
}

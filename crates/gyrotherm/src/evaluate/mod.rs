//! The figures of one log (`evaluate`): one entry ([`evaluate`]) for a single gyro's column
//! and for each axis of a unit, with a model's compensated output beside the raw one and a
//! spec sheet's verdict. The result is written as text or JSON without the caller asking
//! which form it holds.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::csvlog::{read_one, ColumnError, ImuLog, LogError, OneLog, ReadOptions, TestLog};
use crate::metrics::{Evaluation, EvaluationError};
use crate::settings::evaluate::EvaluateError;
use crate::settings::EvaluateSettings;
use crate::spec::unit::ImuJudgeError;
use crate::spec::{MeasureOptions, Spec, SpecError, Verdict};
use crate::told::Told;
use crate::unit_model::Model;
use unit::{evaluate_imu_spec, UnitEvaluation};

pub mod unit;

/// What to evaluate and how.
#[derive(Debug, Clone, Copy)]
pub struct EvaluateJob<'a> {
    /// The log.
    pub input: &'a Path,
    /// How to read it (a model's columns are read in its place).
    pub read: &'a ReadOptions,
    /// The gyro column a unit's rate table turns (None: found from the data).
    pub table_axis: Option<&'a str>,
    /// A model whose compensated output is judged beside the raw one (a single gyro's model
    /// is the unit of its one axis).
    pub model: Option<&'a Model>,
    pub settings: &'a EvaluateSettings,
    pub spec: Option<&'a Spec>,
}

/// Why a log could not be evaluated.
#[derive(Debug)]
#[non_exhaustive]
pub enum EvaluateJobError {
    /// The log at `path` could not be read.
    Read { path: PathBuf, source: LogError },
    /// The column asked for is not in the log at `path`.
    Column { path: PathBuf, source: ColumnError },
    /// The log at `path` has no sample period.
    Period { path: PathBuf },
    /// The figures could not be computed.
    Evaluate(EvaluateError),
    /// The figures the spec sheet needs could not be measured on the log named `log`.
    Measure {
        log: String,
        source: EvaluationError,
    },
    /// The spec sheet's verdict.
    Spec(SpecError),
    /// A unit's figures, on the log named `log`.
    Unit {
        log: String,
        source: Box<ImuJudgeError>,
    },
}

impl std::fmt::Display for EvaluateJobError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EvaluateJobError::Read { path, .. } => write!(f, "cannot use log {}", path.display()),
            EvaluateJobError::Column { path, .. } => write!(f, "{}", path.display()),
            EvaluateJobError::Period { path } => write!(
                f,
                "{}: cannot tell the sample period (need at least two samples with increasing \
                 time_s)",
                path.display()
            ),
            EvaluateJobError::Evaluate(e) => e.fmt(f),
            EvaluateJobError::Measure { log, .. } | EvaluateJobError::Unit { log, .. } => {
                f.write_str(log)
            }
            EvaluateJobError::Spec(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for EvaluateJobError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            EvaluateJobError::Read { source, .. } => Some(source),
            EvaluateJobError::Column { source, .. } => Some(source),
            EvaluateJobError::Measure { source, .. } => Some(source),
            EvaluateJobError::Unit { source, .. } => Some(source.as_ref()),
            // Transparent: these errors' own messages are this one's.
            EvaluateJobError::Evaluate(e) => e.source(),
            EvaluateJobError::Spec(e) => e.source(),
            EvaluateJobError::Period { .. } => None,
        }
    }
}

/// A log's figures, with what to tell about reading and τ.
#[derive(Debug)]
pub struct Evaluated {
    form: Form,
    /// Lines about reading the log and the τ used.
    pub told: Vec<Told>,
}

#[derive(Debug)]
enum Form {
    Single {
        figures: Evaluation,
        verdict: Option<Verdict>,
    },
    Unit(UnitEvaluation),
}

/// The figures of the log: a single gyro's column, or each gyro axis of a unit's log (a
/// unit's when the options name several columns, the file's format holds a unit, or a model
/// is given, whose columns are read and whose output is judged beside the raw one). The log
/// is read through the one entry every job reads through ([`read_log_set`](crate::csvlog::read_log_set)).
pub fn evaluate(job: &EvaluateJob) -> Result<Evaluated, EvaluateJobError> {
    let path = job.input;
    let model = job.model.map(|m| m.to_unit(job.read));
    let opts = match &model {
        Some(m) => m.read_options(job.read),
        None => job.read.clone(),
    };
    let unit = model.is_some() || job.read.reads_unit(&[path]);
    let read =
        read_one(path, &opts, job.table_axis, unit).map_err(|source| EvaluateJobError::Read {
            path: path.to_path_buf(),
            source,
        })?;
    match read.log {
        OneLog::Single(log) => evaluate_single(job, log, read.told),
        OneLog::Unit(log) => evaluate_unit(job, model.as_deref(), &log, read.told),
    }
}

fn evaluate_single(
    job: &EvaluateJob,
    mut log: TestLog,
    mut told: Vec<Told>,
) -> Result<Evaluated, EvaluateJobError> {
    let path = job.input;
    let log_name = job.read.log_column(&job.settings.column).to_owned();
    let values = log
        .take_column(&log_name)
        .map_err(|source| EvaluateJobError::Column {
            path: path.to_path_buf(),
            source,
        })?;
    let tau0_s = log.sample_period_s();
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(EvaluateJobError::Period {
            path: path.to_path_buf(),
        });
    }
    let settings = EvaluateSettings {
        column: log_name.clone(),
        ..job.settings.clone()
    };
    let (mut figures, tau) = settings
        .evaluate(&log, &values, tau0_s)
        .map_err(EvaluateJobError::Evaluate)?;
    // Named as in the file (the user's --gyro-col, not the standard `gyro_dps`).
    figures.column = job.read.file_column(&log_name).to_owned();
    told.extend(tau.note(tau0_s).map(Told::Line));
    let verdict = match job.spec {
        Some(spec) => {
            let (rate_dps, opts, _) = settings
                .prepare(&values, tau0_s)
                .map_err(EvaluateJobError::Evaluate)?;
            let mopts = MeasureOptions {
                evaluation: opts,
                noise_terms: spec.needs_noise_terms(),
            };
            let name = path.display().to_string();
            let f = crate::spec::measure(&log, &rate_dps, &mopts).map_err(|source| {
                EvaluateJobError::Measure {
                    log: name.clone(),
                    source,
                }
            })?;
            Some(crate::spec::judge(spec, &[(name, f)]).map_err(EvaluateJobError::Spec)?)
        }
        None => None,
    };
    Ok(Evaluated {
        form: Form::Single { figures, verdict },
        told,
    })
}

fn evaluate_unit(
    job: &EvaluateJob,
    model: Option<&crate::model::unit::ImuModel>,
    log: &ImuLog,
    mut told: Vec<Told>,
) -> Result<Evaluated, EvaluateJobError> {
    let name = job.input.display().to_string();
    let unit = evaluate_imu_spec(log, model, job.settings, job.spec, &name).map_err(|source| {
        EvaluateJobError::Unit {
            log: name.clone(),
            source: Box::new(source),
        }
    })?;
    told.extend(
        unit.tau
            .note(unit.axes[0].raw.sample_period_s)
            .map(Told::Line),
    );
    Ok(Evaluated {
        form: Form::Unit(unit),
        told,
    })
}

impl Evaluated {
    /// Whether the figures meet the spec sheet (true without one).
    pub fn pass(&self) -> bool {
        match &self.form {
            Form::Single { verdict, .. } => verdict.as_ref().is_none_or(|v| v.pass),
            Form::Unit(u) => u.verdict.as_ref().is_none_or(|v| v.pass),
        }
    }

    /// The figures as JSON (`evaluate --json`): a single gyro's figures with their verdict;
    /// a unit's axes, each carrying its verdict as the single-axis output does, and the
    /// unit's verdict beside them.
    pub fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        match &self.form {
            Form::Single { figures, verdict } => {
                let mut j = serde_json::to_value(figures)?;
                if let (Some(v), Some(o)) = (verdict, j.as_object_mut()) {
                    o.insert("verdict".into(), serde_json::to_value(v)?);
                }
                Ok(j)
            }
            Form::Unit(u) => Ok(u.to_json()),
        }
    }

    /// The figures as text (a unit: per axis, raw and compensated), then the verdicts.
    pub fn write_text(&self, w: &mut dyn Write) -> std::io::Result<()> {
        match &self.form {
            Form::Single { figures, verdict } => {
                write_figures(w, figures)?;
                if let Some(v) = verdict {
                    writeln!(w)?;
                    write_verdict(w, v)?;
                }
            }
            Form::Unit(unit) => write_unit(w, unit)?,
        }
        Ok(())
    }
}

fn write_unit(w: &mut dyn Write, unit: &UnitEvaluation) -> std::io::Result<()> {
    let axes = &unit.axes;
    for (k, a) in axes.iter().enumerate() {
        if k > 0 {
            writeln!(w)?;
        }
        match &a.compensated {
            Some(c) => {
                writeln!(
                    w,
                    "axis {}: {} (model reads {})",
                    k + 1,
                    a.gyro,
                    a.temps.join(", ")
                )?;
                writeln!(w, "raw:")?;
                write_figures(w, &a.raw)?;
                writeln!(w, "compensated:")?;
                write_figures(w, c)?;
            }
            None => {
                writeln!(w, "axis {}: {}", k + 1, a.gyro)?;
                write_figures(w, &a.raw)?;
            }
        }
        if let Some(v) = &a.verdict {
            writeln!(w)?;
            writeln!(w, "axis {} ({}) against the spec:", k + 1, a.gyro)?;
            write_verdict(w, v)?;
        }
    }
    if let Some(v) = &unit.verdict {
        writeln!(w)?;
        writeln!(w, "{}", v.line(axes.len()))?;
    }
    Ok(())
}

fn write_verdict(w: &mut dyn Write, v: &Verdict) -> std::io::Result<()> {
    for line in v.lines() {
        writeln!(w, "{line}")?;
    }
    Ok(())
}

/// The figures of one column as text (the single-axis output, and each axis's block of a
/// unit log).
fn write_figures(w: &mut dyn Write, e: &Evaluation) -> std::io::Result<()> {
    writeln!(
        w,
        "{} ({} samples, τ0 = {} s)",
        e.column, e.samples, e.sample_period_s
    )?;
    writeln!(w, "bias                 {:>14} °/h", num(e.bias_dph, 6))?;
    writeln!(
        w,
        "bias stability       {:>14} °/h (1σ of {} means of {} s{})",
        num(e.bias_stability_dph, 6),
        e.means,
        e.tau_s,
        if e.stop_segments_only {
            ", stop segments only"
        } else {
            ""
        }
    )?;
    if let Some(r) = &e.scale {
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| num(x, 3));
        writeln!(w, "scale factor         {:>14}", num(r.scale_factor, 9))?;
        writeln!(
            w,
            "nonlinearity         {:>14} ppm",
            num(r.nonlinearity_ppm, 3)
        )?;
        writeln!(w, "asymmetry            {:>14} ppm", opt(r.asymmetry_ppm))?;
        writeln!(
            w,
            "SF thermal error     {:>14} ppm (max |K(t) − K_ref|, K_ref = {}, {} rate segments)",
            num(r.sf_thermal_error_ppm, 3),
            num(r.reference_scale, 9),
            r.scale_over_time.len()
        )?;
    }
    Ok(())
}

/// Fixed-point with `prec` decimals for ordinary magnitudes, scientific beyond (a figure of
/// 1e28 °/h is not printed as 29 digits).
fn num(x: f64, prec: usize) -> String {
    if x != 0.0 && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:.prec$e}")
    } else {
        format!("{x:.prec$}")
    }
}

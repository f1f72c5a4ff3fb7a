//! Training a model on a job's logs: one entry ([`train`]) for a single gyro and for an
//! inertial unit. A single gyro's logs give a single-gyro model file, a unit's logs a unit's
//! file ([`Model`] holds either); what the fit did is told the same way for both.

use std::path::Path;

use crate::csvlog::{ImuLog, LogSet, LogSetForm, ReadOptions};
use crate::fit::unit::{fit_imu_with_events, ImuFitEvent, UnitFitError};
use crate::fit::{fit_model, FitConfig, FitError, NamedLog, Target};
use crate::model::unit::ImuModel;
use crate::model::{ColumnsDef, TempSensorDef};
use crate::told::Told;
use crate::unit_model::Model;

/// What a fit tells as it runs (from the fit's threads).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TrainEvent {
    /// An LSTM of the model finished epoch `epoch` (0-based) with this loss.
    Epoch {
        target: Target,
        epoch: usize,
        loss: f64,
    },
    /// A step of the fit, as a line for the user.
    Step(String),
    /// A step of a unit's fit, per axis and sensor (from the axes' threads).
    Axis(AxisStep),
}

/// A step of a unit's fit: the event, the names of its axis and sensor, and its line for
/// the user.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisStep {
    pub event: ImuFitEvent,
    /// The axis's gyro column.
    pub gyro: String,
    /// The sensor's temperature column (None when an axis starts).
    pub temp: Option<String>,
    /// The step as a line, with the seconds since the fit started.
    pub line: String,
}

/// Why a model could not be trained.
#[derive(Debug)]
#[non_exhaustive]
pub enum TrainError {
    /// A single gyro's fit.
    Single(FitError),
    /// An inertial unit's fit.
    Unit(UnitFitError),
}

impl std::fmt::Display for TrainError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Transparent: the fit's error is this error's own.
        match self {
            TrainError::Single(e) => e.fmt(f),
            TrainError::Unit(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for TrainError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            TrainError::Single(e) => e.source(),
            TrainError::Unit(e) => e.source(),
        }
    }
}

/// A trained model, with what to tell about it once written.
#[derive(Debug)]
pub struct Trained {
    pub model: Model,
    summary: String,
    told: Vec<Told>,
}

impl Trained {
    /// What to tell once the model is written to `out`, `seconds` after training started: the
    /// `wrote` line, then what each target or axis holds and how it scored.
    pub fn told(&self, out: &Path, seconds: f64) -> Vec<Told> {
        let mut told = vec![Told::Line(format!(
            "wrote {} ({}) in {seconds:.1} s",
            out.display(),
            self.summary
        ))];
        told.extend(self.told.iter().cloned());
        told
    }
}

/// The epochs a progress bar per LSTM should count, when the fit trains LSTMs one at a time
/// (a single gyro's recipe); None when it trains none or several at once (the axes of a
/// unit run on threads and tell their steps instead).
pub fn epoch_bars(logs: &LogSet, cfg: &FitConfig) -> Option<usize> {
    match logs.form() {
        LogSetForm::Single(_) if cfg.model_method().is_recipe() => Some(cfg.recipe.epochs),
        _ => None,
    }
}

/// Fit a model on `logs`: a single gyro's model, or one per axis of a unit (each axis on its
/// own thread, each of its sensors in turn). `temp_sensor` holds the limits the compensator
/// believes; `columns` the read options, which a single-gyro file remembers so that
/// `compensate` reads a log of the same layout without them.
pub fn train(
    logs: &LogSet,
    cfg: &FitConfig,
    temp_sensor: &TempSensorDef,
    columns: &ReadOptions,
    events: &(dyn Fn(TrainEvent) + Sync),
) -> Result<Trained, TrainError> {
    match logs.form() {
        LogSetForm::Single(logs) => train_single(logs, cfg, temp_sensor, columns, events),
        LogSetForm::Unit(logs) => train_unit(logs, cfg, temp_sensor, events),
    }
}

fn train_single(
    logs: &[(String, crate::csvlog::TestLog)],
    cfg: &FitConfig,
    temp_sensor: &TempSensorDef,
    columns: &ReadOptions,
    events: &(dyn Fn(TrainEvent) + Sync),
) -> Result<Trained, TrainError> {
    let named: Vec<NamedLog> = logs
        .iter()
        .map(|(n, l)| NamedLog { name: n, log: l })
        .collect();
    let mut outcome = fit_model(&named, cfg, &|target, epoch, loss| {
        events(TrainEvent::Epoch {
            target,
            epoch,
            loss,
        })
    })
    .map_err(TrainError::Single)?;
    outcome.model.features.temp_sensor = *temp_sensor;
    outcome.model.columns = Some(ColumnsDef::of(columns));
    let m = &outcome.model;
    let summary = format!(
        "{} model; bias: {}, scale factor: {}",
        m.method.as_str(),
        if m.bias.is_some() {
            "fitted"
        } else {
            "none (no static log)"
        },
        if m.scale.is_some() {
            "fitted"
        } else {
            "none (no rate-table log)"
        },
    );
    // Each line of the description is indented under the `wrote` line.
    let told = outcome
        .describe(&named, cfg)
        .into_iter()
        .map(|l| Told::Item(l.strip_prefix("  ").map_or(l.clone(), str::to_owned)))
        .collect();
    Ok(Trained {
        model: Model::from_single(outcome.model),
        summary,
        told,
    })
}

fn train_unit(
    logs: &[(String, ImuLog)],
    cfg: &FitConfig,
    temp_sensor: &TempSensorDef,
    events: &(dyn Fn(TrainEvent) + Sync),
) -> Result<Trained, TrainError> {
    for (name, l) in logs {
        let what = l
            .table_axis
            .as_deref()
            .map_or("static".to_owned(), |a| format!("rate table on {a}"));
        events(TrainEvent::Step(format!("{name}: {what}")));
    }
    let axes = logs.first().map_or(0, |(_, l)| l.gyro.len());
    let sensors = logs.first().map_or(0, |(_, l)| l.temp.len());
    events(TrainEvent::Step(format!(
        "fitting {axes} axes on their own threads, each on {sensors} sensor(s) in turn"
    )));
    let started = std::time::Instant::now();
    let step = |s: AxisStep| events(TrainEvent::Axis(s));
    let steps = step_lines(started, logs, &step);
    let model = fit_imu_with_events(logs, cfg, temp_sensor, &|_, _, _, _, _| {}, &steps)
        .map_err(TrainError::Unit)?;
    let summary = format!("{} model for {axes} axes", cfg.model_method().as_str());
    let told = axis_lines(&model);
    Ok(Trained {
        model: Model::from_unit(model),
        summary,
        told,
    })
}

/// Per axis: the sensors it reads, what it fitted and each sensor's cross-validated score,
/// on the bias (°/h) when the axis had a static run, else on the scale factor (ppm): in the
/// units a gyro engineer reads; with `auto`, a second line with every candidate's score and
/// the choice.
fn axis_lines(model: &ImuModel) -> Vec<Told> {
    let fitted = |b: bool| if b { "fitted" } else { "none" };
    model
        .axes
        .iter()
        .flat_map(|a| {
            let on_bias = a.model.bias.is_some();
            let scores: Vec<String> = a
                .scores
                .iter()
                .map(|s| match s.cv_rms {
                    Some(r) if on_bias => format!("{} {:.4} °/h", s.temp, r * 3600.0),
                    Some(r) => format!("{} {:.2} ppm", s.temp, r * 1e6),
                    None => format!("{} -", s.temp),
                })
                .collect();
            let line = Told::Item(format!(
                "{}: reads {} (bias: {}, scale factor: {}); one-sensor cross-validated RMS of \
                 the {}: {}",
                a.gyro,
                a.temps.join(", "),
                fitted(a.model.bias.is_some()),
                fitted(a.model.scale.is_some()),
                if on_bias { "bias" } else { "scale factor" },
                scores.join(", ")
            ));
            let choice = a
                .model
                .method_choice
                .as_ref()
                .map(|c| Told::Item(format!("{}: {}", a.gyro, c.describe())));
            std::iter::once(line).chain(choice)
        })
        .collect()
}

/// A line for each step of a unit fit ([`ImuFitEvent`]): the axis and sensor, with the
/// seconds since `started` (the axes run on threads, so lines of several axes interleave;
/// each line names its axis).
pub(crate) fn step_lines<'a>(
    started: std::time::Instant,
    logs: &[(String, ImuLog)],
    events: &'a (dyn Fn(AxisStep) + Sync),
) -> impl Fn(ImuFitEvent) + Sync + 'a {
    let (gyro, temp) = logs
        .first()
        .map(|(_, l)| l.column_names())
        .unwrap_or_default();
    move |e: ImuFitEvent| {
        let at = started.elapsed().as_secs_f64();
        let g = |k: usize| gyro.get(k).map_or("?", String::as_str);
        let t = |j: usize| temp.get(j).map_or("?", String::as_str);
        let (axis, sensor) = match e {
            ImuFitEvent::AxisStarted { axis } | ImuFitEvent::Scoring { axis, .. } => (axis, None),
            ImuFitEvent::SensorStarted { axis, sensor }
            | ImuFitEvent::SensorFinished { axis, sensor, .. }
            | ImuFitEvent::AxisFinished { axis, sensor }
            | ImuFitEvent::LstmTraining { axis, sensor } => (axis, Some(sensor)),
        };
        let line = match e {
            ImuFitEvent::AxisStarted { axis } => format!(
                "[{at:6.1} s] {}: axis starts ({} sensor(s) to try)",
                g(axis),
                temp.len()
            ),
            ImuFitEvent::SensorStarted { axis, sensor } => format!(
                "[{at:6.1} s] {}: fitting on {} (sensor {} of {})",
                g(axis),
                t(sensor),
                sensor + 1,
                temp.len()
            ),
            ImuFitEvent::SensorFinished {
                axis,
                sensor,
                cv_rms,
            } => format!(
                "[{at:6.1} s] {}: {} done (cross-validated RMS {})",
                g(axis),
                t(sensor),
                cv_rms.map_or("-".to_owned(), |r| format!("{r:.3e}"))
            ),
            ImuFitEvent::AxisFinished { axis, sensor } => {
                format!("[{at:6.1} s] {}: axis done, reads {}", g(axis), t(sensor))
            }
            ImuFitEvent::Scoring { axis, run, of } => format!(
                "[{at:6.1} s] {}: auto: fitting thermal and thermal-lstm without static run {} \
                 of {} and scoring them on it",
                g(axis),
                run + 1,
                of
            ),
            ImuFitEvent::LstmTraining { axis, sensor } => format!(
                "[{at:6.1} s] {}: auto: training thermal-lstm on {}",
                g(axis),
                t(sensor)
            ),
        };
        events(AxisStep {
            event: e,
            gyro: g(axis).to_owned(),
            temp: sensor.map(|j| t(j).to_owned()),
            line,
        });
    }
}

//! Fitting an inertial unit's model ([`ImuModel`]): per gyro axis a bias and a scale-factor
//! model, on the temperature sensors it reads.
//!
//! By default ([`ImuSensors::All`]) every axis may read every listed sensor: with the
//! `thermal` method each sensor's lags are identified on its own, the sensor whose one-sensor
//! fit has the lowest cross-validated RMS comes first, and the others join while they lower
//! the cross-validated RMS ([`crate::fit::thermal::multi`]); the axis's model is then the first
//! sensor's model plus each further sensor's linear part ([`SensorModel`]), run by the flight
//! [`AxisCompensator`](gyrotherm_core::multi::AxisCompensator). With [`ImuSensors::ChooseOne`] (and for methods without
//! cross-validation, which keep the first sensor) each axis reads one sensor, an ordinary
//! single-sensor [`ModelFile`]. The axes fit on their own threads. A fault in one sensor
//! reaches only the axes that read it. An axis with further sensors also keeps its first
//! sensor's one-sensor model as its `fallback` ([`ImuAxis::fallback`]), which it runs on
//! (status `fallback`) while a further sensor is given up on.
//!
//! With `thermal-lstm` (and [`ImuSensors::All`]) an axis that reads several sensors gets the
//! residual LSTM on its several-sensor fit: the LSTM reads the first sensor's thermal states
//! and learns the residual of the whole fit, and flies as the first sensor's model with the
//! further parts added. With `auto` each axis keeps its `thermal` fit,
//! exactly as `thermal` builds it, or that fit with the LSTM on it, exactly as `thermal-lstm`
//! builds it, whichever scores lower on held-out validation of the training runs (as `auto`
//! scores one gyro, [`crate::fit::auto`]); the axis's model records both scores and the
//! choice ([`ModelFile::method_choice`]).
//!
//! [`SensorModel`]: crate::model::unit::SensorModel
//! [`ModelFile`]: crate::model::ModelFile
//! [`ModelFile::method_choice`]: crate::model::ModelFile::method_choice

use crate::csvlog::{ImuLog, TestLog};
use crate::fit::{
    chooses_method, fit_model, uses_identification, FitConfig, FitError, FitOutcome, NamedLog,
};
use crate::model::unit::{
    axis_checks, check_axis_count, ImuAxis, ImuError, ImuModel, SensorScore, IMU_FORMAT_VERSION,
    IMU_FORMAT_VERSION_ONE_SENSOR,
};
use crate::model::TempSensorDef;
use crate::per_thread::on_threads;
pub use crate::settings::fit::{ImuFitSettings, ImuSensors};

mod auto;
mod several;

use auto::fit_axis_auto;
use several::fit_axis_multi;

/// Why an inertial unit's model cannot be fitted.
#[derive(Debug)]
#[non_exhaustive]
pub enum UnitFitError {
    /// Fitting axis `gyro` on sensor `temp` failed.
    Fit {
        gyro: String,
        temp: String,
        source: Box<FitError>,
    },
    /// The logs do not make a unit, or the model fitted is not valid.
    Model(ImuError),
}

impl From<ImuError> for UnitFitError {
    fn from(e: ImuError) -> Self {
        UnitFitError::Model(e)
    }
}

impl std::fmt::Display for UnitFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            UnitFitError::Fit { gyro, temp, .. } => {
                write!(f, "fitting axis {gyro} on sensor {temp} failed")
            }
            // Transparent: the model's error is this error's own.
            UnitFitError::Model(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for UnitFitError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            UnitFitError::Fit { source, .. } => Some(source.as_ref()),
            UnitFitError::Model(e) => e.source(),
        }
    }
}

/// Progress of an inertial-unit fit: axis index, sensor index, and the fit's own progress
/// (target, epoch, loss), as [`fit_model`] reports it.
pub(crate) type ImuProgress<'a> = dyn Fn(usize, usize, crate::fit::Target, usize, f64) + Sync + 'a;

/// A step of an inertial-unit fit, as it happens (from the axes' threads): what a caller
/// needs to say which axis and sensor are being fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ImuFitEvent {
    /// Axis `axis` starts (its sensors are then tried in column order).
    AxisStarted { axis: usize },
    /// Axis `axis` starts its fit on sensor `sensor` (indices into the column lists).
    SensorStarted { axis: usize, sensor: usize },
    /// Axis `axis` finished its fit on sensor `sensor`, with its cross-validated RMS.
    SensorFinished {
        axis: usize,
        sensor: usize,
        cv_rms: Option<f64>,
    },
    /// Axis `axis` is done and reads sensor `sensor` first (and any further sensors chosen).
    AxisFinished { axis: usize, sensor: usize },
    /// `auto`: axis `axis` fits both candidates without the `run`-th of its `of` static runs
    /// (counted from 0) and scores them on it.
    Scoring { axis: usize, run: usize, of: usize },
    /// `auto`: axis `axis` trains `thermal-lstm` on sensor `sensor` (a candidate to score on
    /// held-out blocks, or the choice).
    LstmTraining { axis: usize, sensor: usize },
}

/// Receiver of [`ImuFitEvent`]s.
pub(crate) type ImuEvents<'a> = dyn Fn(ImuFitEvent) + Sync + 'a;

/// Fit every axis of the unit with the default [`ImuFitSettings`] (see [`fit_imu_with`]).
pub fn fit_imu(
    logs: &[(String, ImuLog)],
    cfg: &FitConfig,
    temp_sensor: &TempSensorDef,
    progress: &ImuProgress,
) -> Result<ImuModel, UnitFitError> {
    fit_imu_with(logs, cfg, &ImuFitSettings::default(), temp_sensor, progress)
}

/// [`fit_imu`], telling `events` as each axis and each sensor tried starts and finishes.
pub(crate) fn fit_imu_with_events(
    logs: &[(String, ImuLog)],
    cfg: &FitConfig,
    temp_sensor: &TempSensorDef,
    progress: &ImuProgress,
    events: &ImuEvents,
) -> Result<ImuModel, UnitFitError> {
    fit_imu_full(
        logs,
        cfg,
        &ImuFitSettings::default(),
        temp_sensor,
        progress,
        events,
    )
}

/// Fit every axis of the unit (see the module doc): logs read with the column lists; each
/// axis on its own thread; `temp_sensor` the limits every axis's compensator believes.
pub fn fit_imu_with(
    logs: &[(String, ImuLog)],
    cfg: &FitConfig,
    settings: &ImuFitSettings,
    temp_sensor: &TempSensorDef,
    progress: &ImuProgress,
) -> Result<ImuModel, UnitFitError> {
    fit_imu_full(logs, cfg, settings, temp_sensor, progress, &|_| {})
}

/// [`fit_imu_with`], telling `events` as each axis and each sensor tried starts and finishes.
pub(crate) fn fit_imu_full(
    logs: &[(String, ImuLog)],
    cfg: &FitConfig,
    settings: &ImuFitSettings,
    temp_sensor: &TempSensorDef,
    progress: &ImuProgress,
    events: &ImuEvents,
) -> Result<ImuModel, UnitFitError> {
    let (gyro_cols, temp_cols) = ImuLog::shared_columns(logs)
        .map_err(|name| {
            ImuError::Layout(format!(
                "{name}: the training logs must be read with the same gyro and temperature columns"
            ))
        })?
        .ok_or_else(|| ImuError::Layout("no training logs".into()))?;
    // Before any fit: a model that could not be compensated is not worth the hours.
    check_axis_count(gyro_cols.len())?;
    // `auto` fits each axis's several-sensor `thermal` candidate as `thermal` does.
    let auto = settings.sensors == ImuSensors::All && chooses_method(cfg);
    let multi_path = settings.sensors == ImuSensors::All && (uses_identification(cfg) || auto);
    // What the lag search takes of each temperature column depends on no axis: made once per
    // sensor and run (a thread per sensor) for all the axes that read it.
    let shared: Vec<Vec<Option<SharedTables>>> = if multi_path {
        on_threads(temp_cols.len(), |j| {
            logs.iter()
                .map(|(_, l)| crate::fit::thermal::shared_tables(&l.time_s, &l.temp[j].values))
                .collect::<Vec<_>>()
        })
    } else {
        Vec::new()
    };
    let job = UnitJob {
        logs,
        shared: &shared,
        gyro_cols: &gyro_cols,
        temp_cols: &temp_cols,
        cfg,
        settings,
        temp_sensor,
        progress,
        events,
    };
    type Checked = (ImuAxis, Result<(), ImuError>);
    let axes: Vec<Result<Checked, UnitFitError>> = on_threads(gyro_cols.len(), |k| {
        let axis = if auto {
            fit_axis_auto(&job, k)
        } else if multi_path {
            fit_axis_multi(&job, k)
        } else {
            fit_axis(&job, k)
        }?;
        // The axis's part of the model's checks, here while other axes still fit.
        let checked = axis_checks(job.temp_cols, &axis);
        Ok((axis, checked))
    });
    let (axes, checks): (Vec<ImuAxis>, Vec<_>) = axes
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .unzip();
    let several = axes.iter().any(|a| !a.more.is_empty());
    let model = ImuModel {
        imu_format_version: if several {
            IMU_FORMAT_VERSION
        } else {
            IMU_FORMAT_VERSION_ONE_SENSOR
        },
        gyro_cols,
        temp_cols,
        axes,
    };
    // ImuModel::validate, its per-axis part made in the axes' threads.
    model.validate_columns()?;
    checks.into_iter().collect::<Result<(), _>>()?;
    Ok(model)
}

/// One unit fit's inputs, the same for every axis (each axis's fit runs on its own thread).
#[derive(Clone, Copy)]
struct UnitJob<'a> {
    logs: &'a [(String, ImuLog)],
    /// The temperature columns' search features per sensor and run (empty: made per axis).
    shared: &'a [Vec<Option<SharedTables>>],
    gyro_cols: &'a [String],
    temp_cols: &'a [String],
    cfg: &'a FitConfig,
    settings: &'a ImuFitSettings,
    temp_sensor: &'a TempSensorDef,
    progress: &'a ImuProgress<'a>,
    events: &'a ImuEvents<'a>,
}

/// Axis `k` on the sensor whose one-sensor fit cross-validates best.
fn fit_axis(job: &UnitJob, k: usize) -> Result<ImuAxis, UnitFitError> {
    let UnitJob {
        logs,
        gyro_cols,
        temp_cols,
        cfg,
        temp_sensor,
        progress,
        events,
        ..
    } = *job;
    events(ImuFitEvent::AxisStarted { axis: k });
    let mut best: Option<(usize, FitOutcome)> = None;
    let mut scores = Vec::with_capacity(temp_cols.len());
    for (j, temp) in temp_cols.iter().enumerate() {
        events(ImuFitEvent::SensorStarted { axis: k, sensor: j });
        let axis_logs: Vec<(String, TestLog)> = logs
            .iter()
            .map(|(n, l)| (n.clone(), l.axis_data(k, j)))
            .collect();
        let named: Vec<NamedLog> = axis_logs
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect();
        let outcome =
            fit_model(&named, cfg, &|t, e, loss| progress(k, j, t, e, loss)).map_err(|source| {
                UnitFitError::Fit {
                    gyro: gyro_cols[k].clone(),
                    temp: temp.clone(),
                    source: Box::new(source),
                }
            })?;
        let cv = |t: &Option<crate::fit::TrainSummary>| {
            t.as_ref()
                .and_then(|s| s.thermal.as_ref())
                .and_then(|r| r.cv_rms)
        };
        let cv_rms = if outcome.model.bias.is_some() {
            cv(&outcome.bias_training)
        } else {
            cv(&outcome.scale_training)
        };
        events(ImuFitEvent::SensorFinished {
            axis: k,
            sensor: j,
            cv_rms,
        });
        scores.push(SensorScore {
            temp: temp.clone(),
            cv_rms,
        });
        let better = match &best {
            None => true,
            Some((b, _)) => match (cv_rms, scores[*b].cv_rms) {
                (Some(new), Some(old)) => new < old,
                _ => false,
            },
        };
        if better {
            best = Some((j, outcome));
        }
    }
    let (j, mut outcome) = best.ok_or_else(|| ImuError::Layout("no temperature columns".into()))?;
    outcome.model.features.temp_sensor = *temp_sensor;
    events(ImuFitEvent::AxisFinished { axis: k, sensor: j });
    Ok(ImuAxis {
        gyro: gyro_cols[k].clone(),
        temps: vec![temp_cols[j].clone()],
        scores,
        model: outcome.model,
        more: Vec::new(),
        multi_cv_rms: None,
        fallback: None,
    })
}

/// A temperature column's features for the lag search (published spec, no lags).
type SharedTables = (crate::features::FeatureTable, crate::features::FeatureTable);

/// Why axis `gyro`'s fit on sensor `temp` failed.
fn fit_error(gyro: &str, temp: &str, source: FitError) -> UnitFitError {
    UnitFitError::Fit {
        gyro: gyro.to_owned(),
        temp: temp.to_owned(),
        source: Box::new(source),
    }
}

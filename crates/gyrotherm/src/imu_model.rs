//! One model file for an inertial unit: per gyro axis a bias and a scale-factor model, the
//! gyro columns and the temperature sensors the unit's log must hold, and which sensors each
//! axis reads.
//!
//! By default ([`ImuSensors::All`]) every axis may read every listed sensor: with the
//! `thermal` method each sensor's lags are identified on its own, the sensor whose one-sensor
//! fit has the lowest cross-validated RMS comes first, and the others join while they lower
//! the cross-validated RMS ([`crate::fit::thermal::multi`]); the axis's model is then the first
//! sensor's model plus each further sensor's linear part ([`SensorModel`]), run by the flight
//! [`AxisCompensator`]. With [`ImuSensors::ChooseOne`] (and for methods without
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
//! The file is JSON with `imu_format_version` (which tells it from a single-axis file, whose
//! format is unchanged): 1 when every axis reads one sensor (as older builds wrote), 2 when
//! an axis reads several; sealed with `content_sha256` like a single-axis file. It is read
//! with a single-axis file's checks ([`crate::model`]): a key named twice is refused, a file
//! without its seal is read with a warning for the caller to tell ([`Seal::warning`]), every
//! axis's model is checked as a single-axis model, each further sensor's parts as least-squares
//! sub-models (plausible coefficients, one per term), and B and K of the whole axis, further
//! sensors included, must stay plausible over the training range. A unit has 1 to
//! [`MAX_STREAM_AXES`] axes, each on a gyro column of its own.

use serde::{Deserialize, Serialize};
use std::path::Path;

use gyrotherm_core::compensator::Status;
use gyrotherm_core::features::LagOutputs;
use gyrotherm_core::multi::{AxisCompensator, MAX_SENSORS};

use crate::compensate::{hidden_size, sized_compensator};
use crate::csvlog::{ImuLog, ReadOptions, TestLog};
use crate::fit::thermal::multi::{self, MultiConfig, SensorData};
use crate::fit::thermal::Identified;
use crate::fit::{
    chooses_method, fit_model, uses_identification, FitConfig, FitError, FitOutcome, NamedLog,
};
use crate::flight_size::build_sized;
use crate::flight_size::{FlightAxis, HiddenSize};
pub use crate::imu_error::ImuError;
use crate::model::{
    content_digest_of, parse_sealed, ModelFile, Seal, SealedTextError, SubModel, Target,
    TempSensorDef, CHECKSUM_KEY,
};
use crate::settings::fit::IMU_IDENTIFY_EVERY;
pub use crate::settings::fit::{ImuFitSettings, ImuSensors};
use crate::targets::{self, TargetSet};

pub use crate::flight_size::MAX_STREAM_AXES;

/// Version of the inertial-unit file layout when an axis reads several sensors.
pub const IMU_FORMAT_VERSION: u32 = 2;
/// Version of the layout when every axis reads one sensor (the first layout; such files are
/// written as before).
pub const IMU_FORMAT_VERSION_ONE_SENSOR: u32 = 1;
/// The key that marks an inertial-unit model file.
pub(crate) const IMU_VERSION_KEY: &str = "imu_format_version";

/// A sensor tried for an axis and its score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorScore {
    /// The temperature column.
    pub temp: String,
    /// Cross-validated RMS of the fit on this sensor (bias °/s, or K for a scale-only
    /// axis); None when the method has no cross-validation.
    pub cv_rms: Option<f64>,
}

/// A further sensor an axis reads (`temps[i + 1]` for `more[i]`): its lags and its parts of
/// the bias and the scale factor, each a baseline over that sensor's features (`T, dT,
/// T − lag_j(T)`, the first sensor's step period and rate lag) without a constant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorModel {
    /// Time constants of this sensor's lags, s, fastest first.
    pub lags_s: Vec<f64>,
    /// Its part of the bias, °/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<SubModel>,
    /// Its part of the scale factor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<SubModel>,
}

/// One gyro axis of the unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuAxis {
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns this axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// Every sensor tried, in column order, with its one-sensor score.
    pub scores: Vec<SensorScore>,
    /// The first sensor's bias and scale-factor model (the whole model with one sensor).
    pub model: ModelFile,
    /// The further sensors' parts, in the order of `temps[1..]` (empty: one sensor).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub more: Vec<SensorModel>,
    /// Cross-validated RMS of the bias on all the sensors read (with several).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multi_cv_rms: Option<f64>,
    /// With further sensors: the one-sensor model on the first sensor alone (its `thermal`
    /// fit), which the axis runs on while a further sensor is given up on (status
    /// `fallback`, [`gyrotherm_core::multi`]). Files written before it have none: such an
    /// axis stays held and then degraded while a further sensor is lost.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<ModelFile>,
}

/// An inertial unit's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuModel {
    /// [`IMU_FORMAT_VERSION`].
    pub imu_format_version: u32,
    /// The gyro columns, in the order of the axes (and of the exported `gyro[]`).
    pub gyro_cols: Vec<String>,
    /// The temperature columns, in the order of the exported `temp[]`.
    pub temp_cols: Vec<String>,
    /// One entry per gyro column, same order.
    pub axes: Vec<ImuAxis>,
}

/// Whether model-file text is an inertial unit's (it has [`IMU_VERSION_KEY`]): the one place
/// the two file forms are told apart (by `unit_model::Model::load`).
pub(crate) fn is_imu_model_text(text: &str) -> bool {
    serde_json::from_str::<serde_json::Value>(text.strip_prefix('\u{feff}').unwrap_or(text))
        .ok()
        .and_then(|v| v.get(IMU_VERSION_KEY).cloned())
        .is_some()
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
) -> Result<ImuModel, ImuError> {
    fit_imu_with(logs, cfg, &ImuFitSettings::default(), temp_sensor, progress)
}

/// [`fit_imu`], telling `events` as each axis and each sensor tried starts and finishes.
pub(crate) fn fit_imu_with_events(
    logs: &[(String, ImuLog)],
    cfg: &FitConfig,
    temp_sensor: &TempSensorDef,
    progress: &ImuProgress,
    events: &ImuEvents,
) -> Result<ImuModel, ImuError> {
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
) -> Result<ImuModel, ImuError> {
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
) -> Result<ImuModel, ImuError> {
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
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..temp_cols.len())
                .map(|j| {
                    scope.spawn(move || {
                        logs.iter()
                            .map(|(_, l)| {
                                crate::fit::thermal::shared_tables(&l.time_s, &l.temp[j].values)
                            })
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
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
    let axes: Vec<Result<Checked, ImuError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..gyro_cols.len())
            .map(|k| {
                scope.spawn(move || {
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
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| match h.join() {
                Ok(r) => r,
                Err(p) => std::panic::resume_unwind(p),
            })
            .collect()
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
fn fit_axis(job: &UnitJob, k: usize) -> Result<ImuAxis, ImuError> {
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
                ImuError::Fit {
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

/// One axis's training data on every sensor, each sensor's lags identified on the runs given
/// (all of them, or all but one for a fold of `auto`'s validation).
struct AxisRuns {
    /// The runs' columns for this axis, the temperature column of the sensor last put in place
    /// ([`use_sensor`]).
    axis_logs: Vec<(String, TestLog)>,
    /// Per sensor, in column order: its identification and its bias and scale-factor training
    /// sets (in run order).
    per_sensor: Vec<(Identified, Vec<TargetSet>, Vec<TargetSet>)>,
}

impl AxisRuns {
    /// Every sensor's identification and training sets, as the selection reads them.
    fn data(&self) -> Vec<SensorData<'_>> {
        self.per_sensor
            .iter()
            .map(|(id, bias, scale)| SensorData { id, bias, scale })
            .collect()
    }

    /// The runs as the fit reads them, with the temperature column last put in place.
    fn named(&self) -> Vec<NamedLog<'_>> {
        self.axis_logs
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect()
    }
}

/// Puts sensor `j`'s temperature column in place in each run's axis columns (`runs`: the
/// runs' indices in `logs`, in the order of `axis_logs`; the rest is the same for every
/// sensor).
fn use_sensor(
    axis_logs: &mut [(String, TestLog)],
    logs: &[(String, ImuLog)],
    runs: &[usize],
    j: usize,
) {
    for ((_, a), &i) in axis_logs.iter_mut().zip(runs) {
        a.temp_c.clear();
        a.temp_c.extend_from_slice(&logs[i].1.temp[j].values);
    }
}

/// The several-sensor fits' settings: the thermal recipe's (an experiment may override the
/// ridge grid) and the selection's.
fn multi_settings<'c>(
    cfg: &'c FitConfig,
    settings: &ImuFitSettings,
) -> (
    std::borrow::Cow<'c, crate::fit::thermal::ThermalConfig>,
    MultiConfig,
) {
    // The several-sensor fits' ridge strengths (an experiment's override of the grid).
    let multi_thermal = match settings.multi_ridge_decades {
        None => std::borrow::Cow::Borrowed(&cfg.thermal),
        Some((lo, hi)) => std::borrow::Cow::Owned(crate::fit::thermal::ThermalConfig {
            ridge_grid: (lo..=hi).map(|k| 10f64.powi(k)).collect(),
            ..cfg.thermal.clone()
        }),
    };
    let mc = MultiConfig {
        min_gain: settings.min_gain,
        extra: settings.multi_extra,
        first: settings.multi_first,
        select_folds: settings.multi_select_folds,
    };
    (multi_thermal, mc)
}

/// Each sensor's lags identified for axis `k` on the runs `runs` (indices into the job's logs)
/// with `cfg` and its training sets made, telling `events`.
fn prepare_axis(
    job: &UnitJob,
    runs: &[usize],
    k: usize,
    cfg: &FitConfig,
    events: &ImuEvents,
) -> Result<AxisRuns, ImuError> {
    let UnitJob {
        logs,
        shared,
        gyro_cols,
        temp_cols,
        ..
    } = *job;
    let fit_err = |j: usize, source| fit_error(&gyro_cols[k], &temp_cols[j], source);
    let target_err = |j: usize, run: &str, source: targets::TargetError| {
        fit_err(
            j,
            FitError::Targets {
                run: run.to_owned(),
                source,
            },
        )
    };
    // The targets' per-sample part reads the axis's gyro column, not the sensor: made once per
    // run for the four sensors.
    // One copy of each run's columns for this axis; each sensor in turn puts its temperature
    // column in place (the rest is the same for every sensor).
    let mut axis_logs: Vec<(String, TestLog)> = runs
        .iter()
        .map(|&i| (logs[i].0.clone(), logs[i].1.axis_data(k, 0)))
        .collect();
    let samples: Vec<(bool, Result<targets::GyroSamples, targets::TargetError>)> = axis_logs
        .iter()
        .map(|(_, a)| {
            if targets::is_static(a) {
                (false, targets::bias_samples(a, cfg.bias_window_s))
            } else {
                (
                    true,
                    targets::scale_samples(a, cfg.settle_s, cfg.scale_window_s),
                )
            }
        })
        .collect();
    let mut per_sensor = Vec::with_capacity(temp_cols.len());
    for j in 0..temp_cols.len() {
        events(ImuFitEvent::SensorStarted { axis: k, sensor: j });
        use_sensor(&mut axis_logs, logs, runs, j);
        let named: Vec<NamedLog> = axis_logs
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect();
        // A unit searches lags once per sensor and axis, so each search keeps a fifth of the
        // labelled steps (`IMU_IDENTIFY_EVERY`, chosen on the design family).
        let prepared: Option<Vec<crate::fit::thermal::Prepared>> = shared
            .get(j)
            .into_iter()
            .flat_map(|per_run| runs.iter().map(move |&i| per_run.get(i)))
            .zip(&samples)
            .map(|(t, (_, s))| match (t, s) {
                (Some(Some((published, base))), Ok(samples)) => {
                    Some(crate::fit::thermal::Prepared {
                        samples,
                        published,
                        base,
                    })
                }
                _ => None,
            })
            .collect();
        let id = match prepared.filter(|p| p.len() == runs.len()) {
            Some(p) => {
                let runs: Vec<(&str, &TestLog)> =
                    axis_logs.iter().map(|(n, l)| (n.as_str(), l)).collect();
                crate::fit::thermal::identify_shared(&runs, &p, &cfg.thermal, IMU_IDENTIFY_EVERY)
                    .map_err(|e| fit_err(j, FitError::from(e)))?
            }
            // Something could not be made ahead: the search on its own says what.
            None => crate::fit::identify_every(&named, cfg, IMU_IDENTIFY_EVERY)
                .map_err(|e| fit_err(j, e))?,
        };
        let (mut bias, mut scale) = (Vec::new(), Vec::new());
        for ((name, l), (is_scale, s)) in axis_logs.iter().zip(&samples) {
            let t = targets::targets_from(l, &id.spec, s, *is_scale)
                .map_err(|e| target_err(j, name, e))?;
            if *is_scale {
                scale.push(t);
            } else {
                bias.push(t);
            }
        }
        per_sensor.push((id, bias, scale));
    }
    Ok(AxisRuns {
        axis_logs,
        per_sensor,
    })
}

/// The bias model on the sensors `order` (two or more): one fit over them (averaged over each
/// sensor first with [`multi::FirstBy::Average`], an experiment), then averaged with the
/// first sensor's one-sensor model `one` by the experiment's weight `blend` (0: not at all).
fn several_sensor_bias(
    data: &[SensorData],
    order: &[usize],
    multi_thermal: &crate::fit::thermal::ThermalConfig,
    mc: &MultiConfig,
    shared: Option<&multi::Shared>,
    one: Option<&SubModel>,
    blend: f64,
) -> Result<multi::MultiFit, crate::fit::thermal::ThermalError> {
    let b = if mc.first == multi::FirstBy::Average {
        multi::fit_multi_averaged(data, order, multi_thermal, mc, false)
    } else {
        multi::fit_multi_with(data, order, multi_thermal, mc, false, shared)
    }?;
    Ok(blend_with_one(b, one, blend))
}

/// The coverage map of an axis that reads several sensors. Its cells are the first sensor's
/// (T, dT), which the flight axis steps; its σ is the first sensor's one-sensor map's, times
/// the ratio of the several-sensor fit's cross-validated bias RMS (`several_cv`) to the first
/// sensor's alone (`one_cv`), both from the same folds of the sensor selection, and times
/// `lstm_ratio` where a residual LSTM on the several-sensor fit was kept (as a single gyro's
/// map shrinks by its LSTM's held-out ratio). Without both scores the axis has no map, and its
/// note says why.
fn several_sensor_coverage(
    model: &mut ModelFile,
    one_cv: Option<f64>,
    several_cv: Option<f64>,
    lstm_ratio: Option<f64>,
) {
    let ratio = match (one_cv, several_cv) {
        (Some(one), Some(several)) if one > 0.0 && several.is_finite() && several > 0.0 => {
            several / one
        }
        _ => {
            model.coverage = None;
            model.coverage_note = Some(
                "the several-sensor fit has no cross-validated score to scale the first \
                 sensor's map by: no coverage map"
                    .to_owned(),
            );
            return;
        }
    };
    shrink_map(model, Some(ratio));
    shrink_map(model, lstm_ratio);
}

/// The map's σ times `ratio`, where both are there. A kept LSTM's held-out ratio is applied by
/// itself, after the sensors' (`auto`'s LSTM candidate and `thermal-lstm` by name shrink the
/// same map in the same steps, so both write the same numbers).
fn shrink_map(model: &mut ModelFile, ratio: Option<f64>) {
    if let (Some(r), Some(c)) = (ratio, model.coverage.as_mut()) {
        *c = c.rescaled(r, c.growth_per_cell);
    }
}

/// `thermal-lstm`'s residual LSTM (`cfg`'s recipe) on an axis's several-sensor bias fit: the
/// first sensor's least-squares part `first` on its training sets `first_sets`, and each
/// further sensor's part with its sets (`further`). The LSTM reads the first sensor's thermal
/// states and the first part's prediction, and learns the residual of the whole fit (each
/// run's target less the further parts, which the flight axis adds as they are). Returns the
/// first part with that LSTM, or the first part alone where the LSTM's gate left it out; and
/// with a kept LSTM, the ratio of the held-out blocks' RMS with it to without it.
fn lstm_on_several(
    first: &SubModel,
    first_sets: &[TargetSet],
    further: &[(&SubModel, &[TargetSet])],
    cfg: &FitConfig,
) -> Result<(SubModel, Option<f64>), FitError> {
    let mut sets: Vec<TargetSet> = first_sets.to_vec();
    for (r, set) in sets.iter_mut().enumerate() {
        for (part, part_sets) in further {
            let p = part.predict_table(&part_sets[r].table)?;
            for (row, y) in set.target.iter_mut().enumerate() {
                match p.get(row) {
                    Some(p) => *y -= p,
                    None => set.mask[row] = false,
                }
            }
        }
    }
    Ok(
        match crate::fit::auto::lstm_on_thermal(&sets, first, cfg)? {
            Some((sub, training)) => {
                let ratio = crate::fit::held_out_ratio(&sub, &training);
                (sub, ratio)
            }
            None => (first.clone(), None),
        },
    )
}

/// [`lstm_on_several`] on a several-sensor fit `b` of the sensors `order` of `data`.
fn lstm_on_multi(
    data: &[SensorData],
    order: &[usize],
    b: &multi::MultiFit,
    cfg: &FitConfig,
) -> Result<(SubModel, Option<f64>), FitError> {
    let further: Vec<(&SubModel, &[TargetSet])> = b
        .extra
        .iter()
        .zip(&order[1..])
        .map(|(part, &j)| (part, data[j].bias))
        .collect();
    lstm_on_several(&b.first, data[order[0]].bias, &further, cfg)
}

/// Why axis `gyro`'s fit on sensor `temp` failed.
fn fit_error(gyro: &str, temp: &str, source: FitError) -> ImuError {
    ImuError::Fit {
        gyro: gyro.to_owned(),
        temp: temp.to_owned(),
        source: Box::new(source),
    }
}

/// One axis on every sensor (see the module doc): each sensor's lags identified on its own,
/// the sensors chosen by cross-validation, one fit over the chosen sensors; `shared` the
/// temperature columns' search features per sensor and run (the job's `shared`).
fn fit_axis_multi(job: &UnitJob, k: usize) -> Result<ImuAxis, ImuError> {
    let events = job.events;
    events(ImuFitEvent::AxisStarted { axis: k });
    let all: Vec<usize> = (0..job.logs.len()).collect();
    let mut runs = prepare_axis(job, &all, k, job.cfg, events)?;
    let (axis, j0) = thermal_axis(job, &all, &mut runs, k, job.cfg)?;
    events(ImuFitEvent::AxisFinished {
        axis: k,
        sensor: j0,
    });
    Ok(axis)
}

/// The several-sensor `thermal` axis on the prepared `runs` (of the job's logs, indices
/// `all`), fitted with `cfg`: the sensors chosen by cross-validation, one fit over them, the
/// first sensor's one-sensor model as the fallback. Returns the axis and its first sensor's
/// column index; `runs` is left with that sensor's column in place.
fn thermal_axis(
    job: &UnitJob,
    all: &[usize],
    runs: &mut AxisRuns,
    k: usize,
    cfg: &FitConfig,
) -> Result<(ImuAxis, usize), ImuError> {
    let UnitJob {
        logs,
        gyro_cols,
        temp_cols,
        settings,
        temp_sensor,
        progress,
        events,
        ..
    } = *job;
    let fit_err = |j: usize, source| fit_error(&gyro_cols[k], &temp_cols[j], source);
    let (multi_thermal, mc) = multi_settings(cfg, settings);
    let data: Vec<SensorData> = runs
        .per_sensor
        .iter()
        .map(|(id, bias, scale)| SensorData { id, bias, scale })
        .collect();
    let (order, single, shared) = multi::select_shared(&data, &multi_thermal, &mc);
    let scores: Vec<SensorScore> = temp_cols
        .iter()
        .zip(&single)
        .map(|(t, s)| SensorScore {
            temp: t.clone(),
            cv_rms: *s,
        })
        .collect();
    // The one-sensor scores come from the selection, after every sensor's identification.
    for (j, s) in single.iter().enumerate() {
        events(ImuFitEvent::SensorFinished {
            axis: k,
            sensor: j,
            cv_rms: *s,
        });
    }
    let j0 = order[0];
    let (id0, bias0, scale0) = &runs.per_sensor[j0];
    use_sensor(&mut runs.axis_logs, logs, all, j0);
    let named: Vec<NamedLog> = runs
        .axis_logs
        .iter()
        .map(|(n, l)| NamedLog { name: n, log: l })
        .collect();
    let has_bias = data.iter().all(|d| !d.bias.is_empty());
    // A residual LSTM rides on the several-sensor fit where there is one (below), so the
    // first sensor's own fit, the fallback then, is `thermal`'s without an LSTM of its own.
    let several_lstm = order.len() > 1 && has_bias && crate::fit::wants_residual_lstm(cfg);
    let one_cfg = if several_lstm {
        crate::fit::auto::candidate_config(cfg, crate::settings::method::Method::Thermal)
    } else {
        cfg.clone()
    };
    // The first sensor's whole one-sensor fit, bias included: with further sensors it is the
    // axis's fallback (kept below before several sensors replace its bias and coverage map).
    // Its training sets are the ones made for the selection.
    let mut outcome = crate::fit::fit_model_with(
        &named,
        &one_cfg,
        Some(id0.clone()),
        true,
        Some((bias0, scale0)),
        &|t, e, loss| progress(k, j0, t, e, loss),
    )
    .map_err(|e| fit_err(j0, e))?;
    outcome.model.features.temp_sensor = *temp_sensor;
    let mut more = Vec::new();
    let mut multi_cv_rms = None;
    let fallback = (order.len() > 1).then(|| outcome.model.clone());
    if order.len() > 1 {
        let thermal_err = |e: crate::fit::thermal::ThermalError| fit_err(j0, FitError::from(e));
        let has_scale = data.iter().all(|d| !d.scale.is_empty());
        let bias = has_bias
            .then(|| {
                several_sensor_bias(
                    &data,
                    &order,
                    &multi_thermal,
                    &mc,
                    shared.as_ref(),
                    outcome.model.bias.as_ref(),
                    settings.blend,
                )
            })
            .transpose()
            .map_err(thermal_err)?;
        // The scale factor reads the further sensors only when they help it too.
        let scale = if has_scale {
            // The selection's statistics are the bias's when the axis has a static run.
            let own = has_bias
                .then(|| multi::shared(&data, order[0], &order[1..], &multi_thermal, &mc, true))
                .flatten();
            let sh = own.as_ref().or(shared.as_ref());
            let one = multi::cv_rms_with(&data, &order[..1], &multi_thermal, &mc, true, sh);
            let all = multi::fit_multi_with(&data, &order, &multi_thermal, &mc, true, sh)
                .map_err(thermal_err)?;
            match (one, all.cv_rms) {
                (Some(o), Some(a)) if a < o * (1.0 - settings.min_gain) => Some(all),
                _ => None,
            }
        } else {
            None
        };
        if let Some(b) = &bias {
            let (first, lstm_ratio) = if several_lstm {
                lstm_on_multi(&data, &order, b, cfg).map_err(|e| fit_err(j0, e))?
            } else {
                (b.first.clone(), None)
            };
            outcome.model.bias = Some(first);
            multi_cv_rms = b.cv_rms;
            several_sensor_coverage(&mut outcome.model, single[j0], b.cv_rms, lstm_ratio);
        }
        if let Some(s) = &scale {
            outcome.model.scale = Some(s.first.clone());
        }
        // With `thermal-lstm`, the residual LSTM was trained on the residual of the
        // several-sensor fit; the axis is labelled with what it holds (its gate may have left
        // the LSTM out).
        outcome.model.method = crate::fit::thermal_lstm::label(
            cfg.model_method(),
            outcome.model.bias.as_ref(),
            outcome.model.scale.as_ref(),
        );
        for (i, &j) in order[1..].iter().enumerate() {
            more.push(SensorModel {
                lags_s: data[j].id.report.lags_s.clone(),
                bias: bias.as_ref().map(|b| b.extra[i].clone()),
                scale: scale.as_ref().map(|s| s.extra[i].clone()),
            });
        }
    }
    Ok((
        ImuAxis {
            gyro: gyro_cols[k].clone(),
            temps: order.iter().map(|&j| temp_cols[j].clone()).collect(),
            scores,
            model: outcome.model,
            more,
            multi_cv_rms,
            fallback,
        },
        j0,
    ))
}

/// One axis with `auto`: its `thermal` fit ([`thermal_axis`], as `--method thermal` builds
/// it, on one sensor or several) against `thermal-lstm` on that fit (as `--method
/// thermal-lstm` builds it: on several sensors, [`lstm_on_several`]), scored as
/// [`crate::fit::auto`] scores one gyro: each static run left out in turn when there are two
/// or more (both candidates fitted again without it, the lags identified again), else the
/// LSTM's held-out blocks of the static run. Both are scored on the same rows by the same
/// prediction ([`axis_bias_on`]); the lower RMS wins, `thermal` on a tie. The axis's model
/// records the scores and the choice ([`ModelFile::method_choice`]).
fn fit_axis_auto(job: &UnitJob, k: usize) -> Result<ImuAxis, ImuError> {
    let UnitJob {
        logs,
        gyro_cols,
        temp_cols,
        cfg,
        settings,
        temp_sensor,
        progress,
        events,
        ..
    } = *job;
    use crate::fit::auto::{candidate_config, choose};
    use crate::model::Validation;
    use crate::settings::method::Method;
    let thermal_cfg = candidate_config(cfg, Method::Thermal);
    let lstm_cfg = candidate_config(cfg, Method::ThermalLstm);
    events(ImuFitEvent::AxisStarted { axis: k });
    let all: Vec<usize> = (0..logs.len()).collect();
    let mut runs = prepare_axis(job, &all, k, &thermal_cfg, events)?;
    let (mut thermal, j0) = thermal_axis(job, &all, &mut runs, k, &thermal_cfg)?;
    let fit_err = |source| fit_error(&gyro_cols[k], &temp_cols[j0], source);
    let finished = |axis: ImuAxis| {
        events(ImuFitEvent::AxisFinished {
            axis: k,
            sensor: j0,
        });
        Ok(axis)
    };
    // The `thermal-lstm` candidate on every run: the residual LSTM on the axis's `thermal`
    // fit. On one sensor that is `thermal-lstm` on it, as the single-gyro path fits it (its
    // lags and training sets the ones made for the selection); on several, the LSTM on the
    // several-sensor fit's residual, as `--method thermal-lstm` fits the axis.
    let lstm_fit = |thermal: &ImuAxis| -> Result<ImuAxis, ImuError> {
        events(ImuFitEvent::LstmTraining {
            axis: k,
            sensor: j0,
        });
        let (id0, bias0, scale0) = &runs.per_sensor[j0];
        if thermal.more.is_empty() {
            let mut outcome = crate::fit::fit_model_with(
                &runs.named(),
                &lstm_cfg,
                Some(id0.clone()),
                true,
                Some((bias0, scale0)),
                &|t, e, loss| progress(k, j0, t, e, loss),
            )
            .map_err(fit_err)?;
            outcome.model.features.temp_sensor = *temp_sensor;
            return Ok(ImuAxis {
                model: outcome.model,
                fallback: None,
                ..thermal.clone()
            });
        }
        let (Some(first), true) = (
            thermal.model.bias.as_ref(),
            thermal.more.iter().all(|m| m.bias.is_some()),
        ) else {
            return Ok(thermal.clone());
        };
        let sets = |t: &String| {
            let j = temp_cols.iter().position(|c| c == t).unwrap_or(j0);
            &runs.per_sensor[j].1[..]
        };
        let further: Vec<(&SubModel, &[TargetSet])> = thermal.temps[1..]
            .iter()
            .zip(&thermal.more)
            .filter_map(|(t, m)| Some((m.bias.as_ref()?, sets(t))))
            .collect();
        let (bias, lstm_ratio) =
            lstm_on_several(first, sets(&thermal.temps[0]), &further, &lstm_cfg)
                .map_err(fit_err)?;
        let mut axis = thermal.clone();
        shrink_map(&mut axis.model, lstm_ratio);
        axis.model.method = crate::fit::thermal_lstm::label(
            Method::ThermalLstm,
            Some(&bias),
            axis.model.scale.as_ref(),
        );
        axis.model.bias = Some(bias);
        Ok(axis)
    };
    let statics: Vec<usize> = all
        .iter()
        .copied()
        .filter(|&i| targets::is_static(&runs.axis_logs[i].1))
        .collect();
    let (choice, lstm) = match (statics.len(), settings.auto_keep) {
        // An experiment's candidate, kept without scoring (and without a recorded choice).
        (_, Some(Method::ThermalLstm)) => return finished(lstm_fit(&thermal)?),
        (_, Some(_)) => return finished(thermal),
        // No bias to choose on: the scale factor is `thermal`'s in either candidate.
        (0, _) => return finished(thermal),
        (1, _) => {
            let (_, bias0, _) = &runs.per_sensor[j0];
            let held = crate::fit::residual::validation_rows(bias0, &lstm_cfg.recipe);
            if held.iter().all(Vec::is_empty) {
                // Too short for held-out blocks: nothing could say the LSTM helps, so it is
                // not trained.
                return finished(thermal);
            }
            let lstm = lstm_fit(&thermal)?;
            let (Some(t_parts), Some(l_parts)) = (bias_parts(&thermal), bias_parts(&lstm)) else {
                return finished(thermal);
            };
            let mut ss = [0.0; 2];
            let mut n = 0;
            for (r, rows) in held.iter().enumerate() {
                // The training sets of the axis's sensors, in the order it reads them.
                let sets: Vec<&TargetSet> = thermal
                    .temps
                    .iter()
                    .map(|t| {
                        let j = temp_cols.iter().position(|c| c == t).unwrap_or(j0);
                        &runs.per_sensor[j].1[r]
                    })
                    .collect();
                let (s, m) = candidates_ss([&t_parts, &l_parts], &sets, rows).map_err(fit_err)?;
                ss[0] += s[0];
                ss[1] += s[1];
                n += m;
            }
            let scores = ss.map(|s| (s / n.max(1) as f64).sqrt());
            (choose(Validation::HeldOutBlocks, scores), Some(lstm))
        }
        _ => {
            let scores = leave_one_run_out(job, &statics, k, &thermal_cfg, &lstm_cfg)?;
            let mut choice = choose(Validation::LeaveOneRunOut, scores);
            if choice.folds_left_out_the_lstm() {
                // The folds say nothing of the LSTM: its fit on every run decides by its gate.
                choice.chosen = Method::ThermalLstm;
            }
            (choice, None)
        }
    };
    if choice.chosen == Method::Thermal {
        thermal.model.method_choice = Some(choice);
        return finished(thermal);
    }
    let mut lstm = match lstm {
        Some(l) => l,
        None => lstm_fit(&thermal)?,
    };
    if lstm.model.method != Method::ThermalLstm {
        // Its gate kept no LSTM: the fit is the `thermal` candidate's model form alone (on one
        // sensor, less than the `thermal` candidate may hold).
        thermal.model.method_choice = Some(choice.with_lstm_left_out());
        return finished(thermal);
    }
    lstm.model.method_choice = Some(choice);
    finished(lstm)
}

/// An axis's bias parts, the first sensor's first (None when a part has no bias model).
fn bias_parts(a: &ImuAxis) -> Option<Vec<&SubModel>> {
    std::iter::once(a.model.bias.as_ref())
        .chain(a.more.iter().map(|m| m.bias.as_ref()))
        .collect()
}

/// `auto`'s scores of an axis with two or more static runs (`statics`, indices into the job's
/// logs):
/// each left out in turn, both candidates fitted on the other runs (every sensor's lags
/// identified again, the sensors chosen again) and their bias predicted on it. Returns each
/// candidate's RMS over every left-out run, each run's mean removed.
fn leave_one_run_out(
    job: &UnitJob,
    statics: &[usize],
    k: usize,
    thermal_cfg: &FitConfig,
    lstm_cfg: &FitConfig,
) -> Result<[f64; 2], ImuError> {
    let UnitJob {
        logs,
        gyro_cols,
        temp_cols,
        settings,
        ..
    } = *job;
    let (multi_thermal, mc) = multi_settings(thermal_cfg, settings);
    let mut ss = [0.0; 2];
    let mut n = 0usize;
    for (run, &h) in statics.iter().enumerate() {
        (job.events)(ImuFitEvent::Scoring {
            axis: k,
            run,
            of: statics.len(),
        });
        let others: Vec<usize> = (0..logs.len()).filter(|&i| i != h).collect();
        let runs = prepare_axis(job, &others, k, thermal_cfg, &|_| {})?;
        let data = runs.data();
        if data.iter().any(|d| d.bias.is_empty()) {
            continue;
        }
        let (order, _, sh) = multi::select_shared(&data, &multi_thermal, &mc);
        let j0 = order[0];
        let fit_err = |source| fit_error(&gyro_cols[k], &temp_cols[j0], source);
        let (id0, bias0, _) = &runs.per_sensor[j0];
        // The first sensor's one-sensor bias model, as `thermal` fits it.
        let (one, _) = crate::fit::thermal::fit_target(bias0, &thermal_cfg.thermal, id0, false)
            .map_err(|e| fit_err(FitError::from(e)))?;
        let several = (order.len() > 1)
            .then(|| {
                several_sensor_bias(
                    &data,
                    &order,
                    &multi_thermal,
                    &mc,
                    sh.as_ref(),
                    Some(&one),
                    settings.blend,
                )
            })
            .transpose()
            .map_err(|e| fit_err(FitError::from(e)))?;
        let t_parts: Vec<&SubModel> = match &several {
            Some(b) => std::iter::once(&b.first).chain(&b.extra).collect(),
            None => vec![&one],
        };
        // The LSTM on this fold's `thermal` fit, as `fit_axis_auto` trains it on every run.
        let lstm = match &several {
            Some(b) => {
                lstm_on_multi(&data, &order, b, lstm_cfg)
                    .map_err(fit_err)?
                    .0
            }
            None => {
                match crate::fit::auto::lstm_on_thermal(bias0, &one, lstm_cfg).map_err(fit_err)? {
                    Some((l, _)) => l,
                    None => continue,
                }
            }
        };
        let l_parts: Vec<&SubModel> = std::iter::once(&lstm)
            .chain(t_parts[1..].iter().copied())
            .collect();
        // The left-out run's training sets on each sensor read, at this fold's lags.
        let held: Vec<TargetSet> = order
            .iter()
            .map(|&j| {
                let log = logs[h].1.axis_data(k, j);
                targets::bias_targets(&log, &runs.per_sensor[j].0.spec, thermal_cfg.bias_window_s)
                    .map_err(|source| {
                        fit_err(FitError::Targets {
                            run: logs[h].0.clone(),
                            source,
                        })
                    })
            })
            .collect::<Result<_, _>>()?;
        let held_refs: Vec<&TargetSet> = held.iter().collect();
        let rows: Vec<usize> = (0..held[0].table.n_rows()).collect();
        let (s, m) = candidates_ss([&t_parts, &l_parts], &held_refs, &rows).map_err(fit_err)?;
        ss[0] += s[0];
        ss[1] += s[1];
        n += m;
    }
    Ok(ss.map(|s| (s / n.max(1) as f64).sqrt()))
}

/// An axis's bias on a run: each part (the first sensor's model first) predicted on its
/// sensor's feature table of the run (`sets`, same order), summed; as long as the shortest
/// table.
fn axis_bias_on(parts: &[&SubModel], sets: &[&TargetSet]) -> Result<Vec<f64>, FitError> {
    let n = sets.iter().map(|s| s.table.n_rows()).min().unwrap_or(0);
    let mut sum = vec![0.0; n];
    for (p, s) in parts.iter().zip(sets) {
        for (v, x) in sum.iter_mut().zip(p.predict_table(&s.table)?) {
            *v += x;
        }
    }
    Ok(sum)
}

/// The two candidates' sums of squared bias residual on `rows` of one run (the labelled ones
/// both predict; each candidate's mean over them removed) and how many rows: each candidate's
/// bias parts (`thermal`'s, then `thermal-lstm`'s) on the sensors of `sets`, through
/// [`axis_bias_on`].
fn candidates_ss(
    parts: [&[&SubModel]; 2],
    sets: &[&TargetSet],
    rows: &[usize],
) -> Result<([f64; 2], usize), FitError> {
    let preds = [axis_bias_on(parts[0], sets)?, axis_bias_on(parts[1], sets)?];
    let first = sets[0];
    let n = preds[0].len().min(preds[1].len());
    let used: Vec<usize> = rows
        .iter()
        .copied()
        .filter(|&r| r < n && first.mask[r] && first.target[r].is_finite())
        .collect();
    let mut ss = [0.0; 2];
    for (c, pred) in preds.iter().enumerate() {
        let resid: Vec<f64> = used.iter().map(|&r| first.target[r] - pred[r]).collect();
        let mean = resid.iter().sum::<f64>() / resid.len().max(1) as f64;
        ss[c] = resid.iter().map(|e| (e - mean) * (e - mean)).sum::<f64>();
    }
    Ok((ss, used.len()))
}

/// The several-sensor fit averaged with the first sensor's one-sensor fit `one`, weight `w`
/// on `one`: the first sensor's coefficients averaged (same terms), each further sensor's
/// scaled by `1 − w`. Unchanged when `w` is 0 or the terms differ.
fn blend_with_one(mut b: multi::MultiFit, one: Option<&SubModel>, w: f64) -> multi::MultiFit {
    if w == 0.0 {
        return b;
    }
    let (
        Some(SubModel::Baseline {
            terms: t1,
            coefficients: c1,
        }),
        SubModel::Baseline {
            terms: tm,
            coefficients: cm,
        },
    ) = (one, &mut b.first)
    else {
        return b;
    };
    if t1 != tm || c1.len() != cm.len() {
        return b;
    }
    for (m, o) in cm.iter_mut().zip(c1) {
        *m = w * o + (1.0 - w) * *m;
    }
    for e in &mut b.extra {
        if let SubModel::Baseline { coefficients, .. } = e {
            for c in coefficients.iter_mut() {
                *c *= 1.0 - w;
            }
        }
    }
    b
}

/// One axis's checks in [`ImuModel::validate`]: its sensors among `temp_cols`, its model, and
/// the flight compensator its further sensors build.
fn axis_checks(temp_cols: &[String], a: &ImuAxis) -> Result<(), ImuError> {
    let distinct = a
        .temps
        .iter()
        .enumerate()
        .all(|(i, t)| !a.temps[..i].contains(t));
    if a.temps.is_empty()
        || a.temps.len() > MAX_SENSORS
        || !distinct
        || !a.temps.iter().all(|t| temp_cols.contains(t))
    {
        return Err(ImuError::Layout(format!(
            "axis {} must read 1 to {MAX_SENSORS} distinct temperature columns among \
             {}",
            a.gyro,
            temp_cols.join(", ")
        )));
    }
    if a.more.len() + 1 != a.temps.len() {
        return Err(ImuError::Layout(format!(
            "axis {}: `more` must hold one entry per further sensor ({} of them)",
            a.gyro,
            a.temps.len() - 1
        )));
    }
    a.model.validate().map_err(|source| ImuError::Axis {
        gyro: a.gyro.clone(),
        source: Box::new(source),
    })?;
    if let Some(f) = &a.fallback {
        if a.more.is_empty() {
            return Err(ImuError::Layout(format!(
                "axis {}: a `fallback` model is only for an axis that reads further sensors \
                 (remove it: this axis's model already reads its one sensor alone)",
                a.gyro
            )));
        }
        f.validate().map_err(|source| ImuError::Axis {
            gyro: a.gyro.clone(),
            source: Box::new(source),
        })?;
    }
    if !a.more.is_empty() {
        // The further sensors' parts must build a flight compensator, and with the first
        // sensor's model keep B and K plausible over the training range, as a single-axis
        // model must.
        let size = axes_hidden_size(std::slice::from_ref(a))?;
        let comp = build_sized!(FlightAxis, size, H => boxed_axis::<H>(temp_cols, a)?);
        let further: Vec<_> = comp
            .further()
            .into_iter()
            .map(|(_, s, b, k)| (s, b, k))
            .collect();
        a.model
            .check_outputs_with_further(comp.first().spec(), &further)
            .map_err(|source| ImuError::Axis {
                gyro: a.gyro.clone(),
                source: Box::new(source),
            })?;
    }
    Ok(())
}

/// Refuse more gyro axes than a unit model may have: the capacity of the flight unit that
/// compensates it ([`MAX_STREAM_AXES`]).
fn check_axis_count(n: usize) -> Result<(), ImuError> {
    if n > MAX_STREAM_AXES {
        return Err(ImuError::Layout(format!(
            "{n} gyro columns: a unit model has at most {MAX_STREAM_AXES} axes (what \
             `compensate` runs); split the unit into models of at most {MAX_STREAM_AXES} gyro \
             columns"
        )));
    }
    Ok(())
}

/// The first name listed twice in `names`, with both positions (1-based).
fn repeated(names: &[String]) -> Option<(&str, usize, usize)> {
    names.iter().enumerate().find_map(|(i, n)| {
        names[..i]
            .iter()
            .position(|m| m == n)
            .map(|j| (n.as_str(), j + 1, i + 1))
    })
}

/// `check` of each axis, on a thread per axis when there are several, in axis order.
fn each_axis<T: Send>(axes: &[ImuAxis], check: impl Fn(&ImuAxis) -> T + Sync) -> Vec<T> {
    if axes.len() < 2 {
        return axes.iter().map(check).collect();
    }
    let check = &check;
    std::thread::scope(|scope| {
        let handles: Vec<_> = axes.iter().map(|a| scope.spawn(move || check(a))).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// The LSTM size a unit of `axes` runs at: the largest LSTM of any axis's model or fallback
/// (8 without one); see [`crate::flight_size`].
fn axes_hidden_size(axes: &[ImuAxis]) -> Result<HiddenSize, ImuError> {
    let mut size = HiddenSize::H8;
    for a in axes {
        for m in std::iter::once(&a.model).chain(a.fallback.as_ref()) {
            let s = hidden_size([m.bias.as_ref(), m.scale.as_ref()]).map_err(|source| {
                ImuError::Compensate {
                    gyro: a.gyro.clone(),
                    source: Box::new(source),
                }
            })?;
            size = size.max(s);
        }
    }
    Ok(size)
}

/// [`axis_compensator_in`], boxed in a frame of its own (see [`crate::flight_size`]).
#[inline(never)]
fn boxed_axis<const H: usize>(
    temp_cols: &[String],
    a: &ImuAxis,
) -> Result<Box<AxisCompensator<H>>, ImuError> {
    axis_compensator_in::<H>(temp_cols, a).map(Box::new)
}

/// [`ImuModel::axis_compensator`] with the model's temperature columns `temp_cols`, at `H`
/// hidden units.
fn axis_compensator_in<const H: usize>(
    temp_cols: &[String],
    a: &ImuAxis,
) -> Result<AxisCompensator<H>, ImuError> {
    let index = |t: &String| {
        temp_cols
            .iter()
            .position(|c| c == t)
            .ok_or_else(|| ImuError::Layout(format!("axis {} reads unknown sensor {t}", a.gyro)))
    };
    let layout = |what: String| ImuError::Layout(format!("axis {}: {what}", a.gyro));
    let first = sized_compensator::<H>(&a.model).map_err(|source| ImuError::Compensate {
        gyro: a.gyro.clone(),
        source: Box::new(source),
    })?;
    let spec0 = *first.spec();
    let mut axis = AxisCompensator::new(first, index(&a.temps[0])?);
    for (t, m) in a.temps.iter().skip(1).zip(&a.more) {
        let spec = spec0
            .with_lags(&m.lags_s, LagOutputs::DiffFromT)
            .map_err(|e| layout(format!("sensor {t}: {e}")))?;
        let part = |sub: &Option<SubModel>, what: Target| match sub {
            None => Ok(None),
            Some(
                sub @ SubModel::Baseline {
                    terms,
                    coefficients,
                },
            ) => {
                // A single-axis file's checks of a least-squares part: its terms, one
                // coefficient per term, each finite and plausible.
                sub.validate(spec.n_features())
                    .map_err(|source| ImuError::FurtherSensor {
                        gyro: a.gyro.clone(),
                        temp: t.clone(),
                        part: what,
                        source: Box::new(source),
                    })?;
                crate::baseline::to_core(terms, coefficients)
                    .map(Some)
                    .map_err(|e| layout(format!("sensor {t}, {}: {e}", what.as_str())))
            }
            Some(_) => Err(layout(format!(
                "sensor {t}, {}: a further sensor's part must be a baseline",
                what.as_str()
            ))),
        };
        axis = axis
            .with_sensor(
                index(t)?,
                spec,
                part(&m.bias, Target::Bias)?,
                part(&m.scale, Target::Scale)?,
            )
            .map_err(|e| layout(format!("sensor {t}: {e}")))?;
    }
    if let Some(f) = &a.fallback {
        let f = sized_compensator::<H>(f).map_err(|source| ImuError::Compensate {
            gyro: a.gyro.clone(),
            source: Box::new(source),
        })?;
        axis = axis.with_fallback(f);
    }
    Ok(axis)
}

impl ImuModel {
    /// Checks the layout (one axis per gyro column, in order; each axis's sensors among the
    /// temperature columns) and every axis's model.
    pub fn validate(&self) -> Result<(), ImuError> {
        self.validate_columns()?;
        // The axes' checks (each runs its models over the training range) on a thread per
        // axis; the first axis in order that fails is told, as checking in turn would.
        each_axis(&self.axes, |a| axis_checks(&self.temp_cols, a))
            .into_iter()
            .collect()
    }

    /// [`ImuModel::validate`]'s checks of the file's version and gyro columns.
    fn validate_columns(&self) -> Result<(), ImuError> {
        // What is wrong with the axes is said before the version: the version expected
        // follows from them.
        if self.axes.is_empty() || self.gyro_cols.is_empty() {
            return Err(ImuError::Layout(
                "the model has no gyro axes (`axes` and `gyro_cols` must list at least one); \
                 re-train"
                    .into(),
            ));
        }
        check_axis_count(self.axes.len().max(self.gyro_cols.len()))?;
        if let Some((g, i, j)) = repeated(&self.gyro_cols) {
            return Err(ImuError::Layout(format!(
                "gyro column {g:?} is listed twice in `gyro_cols` (axes {i} and {j}): each axis \
                 reads a gyro column of its own; re-train, or check a hand edit"
            )));
        }
        if let Some((t, i, j)) = repeated(&self.temp_cols) {
            return Err(ImuError::Layout(format!(
                "temperature column {t:?} is listed twice in `temp_cols` (entries {i} and {j}); \
                 re-train, or check a hand edit"
            )));
        }
        let several = self.axes.iter().any(|a| a.temps.len() > 1);
        let expected = if several {
            IMU_FORMAT_VERSION
        } else {
            IMU_FORMAT_VERSION_ONE_SENSOR
        };
        if self.imu_format_version != expected {
            return Err(ImuError::Layout(format!(
                "{IMU_VERSION_KEY} {} is not supported here (this build reads \
                 {IMU_FORMAT_VERSION_ONE_SENSOR} when every axis reads one sensor, \
                 {IMU_FORMAT_VERSION} when an axis reads several)",
                self.imu_format_version
            )));
        }
        let gyros: Vec<&String> = self.axes.iter().map(|a| &a.gyro).collect();
        if gyros != self.gyro_cols.iter().collect::<Vec<_>>() || gyros.is_empty() {
            return Err(ImuError::Layout(
                "the axes must list the gyro columns, in order".into(),
            ));
        }
        Ok(())
    }

    /// The flight compensator of one axis: its first sensor's
    /// [`Compensator`](gyrotherm_core::compensator::Compensator) and each further sensor's
    /// pipeline and parts, reading the indices of its sensors among
    /// [`ImuModel::temp_cols`], at the unit's LSTM size ([`ImuModel::hidden_size`]).
    pub(crate) fn axis_compensator(&self, a: &ImuAxis) -> Result<FlightAxis, ImuError> {
        let size = self.hidden_size()?;
        Ok(build_sized!(FlightAxis, size, H => boxed_axis::<H>(&self.temp_cols, a)?))
    }

    /// The LSTM size every axis of the unit runs at: the largest LSTM of any axis's model or
    /// fallback (8 without one). An LSTM of a size flight code is not built for is refused,
    /// naming the axis and the size.
    pub fn hidden_size(&self) -> Result<HiddenSize, ImuError> {
        axes_hidden_size(&self.axes)
    }

    /// The sealed JSON text (pretty; `content_sha256` of the compact content last).
    pub fn to_json(&self) -> Result<String, ImuError> {
        self.validate()?;
        let text = serde_json::to_string_pretty(self).map_err(ImuError::Json)?;
        let body = text.strip_suffix("\n}").unwrap_or(&text);
        Ok(format!(
            "{body},\n  \"{CHECKSUM_KEY}\": \"{}\"\n}}\n",
            self.content_digest()?
        ))
    }

    /// The `content_sha256` of the model: SHA-256 of its compact JSON content (how the file
    /// is formatted does not change it).
    pub fn content_digest(&self) -> Result<String, ImuError> {
        content_digest_of(self).map_err(ImuError::Json)
    }

    /// Parse and check the text (the checksum, when present, must match).
    pub fn from_json(text: &str) -> Result<ImuModel, ImuError> {
        Self::from_json_sealed(text).map(|(m, _)| m)
    }

    /// [`from_json`](Self::from_json), also saying whether the text was sealed (a caller
    /// warns on [`Seal::Absent`], see [`Seal::warning`]). Read as a single-axis file is: a
    /// key named twice in any object is refused.
    pub fn from_json_sealed(text: &str) -> Result<(ImuModel, Seal), ImuError> {
        let (m, sealed) = Self::parse(text, true)?;
        Ok((m, if sealed { Seal::Verified } else { Seal::Absent }))
    }

    /// The model and whether the text held a checksum (checked only when `verify`).
    fn parse(text: &str, verify: bool) -> Result<(ImuModel, bool), ImuError> {
        let (m, sealed): (ImuModel, bool) =
            parse_sealed(text, verify, |_| Ok::<(), std::convert::Infallible>(())).map_err(
                |e| match e {
                    SealedTextError::DuplicateKey(d) => ImuError::DuplicateKey(d),
                    SealedTextError::NotJson(e) | SealedTextError::Fields(e) => ImuError::Json(e),
                    SealedTextError::Refused(never) => match never {},
                    SealedTextError::Checksum { found, computed } => {
                        ImuError::Checksum { found, computed }
                    }
                },
            )?;
        m.validate()?;
        Ok((m, sealed))
    }

    /// Re-seal a unit model file after a deliberate hand edit, as [`ModelFile::seal`]: read
    /// it without checking its `content_sha256`, check everything else, and write it back
    /// with a new one. Returns the model and its new digest.
    pub fn seal(path: &Path) -> Result<(ImuModel, String), ImuError> {
        let text = read_text(path)?;
        let (m, _) = Self::parse(&text, false)?;
        m.save(path)?;
        let digest = m.content_digest()?;
        Ok((m, digest))
    }

    /// Write atomically.
    pub fn save(&self, path: &Path) -> Result<(), ImuError> {
        let text = self.to_json()?;
        crate::atomic_file::write_bytes_atomically(path, text.as_bytes()).map_err(|source| {
            ImuError::Io {
                path: path.to_path_buf(),
                source,
            }
        })
    }

    /// Read and check a file.
    pub fn load(path: &Path) -> Result<ImuModel, ImuError> {
        Self::load_sealed(path).map(|(m, _)| m)
    }

    /// [`load`](Self::load), also saying whether the file was sealed (a caller warns on
    /// [`Seal::Absent`]; see [`Seal::warning`]).
    pub fn load_sealed(path: &Path) -> Result<(ImuModel, Seal), ImuError> {
        Self::from_json_sealed(&read_text(path)?)
    }

    /// Read options naming the model's columns (the rest of `base` kept): its gyro columns
    /// and the temperature columns its axes read ([`ImuModel::temps_read`]).
    pub fn read_options(&self, base: &ReadOptions) -> ReadOptions {
        ReadOptions {
            gyro_col: self.gyro_cols.join(","),
            temp_col: self.temps_read().join(","),
            ..base.clone()
        }
    }

    /// The temperature columns some axis reads, in the order of [`ImuModel::temp_cols`]: the
    /// ones a log must hold (a column no axis reads changes no output).
    pub fn temps_read(&self) -> Vec<&str> {
        self.temp_cols
            .iter()
            .filter(|t| self.axes.iter().any(|a| a.temps.contains(t)))
            .map(String::as_str)
            .collect()
    }

    /// Index of each axis's first (or only) sensor in the temperature columns.
    pub(crate) fn sensor_index(&self) -> Vec<usize> {
        self.axes
            .iter()
            .map(|a| {
                self.temp_cols
                    .iter()
                    .position(|t| *t == a.temps[0])
                    .unwrap_or(0)
            })
            .collect()
    }
}

/// The text of the file `path`.
fn read_text(path: &Path) -> Result<String, ImuError> {
    crate::input_file::read_capped_to_string(path, crate::input_file::InputKind::Model).map_err(
        |source| ImuError::Io {
            path: path.to_path_buf(),
            source,
        },
    )
}

/// The compensated series of one axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AxisCompensated {
    pub bias_dps: Vec<f64>,
    pub scale: Vec<f64>,
    pub gyro_comp_dps: Vec<f64>,
    pub status: Vec<Status>,
}

/// The flight compensators of every axis, in axis order, each reading its own sensors
/// among `temps[]` in the order of [`ImuModel::temp_cols`].
pub fn imu_axis_compensators(model: &ImuModel) -> Result<Vec<FlightAxis>, ImuError> {
    model
        .axes
        .iter()
        .map(|a| model.axis_compensator(a))
        .collect()
}

/// Compensate an inertial unit's log: each axis's flight compensator fed, sample by sample,
/// with its gyro column and the model's temperature columns. The log must hold the model's
/// gyro columns and the temperature columns its axes read (the error names the first one
/// missing); a column no axis reads is not looked for.
pub fn compensate_imu(model: &ImuModel, log: &ImuLog) -> Result<Vec<AxisCompensated>, ImuError> {
    let find = |list: &[crate::csvlog::NamedSeries], name: &str, role| {
        list.iter()
            .position(|s| s.name == name)
            .ok_or_else(|| ImuError::MissingColumn {
                column: name.to_owned(),
                role,
            })
    };
    let mut comps = imu_axis_compensators(model)?;
    let read = model.temps_read();
    let temps: Vec<Option<&[f64]>> = model
        .temp_cols
        .iter()
        .map(|t| {
            if !read.contains(&t.as_str()) {
                return Ok(None);
            }
            find(&log.temp, t, "temperature").map(|i| Some(log.temp[i].values.as_slice()))
        })
        .collect::<Result<_, _>>()?;
    let n = log.len();
    let mut out = Vec::with_capacity(model.axes.len());
    let mut row = vec![0.0; temps.len()];
    for (a, comp) in model.axes.iter().zip(&mut comps) {
        let g = &log.gyro[find(&log.gyro, &a.gyro, "gyro")?].values;
        let mut r = AxisCompensated {
            bias_dps: Vec::with_capacity(n),
            scale: Vec::with_capacity(n),
            gyro_comp_dps: Vec::with_capacity(n),
            status: Vec::with_capacity(n),
        };
        for i in 0..n {
            for (v, t) in row.iter_mut().zip(&temps) {
                *v = t.map_or(f64::NAN, |t| t[i]);
            }
            let c = comp.step(log.time_s[i], g[i], &row);
            r.bias_dps.push(c.bias_dps);
            r.scale.push(c.scale);
            r.gyro_comp_dps.push(c.rate_dps);
            r.status.push(c.status);
        }
        out.push(r);
    }
    Ok(out)
}

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

use crate::csvlog::{ImuLog, TestLog};
use crate::fit::thermal::multi::{self, MultiConfig, SensorData};
use crate::fit::thermal::Identified;
use crate::fit::{
    chooses_method, fit_model, uses_identification, FitConfig, FitError, FitOutcome, NamedLog,
};
use crate::model::unit::{
    axis_checks, check_axis_count, ImuAxis, ImuError, ImuModel, SensorModel, SensorScore,
    IMU_FORMAT_VERSION, IMU_FORMAT_VERSION_ONE_SENSOR,
};
use crate::model::{ModelFile, SubModel, TempSensorDef};
use crate::per_thread::on_threads;
use crate::settings::fit::IMU_IDENTIFY_EVERY;
pub use crate::settings::fit::{ImuFitSettings, ImuSensors};
use crate::targets::{self, TargetSet};

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
) -> Result<AxisRuns, UnitFitError> {
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
fn fit_error(gyro: &str, temp: &str, source: FitError) -> UnitFitError {
    UnitFitError::Fit {
        gyro: gyro.to_owned(),
        temp: temp.to_owned(),
        source: Box::new(source),
    }
}

/// One axis on every sensor (see the module doc): each sensor's lags identified on its own,
/// the sensors chosen by cross-validation, one fit over the chosen sensors; `shared` the
/// temperature columns' search features per sensor and run (the job's `shared`).
fn fit_axis_multi(job: &UnitJob, k: usize) -> Result<ImuAxis, UnitFitError> {
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
) -> Result<(ImuAxis, usize), UnitFitError> {
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
fn fit_axis_auto(job: &UnitJob, k: usize) -> Result<ImuAxis, UnitFitError> {
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
    let lstm_fit = |thermal: &ImuAxis| -> Result<ImuAxis, UnitFitError> {
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
) -> Result<[f64; 2], UnitFitError> {
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

//! An axis on several temperature sensors: each sensor's lags identified on its own, the
//! sensors chosen by cross-validation, one fit over the chosen ones, its coverage map and its
//! residual LSTM (see the parent module).

use super::{fit_error, ImuEvents, ImuFitEvent, ImuFitSettings, UnitFitError, UnitJob};
use crate::csvlog::{ImuLog, TestLog};
use crate::fit::thermal::multi::{self, MultiConfig, SensorData};
use crate::fit::thermal::Identified;
use crate::fit::{FitConfig, FitError, NamedLog};
use crate::model::unit::{ImuAxis, SensorModel, SensorScore};
use crate::model::{ModelFile, SubModel};
use crate::settings::fit::IMU_IDENTIFY_EVERY;
use crate::targets::{self, TargetSet};

/// One axis's training data on every sensor, each sensor's lags identified on the runs given
/// (all of them, or all but one for a fold of `auto`'s validation).
pub(super) struct AxisRuns {
    /// The runs' columns for this axis, the temperature column of the sensor last put in place
    /// ([`use_sensor`]).
    pub(super) axis_logs: Vec<(String, TestLog)>,
    /// Per sensor, in column order: its identification and its bias and scale-factor training
    /// sets (in run order).
    pub(super) per_sensor: Vec<(Identified, Vec<TargetSet>, Vec<TargetSet>)>,
}

impl AxisRuns {
    /// Every sensor's identification and training sets, as the selection reads them.
    pub(super) fn data(&self) -> Vec<SensorData<'_>> {
        self.per_sensor
            .iter()
            .map(|(id, bias, scale)| SensorData { id, bias, scale })
            .collect()
    }

    /// The runs as the fit reads them, with the temperature column last put in place.
    pub(super) fn named(&self) -> Vec<NamedLog<'_>> {
        self.axis_logs
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect()
    }
}

/// Puts sensor `j`'s temperature column in place in each run's axis columns (`runs`: the
/// runs' indices in `logs`, in the order of `axis_logs`; the rest is the same for every
/// sensor).
pub(super) fn use_sensor(
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
pub(super) fn multi_settings<'c>(
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
pub(super) fn prepare_axis(
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
pub(super) fn several_sensor_bias(
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
pub(super) fn several_sensor_coverage(
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
pub(super) fn shrink_map(model: &mut ModelFile, ratio: Option<f64>) {
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
pub(super) fn lstm_on_several(
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
pub(super) fn lstm_on_multi(
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

/// One axis on every sensor (see the module doc): each sensor's lags identified on its own,
/// the sensors chosen by cross-validation, one fit over the chosen sensors; `shared` the
/// temperature columns' search features per sensor and run (the job's `shared`).
pub(super) fn fit_axis_multi(job: &UnitJob, k: usize) -> Result<ImuAxis, UnitFitError> {
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
pub(super) fn thermal_axis(
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

/// An axis's bias on a run: each part (the first sensor's model first) predicted on its
/// sensor's feature table of the run (`sets`, same order), summed; as long as the shortest
/// table.
pub(super) fn axis_bias_on(parts: &[&SubModel], sets: &[&TargetSet]) -> Result<Vec<f64>, FitError> {
    let n = sets.iter().map(|s| s.table.n_rows()).min().unwrap_or(0);
    let mut sum = vec![0.0; n];
    for (p, s) in parts.iter().zip(sets) {
        for (v, x) in sum.iter_mut().zip(p.predict_table(&s.table)?) {
            *v += x;
        }
    }
    Ok(sum)
}

/// The several-sensor fit averaged with the first sensor's one-sensor fit `one`, weight `w`
/// on `one`: the first sensor's coefficients averaged (same terms), each further sensor's
/// scaled by `1 − w`. Unchanged when `w` is 0 or the terms differ.
pub(super) fn blend_with_one(
    mut b: multi::MultiFit,
    one: Option<&SubModel>,
    w: f64,
) -> multi::MultiFit {
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

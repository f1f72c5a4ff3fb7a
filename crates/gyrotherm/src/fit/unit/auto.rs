//! `auto` on an axis: its `thermal` fit or that fit with the LSTM on it, whichever scores lower
//! on held-out validation of the training runs (see the parent module).

use super::several::{
    axis_bias_on, lstm_on_multi, lstm_on_several, multi_settings, prepare_axis,
    several_sensor_bias, shrink_map, thermal_axis,
};
use super::{fit_error, ImuFitEvent, UnitFitError, UnitJob};
use crate::fit::thermal::multi;
use crate::fit::{FitConfig, FitError};
use crate::model::unit::ImuAxis;
use crate::model::SubModel;
use crate::targets::{self, TargetSet};

/// One axis with `auto`: its `thermal` fit ([`thermal_axis`], as `--method thermal` builds
/// it, on one sensor or several) against `thermal-lstm` on that fit (as `--method
/// thermal-lstm` builds it: on several sensors, [`lstm_on_several`]), scored as
/// [`crate::fit::auto`] scores one gyro: each static run left out in turn when there are two
/// or more (both candidates fitted again without it, the lags identified again), else the
/// LSTM's held-out blocks of the static run. Both are scored on the same rows by the same
/// prediction ([`axis_bias_on`]); the lower RMS wins, `thermal` on a tie. The axis's model
/// records the scores and the choice ([`ModelFile::method_choice`]).
pub(super) fn fit_axis_auto(job: &UnitJob, k: usize) -> Result<ImuAxis, UnitFitError> {
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
pub(super) fn bias_parts(a: &ImuAxis) -> Option<Vec<&SubModel>> {
    std::iter::once(a.model.bias.as_ref())
        .chain(a.more.iter().map(|m| m.bias.as_ref()))
        .collect()
}

/// `auto`'s scores of an axis with two or more static runs (`statics`, indices into the job's
/// logs):
/// each left out in turn, both candidates fitted on the other runs (every sensor's lags
/// identified again, the sensors chosen again) and their bias predicted on it. Returns each
/// candidate's RMS over every left-out run, each run's mean removed.
pub(super) fn leave_one_run_out(
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

/// The two candidates' sums of squared bias residual on `rows` of one run (the labelled ones
/// both predict; each candidate's mean over them removed) and how many rows: each candidate's
/// bias parts (`thermal`'s, then `thermal-lstm`'s) on the sensors of `sets`, through
/// [`axis_bias_on`].
pub(super) fn candidates_ss(
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

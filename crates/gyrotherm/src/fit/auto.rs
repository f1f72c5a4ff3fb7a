//! The `auto` method: fits the candidates `thermal` and `thermal-lstm`, scores each on
//! held-out validation that mirrors the use, and keeps the better.
//!
//! - Two or more static runs: each is left out in turn. The candidates are fitted on the other
//!   runs (the lags identified again without it) and predict the left-out run's bias; the score
//!   is the RMS of their residual over every left-out run, each run's mean removed.
//! - One static run: `thermal-lstm` holds out every few blocks of the run from its LSTM's
//!   training; the scores are the residual RMS on those blocks of `thermal`'s model alone and
//!   with the LSTM as kept. A run too short for such blocks gets `thermal`, and no LSTM is
//!   trained.
//!
//! The lower score wins; on a tie, the first candidate (`thermal`, the simpler), except where
//! every left-out run's fold left its LSTM out (its gate), so that the scores are equal: the
//! folds then say nothing of the LSTM, and `thermal-lstm`'s fit on every run decides by its own
//! gate. The chosen method is then fitted on every run, and the model is labelled with what
//! it holds; where the chosen `thermal-lstm` keeps no LSTM, `thermal` stays. The scores
//! and the choice go into the model file ([`MethodChoice`]) and the lines `train` prints. The
//! scale factor is `thermal`'s in both candidates.

use super::error::FitError;
use super::thermal::Identified;
use super::{
    fit_model, fit_model_identified, identify, residual, thermal, thermal_base, FitConfig,
    FitOutcome, NamedLog, RecipeSettings, TrainSummary,
};
use crate::model::{CandidateScore, MethodChoice, SubModel, Target, Validation};
use crate::settings::method::Method;
use crate::targets::{self, TargetSet};

/// The candidates, in the order they are scored (the first wins a tie).
pub(crate) const CANDIDATES: [Method; 2] = [Method::Thermal, Method::ThermalLstm];

/// The configuration that fits candidate `method` under `auto`'s settings `cfg`: `thermal`
/// with its own recipe, `thermal-lstm` with `auto`'s knobs (its own, as a fit was asked).
pub(crate) fn candidate_config(cfg: &FitConfig, method: Method) -> FitConfig {
    let recipe = match method {
        Method::Thermal => RecipeSettings::of_kind(Method::Thermal),
        m => RecipeSettings {
            kind: m,
            ..cfg.recipe.clone()
        },
    };
    FitConfig {
        method,
        recipe,
        ..cfg.clone()
    }
}

/// Fit with `auto`: see the module documentation.
pub(crate) fn fit(
    logs: &[NamedLog],
    cfg: &FitConfig,
    progress: &(dyn Fn(Target, usize, f64) + Sync),
) -> Result<FitOutcome, FitError> {
    let statics: Vec<usize> = (0..logs.len())
        .filter(|&i| targets::is_static(logs[i].log))
        .collect();
    let lstm_cfg = candidate_config(cfg, Method::ThermalLstm);
    let thermal_cfg = candidate_config(cfg, Method::Thermal);
    let (validation, scores, lstm_fit) = match statics.len() {
        // No bias to choose on: the scale factor is `thermal`'s in either candidate.
        0 => return fit_model(logs, &thermal_cfg, progress),
        1 => {
            let Some(id) = held_out_blocks(logs, &thermal_cfg, &lstm_cfg)? else {
                // Too short for held-out blocks: nothing could say the LSTM helps, so it is
                // not trained.
                return fit_model(logs, &thermal_cfg, progress);
            };
            // The candidates share the settings the lags are identified with.
            let fit = fit_model_identified(logs, &lstm_cfg, Some(id), progress)?;
            let Some((base, kept)) = fit.bias_training.as_ref().and_then(|t| t.held_out_rms) else {
                // Too short for held-out blocks: nothing says the LSTM helps.
                return fit_model(logs, &thermal_cfg, progress);
            };
            (Validation::HeldOutBlocks, [base, kept], Some(fit))
        }
        _ => (
            Validation::LeaveOneRunOut,
            leave_one_run_out(logs, &statics, &thermal_cfg, &lstm_cfg)?,
            None,
        ),
    };
    let mut choice = choose(validation, scores);
    if choice.folds_left_out_the_lstm() {
        // No fold could say anything of the LSTM: its fit on every run, its own gate on
        // held-out blocks deciding, is what `thermal-lstm` would fly.
        choice.chosen = Method::ThermalLstm;
    }
    let mut fit = match (choice.chosen, lstm_fit) {
        (Method::ThermalLstm, Some(fit)) => fit,
        _ => fit_model(logs, &candidate_config(cfg, choice.chosen), progress)?,
    };
    if choice.chosen == Method::ThermalLstm && fit.model.method != Method::ThermalLstm {
        // Its gate kept no LSTM: what the scores chose is not what the fit holds.
        choice = choice.with_lstm_left_out();
        fit = fit_model(logs, &thermal_cfg, progress)?;
    }
    fit.model.method_choice = Some(choice);
    Ok(fit)
}

/// The lags `thermal` identifies on `logs`, when the static runs are long enough for the
/// blocks the `thermal-lstm` candidate holds out of its LSTM's training
/// ([`residual::validation_rows`], cut from the training sets at those lags); None otherwise.
fn held_out_blocks(
    logs: &[NamedLog],
    thermal_cfg: &FitConfig,
    lstm_cfg: &FitConfig,
) -> Result<Option<Identified>, FitError> {
    let id = identify(logs, thermal_cfg)?;
    let sets: Vec<TargetSet> = logs
        .iter()
        .filter(|l| targets::is_static(l.log))
        .map(|l| {
            targets::bias_targets(l.log, &id.spec, thermal_cfg.bias_window_s).map_err(|source| {
                FitError::Targets {
                    run: l.name.to_owned(),
                    source,
                }
            })
        })
        .collect::<Result<_, _>>()?;
    let any = residual::validation_rows(&sets, &lstm_cfg.recipe)
        .iter()
        .any(|r| !r.is_empty());
    Ok(any.then_some(id))
}

/// The choice on `scores` (of [`CANDIDATES`], in order): the lowest wins, the first
/// (`thermal`) on a tie or where a score is not a number.
pub(crate) fn choose(validation: Validation, scores: [f64; 2]) -> MethodChoice {
    let chosen = if scores[1] < scores[0] {
        Method::ThermalLstm
    } else {
        Method::Thermal
    };
    MethodChoice {
        validation,
        candidates: CANDIDATES
            .iter()
            .zip(scores)
            .map(|(&method, bias_rms_dps)| CandidateScore {
                method,
                bias_rms_dps,
            })
            .collect(),
        chosen,
        lstm_left_out: false,
    }
}

/// `thermal-lstm`'s bias model on a fitted `thermal` bias model `thermal_sub` of the training
/// sets `sets`: the residual LSTM as the `thermal-lstm` candidate trains it, with what its
/// training measured (None when `thermal_sub` is not a least-squares model).
pub(crate) fn lstm_on_thermal(
    sets: &[TargetSet],
    thermal_sub: &SubModel,
    lstm_cfg: &FitConfig,
) -> Result<Option<(SubModel, TrainSummary)>, FitError> {
    let SubModel::Baseline {
        terms,
        coefficients,
    } = thermal_sub
    else {
        return Ok(None);
    };
    let base = thermal_base(sets, terms, coefficients);
    let n_in = sets[0].table.n_features;
    residual::fit_lstm_on_base(
        sets,
        base,
        &lstm_cfg.recipe,
        n_in,
        lstm_cfg.seed,
        &mut |_, _| {},
    )
    .map(Some)
}

/// Each static run left out in turn: both candidates fitted on the others, their bias residual
/// on it. Returns each candidate's RMS over every left-out run, each run's mean removed. The
/// folds run at once, each on a thread of its own (an LSTM's training alone keeps two cores
/// only partly busy); their sums are taken in run order, so the scores do not depend on which
/// fold finished first.
fn leave_one_run_out(
    logs: &[NamedLog],
    statics: &[usize],
    thermal_cfg: &FitConfig,
    lstm_cfg: &FitConfig,
) -> Result<[f64; 2], FitError> {
    let folds: Vec<Result<Option<Fold>, FitError>> = std::thread::scope(|s| {
        let handles: Vec<_> = statics
            .iter()
            .map(|&k| s.spawn(move || fold(logs, k, thermal_cfg, lstm_cfg)))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join().unwrap_or(Err(FitError::ThreadPanicked {
                    target: Target::Bias,
                }))
            })
            .collect()
    });
    let mut ss = [0.0; 2];
    let mut n = 0usize;
    for f in folds {
        if let Some((fold_ss, fold_n)) = f? {
            ss[0] += fold_ss[0];
            ss[1] += fold_ss[1];
            n += fold_n;
        }
    }
    Ok(ss.map(|s| (s / n.max(1) as f64).sqrt()))
}

/// A fold's sums of squared residuals (each candidate's) and the samples they sum over.
type Fold = ([f64; 2], usize);

/// Static run `k` left out: both candidates fitted on the other runs, their residual on it
/// (None when the fold has nothing to score).
fn fold(
    logs: &[NamedLog],
    k: usize,
    thermal_cfg: &FitConfig,
    lstm_cfg: &FitConfig,
) -> Result<Option<Fold>, FitError> {
    let others: Vec<NamedLog> = logs
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != k)
        .map(|(_, l)| *l)
        .collect();
    let id = identify(&others, thermal_cfg)?;
    let sets_of = |ls: &[NamedLog]| -> Result<Vec<TargetSet>, FitError> {
        ls.iter()
            .filter(|l| targets::is_static(l.log))
            .map(|l| {
                targets::bias_targets(l.log, &id.spec, thermal_cfg.bias_window_s).map_err(
                    |source| FitError::Targets {
                        run: l.name.to_owned(),
                        source,
                    },
                )
            })
            .collect()
    };
    let sets = sets_of(&others)?;
    let held = sets_of(&logs[k..=k])?;
    let (Some(held), false) = (held.first(), sets.is_empty()) else {
        return Ok(None);
    };
    let (thermal_sub, _) = thermal::fit_target(&sets, &thermal_cfg.thermal, &id, false)?;
    let Some((lstm_sub, _)) = lstm_on_thermal(&sets, &thermal_sub, lstm_cfg)? else {
        return Ok(None);
    };
    let labelled: Vec<usize> = (0..held.table.n_rows())
        .filter(|&r| held.mask[r] && held.target[r].is_finite())
        .collect();
    let mut ss = [0.0; 2];
    for (c, sub) in [&thermal_sub, &lstm_sub].into_iter().enumerate() {
        let pred = sub.predict_table(&held.table)?;
        let resid: Vec<f64> = labelled.iter().map(|&r| held.target[r] - pred[r]).collect();
        let mean = resid.iter().sum::<f64>() / resid.len().max(1) as f64;
        ss[c] = resid.iter().map(|e| (e - mean) * (e - mean)).sum::<f64>();
    }
    Ok(Some((ss, labelled.len())))
}

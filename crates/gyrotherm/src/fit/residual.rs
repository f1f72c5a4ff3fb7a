//! The residual recipe: a least-squares base on thermal-state inputs
//! ([`FeatureSpec::THERMAL_STATE`]: T, dT and `T - lag_τ(T)` for τ = 300, 1000, 3000 s), each
//! training run with its own offset, plus an LSTM on the base's residual.
//!
//! The base's terms are chosen from the training data ([`BaseTerms::Selected`], for bias and
//! scale factor alike): the ladder of [`super::terms`] ranked by blocked cross-validation in
//! time ([`super::select`]); the scores are reported in [`TrainSummary::selection`]. The LSTM
//! (8 hidden, as published and as flight code runs it) is trained on the base's residual with
//! windowed truncated BPTT and burn-in, and stopped early on held-out blocks of the training
//! runs (never the test run): the runs are cut into blocks and every `validation_every`-th
//! block is kept for validation. It is kept only if it beats "no correction" on those blocks
//! by [`RecipeSettings::min_val_improvement`], scaled by the gain they support. The scale factor
//! gets the base only, or a residual LSTM too with `RecipeSettings::scale_lstm` (an experiment
//! knob).
//!
//! Why a least-squares base under the LSTM, and why the LSTM is gated: an 8-unit LSTM alone
//! does not extrapolate to a profile with faster temperature swings, where a base of the
//! right form does; the gate drops it where it found nothing to learn
//! (`docs/experiments/lstm-recipes.md`, `docs/experiments/lstm-residual.md`).

use super::error::FitError;
use super::recipe::{LstmVerdict, RecipeSettings, TrainSummary, MIN_GAIN};
use super::select::{select_terms, FOLDS, GAP_STEPS};
use super::terms::{candidates, ladder, BaseTerms};
use crate::baseline::{fit_fixed_effects, FixedEffectsFit, Terms};
use crate::features::FeatureSpec;
use crate::model::{SubModel, Target};
use crate::nn::{
    predict, train_normalised, Bptt, LrSchedule, NormalisedFit, Sequence, TrainConfig, WindowStart,
};
use crate::settings::fit::DEFAULT_HIDDEN;
use crate::settings::method::Method;
use crate::targets::TargetSet;

impl RecipeSettings {
    /// The residual recipe with its default knobs.
    pub fn residual() -> Self {
        RecipeSettings {
            kind: Method::Residual,
            epochs: 300,
            lr: 0.003,
            hidden: DEFAULT_HIDDEN,
            window: 1000,
            burn_in: 200,
            batch: 4,
            block_steps: 1000,
            validation_every: 4,
            patience: Some(30),
            scale_lstm: false,
            min_val_improvement: 0.05,
            base: BaseTerms::Selected,
            scale_base: BaseTerms::Selected,
            residual_smooth_steps: 1,
            base_input: false,
            validate_on_runs: false,
            sampled_windows: false,
            lr_schedule: LrSchedule::Constant,
        }
    }
}

impl Default for RecipeSettings {
    /// The thermal recipe ([`super::thermal`]): chosen on a family of simulated units
    /// (docs/experiments/generalisation.md).
    fn default() -> Self {
        Self::of_kind(Method::Thermal)
    }
}

/// The base alone as a model file's sub-model.
fn base_sub_model(base: &FixedEffectsFit) -> SubModel {
    SubModel::Baseline {
        terms: base.terms.clone(),
        coefficients: base.coefficients.clone(),
    }
}

/// One block of a run for the residual LSTM: rows, residual target and loss mask.
struct Block {
    rows: Vec<f64>,
    target: Vec<f64>,
    mask: Vec<bool>,
}

/// The base's residual on run `s` (`offset`: the run's own offset against the base's mean
/// one), cut into `block_steps` blocks for the residual LSTM: each block starts from zero
/// state, so its first `burn_in` steps are left out of the loss; a tail no longer than the
/// burn-in and blocks with no labelled step are dropped. With `base_input` the rows carry the
/// base prediction after the features, as flight code computes it (mean offset, no run
/// offset).
fn run_blocks(
    s: &TargetSet,
    base: &FixedEffectsFit,
    offset: f64,
    recipe: &RecipeSettings,
) -> Vec<Block> {
    let nr = s.table.n_rows();
    let n_lstm = s.table.n_features + usize::from(recipe.base_input);
    let block = recipe.block_steps.max(recipe.burn_in + 1);
    let resid: Vec<f64> = (0..nr)
        .map(|r| {
            if s.mask[r] {
                s.target[r] - base.predict_row(s.table.row(r)) - offset
            } else {
                f64::NAN
            }
        })
        .collect();
    let resid = smooth_masked(&resid, &s.mask, recipe.residual_smooth_steps);
    let rows: Vec<f64> = if recipe.base_input {
        (0..nr)
            .flat_map(|r| {
                let x = s.table.row(r);
                x.iter().copied().chain([base.predict_row(x)])
            })
            .collect()
    } else {
        s.table.rows.clone()
    };
    let mut out = Vec::new();
    let mut start = 0;
    while start < nr {
        let end = (start + block).min(nr);
        if end - start <= recipe.burn_in {
            break;
        }
        let b = Block {
            rows: rows[start * n_lstm..end * n_lstm].to_vec(),
            target: resid[start..end].to_vec(),
            mask: (start..end)
                .map(|r| s.mask[r] && r - start >= recipe.burn_in)
                .collect(),
        };
        if b.mask.iter().any(|m| *m) {
            out.push(b);
        }
        start = end;
    }
    out
}

/// The held-out-run question for the residual LSTM, asked of each training run `k` in turn:
/// the base (the same terms) is refitted on the other runs, an LSTM is trained on their
/// residuals and stopped early on run `k`, whose residual is out of sample for the base (its
/// offset is its mean residual: bias stability ignores a constant). Returns, per run, the
/// relative reduction of run `k`'s loss by the LSTM against no correction,
/// `1 - best / epoch-0` (0 where it never helped). Needs two or more runs.
fn leave_one_run_out(
    train: &[TargetSet],
    terms: &Terms,
    recipe: &RecipeSettings,
    cfg: &TrainConfig,
) -> Result<Vec<f64>, FitError> {
    let n_lstm = train[0].table.n_features + usize::from(recipe.base_input);
    // Early stopping on the left-out run, whatever the main training's validation.
    let cfg = &TrainConfig {
        patience: recipe.patience,
        ..cfg.clone()
    };
    let mut out = Vec::with_capacity(train.len());
    for k in 0..train.len() {
        let others: Vec<TargetSet> = train
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != k)
            .map(|(_, s)| s.clone())
            .collect();
        // A base that cannot be refitted without run `k` cannot vouch for the LSTM there.
        let Ok(base_k) = fit_fixed_effects(&others, terms) else {
            out.push(0.0);
            continue;
        };
        let tr_blocks: Vec<Block> = others
            .iter()
            .enumerate()
            .flat_map(|(j, s)| run_blocks(s, &base_k, base_k.run_offset[j], recipe))
            .collect();
        let held = &train[k];
        let (mut sum, mut n) = (0.0, 0usize);
        for r in (0..held.table.n_rows()).filter(|r| held.mask[*r]) {
            sum += held.target[r] - base_k.predict_row(held.table.row(r));
            n += 1;
        }
        let offset = if n > 0 { sum / n as f64 } else { 0.0 };
        let va_blocks = run_blocks(held, &base_k, offset, recipe);
        if tr_blocks.is_empty() || va_blocks.is_empty() {
            out.push(0.0);
            continue;
        }
        let fit = train_normalised(
            &seqs(&tr_blocks),
            &seqs(&va_blocks),
            n_lstm,
            cfg,
            &mut |_, _| {},
        )?;
        let o = &fit.output;
        out.push(match (o.best_epoch, o.val_loss_history.first()) {
            (Some(b), Some(&v0)) if v0 > 0.0 => (1.0 - o.val_loss_history[b] / v0).max(0.0),
            _ => 0.0,
        });
    }
    Ok(out)
}

fn seqs(bs: &[Block]) -> Vec<Sequence<'_>> {
    bs.iter()
        .map(|b| Sequence::new(&b.rows, &b.target).with_mask(&b.mask))
        .collect()
}

pub(crate) fn fit(
    train: &[TargetSet],
    recipe: &RecipeSettings,
    target: Target,
    n_in: usize,
    seed: u64,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, TrainSummary), FitError> {
    let base_kind = match target {
        Target::Bias => recipe.base,
        Target::Scale => recipe.scale_base,
    };
    if n_in != FeatureSpec::THERMAL_STATE.n_features() {
        return Err(FitError::FeatureCount {
            expected: FeatureSpec::THERMAL_STATE.n_features(),
            found: n_in,
        });
    }
    // 1. The physical baseline on every labelled step of every run, each run with its own
    //    offset (turn-on bias / scale-factor repeatability); the model keeps their mean.
    if let BaseTerms::Family(i) = base_kind {
        if i as usize >= ladder().len() {
            return Err(FitError::NoSuchFamily {
                index: i as usize,
                ladder: ladder().len(),
            });
        }
    }
    let (base, selection) = match base_kind.fixed_terms(target) {
        Some(terms) => (fit_fixed_effects(train, &terms)?, None),
        None => {
            let cands = candidates(target);
            let sel = select_terms(train, &cands, FOLDS, GAP_STEPS)?;
            let fit = fit_fixed_effects(train, &cands[sel.chosen].terms)?;
            (fit, Some(sel))
        }
    };
    if base.terms.n_features != n_in {
        return Err(FitError::FeatureCount {
            expected: base.terms.n_features,
            found: n_in,
        });
    }
    let want_lstm = match target {
        Target::Bias => true,
        Target::Scale => recipe.scale_lstm,
    };
    if !want_lstm || recipe.epochs == 0 {
        let summary = TrainSummary {
            final_loss: base.rms,
            baseline_rms: Some(base.rms),
            selection,
            ..TrainSummary::default()
        };
        return Ok((base_sub_model(&base), summary));
    }
    let (sub, mut summary) = fit_lstm_on_base(train, base, recipe, n_in, seed, progress)?;
    summary.selection = selection;
    Ok((sub, summary))
}

/// Steps 2 and 3 of the recipe on a fitted least-squares `base` (its run offsets included):
/// an LSTM trained on the base's residual, kept only where the validation blocks (and, with
/// [`RecipeSettings::validate_on_runs`] and two or more runs, each left-out run) say it helps.
/// Shared by the residual recipes and the thermal recipe's optional residual LSTM.
pub(crate) fn fit_lstm_on_base(
    train: &[TargetSet],
    base: FixedEffectsFit,
    recipe: &RecipeSettings,
    n_in: usize,
    seed: u64,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, TrainSummary), FitError> {
    // 2. Residual per run, cut into blocks; every `validation_every`-th block validates.
    let n_lstm = n_in + usize::from(recipe.base_input);
    let mut train_blocks = Vec::new();
    let mut val_blocks = Vec::new();
    let mut k = 0usize;
    for (run, s) in train.iter().enumerate() {
        for b in run_blocks(s, &base, base.run_offset[run], recipe) {
            if recipe.validation_every > 0
                && k % recipe.validation_every == recipe.validation_every - 1
            {
                val_blocks.push(b);
            } else {
                train_blocks.push(b);
            }
            k += 1;
        }
    }
    let block = recipe.block_steps.max(recipe.burn_in + 1);
    if train_blocks.is_empty() {
        return Err(FitError::RunsTooShort {
            block_steps: block,
            burn_in: recipe.burn_in,
        });
    }
    let (tr, va) = (seqs(&train_blocks), seqs(&val_blocks));
    let cfg = TrainConfig {
        hidden_size: recipe.hidden,
        epochs: recipe.epochs,
        lr: recipe.lr,
        seed,
        bptt: if recipe.sampled_windows {
            Bptt::Sampled {
                window: recipe.window.max(recipe.burn_in + 1),
                burn_in: recipe.burn_in,
                batch: recipe.batch.max(1),
            }
        } else {
            Bptt::Truncated {
                window: recipe.window.max(recipe.burn_in + 1),
                burn_in: recipe.burn_in,
                batch: recipe.batch.max(1),
                start: WindowStart::Zero,
            }
        },
        clip_grad_norm: Some(1.0),
        patience: if va.is_empty() { None } else { recipe.patience },
        lr_schedule: recipe.lr_schedule,
        zero_output_init: true,
        ..TrainConfig::default()
    };
    let run_gate = if recipe.validate_on_runs && train.len() >= 2 {
        Some(leave_one_run_out(train, &base.terms, recipe, &cfg)?)
    } else {
        None
    };
    let runs_ok = run_gate
        .as_ref()
        .is_none_or(|g| g.iter().all(|v| *v >= recipe.min_val_improvement));
    let fit = train_normalised(&tr, &va, n_lstm, &cfg, progress)?;
    // 3. Keep the LSTM only if it beat "no correction" (epoch 0, zero output layer) on the
    //    validation blocks by `min_val_improvement`, and shrink its contribution to what the
    //    validation blocks support.
    let out = &fit.output;
    let val_improvement = match (out.best_epoch, out.val_loss_history.first()) {
        (Some(b), Some(&v0)) if v0 > 0.0 => Some(1.0 - out.val_loss_history[b] / v0),
        _ => None,
    };
    let blocks_ok = val_improvement.is_none_or(|g| g >= recipe.min_val_improvement);
    let sums = if val_blocks.is_empty() {
        None
    } else {
        Some(validation_sums(&fit, &val_blocks, n_lstm)?)
    };
    let gain = match (val_improvement, &sums) {
        _ if !(runs_ok && blocks_ok) => 0.0,
        (None, _) | (_, None) => 1.0,
        (Some(_), Some(sums)) => sums.gain(),
    };
    let verdict = if gain < MIN_GAIN {
        LstmVerdict::LeftOut {
            validation_blocks: !blocks_ok,
            left_out_runs: !runs_ok,
        }
    } else {
        LstmVerdict::Kept
    };
    let mut target_norm = fit.target_z.clone();
    target_norm.mean[0] *= gain;
    target_norm.std[0] *= gain;
    let summary = TrainSummary {
        epochs: fit.output.loss_history.len(),
        final_loss: fit.output.loss_history.last().copied().unwrap_or(f64::NAN),
        loss_history: fit.output.loss_history,
        val_loss_history: fit.output.val_loss_history,
        best_epoch: fit.output.best_epoch,
        baseline_rms: Some(base.rms),
        lstm_gain: Some(gain),
        val_improvement,
        selection: None,
        run_gate,
        lstm_verdict: Some(verdict),
        thermal: None,
        held_out_rms: sums.map(|v| {
            let g = if verdict == LstmVerdict::Kept {
                gain
            } else {
                0.0
            };
            (v.rms(0.0), v.rms(g))
        }),
    };
    if verdict != LstmVerdict::Kept {
        // The LSTM predicted none of the held-out residual: the physical fit alone.
        return Ok((base_sub_model(&base), summary));
    }
    Ok((
        SubModel::Residual {
            terms: base.terms,
            coefficients: base.coefficients,
            params: fit.output.params,
            input_norm: fit.input_z,
            target_norm,
            lstm_reads_base: recipe.base_input,
        },
        summary,
    ))
}

/// The rows of each run of `train` that [`fit_lstm_on_base`] keeps out of the LSTM's training
/// as validation blocks (labelled, past each block's burn-in), cut as it cuts them: for
/// scoring another model on the same rows.
pub(crate) fn validation_rows(train: &[TargetSet], recipe: &RecipeSettings) -> Vec<Vec<usize>> {
    let block = recipe.block_steps.max(recipe.burn_in + 1);
    let every = recipe.validation_every;
    let mut k = 0usize;
    train
        .iter()
        .map(|s| {
            let nr = s.table.n_rows();
            let mut rows = Vec::new();
            let mut start = 0;
            while start < nr {
                let end = (start + block).min(nr);
                if end - start <= recipe.burn_in {
                    break;
                }
                let labelled: Vec<usize> = (start + recipe.burn_in..end)
                    .filter(|&r| s.mask[r])
                    .collect();
                if !labelled.is_empty() {
                    if every > 0 && k % every == every - 1 {
                        rows.extend(labelled);
                    }
                    k += 1;
                }
                start = end;
            }
            rows
        })
        .collect()
}

/// Centred moving average of `x` over `width` steps (1 or less: unchanged), over the labelled
/// steps inside each window only; unlabelled steps stay NaN.
fn smooth_masked(x: &[f64], mask: &[bool], width: usize) -> Vec<f64> {
    if width <= 1 {
        return x.to_vec();
    }
    let n = x.len();
    let mut sum = vec![0.0; n + 1];
    let mut cnt = vec![0usize; n + 1];
    for i in 0..n {
        let ok = mask[i] && x[i].is_finite();
        sum[i + 1] = sum[i] + if ok { x[i] } else { 0.0 };
        cnt[i + 1] = cnt[i] + usize::from(ok);
    }
    let half = width / 2;
    (0..n)
        .map(|i| {
            if !mask[i] {
                return f64::NAN;
            }
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(n));
            let c = cnt[b] - cnt[a];
            if c == 0 {
                f64::NAN
            } else {
                (sum[b] - sum[a]) / c as f64
            }
        })
        .collect()
}

/// Sums over the counted steps of the validation blocks of the residual `r` and the LSTM's
/// residual prediction `p` (raw units, each block from zero state): `Σ r²`, `Σ r·p`, `Σ p²`
/// and the step count.
struct ValidationSums {
    rr: f64,
    rp: f64,
    pp: f64,
    n: usize,
}

impl ValidationSums {
    /// Least-squares gain `g = Σ r·p / Σ p²`, clamped to [0, 1]: shrinkage toward the
    /// baseline alone.
    fn gain(&self) -> f64 {
        if self.pp > 0.0 {
            (self.rp / self.pp).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// RMS of `r − g·p` (g = 0: the base alone).
    fn rms(&self, g: f64) -> f64 {
        let ss = self.rr - 2.0 * g * self.rp + g * g * self.pp;
        (ss.max(0.0) / self.n.max(1) as f64).sqrt()
    }
}

fn validation_sums(
    fit: &NormalisedFit,
    val: &[Block],
    n_in: usize,
) -> Result<ValidationSums, FitError> {
    let mut s = ValidationSums {
        rr: 0.0,
        rp: 0.0,
        pp: 0.0,
        n: 0,
    };
    for b in val {
        let x: Vec<f64> = b
            .rows
            .iter()
            .enumerate()
            .map(|(k, v)| fit.input_z.apply(k % n_in, *v))
            .collect();
        let y = predict(&fit.output.params, &x)?;
        for ((yn, r), m) in y.iter().zip(&b.target).zip(&b.mask) {
            if *m {
                let p = fit.target_z.invert(0, *yn);
                s.rr += r * r;
                s.rp += r * p;
                s.pp += p * p;
                s.n += 1;
            }
        }
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::smooth_masked;

    /// A centred moving average leaves a straight line unchanged away from the ends (the mean
    /// of a symmetric window of a line is its centre value), skips unlabelled steps and keeps
    /// them unlabelled (independent: the definition).
    #[test]
    fn smooth_masked_is_a_centred_mean_over_labelled_steps() {
        let x: Vec<f64> = (0..20).map(|i| 2.0 * i as f64 + 1.0).collect();
        let all = vec![true; x.len()];
        let y = smooth_masked(&x, &all, 5);
        for i in 2..18 {
            assert!(
                (y[i] - x[i]).abs() < 1e-12,
                "step {i}: want {}, got {}",
                x[i],
                y[i]
            );
        }
        // At the start the window is cut: steps 0..=2.
        assert!((y[0] - (1.0 + 3.0 + 5.0) / 3.0).abs() < 1e-12);
        let mut mask = all.clone();
        mask[10] = false;
        let y = smooth_masked(&x, &mask, 3);
        assert!(y[10].is_nan());
        // Step 9 averages steps 8 and 9 only.
        assert!((y[9] - (x[8] + x[9]) / 2.0).abs() < 1e-12, "got {}", y[9]);
        assert_eq!(smooth_masked(&x, &all, 1), x);
    }
}

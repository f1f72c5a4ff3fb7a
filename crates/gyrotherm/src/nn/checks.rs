//! Checks of a training problem before any arithmetic: shapes, finiteness, settings.

use super::config::{Bptt, Sequence, TrainConfig};
use super::error::TrainError;

/// Check shapes and finiteness of runs (`set`: "training", "validation", "evaluation").
pub(crate) fn check_runs(
    set: &'static str,
    runs: &[Sequence<'_>],
    input_size: usize,
) -> Result<(), TrainError> {
    for (n, r) in runs.iter().enumerate() {
        let steps = r.steps();
        if steps == 0 {
            return Err(TrainError::EmptyRun { set, run: n });
        }
        if r.inputs.len() != steps * input_size {
            return Err(TrainError::InputLength {
                set,
                run: n,
                values: r.inputs.len(),
                steps,
                input_size,
            });
        }
        if let Some(m) = r.loss_mask {
            if m.len() != steps {
                return Err(TrainError::MaskLength {
                    set,
                    run: n,
                    mask: m.len(),
                    steps,
                });
            }
        }
        if let Some(k) = r.inputs.iter().position(|v| !v.is_finite()) {
            return Err(TrainError::NonFiniteInput {
                set,
                run: n,
                input: k % input_size,
                step: k / input_size,
                value: r.inputs[k],
            });
        }
        if let Some(t) = (0..steps).find(|&t| r.counts(t) && !r.target[t].is_finite()) {
            return Err(TrainError::NonFiniteTarget {
                set,
                run: n,
                step: t,
                value: r.target[t],
            });
        }
    }
    Ok(())
}

/// Validated sizes of a training problem.
pub(crate) fn check_problem(
    runs: &[Sequence<'_>],
    validation: &[Sequence<'_>],
    input_size: usize,
    cfg: &TrainConfig,
) -> Result<(), TrainError> {
    if runs.is_empty() {
        return Err(TrainError::NoRuns);
    }
    if input_size == 0 || cfg.hidden_size == 0 {
        return Err(TrainError::ZeroSize {
            input_size,
            hidden_size: cfg.hidden_size,
        });
    }
    check_runs("training", runs, input_size)?;
    check_runs("validation", validation, input_size)?;
    let counted = |rs: &[Sequence<'_>]| {
        rs.iter()
            .map(|r| (0..r.steps()).filter(|&t| r.counts(t)).count())
            .sum::<usize>()
    };
    if counted(runs) == 0 {
        return Err(TrainError::AllMasked { set: "training" });
    }
    if !validation.is_empty() && counted(validation) == 0 {
        return Err(TrainError::AllMasked { set: "validation" });
    }
    let pos = |v: f64| v.is_finite() && v > 0.0;
    if !pos(cfg.lr)
        || !pos(cfg.eps)
        || !(0.0..1.0).contains(&cfg.beta1)
        || !(0.0..1.0).contains(&cfg.beta2)
    {
        return Err(TrainError::AdamSettings {
            lr: cfg.lr,
            eps: cfg.eps,
            beta1: cfg.beta1,
            beta2: cfg.beta2,
        });
    }
    if let Some(c) = cfg.clip_grad_norm {
        if !pos(c) {
            return Err(TrainError::ClipGradNorm { value: c });
        }
    }
    let windowed = match cfg.bptt {
        Bptt::Full => None,
        Bptt::Truncated {
            window,
            burn_in,
            batch,
            ..
        }
        | Bptt::Sampled {
            window,
            burn_in,
            batch,
        } => Some((window, burn_in, batch)),
    };
    if let Some((window, burn_in, batch)) = windowed {
        if window <= burn_in || batch == 0 {
            return Err(TrainError::Window {
                window,
                burn_in,
                batch,
            });
        }
    }
    if let Bptt::Sampled { burn_in, .. } = cfg.bptt {
        // A window counts its steps from `burn_in` on: some run must be longer than that.
        if runs.iter().all(|r| r.steps() <= burn_in) {
            return Err(TrainError::RunsTooShort { burn_in });
        }
    }
    Ok(())
}

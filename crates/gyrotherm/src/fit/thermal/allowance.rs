//! What the training runs allow the thermal fit: folds, gap, lag range, lag count and basis,
//! with the notes that say how a short or coarse log degrades it.

use super::*;

/// What the training runs allow: folds, gap, lag range, lag count, basis; with notes.
pub(super) struct Allowance {
    pub(super) folds: usize,
    pub(super) gap_steps: usize,
    pub(super) tau_max_s: f64,
    pub(super) n_lags: usize,
    pub(super) basis: Basis,
    pub(super) notes: Vec<String>,
}

pub(super) fn allowance(runs: &[RunData], cfg: &ThermalConfig) -> Result<Allowance, ThermalError> {
    let labelled: usize = runs
        .iter()
        .map(|r| r.mask.iter().filter(|m| **m).count())
        .sum();
    let longest_s = runs
        .iter()
        .map(|r| r.log.time_s.last().copied().unwrap_or(0.0) - r.log.time_s[0])
        .fold(0.0f64, f64::max);
    let period = runs
        .iter()
        .map(|r| r.log.sample_period_s())
        .filter(|p| p.is_finite())
        .fold(f64::INFINITY, f64::min);
    let mut notes = Vec::new();
    let tmin = runs
        .iter()
        .flat_map(|r| r.log.temp_c.iter().copied())
        .fold(f64::INFINITY, f64::min);
    let tmax = runs
        .iter()
        .flat_map(|r| r.log.temp_c.iter().copied())
        .fold(f64::NEG_INFINITY, f64::max);
    if tmax.is_nan() || tmin.is_nan() || tmax - tmin <= 0.5 {
        return Err(ThermalError::ConstantTemperature);
    }
    let needed = 3 + runs.len();
    if labelled < needed {
        return Err(ThermalError::TooFewSteps {
            steps: labelled,
            needed,
        });
    }
    // Steps per fold: each fold should hold at least 40 labelled steps per term it checks.
    let per_run_min = runs
        .iter()
        .map(|r| r.mask.iter().filter(|m| **m).count())
        .min()
        .unwrap_or(0);
    let mut folds = cfg.folds;
    while folds > 2 && per_run_min / folds < 40 {
        folds -= 1;
    }
    if per_run_min / folds < 20 {
        folds = 0;
        notes.push(format!(
            "no cross-validation: {per_run_min} labelled steps in the shortest run are too few \
             for folds; ridge strength fixed at {:.0e}",
            cfg.fallback_ridge
        ));
    } else if folds < cfg.folds {
        notes.push(format!(
            "{folds} cross-validation folds instead of {} (short runs: {per_run_min} labelled \
             steps)",
            cfg.folds
        ));
    }
    let step = period.max(1.0);
    let gap_steps = ((cfg.gap_s / step).round() as usize).min(per_run_min / 10);
    let mut tau_max_s = cfg.tau_range_s.1;
    let bound = cfg.max_tau_fraction * longest_s;
    if bound < tau_max_s {
        tau_max_s = bound.max(cfg.tau_range_s.0);
        notes.push(format!(
            "lags up to {tau_max_s:.0} s only ({}% of the {longest_s:.0} s run) instead of {:.0} s",
            (100.0 * cfg.max_tau_fraction).round(),
            cfg.tau_range_s.1
        ));
    }
    let tau_min_s = cfg.tau_range_s.0.max(3.0 * period);
    // Each lag needs room: a factor 2 between neighbours.
    let mut n_lags = cfg.n_lags.clamp(1, 3);
    while n_lags > 1 && tau_min_s * cfg.min_lag_ratio.powi(n_lags as i32 - 1) > tau_max_s {
        n_lags -= 1;
    }
    if n_lags < cfg.n_lags {
        notes.push(format!(
            "{n_lags} lag(s) instead of {}: the runs are too short to tell more apart",
            cfg.n_lags
        ));
    }
    let mut basis = cfg.basis;
    // Ten labelled steps per term at least (each step is one target value).
    while basis != Basis::Minimal && labelled < 100 * self::basis(basis, n_lags).len() {
        basis = match basis {
            Basis::Full => Basis::Small,
            Basis::Small => Basis::Linear,
            Basis::Linear => Basis::Lean,
            _ => Basis::Minimal,
        };
    }
    if basis != cfg.basis {
        notes.push(format!(
            "terms `{}` instead of `{}`: {labelled} labelled steps",
            basis.name(),
            cfg.basis.name()
        ));
    }
    Ok(Allowance {
        folds,
        gap_steps,
        tau_max_s,
        n_lags,
        basis,
        notes,
    })
}

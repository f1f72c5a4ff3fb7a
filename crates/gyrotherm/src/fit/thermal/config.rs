//! The thermal-state recipe's settings (experiment knobs; the defaults are the recipe's).

use super::Basis;

/// Settings of the thermal-state recipe: experiment knobs, public (as
/// `gyrotherm::fit::thermal::ThermalConfig` and `FitConfig::thermal`) only with the
/// `experiments` feature of this crate.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalConfig {
    /// Lags to identify (1 to 3; fewer when the runs are short).
    pub n_lags: usize,
    /// Range of the time constants searched, s (the upper end is also bounded by
    /// [`ThermalConfig::max_tau_fraction`] of the longest training run).
    pub tau_range_s: (f64, f64),
    /// Grid points over `tau_range_s` (log-spaced) for the first search.
    pub tau_grid: usize,
    /// Longest time constant as a fraction of the longest training run.
    pub max_tau_fraction: f64,
    /// Blocked cross-validation folds per run (fewer when the runs are short).
    pub folds: usize,
    /// Steps left out either side of a validation fold (the bias target is a 100 s moving
    /// average; scaled down with the step count on coarse logs).
    pub gap_s: f64,
    /// Ridge strengths tried, relative to unit-RMS columns (penalty λ·n·Σ β_j² on the scaled
    /// coefficients).
    pub ridge_grid: Vec<f64>,
    /// Ridge strength used when the runs are too short to cross-validate.
    pub fallback_ridge: f64,
    /// Which terms the bias model gets, and the lag identification uses ([`basis`](super::basis)).
    pub basis: Basis,
    /// Which terms the scale-factor model gets.
    pub scale_basis: Basis,
    /// Least ratio between neighbouring time constants (close lags are nearly collinear,
    /// and their large opposite coefficients extrapolate badly).
    pub min_lag_ratio: f64,
    /// Identify the lags on the bias and the scale factor together (the sum of their
    /// cross-validated scores, each relative to its target's spread) when both kinds of run
    /// are given; otherwise on the bias alone.
    pub joint: bool,
    /// The strongest ridge whose cross-validated score is within this relative margin of the
    /// best is taken (prefer the smoother fit when the data cannot tell them apart).
    pub ridge_tolerance: f64,
    /// Train an LSTM on the fitted model's residual (the residual recipe's knobs and gates:
    /// validation blocks, and each left-out run with `validate_on_runs`), reading the
    /// identified thermal states and, with [`RecipeSettings::base_input`](crate::fit::RecipeSettings),
    /// the model's prediction. Off by default (`docs/experiments/lstm-on-thermal-base.md`).
    pub residual_lstm: bool,
}

impl Default for ThermalConfig {
    fn default() -> Self {
        ThermalConfig {
            n_lags: 3,
            tau_range_s: (60.0, 12000.0),
            tau_grid: 9,
            max_tau_fraction: 0.5,
            folds: 5,
            gap_s: 200.0,
            ridge_grid: (0..=9).map(|k| 10f64.powi(-9 + k)).collect(),
            fallback_ridge: 1e-4,
            basis: Basis::Lean,
            scale_basis: Basis::Full,
            min_lag_ratio: 3.0,
            joint: true,
            ridge_tolerance: 0.0,
            residual_lstm: false,
        }
    }
}

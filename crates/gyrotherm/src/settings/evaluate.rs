//! The standard figures of a log column (`gyrotherm evaluate`): the settings, and the policy
//! for the bias-stability smoothing time τ.

use crate::csvlog::{rate_column_to_dph, TestLog, GYRO_COL};
use crate::metrics::{self, Evaluation, EvaluationError, EvaluationOptions};
use crate::setting_rule::{Rule, SettingError};

/// The preferred bias-stability smoothing time, s (100 s, He et al. 2024 and docs/method.md §4).
pub(crate) const PREFERRED_TAU_S: f64 = crate::metrics::BIAS_STABILITY_TAU_S;
/// Default time dropped at the start of each rate-table segment, s.
pub const DEFAULT_SETTLE_S: f64 = crate::targets::SETTLE_S;

/// What `gyrotherm evaluate` judges and how.
#[derive(Debug, Clone, PartialEq)]
pub struct EvaluateSettings {
    /// Rate column to judge: `gyro_dps` or a numeric extra column (`*_dps`, `*_dph`,
    /// `*_rad_s`).
    pub column: String,
    /// Smoothing time of the bias stability, s (None: `PREFERRED_TAU_S`, or the multiple
    /// of the sample period nearest to it when it is not one).
    pub tau_s: Option<f64>,
    /// Time dropped at the start of each rate-table segment, s.
    pub settle_s: f64,
    /// Room-temperature scale factor for the thermal error (None: the first rate segment's).
    pub reference_scale: Option<f64>,
}

impl Default for EvaluateSettings {
    fn default() -> Self {
        EvaluateSettings {
            column: GYRO_COL.to_owned(),
            tau_s: None,
            settle_s: DEFAULT_SETTLE_S,
            reference_scale: None,
        }
    }
}

/// Why a column could not be evaluated.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum EvaluateError {
    /// A setting breaks its rule.
    Setting(SettingError),
    /// The column's name gives no rate unit.
    NoRateUnit { column: String },
    /// τ leaves fewer than two means.
    TauTooLong {
        tau_s: f64,
        samples: usize,
        tau0_s: f64,
    },
    /// The figures themselves.
    Figures {
        column: String,
        source: EvaluationError,
    },
}

impl std::fmt::Display for EvaluateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EvaluateError::Setting(e) => e.fmt(f),
            EvaluateError::NoRateUnit { column } => write!(
                f,
                "column `{column}` has no rate unit in its name; name it *_dps, *_dph or *_rad_s"
            ),
            EvaluateError::TauTooLong {
                tau_s,
                samples,
                tau0_s,
            } => {
                let duration_s = tau0_s * *samples as f64;
                write!(
                    f,
                    "tau_s = {tau_s:?} s is longer than half the log ({samples} samples of \
                     {tau0_s} s = {duration_s} s): the bias stability needs at least two \
                     means; give at most {} s",
                    duration_s / 2.0
                )
            }
            EvaluateError::Figures { column, .. } => write!(f, "column {column}"),
        }
    }
}

impl std::error::Error for EvaluateError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the setting's message is this error's own.
            EvaluateError::Setting(e) => e.source(),
            EvaluateError::Figures { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// The τ used, and whether it was moved off `PREFERRED_TAU_S` (then the caller should say
/// so: a log at one sample per 15 s gets τ = 105 s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolvedTau {
    pub tau_s: f64,
    pub adjusted: bool,
}

impl ResolvedTau {
    /// The sentence saying why τ is not 100 s.
    pub fn note(&self, tau0_s: f64) -> Option<String> {
        self.adjusted.then(|| {
            format!(
                "τ = {} s, the multiple of the {tau0_s} s sample period nearest {} s ({} s is \
                 not one; give tau_s to choose)",
                self.tau_s, PREFERRED_TAU_S, PREFERRED_TAU_S
            )
        })
    }
}

impl EvaluateSettings {
    /// Check every value; the error names the setting and the rule.
    pub fn validate(&self) -> Result<(), SettingError> {
        super::check_opt("tau_s", self.tau_s, Rule::PositiveSeconds)?;
        super::check("settle_s", self.settle_s, Rule::NonNegativeSeconds)?;
        super::check_opt(
            "reference_scale",
            self.reference_scale,
            Rule::PositiveScaleFactor,
        )?;
        Ok(())
    }

    /// τ for a column of `samples` values every `tau0_s`: the one given, or the default; at
    /// most half the log (two means).
    pub(crate) fn resolve_tau(
        &self,
        tau0_s: f64,
        samples: usize,
    ) -> Result<ResolvedTau, EvaluateError> {
        let r = match self.tau_s {
            Some(tau_s) => ResolvedTau {
                tau_s,
                adjusted: false,
            },
            None => {
                let (tau_s, adjusted) = metrics::default_tau_s(tau0_s, PREFERRED_TAU_S);
                ResolvedTau { tau_s, adjusted }
            }
        };
        if r.tau_s > tau0_s * samples as f64 / 2.0 {
            return Err(EvaluateError::TauTooLong {
                tau_s: r.tau_s,
                samples,
                tau0_s,
            });
        }
        Ok(r)
    }

    /// The figures of `values` (the column [`Self::column`] of `log`, sampled every
    /// `tau0_s`), and the τ used.
    pub fn evaluate(
        &self,
        log: &TestLog,
        values: &[f64],
        tau0_s: f64,
    ) -> Result<(Evaluation, ResolvedTau), EvaluateError> {
        let (rate_dps, opts, tau) = self.prepare(values, tau0_s)?;
        let e = metrics::evaluate(
            &self.column,
            &log.time_s,
            &rate_dps,
            tau0_s,
            log.table_dps.as_deref(),
            &opts,
        )
        .map_err(|source| EvaluateError::Figures {
            column: self.column.clone(),
            source,
        })?;
        Ok((e, tau))
    }

    /// What [`evaluate`](Self::evaluate) judges, before it judges it: the column's values in
    /// °/s, the figures' options and the τ used (also what a spec sheet is judged on).
    pub(crate) fn prepare(
        &self,
        values: &[f64],
        tau0_s: f64,
    ) -> Result<(Vec<f64>, EvaluationOptions, ResolvedTau), EvaluateError> {
        self.validate().map_err(EvaluateError::Setting)?;
        let to_dph = rate_column_to_dph(&self.column).ok_or_else(|| EvaluateError::NoRateUnit {
            column: self.column.clone(),
        })?;
        let tau = self.resolve_tau(tau0_s, values.len())?;
        // Factor first: v·to_dph could overflow where v·(to_dph/3600) does not.
        let to_dps = to_dph / 3600.0;
        let rate_dps: Vec<f64> = values.iter().map(|v| v * to_dps).collect();
        let opts = EvaluationOptions {
            tau_s: tau.tau_s,
            settle_s: self.settle_s,
            reference_scale: self.reference_scale,
        };
        Ok((rate_dps, opts, tau))
    }
}

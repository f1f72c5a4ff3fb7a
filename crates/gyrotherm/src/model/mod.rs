//! Model files: one JSON file per fitted compensation model.
//!
//! ```json
//! {
//!   "format_version": 1,
//!   "method": "linear",
//!   "features": {"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
//!                "lag_tau_s": [], "lag_outputs": "diff_from_t",
//!                "temp_sensor": {"min_c": -60.0, "max_c": 100.0, "max_rate_c_per_s": 2.0,
//!                                "step_allowance_c": 1.0, "degraded_after_s": 60.0}},
//!   "bias": {"baseline": {"terms": {"n_features": 2, "powers": [[0,0],[1,0],[0,1]]},
//!                         "coefficients": [0.001, 2e-5, 0.01]}},
//!   "scale": {"lstm": {"params": {…LstmParams…}, "input_norm": {…}, "target_norm": {…}}},
//!   "training": {"temp_range_c": {"min": -40.0, "max": 60.0}, …}
//! }
//! ```
//! `bias` predicts the bias B in °/s, `scale` the scale factor K (dimensionless, ≈1) of
//! `G = (Ĝ - B) / K` (eq. 4 of He et al. 2024); either may be absent. Floats are written in
//! shortest round-trip form, so save → load is bit-exact. [`ModelFile::load`] checks the
//! version first, then the fields (unknown fields are refused), then shapes and finiteness.
//! A key named twice in one object is refused anywhere in the file (see
//! `crate::json_keys`).

use crate::atomic_file::write_bytes_atomically;
use crate::baseline::TermsError;
use crate::baseline::{self, Terms};
use crate::csvlog::ReadOptions;
use crate::features::FeatureTable;
use crate::json_keys::{check_unique_keys, DuplicateKey, KeyCheckError};
use crate::nn::params::{LstmParams, ParamsError};
use crate::nn::zscore::ZScore;
use gyrotherm_core::baseline::{BaselineError, BaselineModel};
use gyrotherm_core::features::{FeatureKind, FeatureSpec};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// The format version this build writes.
pub(crate) const FORMAT_VERSION: u32 = 1;
/// The format versions this build reads.
pub(crate) const SUPPORTED_VERSIONS: &[u32] = &[1];

/// Largest |coefficient| of a least-squares term: far beyond any fit of a gyro's drift in
/// °C and °C/s, short of what makes f64 sums overflow.
pub(crate) const MAX_PLAUSIBLE_COEFFICIENT: f64 = 1e15;
/// Largest |bias| a model may predict inside its training range, °/s: beyond the measuring
/// range of any fibre optic gyro.
pub(crate) const MAX_PLAUSIBLE_BIAS_DPS: f64 = 1e3;
/// Range of scale factor K (nominal 1) a model may predict inside its training range.
pub(crate) const PLAUSIBLE_SCALE: (f64, f64) = (0.1, 10.0);
/// Most feature steps of one probe run in the training-range check (a ramp at the slowest
/// rate stops there).
const MAX_PROBE_STEPS: usize = 20_000;
/// Key of the content checksum in a model file.
pub const CHECKSUM_KEY: &str = "content_sha256";

/// Whether a loaded model file carried a content checksum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seal {
    /// The file's `content_sha256` matched its content.
    Verified,
    /// The file had no `content_sha256` (written before files were sealed, or by hand): its
    /// other checks passed, but corruption of a value cannot be told from a deliberate one.
    Absent,
}

pub use crate::settings::Method;

/// One target's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SubModel {
    /// An LSTM with z-score normalisation of its inputs (one channel per feature) and target.
    Lstm {
        params: LstmParams,
        input_norm: ZScore,
        target_norm: ZScore,
    },
    /// A baseline: Σ coefficients\[j\] · monomial j of the raw features.
    Baseline {
        terms: Terms,
        coefficients: Vec<f64>,
    },
    /// A baseline plus an LSTM fitted to its residual: y = baseline(x) + lstm(x) (a residual
    /// LSTM on top of a physical fit); with `lstm_reads_base`,
    /// y = baseline(x) + lstm(x, baseline(x)): the LSTM reads the features followed by the
    /// baseline's value (`n_features + 1` inputs).
    Residual {
        terms: Terms,
        coefficients: Vec<f64>,
        params: LstmParams,
        input_norm: ZScore,
        target_norm: ZScore,
        /// The LSTM's last input is the baseline's value (absent in older files: false).
        #[serde(default)]
        lstm_reads_base: bool,
    },
}

/// A model file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// `FORMAT_VERSION`.
    pub format_version: u32,
    /// How it was fitted.
    pub method: Method,
    /// The model inputs.
    pub features: FeatureDef,
    /// Bias model, output °/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<SubModel>,
    /// Scale-factor model, output dimensionless (K ≈ 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<SubModel>,
    /// Training facts.
    pub training: TrainingInfo,
    /// The (T, dT) region training covered and the cross-validated bias error there (absent
    /// in older files and for LSTM bias models; see [`CoverageDef`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<CoverageDef>,
    /// The log columns (and gyro unit) the model was trained on, so that a log of the same
    /// layout is compensated without naming them again (absent in older files: the options
    /// given, or their defaults). Left out of the file when absent, so an older file's
    /// `content_sha256` still matches.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub columns: Option<ColumnsDef>,
    /// Why training stored no coverage map (absent when it stored one, and in files written
    /// before the reason was kept), so that a later command gives the reason training gave.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage_note: Option<String>,
    /// How `auto` chose the method that fitted this model: every candidate's held-out score
    /// and the choice (absent for any other method, and in older files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method_choice: Option<MethodChoice>,
}

/// Which of the two sub-models of a model file (and which target a fit is for).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Bias, °/s.
    Bias,
    /// Scale factor K, dimensionless.
    Scale,
}

impl Target {
    pub fn as_str(&self) -> &'static str {
        match self {
            Target::Bias => "bias",
            Target::Scale => "scale",
        }
    }
}

/// SHA-256 hex of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let d = Sha256::digest(bytes);
    d.iter().map(|b| format!("{b:02x}")).collect()
}

impl ModelFile {
    /// What the model holds, as a column name: `linear` and `poly` for the classic fits; for
    /// the `lstm` method, `LS + LSTM` when a least-squares base carries a residual LSTM,
    /// `LSTM` when a network alone predicts, and `thermal-state LS` when no LSTM was kept (the
    /// method's gates left it out), so a table never calls a model without an LSTM "lstm".
    pub fn label(&self) -> &'static str {
        let subs = || [&self.bias, &self.scale].into_iter().flatten();
        match self.method {
            m if m.is_recipe() && subs().any(|s| matches!(s, SubModel::Residual { .. })) => {
                "LS + LSTM"
            }
            m if m.is_recipe() && subs().any(|s| matches!(s, SubModel::Lstm { .. })) => "LSTM",
            m if m.is_recipe() => "thermal-state LS",
            m => m.as_str(),
        }
    }

    /// Read options for a log to compensate with this model: the columns it was trained on,
    /// except those the user named in `base` (`given`); `base` as it is for a file without
    /// them.
    pub fn read_options(
        &self,
        base: &ReadOptions,
        given: GivenColumns,
    ) -> Result<ReadOptions, ModelFileError> {
        match &self.columns {
            Some(c) => c.read_options(base, given),
            None => Ok(base.clone()),
        }
    }

    /// What the file tells of its fit, one indented line each (Python's `Model.summary()`):
    /// the thermal lags the inputs use, LSTM epochs and final loss only where an LSTM was
    /// trained (a least-squares fit has none), and the cross-validated bias residual of the
    /// coverage map.
    pub fn describe(&self) -> Vec<String> {
        let mut out = Vec::new();
        let lags = &self.features.lag_tau_s;
        if !lags.is_empty() {
            let each: Vec<String> = lags.iter().map(|l| format!("{l}")).collect();
            out.push(format!("  thermal lags: {} s", each.join(", ")));
        }
        let t = &self.training;
        if let (Some(e), Some(l)) = (t.epochs.filter(|&e| e > 0), t.final_loss) {
            out.push(format!(
                "  LSTM: {e} epochs, final loss {l:.4e} (normalised MSE)"
            ));
        }
        match &self.coverage {
            Some(c) => out.push(format!(
                "  cross-validated bias residual: {:.4} °/h RMS over {} folds ({} of {} (T, dT) \
                 cells covered)",
                c.pooled_rms_dph(),
                c.folds,
                c.covered_cells(),
                c.n_temp * c.n_rate
            )),
            None => {
                if let Some(n) = missing_coverage_note(self) {
                    out.push(format!("  coverage: none: {n}"));
                }
            }
        }
        out
    }

    /// The core feature spec of this model.
    pub fn feature_spec(&self) -> Result<FeatureSpec, ModelFileError> {
        self.features.to_spec()
    }
}

/// What to tell the user when a model file carries no coverage map: nothing when it does.
/// The reason is the one training gave (kept in the file); a file without it was written
/// before gyrotherm stored maps or their reasons.
pub fn missing_coverage_note(model: &ModelFile) -> Option<String> {
    if model.coverage.is_some() {
        return None;
    }
    Some(match &model.coverage_note {
        Some(why) => {
            // The file may have been edited: no control character reaches the terminal.
            let why: String = why
                .chars()
                .take(400)
                .map(|c| if c.is_control() { '?' } else { c })
                .collect();
            format!(
                "the model file has no coverage map ({why}): the coverage and sigma_dph \
                 columns stay empty"
            )
        }
        None => "the model file has no coverage map (written before gyrotherm stored one, or \
                 its bias model is an LSTM alone): the coverage and sigma_dph columns stay \
                 empty; re-train to get them"
            .to_owned(),
    })
}

mod checks;
mod columns;
mod coverage_map;
mod error;
mod flight;
mod ground;
mod inputs;
mod method_choice;
mod seal;
mod training;
pub mod unit;

pub use checks::SubModelError;
pub use columns::{ColumnsDef, GivenColumns};
pub use coverage_map::CoverageDef;
pub use error::ModelFileError;
pub(crate) use flight::{boxed_compensator, sized_compensator};
pub use flight::{hidden_size, CompensateError};
pub(crate) use flight::{static_baseline, static_target, target_model};
pub use inputs::{FeatureDef, LagOutputsDef, TempSensorDef};
pub use method_choice::{CandidateScore, MethodChoice, Validation};
pub(crate) use seal::{content_digest_of, parse_sealed, SealedTextError};
pub use training::{created_by, data_digest, training_ranges, Range, TrainingInfo};

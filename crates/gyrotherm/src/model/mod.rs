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
use crate::csvlog::{ReadOptions, TestLog};
use crate::features::FeatureTable;
use crate::json_keys::{check_unique_keys, DuplicateKey, KeyCheckError};
use crate::nn::params::{LstmParams, ParamsError};
use crate::nn::zscore::ZScore;
use gyrotherm_core::baseline::{BaselineError, BaselineModel};
use gyrotherm_core::compensator::TempLimits;
use gyrotherm_core::features::{FeatureKind, FeatureSpec, LagOutputs, MAX_LAGS};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

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

/// [`LagOutputs`] in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LagOutputsDef {
    /// Lag outputs y_j.
    Level,
    /// T - y_j.
    DiffFromT,
    /// Both.
    Both,
}

/// The feature definition in the file (the core's [`FeatureSpec`], with the lags as a list).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeatureDef {
    /// Model step period, s.
    pub step_period_s: f64,
    /// Rate lag, s (dT = (T(t) - T(t - lag)) / lag).
    pub rate_lag_s: f64,
    /// Moving-average window of T, s (0: none).
    pub smoothing_window_s: f64,
    /// Thermal-state lag time constants, s.
    pub lag_tau_s: Vec<f64>,
    /// Which lag outputs are features.
    pub lag_outputs: LagOutputsDef,
    /// Which temperature readings are believed (absent in older files: the defaults).
    #[serde(default)]
    pub temp_sensor: TempSensorDef,
}

/// Temperature-sensor fault limits in the file (the core's [`TempLimits`]): a reading outside
/// `min_c..=max_c`, or changing faster than `max_rate_c_per_s` (plus `step_allowance_c`)
/// since the last good one, is held; held longer than `degraded_after_s` is degraded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TempSensorDef {
    /// Lowest plausible reading, °C.
    pub min_c: f64,
    /// Highest plausible reading, °C.
    pub max_c: f64,
    /// Fastest plausible change, °C/s.
    pub max_rate_c_per_s: f64,
    /// Change always allowed between readings, °C.
    pub step_allowance_c: f64,
    /// Seconds without a good reading before the output is degraded.
    pub degraded_after_s: f64,
}

impl Default for TempSensorDef {
    fn default() -> Self {
        Self::from_core(&TempLimits::DEFAULT)
    }
}

impl TempSensorDef {
    /// The file form of core limits.
    pub(crate) fn from_core(l: &TempLimits) -> Self {
        TempSensorDef {
            min_c: l.min_c,
            max_c: l.max_c,
            max_rate_c_per_s: l.max_rate_c_per_s,
            step_allowance_c: l.step_allowance_c,
            degraded_after_s: l.degraded_after_s,
        }
    }

    /// The core limits, checked (the error names `features.temp_sensor`).
    pub fn to_core(&self) -> Result<TempLimits, ModelFileError> {
        let l = TempLimits {
            min_c: self.min_c,
            max_c: self.max_c,
            max_rate_c_per_s: self.max_rate_c_per_s,
            step_allowance_c: self.step_allowance_c,
            degraded_after_s: self.degraded_after_s,
        };
        l.validate()
            .map_err(|e| ModelFileError::invalid("features.temp_sensor", e.to_string()))?;
        Ok(l)
    }
}

impl FeatureDef {
    /// The file form of `spec`.
    pub fn from_spec(spec: &FeatureSpec) -> FeatureDef {
        FeatureDef {
            step_period_s: spec.step_period_s,
            rate_lag_s: spec.rate_lag_s,
            smoothing_window_s: spec.smoothing_window_s,
            lag_tau_s: spec.lags().to_vec(),
            lag_outputs: match spec.lag_outputs {
                LagOutputs::Level => LagOutputsDef::Level,
                LagOutputs::DiffFromT => LagOutputsDef::DiffFromT,
                LagOutputs::Both => LagOutputsDef::Both,
            },
            temp_sensor: TempSensorDef::default(),
        }
    }

    /// The core spec, checked.
    pub fn to_spec(&self) -> Result<FeatureSpec, ModelFileError> {
        if self.lag_tau_s.len() > MAX_LAGS {
            return Err(ModelFileError::invalid(
                "features",
                format!(
                    "{} lag time constants, at most {MAX_LAGS} supported",
                    self.lag_tau_s.len()
                ),
            ));
        }
        let base = FeatureSpec {
            step_period_s: self.step_period_s,
            rate_lag_s: self.rate_lag_s,
            smoothing_window_s: self.smoothing_window_s,
            ..FeatureSpec::PUBLISHED
        };
        let outputs = match self.lag_outputs {
            LagOutputsDef::Level => LagOutputs::Level,
            LagOutputsDef::DiffFromT => LagOutputs::DiffFromT,
            LagOutputsDef::Both => LagOutputs::Both,
        };
        base.with_lags(&self.lag_tau_s, outputs)
            .map_err(ModelFileError::Features)
    }
}

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

/// A closed range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    pub min: f64,
    pub max: f64,
}

impl Range {
    /// (min, max) of `x` (None if empty).
    pub fn of(x: &[f64]) -> Option<Range> {
        if x.is_empty() {
            return None;
        }
        let (min, max) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        Some(Range { min, max })
    }
    /// True when `v` lies inside.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// Training temperature range (feature 0, °C) and rate range (feature 1, °C/s) over the
/// steps of `tables` (None if there are no steps).
pub fn training_ranges(tables: &[&FeatureTable]) -> Option<(Range, Range)> {
    let mut t = Vec::new();
    let mut r = Vec::new();
    for tab in tables {
        if tab.n_features >= 2 {
            t.extend(tab.column(0));
            r.extend(tab.column(1));
        }
    }
    Some((Range::of(&t)?, Range::of(&r)?))
}

/// How the model was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingInfo {
    /// Temperature range seen in training, °C.
    pub temp_range_c: Range,
    /// Temperature-rate (dT) range seen in training, °C/s.
    pub rate_range_c_per_s: Range,
    /// SHA-256 (lower-case hex) of the training inputs, see [`data_digest`].
    pub data_digest_sha256: String,
    /// Training epochs (None for a least-squares fit).
    #[serde(default)]
    pub epochs: Option<u64>,
    /// Final training loss (normalised MSE for LSTMs; RMS residual for baselines).
    #[serde(default)]
    pub final_loss: Option<f64>,
    /// Random seed (None when nothing was random).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Program and version that wrote the file, e.g. `gyrotherm 0.1.0`.
    pub created_by: String,
    /// Names of the training input files.
    pub inputs: Vec<String>,
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

/// The columns of the logs a model was trained on: the header names of time, gyro output,
/// temperature and rate table, and the unit of the gyro column (see [`ReadOptions`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnsDef {
    pub time_col: String,
    pub gyro_col: String,
    pub temp_col: String,
    pub table_col: String,
    /// `dps`, `dph` or `rad/s`.
    pub gyro_unit: String,
}

/// Which column options a user named (each one named overrides the model's
/// [`ColumnsDef`]; the others come from the model).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GivenColumns {
    pub time_col: bool,
    pub gyro_col: bool,
    pub temp_col: bool,
    pub table_col: bool,
    pub gyro_unit: bool,
}

impl ColumnsDef {
    /// The columns `opts` reads.
    pub fn of(opts: &ReadOptions) -> ColumnsDef {
        ColumnsDef {
            time_col: opts.time_col.clone(),
            gyro_col: opts.gyro_col.clone(),
            temp_col: opts.temp_col.clone(),
            table_col: opts.table_col.clone(),
            gyro_unit: opts.gyro_unit.as_str().to_owned(),
        }
    }

    /// `base` with these columns, except those `given` says the user named.
    pub fn read_options(
        &self,
        base: &ReadOptions,
        given: GivenColumns,
    ) -> Result<ReadOptions, ModelFileError> {
        let pick = |given: bool, flag: &String, mine: &String| {
            if given {
                flag.clone()
            } else {
                mine.clone()
            }
        };
        let gyro_unit = if given.gyro_unit {
            base.gyro_unit
        } else {
            self.gyro_unit
                .parse()
                .map_err(|e: String| ModelFileError::invalid("columns.gyro_unit", e))?
        };
        Ok(ReadOptions {
            time_col: pick(given.time_col, &base.time_col, &self.time_col),
            gyro_col: pick(given.gyro_col, &base.gyro_col, &self.gyro_col),
            temp_col: pick(given.temp_col, &base.temp_col, &self.temp_col),
            table_col: pick(given.table_col, &base.table_col, &self.table_col),
            gyro_unit,
            ..base.clone()
        })
    }

    /// Checked: one column each, names a log can hold, a known gyro unit.
    pub fn validate(&self) -> Result<(), ModelFileError> {
        let opts = self.read_options(&ReadOptions::default(), GivenColumns::default())?;
        if opts.is_multi_column() {
            return Err(ModelFileError::invalid(
                "columns",
                "a single-axis model reads one gyro and one temperature column".to_owned(),
            ));
        }
        opts.validate()
            .map_err(|e| ModelFileError::invalid("columns", e.to_string()))
    }
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

/// `gyrotherm <version>`, for [`TrainingInfo::created_by`].
pub fn created_by() -> String {
    format!("gyrotherm {}", env!("CARGO_PKG_VERSION"))
}

/// SHA-256 hex of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let d = Sha256::digest(bytes);
    d.iter().map(|b| format!("{b:02x}")).collect()
}

/// Digest of training logs: SHA-256 over, per log in order, the sample count (u64 LE), then
/// `time_s`, `gyro_dps`, `temp_c` as f64 LE bytes, then a table flag byte and `table_dps` if
/// present. Pass-through columns are not included. Same numbers, same digest.
pub fn data_digest(logs: &[&TestLog]) -> String {
    let mut h = Sha256::new();
    for log in logs {
        h.update((log.len() as u64).to_le_bytes());
        for col in [&log.time_s, &log.gyro_dps, &log.temp_c] {
            for v in col.iter() {
                h.update(v.to_le_bytes());
            }
        }
        match &log.table_dps {
            Some(t) => {
                h.update([1u8]);
                for v in t {
                    h.update(v.to_le_bytes());
                }
            }
            None => h.update([0u8]),
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
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
mod coverage_map;
mod error;
mod flight;
mod ground;
mod method_choice;
mod seal;
pub mod unit;

pub use checks::SubModelError;
pub use coverage_map::CoverageDef;
pub use error::ModelFileError;
pub(crate) use flight::{boxed_compensator, sized_compensator};
pub use flight::{hidden_size, CompensateError};
pub(crate) use flight::{static_baseline, static_target, target_model};
pub use method_choice::{CandidateScore, MethodChoice, Validation};
use seal::supported_list;
pub(crate) use seal::{content_digest_of, parse_sealed, SealedTextError};

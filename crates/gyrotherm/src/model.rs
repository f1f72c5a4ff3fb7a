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
//! [`crate::json_keys`]).

use crate::atomic_file::write_bytes_atomically;
use crate::baseline::TermsError;
use crate::baseline::{self, Terms};
use crate::csvlog::TestLog;
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
pub const FORMAT_VERSION: u32 = 1;
/// The format versions this build reads.
pub const SUPPORTED_VERSIONS: &[u32] = &[1];

/// Largest |coefficient| of a least-squares term: far beyond any fit of a gyro's drift in
/// °C and °C/s, short of what makes f64 sums overflow.
pub const MAX_PLAUSIBLE_COEFFICIENT: f64 = 1e15;
/// Largest |bias| a model may predict inside its training range, °/s: beyond the measuring
/// range of any fibre optic gyro.
pub const MAX_PLAUSIBLE_BIAS_DPS: f64 = 1e3;
/// Range of scale factor K (nominal 1) a model may predict inside its training range.
pub const PLAUSIBLE_SCALE: (f64, f64) = (0.1, 10.0);
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
    pub fn from_core(l: &TempLimits) -> Self {
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

impl SubModel {
    /// What the sub-model is made of: `"lstm"`, `"least squares"` or
    /// `"least squares + lstm"`.
    pub fn kind(&self) -> &'static str {
        match self {
            SubModel::Lstm { .. } => "lstm",
            SubModel::Baseline { .. } => "least squares",
            SubModel::Residual { .. } => "least squares + lstm",
        }
    }

    /// The LSTM part, if any: parameters, input and target normalisation.
    pub fn lstm(&self) -> Option<(&LstmParams, &ZScore, &ZScore)> {
        match self {
            SubModel::Lstm {
                params,
                input_norm,
                target_norm,
            }
            | SubModel::Residual {
                params,
                input_norm,
                target_norm,
                ..
            } => Some((params, input_norm, target_norm)),
            SubModel::Baseline { .. } => None,
        }
    }

    /// Whether the residual LSTM reads the least-squares base value as one more input.
    pub fn reads_base(&self) -> bool {
        matches!(
            self,
            SubModel::Residual {
                lstm_reads_base: true,
                ..
            }
        )
    }

    /// A baseline sub-model from a fit.
    pub fn from_fit(fit: &baseline::BaselineFit) -> SubModel {
        SubModel::Baseline {
            terms: fit.terms.clone(),
            coefficients: fit.coefficients.clone(),
        }
    }

    /// The flight evaluator of a baseline sub-model (None for an LSTM).
    pub fn baseline_core(&self) -> Option<Result<BaselineModel, BaselineError>> {
        match self {
            SubModel::Baseline {
                terms,
                coefficients,
            }
            | SubModel::Residual {
                terms,
                coefficients,
                ..
            } => Some(baseline::to_core(terms, coefficients)),
            SubModel::Lstm { .. } => None,
        }
    }

    /// Shapes and finiteness for `n_features` inputs; the message names the tensor at fault.
    pub fn validate(&self, n_features: usize) -> Result<(), SubModelError> {
        match self {
            SubModel::Residual {
                terms,
                coefficients,
                params,
                input_norm,
                target_norm,
                lstm_reads_base,
            } => {
                SubModel::Baseline {
                    terms: terms.clone(),
                    coefficients: coefficients.clone(),
                }
                .validate(n_features)?;
                let lstm_inputs = n_features + usize::from(*lstm_reads_base);
                if lstm_inputs > gyrotherm_core::features::MAX_FEATURES {
                    return Err(SubModelError::Invalid(format!(
                        "lstm_reads_base: {n_features} features plus the base value exceed the \
                         flight LSTM's {} inputs",
                        gyrotherm_core::features::MAX_FEATURES
                    )));
                }
                SubModel::Lstm {
                    params: params.clone(),
                    input_norm: input_norm.clone(),
                    target_norm: target_norm.clone(),
                }
                .validate(lstm_inputs)
                .map_err(|e| {
                    if *lstm_reads_base {
                        SubModelError::ReadsBase(Box::new(e))
                    } else {
                        e
                    }
                })
            }
            SubModel::Lstm {
                params,
                input_norm,
                target_norm,
            } => {
                params.validate().map_err(SubModelError::Params)?;
                if params.input_size != n_features {
                    return Err(SubModelError::Invalid(format!(
                        "params.input_size is {} but the feature definition gives {n_features} features",
                        params.input_size
                    )));
                }
                check_norm("input_norm", input_norm, n_features)?;
                check_norm("target_norm", target_norm, 1)
            }
            SubModel::Baseline {
                terms,
                coefficients,
            } => {
                terms.validate().map_err(SubModelError::Terms)?;
                if terms.n_features != n_features {
                    return Err(SubModelError::Invalid(format!(
                        "terms.n_features is {} but the feature definition gives {n_features} features",
                        terms.n_features
                    )));
                }
                if coefficients.len() != terms.len() {
                    return Err(SubModelError::Invalid(format!(
                        "coefficients has {} values for {} terms",
                        coefficients.len(),
                        terms.len()
                    )));
                }
                if let Some(k) = coefficients.iter().position(|c| !c.is_finite()) {
                    return Err(SubModelError::Invalid(format!(
                        "coefficients[{k}] is not finite"
                    )));
                }
                if let Some(k) = coefficients
                    .iter()
                    .position(|c| c.abs() > MAX_PLAUSIBLE_COEFFICIENT)
                {
                    return Err(SubModelError::Invalid(format!(
                        "coefficients[{k}] is {:e}: implausibly large (|c| ≤ {MAX_PLAUSIBLE_COEFFICIENT:e}); \
                         re-train, or check a hand edit",
                        coefficients[k]
                    )));
                }
                Ok(())
            }
        }
    }
}

fn check_norm(name: &str, z: &ZScore, channels: usize) -> Result<(), SubModelError> {
    if z.mean.len() != channels || z.std.len() != channels {
        return Err(SubModelError::Invalid(format!(
            "{name} has {} means and {} stds, expected {channels} each",
            z.mean.len(),
            z.std.len()
        )));
    }
    if let Some(k) = z.mean.iter().position(|v| !v.is_finite()) {
        return Err(SubModelError::Invalid(format!(
            "{name}.mean[{k}] is not finite"
        )));
    }
    if let Some(k) = z.std.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(SubModelError::Invalid(format!(
            "{name}.std[{k}] is {}: must be finite and > 0",
            z.std[k]
        )));
    }
    Ok(())
}

/// A sub-model that cannot be evaluated: the tensor or field at fault.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SubModelError {
    /// The LSTM parameters.
    Params(ParamsError),
    /// The least-squares terms.
    Terms(TermsError),
    /// A field's value (the message names the field).
    Invalid(String),
    /// The LSTM part, which reads the features plus the base value.
    ReadsBase(Box<SubModelError>),
}

impl std::fmt::Display for SubModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SubModelError::Params(e) => e.fmt(f),
            SubModelError::Terms(e) => write!(f, "terms: {e}"),
            SubModelError::Invalid(m) => f.write_str(m),
            SubModelError::ReadsBase(e) => {
                write!(f, "{e} (lstm_reads_base: the features plus the base value)")
            }
        }
    }
}

impl std::error::Error for SubModelError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SubModelError::Params(e) => Some(e),
            SubModelError::Terms(e) => Some(e),
            SubModelError::ReadsBase(e) => Some(e.as_ref()),
            SubModelError::Invalid(_) => None,
        }
    }
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
    /// [`FORMAT_VERSION`].
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
}

/// A model that cannot be read, checked or written: the file, the field and the value at
/// fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum ModelFileError {
    /// The file could not be read.
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file could not be written.
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// An error in the model file at `path`.
    InFile {
        path: PathBuf,
        source: Box<ModelFileError>,
    },
    /// A model that fails its checks was not saved.
    NotSaved(Box<ModelFileError>),
    /// The text is not JSON.
    NotJson(serde_json::Error),
    /// An object names a key twice (`path` says where, e.g. `bias.baseline.coefficients`):
    /// which value counts would depend on the reader, and the content hash covers only one.
    DuplicateKey(DuplicateKey),
    /// A field is missing, unknown or of the wrong type.
    Fields(serde_json::Error),
    /// No `format_version` field.
    MissingVersion,
    /// The `content_sha256` written with the model does not match its content (edited or
    /// damaged since it was saved).
    Checksum { found: String, computed: String },
    /// A `format_version` this build does not read (the value as written).
    UnsupportedVersion { found: String },
    /// The feature definition cannot be built.
    Features(gyrotherm_core::features::SpecError),
    /// The `bias` or `scale` sub-model.
    SubModel {
        target: Target,
        source: SubModelError,
    },
    /// A field's value (`field` names it, e.g. `training.final_loss`).
    Invalid { field: String, problem: String },
}

impl ModelFileError {
    fn invalid(field: &str, problem: String) -> Self {
        ModelFileError::Invalid {
            field: field.to_owned(),
            problem,
        }
    }
}

impl std::fmt::Display for ModelFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModelFileError::Read { path, source } => {
                write!(f, "{}: cannot read model file: {source}", path.display())
            }
            ModelFileError::Write { path, source } => write!(f, "{}: {source}", path.display()),
            ModelFileError::InFile { path, source } => write!(f, "{}: {source}", path.display()),
            ModelFileError::NotSaved(e) => write!(f, "not saved: {e}"),
            ModelFileError::NotJson(e) => write!(f, "not valid JSON: {e}"),
            ModelFileError::DuplicateKey(d) => d.fmt(f),
            ModelFileError::Fields(e) => e.fmt(f),
            ModelFileError::MissingVersion => f.write_str("missing field `format_version`"),
            ModelFileError::UnsupportedVersion { found } => write!(
                f,
                "unsupported format_version {found}: this gyrotherm ({}) reads version {}; use a \
                 matching gyrotherm or re-train",
                env!("CARGO_PKG_VERSION"),
                supported_list()
            ),
            ModelFileError::Features(e) => write!(f, "features: {e}"),
            ModelFileError::SubModel { target, source } => {
                write!(f, "{}: {source}", target.as_str())
            }
            ModelFileError::Checksum { found, computed } => write!(
                f,
                "{CHECKSUM_KEY} is {found} but the content gives {computed}: the file was edited \
                 or damaged after it was saved; re-train, or if the edit is intended, check the \
                 model and run `gyrotherm model seal FILE`"
            ),
            ModelFileError::Invalid { field, problem } if field.is_empty() => f.write_str(problem),
            ModelFileError::Invalid { field, problem } => write!(f, "{field}: {problem}"),
        }
    }
}

impl std::error::Error for ModelFileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ModelFileError::Read { source, .. } | ModelFileError::Write { source, .. } => {
                Some(source)
            }
            ModelFileError::InFile { source, .. } | ModelFileError::NotSaved(source) => {
                Some(source.as_ref())
            }
            ModelFileError::NotJson(e) | ModelFileError::Fields(e) => Some(e),
            ModelFileError::Features(e) => Some(e),
            ModelFileError::SubModel { source, .. } => Some(source),
            _ => None,
        }
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

    /// The core feature spec of this model.
    pub fn feature_spec(&self) -> Result<FeatureSpec, ModelFileError> {
        self.features.to_spec()
    }

    /// Check everything [`load`](Self::load) checks after parsing; the message names the field.
    pub fn validate(&self) -> Result<(), ModelFileError> {
        if !SUPPORTED_VERSIONS.contains(&self.format_version) {
            return Err(ModelFileError::UnsupportedVersion {
                found: self.format_version.to_string(),
            });
        }
        let spec = self.features.to_spec()?;
        self.features.temp_sensor.to_core()?;
        let nf = spec.n_features();
        if self.bias.is_none() && self.scale.is_none() {
            return Err(ModelFileError::invalid(
                "",
                "neither a bias nor a scale model: nothing to compensate".to_owned(),
            ));
        }
        for (target, sub) in [(Target::Bias, &self.bias), (Target::Scale, &self.scale)] {
            let Some(sub) = sub else { continue };
            let name = target.as_str();
            if matches!(self.method, Method::Linear | Method::Poly)
                && matches!(sub, SubModel::Lstm { .. } | SubModel::Residual { .. })
            {
                return Err(ModelFileError::invalid(
                    name,
                    format!(
                        "an lstm sub-model in a model whose method is {}",
                        self.method.as_str()
                    ),
                ));
            }
            sub.validate(nf)
                .map_err(|source| ModelFileError::SubModel { target, source })?;
        }
        let t = &self.training;
        for (name, r) in [
            ("temp_range_c", t.temp_range_c),
            ("rate_range_c_per_s", t.rate_range_c_per_s),
        ] {
            if !(r.min.is_finite() && r.max.is_finite() && r.min <= r.max) {
                return Err(ModelFileError::invalid(
                    &format!("training.{name}"),
                    format!(
                        "min {} and max {} must be finite with min ≤ max",
                        r.min, r.max
                    ),
                ));
            }
        }
        let d = &t.data_digest_sha256;
        if d.len() != 64 || !d.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(ModelFileError::invalid(
                "training.data_digest_sha256",
                format!("{d:?} is not 64 hexadecimal digits"),
            ));
        }
        if let Some(l) = t.final_loss {
            if !l.is_finite() {
                return Err(ModelFileError::Invalid {
                    field: "training.final_loss".to_owned(),
                    problem: format!("{l}, must be finite"),
                });
            }
        }
        self.check_outputs_in_training_range(&spec)
    }

    /// Runs the bias and scale models through the training range (holds at its lowest,
    /// middle and highest temperature, ramps between them at its fastest rates, each long
    /// enough for the slowest lag to settle) and refuses a model whose bias is not finite or
    /// beyond [`MAX_PLAUSIBLE_BIAS_DPS`], or whose scale factor leaves [`PLAUSIBLE_SCALE`]
    /// (K ≤ 0 included) anywhere on the way. The message names the target, T and dT.
    fn check_outputs_in_training_range(&self, spec: &FeatureSpec) -> Result<(), ModelFileError> {
        use gyrotherm_core::features::FeaturePipeline;
        let t = &self.training;
        let (t_lo, t_hi) = (t.temp_range_c.min, t.temp_range_c.max);
        let (r_lo, r_hi) = (t.rate_range_c_per_s.min, t.rate_range_c_per_s.max);
        let dt = spec.step_period_s;
        let slowest = spec.lags().iter().fold(spec.rate_lag_s, |a, &b| a.max(b));
        let hold = ((3.0 * slowest / dt).ceil() as usize + 2).min(MAX_PROBE_STEPS);
        let ramp = |from: f64, to: f64, rate: f64| -> Vec<f64> {
            let n = ((to - from) / (rate * dt)).ceil();
            let n = if n.is_finite() && n > 0.0 {
                (n as usize).min(MAX_PROBE_STEPS)
            } else {
                0
            };
            (0..=n).map(|k| from + rate * dt * k as f64).collect()
        };
        let mut probes: Vec<Vec<f64>> = [t_lo, 0.5 * t_lo + 0.5 * t_hi, t_hi]
            .iter()
            .map(|&temp| vec![temp; hold])
            .collect();
        if r_hi > 0.0 {
            probes.push(ramp(t_lo, t_hi, r_hi));
        }
        if r_lo < 0.0 {
            probes.push(ramp(t_hi, t_lo, r_lo));
        }
        let build = |target: Target, sub: Option<&SubModel>, absent: f64| {
            target_model(sub, absent)
                .map_err(|e| ModelFileError::invalid(target.as_str(), e.to_string()))
        };
        let bias0 = build(Target::Bias, self.bias.as_ref(), 0.0)?;
        let scale0 = build(Target::Scale, self.scale.as_ref(), 1.0)?;
        for temps in probes {
            let (mut bias, mut scale) = (bias0.clone(), scale0.clone());
            let mut pipeline = FeaturePipeline::new(*spec).map_err(ModelFileError::Features)?;
            for (k, &temp) in temps.iter().enumerate() {
                let Ok(Some(step)) = pipeline.push(k as f64 * dt, temp) else {
                    continue;
                };
                let rate = (0..spec.n_features())
                    .find(|&i| spec.kind(i) == Some(FeatureKind::Rate))
                    .and_then(|i| step.features.as_slice().get(i).copied())
                    .unwrap_or(0.0);
                let at = || {
                    format!("at T = {temp:.3} °C, dT = {rate:.3e} °C/s, inside the training range ({t_lo} to {t_hi} °C, {r_lo:.3e} to {r_hi:.3e} °C/s)")
                };
                let b = bias.eval(&step.features).unwrap_or(f64::NAN);
                if !(b.is_finite() && b.abs() <= MAX_PLAUSIBLE_BIAS_DPS) {
                    return Err(ModelFileError::invalid(
                        "bias",
                        format!(
                            "predicts B = {b:e} °/s {}: not a gyro bias (|B| ≤ {MAX_PLAUSIBLE_BIAS_DPS} °/s); re-train, or check a hand edit",
                            at()
                        ),
                    ));
                }
                let k_sf = scale.eval(&step.features).unwrap_or(f64::NAN);
                let (k_lo, k_hi) = PLAUSIBLE_SCALE;
                if !(k_sf >= k_lo && k_sf <= k_hi) {
                    return Err(ModelFileError::invalid(
                        "scale",
                        format!(
                            "predicts K = {k_sf:e} {}: a scale factor must stay within {k_lo} to {k_hi} (nominal 1); re-train, or check a hand edit",
                            at()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// SHA-256 of the model's content (its compact JSON, fields in declaration order):
    /// layout and key order of the file do not change it, any value does.
    pub fn content_digest(&self) -> Result<String, ModelFileError> {
        let compact = serde_json::to_string(self).map_err(ModelFileError::Fields)?;
        Ok(sha256_hex(compact.as_bytes()))
    }

    /// The JSON text (pretty, shortest round-trip floats), after [`validate`](Self::validate),
    /// sealed with `content_sha256` (see [`content_digest`](Self::content_digest)) as the
    /// last key.
    pub fn to_json(&self) -> Result<String, ModelFileError> {
        self.validate()?;
        let text = serde_json::to_string_pretty(self).map_err(ModelFileError::Fields)?;
        let digest = self.content_digest()?;
        let body = text.strip_suffix("\n}").unwrap_or(&text);
        Ok(format!("{body},\n  \"{CHECKSUM_KEY}\": \"{digest}\"\n}}"))
    }

    /// Parse and check JSON text: a leading byte-order mark is skipped; a `content_sha256`
    /// must match the content (a file without one, written before files were sealed or by
    /// hand, is read on its other checks).
    pub fn from_json(text: &str) -> Result<ModelFile, ModelFileError> {
        Self::from_json_sealed(text).map(|(m, _)| m)
    }

    /// [`from_json`](Self::from_json), also saying whether the text was sealed.
    pub fn from_json_sealed(text: &str) -> Result<(ModelFile, Seal), ModelFileError> {
        let (m, sealed) = Self::parse(text, true)?;
        Ok((m, if sealed { Seal::Verified } else { Seal::Absent }))
    }

    /// The model and whether the text held a checksum (checked only when `verify`).
    fn parse(text: &str, verify: bool) -> Result<(ModelFile, bool), ModelFileError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        // Before anything reads a value: a repeated key would give the checksum one value
        // and another reader the other.
        check_unique_keys(text).map_err(|e| match e {
            KeyCheckError::Duplicate(d) => ModelFileError::DuplicateKey(d),
            KeyCheckError::NotJson(e) => ModelFileError::NotJson(e),
        })?;
        // Version first, so that a newer file gets "unsupported version", not a field error.
        let mut v: serde_json::Value =
            serde_json::from_str(text).map_err(ModelFileError::NotJson)?;
        match v.get("format_version") {
            None => return Err(ModelFileError::MissingVersion),
            Some(fv) => match fv.as_u64() {
                Some(n) if SUPPORTED_VERSIONS.contains(&(n as u32)) && n <= u32::MAX as u64 => {}
                _ => {
                    return Err(ModelFileError::UnsupportedVersion {
                        found: fv.to_string(),
                    })
                }
            },
        }
        let sealed = v.as_object_mut().and_then(|o| o.remove(CHECKSUM_KEY));
        let has_seal = sealed.is_some();
        let m: ModelFile = match &sealed {
            // Parsed from the text where possible: its errors give line and column.
            None => serde_json::from_str(text).map_err(ModelFileError::Fields)?,
            Some(_) => serde_json::from_value(v).map_err(ModelFileError::Fields)?,
        };
        if let (Some(found), true) = (sealed, verify) {
            let computed = m.content_digest()?;
            let found = match found {
                serde_json::Value::String(s) => s,
                other => other.to_string(),
            };
            if !found.eq_ignore_ascii_case(&computed) {
                return Err(ModelFileError::Checksum { found, computed });
            }
        }
        m.validate()?;
        Ok((m, has_seal))
    }

    /// Re-seal a model file after a deliberate hand edit: read it without checking its
    /// `content_sha256`, check everything else, and write it back with a new one. Returns
    /// the model and its new digest.
    pub fn seal(path: &Path) -> Result<(ModelFile, String), ModelFileError> {
        let in_file = |e| ModelFileError::InFile {
            path: path.to_path_buf(),
            source: Box::new(e),
        };
        let text = std::fs::read_to_string(path).map_err(|source| ModelFileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let (m, _) = Self::parse(&text, false).map_err(in_file)?;
        m.save(path)?;
        let digest = m.content_digest().map_err(in_file)?;
        Ok((m, digest))
    }

    /// Write to `path` atomically (temporary file + rename), after validating.
    pub fn save(&self, path: &Path) -> Result<(), ModelFileError> {
        let mut text = self.to_json().map_err(|e| ModelFileError::InFile {
            path: path.to_path_buf(),
            source: Box::new(ModelFileError::NotSaved(Box::new(e))),
        })?;
        text.push('\n');
        write_bytes_atomically(path, text.as_bytes()).map_err(|source| ModelFileError::Write {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Read and check a model file.
    pub fn load(path: &Path) -> Result<ModelFile, ModelFileError> {
        Self::load_sealed(path).map(|(m, _)| m)
    }

    /// [`load`](Self::load), also saying whether the file was sealed (a caller warns on
    /// [`Seal::Absent`]; see [`Seal::warning`]).
    pub fn load_sealed(path: &Path) -> Result<(ModelFile, Seal), ModelFileError> {
        let text = std::fs::read_to_string(path).map_err(|source| ModelFileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json_sealed(&text).map_err(|e| ModelFileError::InFile {
            path: path.to_path_buf(),
            source: Box::new(e),
        })
    }
}

impl Seal {
    /// What to tell the user about the model file `path`: nothing when sealed.
    pub fn warning(self, path: &Path) -> Option<String> {
        match self {
            Seal::Verified => None,
            Seal::Absent => Some(format!(
                "{}: no {CHECKSUM_KEY}: the model passed its plausibility checks, but a \
                 corrupted value cannot be told from an intended one; if the content is as \
                 intended, run `gyrotherm model seal {}`",
                path.display(),
                path.display()
            )),
        }
    }
}

fn supported_list() -> String {
    SUPPORTED_VERSIONS
        .iter()
        .map(|v| v.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

// Turning a model file into the flight crate's models: here, beside the model, so that both
// the load-time plausibility check and `compensate` use it without an import cycle.

use gyrotherm_core::compensator::ModelError as FlightModelError;
use gyrotherm_core::compensator::{NormalisedLstm, TargetModel, HIDDEN, LSTM_INPUTS};

/// Widen an LSTM to the flight input count: input columns beyond `input_size` get weight 0.
pub fn padded_core_lstm(
    params: &LstmParams,
) -> Result<gyrotherm_core::lstm::LstmWeights<LSTM_INPUTS, HIDDEN>, CompensateError> {
    let i = params.input_size;
    if i > LSTM_INPUTS {
        return Err(CompensateError::LstmInputs { inputs: i });
    }
    let mut wide = params.clone();
    wide.input_size = LSTM_INPUTS;
    wide.w_ih = params
        .w_ih
        .chunks(i.max(1))
        .flat_map(|row| {
            let mut r = row.to_vec();
            r.resize(LSTM_INPUTS, 0.0);
            r
        })
        .collect();
    wide.to_core::<LSTM_INPUTS, HIDDEN>()
        .map_err(CompensateError::Params)
}

fn core_lstm(
    params: &LstmParams,
    input_norm: &ZScore,
    target_norm: &ZScore,
) -> Result<NormalisedLstm, CompensateError> {
    let w = padded_core_lstm(params)?;
    NormalisedLstm::new(
        &w,
        &input_norm.mean,
        &input_norm.std,
        target_norm.mean[0],
        target_norm.std[0],
    )
    .map_err(CompensateError::Flight)
}

/// The flight model of one target (`None`: the constant `absent`).
pub fn target_model(sub: Option<&SubModel>, absent: f64) -> Result<TargetModel, CompensateError> {
    let Some(sub) = sub else {
        return Ok(TargetModel::constant(absent));
    };
    let baseline = sub
        .baseline_core()
        .transpose()
        .map_err(CompensateError::Baseline)?;
    let lstm = match sub.lstm() {
        Some((params, input_norm, target_norm)) => {
            Some(core_lstm(params, input_norm, target_norm)?)
        }
        None => None,
    };
    let lstm_reads_base = sub.reads_base();
    Ok(TargetModel {
        offset: 0.0,
        baseline,
        lstm,
        lstm_reads_base,
    })
}

/// Why a model could not be turned into the flight compensator, or a log not compensated: the
/// target, sample, line or value at fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum CompensateError {
    /// The model file's feature definition.
    Model(ModelFileError),
    /// The LSTM reads more inputs than flight code takes.
    LstmInputs { inputs: usize },
    /// The LSTM parameters cannot be exported.
    Params(ParamsError),
    /// The least-squares part cannot be evaluated in flight.
    Baseline(BaselineError),
    /// The flight crate refused the model.
    Flight(FlightModelError),
    /// In the bias or scale-factor model.
    InTarget {
        target: Target,
        source: Box<CompensateError>,
    },
}

impl std::fmt::Display for CompensateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CompensateError::Model(e) => e.fmt(f),
            CompensateError::LstmInputs { inputs } => write!(
                f,
                "the LSTM reads {inputs} inputs; flight code takes at most {LSTM_INPUTS}"
            ),
            CompensateError::Params(e) => e.fmt(f),
            CompensateError::Baseline(e) => e.fmt(f),
            CompensateError::Flight(e) => e.fmt(f),
            CompensateError::InTarget { target, source } => {
                write!(f, "{}: {source}", target.as_str())
            }
        }
    }
}

impl std::error::Error for CompensateError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CompensateError::Model(e) => Some(e),
            CompensateError::Params(e) => Some(e),
            CompensateError::Baseline(e) => Some(e),
            CompensateError::InTarget { source, .. } => Some(source.as_ref()),
            // Transparent: the flight crate's message is this error's own.
            CompensateError::Flight(e) => e.source(),
            CompensateError::LstmInputs { .. } => None,
        }
    }
}

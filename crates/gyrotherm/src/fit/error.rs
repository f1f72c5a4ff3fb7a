//! Why a fit was refused.

use crate::baseline::LsqError;
use crate::model::{ModelFileError, Target};
use crate::nn::TrainError;
use crate::settings::method::Method;

/// Why [`fit_model`](super::fit_model) (or one recipe) could not fit a model. Each variant
/// names the run, the target or the value at fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum FitError {
    /// No training logs were given.
    NoLogs,
    /// None of the logs gave a usable target.
    NoUsableLogs,
    /// The targets of run `run` could not be computed.
    Targets {
        run: String,
        source: crate::targets::TargetError,
    },
    /// Rate-table run `run` has no rate segment between two stop segments.
    NoScaleSegments { run: String },
    /// The training runs use different feature definitions.
    MixedFeatures { first: usize, other: usize },
    /// The recipe reads `expected` features, the data has `found`.
    FeatureCount { expected: usize, found: usize },
    /// A fixed base term set (`family:<index>`) beyond the ladder.
    NoSuchFamily { index: usize, ladder: usize },
    /// No candidate term sets were given to choose among.
    NoCandidates,
    /// No candidate term set could be fitted on every fold of the cross-validation.
    NoCandidateFits { folds: usize },
    /// The training runs give no block past the burn-in for the residual LSTM.
    RunsTooShort { block_steps: usize, burn_in: usize },
    /// The training logs have no feature steps.
    NoFeatureSteps,
    /// A least-squares fit was refused.
    LeastSquares(LsqError),
    /// LSTM training was refused.
    Train(TrainError),
    /// The thermal recipe could not identify or fit its model.
    Thermal(super::thermal::ThermalError),
    /// The thermal recipe identifies its features from the logs: fit it through `fit_model`.
    NeedsLogs,
    /// [`fit_target`](super::fit_target) was given a method that is no recipe (`linear` and
    /// `poly` fit by least squares through `fit_model`; `lstm` is read only).
    NotARecipe { method: Method },
    /// The fitted model did not pass the model file's checks.
    Model(ModelFileError),
    /// The fit of one target (bias or scale factor) failed.
    Target {
        target: Target,
        source: Box<FitError>,
    },
    /// The training thread of one target panicked.
    ThreadPanicked { target: Target },
    /// Run `run` is sampled every `period_s` (median step), more sparsely than the models
    /// can step (`max_s`).
    SampledTooSparsely {
        run: String,
        period_s: f64,
        max_s: f64,
    },
    /// Static run `run` (no table column, or one of zeros) has a gyro output spanning
    /// `span_dps`, more than a thermal bias can.
    StaticRunTurns {
        run: String,
        span_dps: f64,
        has_table: bool,
    },
}

impl std::fmt::Display for FitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitError::NoLogs => write!(f, "no training logs given"),
            FitError::NoUsableLogs => write!(f, "no usable training logs"),
            FitError::Targets { run, .. } => write!(f, "{run}: cannot make the training targets"),
            FitError::NoScaleSegments { run } => write!(
                f,
                "{run}: no rate segment has a stop segment on both sides, so no scale factor can \
                 be measured; log stop segments between the table rates"
            ),
            FitError::MixedFeatures { first, other } => write!(
                f,
                "training runs have {first} and {other} features: all must use one feature \
                 definition"
            ),
            FitError::FeatureCount { expected, found } => write!(
                f,
                "the residual recipe reads {expected} features (T, dT and three thermal-state \
                 lags), the training data has {found}"
            ),
            FitError::NoSuchFamily { index, ladder } => {
                write!(f, "base family:{index}: the ladder has {ladder} term sets")
            }
            FitError::NoCandidates => write!(f, "no candidate term sets"),
            FitError::NoCandidateFits { folds } => write!(
                f,
                "no candidate term set could be fitted with a {folds}th of each training run left \
                 out: the runs are too short or too uniform in temperature; log longer or more \
                 varied runs"
            ),
            FitError::RunsTooShort {
                block_steps,
                burn_in,
            } => write!(
                f,
                "no {block_steps}-step block with labelled steps past the {burn_in}-step \
                 burn-in: the training runs are too short for the residual recipe"
            ),
            FitError::NoFeatureSteps => write!(f, "the training logs have no feature steps"),
            FitError::LeastSquares(e) => e.fmt(f),
            FitError::Train(e) => e.fmt(f),
            FitError::Thermal(e) => e.fmt(f),
            FitError::NeedsLogs => write!(
                f,
                "the thermal recipe identifies its features from the logs: fit it with fit_model"
            ),
            FitError::NotARecipe { method } => {
                write!(f, "method `{method}` is no recipe: fit it with fit_model")
            }
            FitError::Model(e) => e.fmt(f),
            FitError::Target { target, .. } => match target {
                Target::Bias => f.write_str("bias model"),
                Target::Scale => f.write_str("scale-factor model"),
            },
            FitError::ThreadPanicked { target } => {
                write!(f, "{} training thread panicked", target.as_str())
            }
            FitError::SampledTooSparsely {
                run,
                period_s,
                max_s,
            } => write!(
                f,
                "{run}: one sample every {period_s} s ({} Hz); the models step every second \
                 and read dT over {max_s} s, so they need at least one sample every {max_s} s \
                 ({} Hz): log faster, or resample",
                1.0 / period_s,
                1.0 / max_s
            ),
            FitError::StaticRunTurns {
                run,
                span_dps,
                has_table,
            } => write!(
                f,
                "{run}: read as a static run ({}), but its gyro output spans {span_dps:.3} °/s \
                 (1st to 99th percentile), more than a thermal bias can ({} °/s): it looks \
                 like a rate-table run; name its table-rate column with --table-col, or check \
                 the gyro column and its unit",
                if *has_table {
                    "its table-rate column is all zeros"
                } else {
                    "no table-rate column"
                },
                super::MAX_STATIC_SPAN_DPS
            ),
        }
    }
}

impl std::error::Error for FitError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent wrappers: their message is the inner error's own.
            FitError::LeastSquares(e) => e.source(),
            FitError::Train(e) => e.source(),
            FitError::Thermal(e) => e.source(),
            FitError::Model(e) => e.source(),
            FitError::Targets { source, .. } => Some(source),
            FitError::Target { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}

impl From<LsqError> for FitError {
    fn from(e: LsqError) -> Self {
        FitError::LeastSquares(e)
    }
}

impl From<TrainError> for FitError {
    fn from(e: TrainError) -> Self {
        FitError::Train(e)
    }
}

impl From<super::thermal::ThermalError> for FitError {
    fn from(e: super::thermal::ThermalError) -> Self {
        FitError::Thermal(e)
    }
}

impl From<ModelFileError> for FitError {
    fn from(e: ModelFileError) -> Self {
        FitError::Model(e)
    }
}

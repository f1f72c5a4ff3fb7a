//! Standard gyro performance figures (IEEE Std 952 / GJB 2426A; definitions in METHOD.md).
//!
//! - [`bias_dph`]: bias B0, the mean output, °/h.
//! - [`bias_stability_dph`]: sample standard deviation (n − 1) of consecutive non-overlapping
//!   means over τ, °/h.
//! - [`scale_factor`]: scale factor, nonlinearity, asymmetry and the scale-factor thermal
//!   error from a rate-table log.
//! - [`repeatability`]: sample standard deviation over repeated runs.
//!
//! Inputs are rates in °/s; results carry their unit in the field name.

pub mod scale_factor;

pub use scale_factor::{
    detect_segments, scale_factor, RateSegment, ScaleFactorError, ScaleFactorOptions,
    ScaleFactorReport, SegmentScale,
};

use std::fmt;

/// °/s → °/h.
pub const DPS_TO_DPH: f64 = 3600.0;

/// Why a figure could not be computed.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MetricsError {
    /// No samples.
    Empty,
    /// A sample is NaN or infinite.
    NonFinite { index: usize },
    /// Sample period not finite and positive.
    BadSamplePeriod(f64),
    /// τ not a positive integer multiple of the sample period.
    TauNotMultiple { tau_s: f64, sample_period_s: f64 },
    /// Fewer than two τ-means fit in the log.
    TooShort {
        samples: usize,
        samples_per_mean: usize,
    },
}

impl fmt::Display for MetricsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MetricsError::Empty => write!(f, "no samples"),
            MetricsError::NonFinite { index } => {
                write!(f, "sample {index} is NaN or infinite; clean or fill the log first")
            }
            MetricsError::BadSamplePeriod(t) => {
                write!(f, "sample period {t} s is not a positive finite number; check the time column")
            }
            MetricsError::TauNotMultiple { tau_s, sample_period_s } => write!(
                f,
                "τ = {tau_s} s is not a positive integer multiple of the sample period {sample_period_s} s"
            ),
            MetricsError::TooShort { samples, samples_per_mean } => write!(
                f,
                "{samples} samples give fewer than two means of {samples_per_mean} samples; use a shorter τ or a longer log"
            ),
        }
    }
}

impl std::error::Error for MetricsError {}

fn check_finite(v: &[f64]) -> Result<(), MetricsError> {
    if v.is_empty() {
        return Err(MetricsError::Empty);
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(MetricsError::NonFinite { index }),
        None => Ok(()),
    }
}

/// Bias B0 = mean output, °/h, of rates in °/s.
pub fn bias_dph(rate_dps: &[f64]) -> Result<f64, MetricsError> {
    check_finite(rate_dps)?;
    Ok(mean(rate_dps) * DPS_TO_DPH)
}

pub(crate) fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Sample standard deviation (n − 1); None for fewer than two values.
pub fn sample_std(v: &[f64]) -> Option<f64> {
    if v.len() < 2 {
        return None;
    }
    let mu = mean(v);
    let ss: f64 = v.iter().map(|x| (x - mu) * (x - mu)).sum();
    Some((ss / (v.len() - 1) as f64).sqrt())
}

/// Standard deviation (n − 1) of consecutive non-overlapping means of m samples (a trailing
/// partial group is dropped), in the unit of the input; also returns the number of means.
pub fn tau_means_std(values: &[f64], m: usize) -> Result<(f64, usize), MetricsError> {
    check_finite(values)?;
    let groups = values.len().checked_div(m).unwrap_or(0);
    if groups < 2 {
        return Err(MetricsError::TooShort {
            samples: values.len(),
            samples_per_mean: m,
        });
    }
    let means: Vec<f64> = values[..groups * m].chunks_exact(m).map(mean).collect();
    Ok((sample_std(&means).unwrap_or(f64::NAN), groups))
}

/// Bias stability.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasStability {
    /// 1σ (n − 1) of the τ-means, °/h.
    pub bias_stability_dph: f64,
    /// Smoothing time τ, s.
    pub tau_s: f64,
    /// Samples per mean.
    pub samples_per_mean: usize,
    /// Number of means.
    pub means: usize,
}

/// Bias stability (GJB 2426A / IEEE 952): sample std (n − 1) of consecutive non-overlapping
/// τ-means of `rate_dps`, in °/h. τ must be an integer multiple of `sample_period_s`.
pub fn bias_stability_dph(
    rate_dps: &[f64],
    sample_period_s: f64,
    tau_s: f64,
) -> Result<BiasStability, MetricsError> {
    if !(sample_period_s.is_finite() && sample_period_s > 0.0) {
        return Err(MetricsError::BadSamplePeriod(sample_period_s));
    }
    let ratio = tau_s / sample_period_s;
    let m = ratio.round();
    if !(ratio.is_finite() && m >= 1.0 && (ratio - m).abs() <= 1e-6 * ratio.max(1.0)) {
        return Err(MetricsError::TauNotMultiple {
            tau_s,
            sample_period_s,
        });
    }
    let m = m as usize;
    let (std, means) = tau_means_std(rate_dps, m)?;
    Ok(BiasStability {
        bias_stability_dph: std * DPS_TO_DPH,
        tau_s,
        samples_per_mean: m,
        means,
    })
}

/// Repeatability over runs: sample std (n − 1) of one figure (bias in °/h, K, …) measured
/// on each run, in the unit of the inputs. None for fewer than two runs or a non-finite value.
pub fn repeatability(per_run: &[f64]) -> Option<f64> {
    if per_run.iter().any(|v| !v.is_finite()) {
        return None;
    }
    sample_std(per_run)
}

/// Repeatability of bias over several runs of rates in °/s: the std (n − 1) of each run's
/// bias, °/h.
pub fn bias_repeatability_dph(runs_dps: &[&[f64]]) -> Result<Option<f64>, MetricsError> {
    let biases = runs_dps
        .iter()
        .map(|r| bias_dph(r))
        .collect::<Result<Vec<f64>, _>>()?;
    Ok(repeatability(&biases))
}

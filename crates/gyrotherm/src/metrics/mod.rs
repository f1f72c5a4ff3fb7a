//! Standard gyro performance figures (IEEE Std 952 / GJB 2426A; definitions in docs/method.md).
//!
//! - [`bias_dph`]: bias B0, the mean output, °/h.
//! - [`bias_stability_dph`]: sample standard deviation (n − 1) of consecutive non-overlapping
//!   means over τ, °/h.
//! - [`scale_factor`](mod@scale_factor): scale factor, nonlinearity, asymmetry and the scale-factor thermal
//!   error from a rate-table log.
//! - [`repeatability`]: sample standard deviation over repeated runs.
//! - [`evaluate`]: all of these for one rate column of a log ([`Evaluation`]).
//!
//! Inputs are rates in °/s; results carry their unit in the field name.

pub mod evaluation;
pub mod scale_factor;

pub use evaluation::{
    evaluate, Evaluation, EvaluationError, EvaluationOptions, RatePoint, ScaleAtTime,
    ScaleFactorFigures,
};

pub use scale_factor::{
    scale_factor, RateSegment, ScaleFactorError, ScaleFactorOptions, ScaleFactorReport,
    SegmentScale,
};

use std::fmt;

/// °/s → °/h.
pub const DPS_TO_DPH: f64 = 3600.0;

/// Bias-stability smoothing time of the comparison, s (100 s: docs/method.md, He et al. 2024).
pub const BIAS_STABILITY_TAU_S: f64 = 100.0;

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
    /// τ leaves fewer than two means in the `samples` samples (every `sample_period_s`) used:
    /// the whole log, or its stop segments after the settle time.
    TauTooLong {
        tau_s: f64,
        samples: usize,
        sample_period_s: f64,
        stop_segments: bool,
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
            MetricsError::TauTooLong { tau_s, samples, sample_period_s, stop_segments } => {
                let duration_s = *samples as f64 * sample_period_s;
                // 1e300 s, not three hundred digits.
                let tau_s = crate::csvlog::short_f64(*tau_s);
                if *stop_segments {
                    write!(
                        f,
                        "τ = {tau_s} s leaves fewer than two τ-means in the stop segments \
                         ({samples} samples of {sample_period_s} s = {duration_s} s after the \
                         settle time; a mean never spans a table rate): use a shorter τ or \
                         longer stops"
                    )
                } else {
                    write!(
                        f,
                        "τ = {tau_s} s is longer than half the log ({samples} samples of \
                         {sample_period_s} s = {duration_s} s): the bias stability needs at \
                         least two τ-means; give τ at most {} s",
                        duration_s / 2.0
                    )
                }
            }
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
pub(crate) fn sample_std(v: &[f64]) -> Option<f64> {
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

/// Samples per τ-mean: τ / sample period, which must be a positive integer.
fn samples_per_mean(sample_period_s: f64, tau_s: f64) -> Result<usize, MetricsError> {
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
    Ok(m as usize)
}

/// The bias-stability smoothing time to use when none was asked for: `preferred_s` (100 s in
/// He et al. 2024) when it is a whole number of sample periods, otherwise the whole multiple
/// of the period nearest to it (at least one period). Returns `(τ, adjusted)`; a caller
/// should say so when `adjusted` (a log at one sample per 15 s gets τ = 105 s).
pub(crate) fn default_tau_s(sample_period_s: f64, preferred_s: f64) -> (f64, bool) {
    if !(sample_period_s.is_finite() && sample_period_s > 0.0) {
        return (preferred_s, false);
    }
    if samples_per_mean(sample_period_s, preferred_s).is_ok() {
        return (preferred_s, false);
    }
    let m = (preferred_s / sample_period_s).round().max(1.0);
    (m * sample_period_s, true)
}

/// Bias stability (GJB 2426A / IEEE 952): sample std (n − 1) of consecutive non-overlapping
/// τ-means of `rate_dps`, in °/h. τ must be an integer multiple of `sample_period_s`.
pub fn bias_stability_dph(
    rate_dps: &[f64],
    sample_period_s: f64,
    tau_s: f64,
) -> Result<BiasStability, MetricsError> {
    let m = samples_per_mean(sample_period_s, tau_s)?;
    let (std, means) = tau_means_std(rate_dps, m).map_err(|e| match e {
        // In seconds: τ far beyond the log gives a sample count no one can read.
        MetricsError::TooShort { samples, .. } => MetricsError::TauTooLong {
            tau_s,
            samples,
            sample_period_s,
            stop_segments: false,
        },
        e => e,
    })?;
    Ok(BiasStability {
        bias_stability_dph: std * DPS_TO_DPH,
        tau_s,
        samples_per_mean: m,
        means,
    })
}

/// Bias and bias stability of a rate-table log, from its stop segments only (table rate 0):
/// τ-means are taken inside each stop segment after `settle_s` (a mean never spans a table
/// rate; a segment's remainder shorter than τ is dropped), and the bias stability is their
/// sample std (n − 1), °/h. The bias is the mean of the used stop samples, °/h.
pub(crate) fn stop_segment_bias_dph(
    time_s: &[f64],
    rate_dps: &[f64],
    table_dps: &[f64],
    settle_s: f64,
    tau_s: f64,
) -> Result<(f64, BiasStability), MetricsError> {
    check_finite(rate_dps)?;
    let period = median_step(time_s).ok_or(MetricsError::Empty)?;
    let m = samples_per_mean(period, tau_s)?;
    let mut means = Vec::new();
    let mut used = Vec::new();
    let tol = crate::table_segments::RATE_TOLERANCE_DPS;
    for seg in scale_factor::detect_segments(time_s, rate_dps, table_dps, settle_s, tol) {
        if seg.table_dps.abs() > tol {
            continue;
        }
        let t0 = time_s[seg.start] + settle_s;
        let samples: Vec<f64> = (seg.start..seg.end)
            .filter(|&i| time_s[i] >= t0)
            .map(|i| rate_dps[i])
            .collect();
        means.extend(samples.chunks_exact(m).map(mean));
        used.extend(samples);
    }
    if means.len() < 2 {
        return Err(MetricsError::TauTooLong {
            tau_s,
            samples: used.len(),
            sample_period_s: period,
            stop_segments: true,
        });
    }
    Ok((
        mean(&used) * DPS_TO_DPH,
        BiasStability {
            bias_stability_dph: sample_std(&means).unwrap_or(f64::NAN) * DPS_TO_DPH,
            tau_s,
            samples_per_mean: m,
            means: means.len(),
        },
    ))
}

/// Median time step, s (None for fewer than two samples).
fn median_step(time_s: &[f64]) -> Option<f64> {
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return None;
    }
    // The element a sort would put there, without the sort.
    let mid = d.len() / 2;
    Some(*d.select_nth_unstable_by(mid, f64::total_cmp).1)
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

#[cfg(test)]
mod stop_segment_tests {
    use super::*;

    #[test]
    fn stop_segment_bias_ignores_rate_segments_and_settle_time() {
        // 1 Hz; segments of 300 s: stop, +20, stop, -20, stop. Stop output alternates
        // between 1e-3 and 3e-3 °/s in 100 s blocks after a 10 s settle spike; rate segments
        // carry 20 °/s. Independent: the 100 s means of the stops are 1e-3, 3e-3, 1e-3, …
        // (after dropping the settle time each stop keeps 290 s = two whole 100 s means).
        let n = 1500;
        let time_s: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let table: Vec<f64> = (0..n)
            .map(|i| match i / 300 {
                1 => 20.0,
                3 => -20.0,
                _ => 0.0,
            })
            .collect();
        let rate: Vec<f64> = (0..n)
            .map(|i| {
                let in_seg = i % 300;
                if table[i] != 0.0 {
                    table[i]
                } else if in_seg < 10 {
                    5.0
                } else if ((in_seg - 10) / 100) % 2 == 0 {
                    1e-3
                } else {
                    3e-3
                }
            })
            .collect();
        let (bias, st) = stop_segment_bias_dph(&time_s, &rate, &table, 10.0, 100.0).unwrap();
        assert_eq!(st.means, 6);
        let means = [1e-3, 3e-3, 1e-3, 3e-3, 1e-3, 3e-3];
        let want = sample_std(&means).unwrap() * DPS_TO_DPH;
        assert!(
            (st.bias_stability_dph - want).abs() < 1e-9 * want,
            "{st:?} vs {want}"
        );
        // Used stop samples: 3 × 290 = 870; per stop 100 at 1e-3, 100 at 3e-3, 90 at 1e-3.
        let want_bias = (3.0 * (190.0 * 1e-3 + 100.0 * 3e-3) / 870.0) * DPS_TO_DPH;
        assert!(
            (bias - want_bias).abs() < 1e-9 * want_bias,
            "{bias} vs {want_bias}"
        );
    }
}

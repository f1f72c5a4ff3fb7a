//! One held-out log's figures for one model's output: [`performance`].

use std::fmt;

use serde::Serialize;

use crate::csvlog::TestLog;
use crate::metrics::{self, MetricsError, ScaleFactorError, ScaleFactorOptions};

/// Output range at one table rate: min and max of the segment means, °/s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RateRange {
    pub table_dps: f64,
    pub min_dps: f64,
    pub max_dps: f64,
}

/// The performance figures (numbers, not pictures) of one output column, raw or compensated,
/// of one held-out log.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Performance {
    /// Static logs: bias stability, °/h.
    pub bias_stability_dph: Option<f64>,
    /// Rate-table logs: max |K(t) − 1| over the rate segments, ppm.
    pub sf_error_ppm: Option<f64>,
    /// Rate-table logs: max |K(t) − K(first segment)|, ppm (the thermal error as defined by
    /// the scale-factor figures).
    pub sf_thermal_error_ppm: Option<f64>,
    /// Rate-table logs: output range per table rate.
    pub rate_ranges: Vec<RateRange>,
}

/// Why the figures of an output column could not be computed.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum PerformanceError {
    /// Bias stability of a static log.
    BiasStability(MetricsError),
    /// Scale factor of a rate-table log.
    ScaleFactor(ScaleFactorError),
}

impl fmt::Display for PerformanceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PerformanceError::BiasStability(e) => write!(f, "{e}"),
            PerformanceError::ScaleFactor(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for PerformanceError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the inner error's message is this error's own.
            PerformanceError::BiasStability(e) => e.source(),
            PerformanceError::ScaleFactor(e) => e.source(),
        }
    }
}

/// Performance of `output_dps` on `log` (its table column decides static or rate-table).
pub fn performance(
    log: &TestLog,
    output_dps: &[f64],
    tau_s: f64,
    settle_s: f64,
) -> Result<Performance, PerformanceError> {
    let mut f = Performance::default();
    if log.is_static() {
        let period = log.sample_period_s();
        f.bias_stability_dph = Some(
            metrics::bias_stability_dph(output_dps, period, tau_s)
                .map_err(PerformanceError::BiasStability)?
                .bias_stability_dph,
        );
        return Ok(f);
    }
    let table = log.table_dps.as_deref().unwrap_or_default();
    let opts = ScaleFactorOptions {
        settle_s,
        ..Default::default()
    };
    let r = metrics::scale_factor(&log.time_s, output_dps, table, &opts)
        .map_err(PerformanceError::ScaleFactor)?;
    let ks: Vec<f64> = r
        .scale_over_time
        .iter()
        .map(|s| s.scale)
        .filter(|k| k.is_finite())
        .collect();
    f.sf_error_ppm = ks.iter().map(|k| (k - 1.0).abs() * 1e6).reduce(f64::max);
    f.sf_thermal_error_ppm = Some(r.sf_thermal_error_ppm).filter(|v| v.is_finite());
    let mut rates: Vec<f64> = r
        .segments
        .iter()
        .map(|s| s.table_dps)
        .filter(|w| *w != 0.0)
        .collect();
    rates.sort_by(f64::total_cmp);
    rates.dedup();
    for w in rates {
        let means = r
            .segments
            .iter()
            .filter(|s| s.table_dps == w && s.mean_output_dps.is_finite())
            .map(|s| s.mean_output_dps);
        let (lo, hi) = means.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), m| {
            (a.min(m), b.max(m))
        });
        if lo.is_finite() {
            f.rate_ranges.push(RateRange {
                table_dps: w,
                min_dps: lo,
                max_dps: hi,
            });
        }
    }
    Ok(f)
}

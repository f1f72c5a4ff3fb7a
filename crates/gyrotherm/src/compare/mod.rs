//! Held-out comparison of compensation methods: the paper's results table for the user's logs.
//!
//! Fits linear, polynomial and LSTM models on the training logs, compensates each held-out log
//! with the flight compensator, and judges it with the standard figures: bias stability
//! (1σ of τ-means, °/h) for static logs; for rate-table logs the scale factor K(t) per segment
//! against the ideal K = 1 (ppm) and the compensated output range at each table rate. When a
//! held-out log carries simulator truth (`noise_dps`), the bias stability of the noise alone is
//! the physical floor no compensation can beat.

//!
//! The results serialise as [`ComparisonSummary`] (`gyrotherm compare --json`) and tabulate as
//! one [`ComparisonTable`], written as text ([`ComparisonTable::write_text`]) and turned into
//! the report's HTML table (`report::comparison_table`).

mod summary;
mod table;

pub use summary::{ComparisonSummary, ModelSummary, TestSummary};
pub use table::{ComparisonTable, TableBlock, TableFigure, TableRow};

use std::fmt;

use serde::Serialize;

use crate::compensate::{compensate_log, extrapolation_warnings, Compensated};
use crate::csvlog::{TestLog, NOISE_COL};
use crate::fit::{fit_model, FitConfig, FitOutcome, NamedLog, Target};
use crate::metrics::{self, MetricsError, ScaleFactorError, ScaleFactorOptions};
use crate::model::Method;
use crate::targets;

/// Bias-stability smoothing time of the comparison, s (100 s: METHOD.md, He et al. 2024).
pub const BIAS_STABILITY_TAU_S: f64 = 100.0;

/// What to compare and how to judge.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareConfig {
    /// Methods to fit, in table order.
    pub methods: Vec<Method>,
    /// Fit settings shared by all methods (the method field is overridden per method).
    pub fit: FitConfig,
    /// Bias-stability smoothing time, s (100 s as in He et al. 2024).
    pub tau_s: f64,
    /// Settle time dropped at each table segment start, s.
    pub settle_s: f64,
}

impl Default for CompareConfig {
    fn default() -> Self {
        CompareConfig {
            methods: vec![Method::Linear, Method::Poly, Method::Lstm],
            fit: FitConfig::new(Method::Lstm),
            tau_s: BIAS_STABILITY_TAU_S,
            settle_s: targets::SETTLE_S,
        }
    }
}

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

/// One method's result on one held-out log.
#[derive(Debug, Clone)]
pub struct MethodResult {
    pub method: Method,
    pub performance: Performance,
    pub compensated: Compensated,
}

/// All results for one held-out log.
#[derive(Debug, Clone)]
pub struct TestResult {
    pub name: String,
    pub is_static: bool,
    pub raw: Performance,
    /// Bias stability of the noise-only truth column, °/h (simulated logs).
    pub floor_dph: Option<f64>,
    pub methods: Vec<MethodResult>,
    /// Extrapolation warnings (test range outside the training range), per method.
    pub warnings: Vec<String>,
}

/// The whole comparison.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub fits: Vec<FitOutcome>,
    pub tests: Vec<TestResult>,
}

/// Why a comparison could not be made.
#[derive(Debug)]
#[non_exhaustive]
pub enum CompareError {
    /// Fitting `method` on the training logs failed.
    Fit {
        method: Method,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// Compensating the held-out log `log` failed.
    Compensate {
        log: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The figures of the held-out log `log` could not be computed.
    Performance {
        log: String,
        source: PerformanceError,
    },
}

impl fmt::Display for CompareError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompareError::Fit { method, source } => write!(f, "{} fit: {source}", method.as_str()),
            CompareError::Compensate { log, source } => write!(f, "{log}: {source}"),
            CompareError::Performance { log, source } => write!(f, "{log}: {source}"),
        }
    }
}

impl std::error::Error for CompareError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CompareError::Fit { source, .. } | CompareError::Compensate { source, .. } => {
                Some(source.as_ref())
            }
            CompareError::Performance { source, .. } => Some(source),
        }
    }
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
            PerformanceError::BiasStability(e) => Some(e),
            PerformanceError::ScaleFactor(e) => Some(e),
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

/// Fit every configured method on `train` and judge each on every log of `test`.
/// `progress(method, target, epoch, loss)` reports LSTM training.
pub fn compare(
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
    progress: &(dyn Fn(Method, Target, usize, f64) + Sync),
) -> Result<Comparison, CompareError> {
    let mut fits = Vec::new();
    for &m in &cfg.methods {
        let fc = FitConfig {
            method: m,
            ..cfg.fit.clone()
        };
        let fit = fit_model(train, &fc, &|t, e, l| progress(m, t, e, l)).map_err(|e| {
            CompareError::Fit {
                method: m,
                source: e.into(),
            }
        })?;
        fits.push(fit);
    }
    let mut tests = Vec::new();
    for t in test {
        let perf_err = |source| CompareError::Performance {
            log: t.name.to_owned(),
            source,
        };
        let raw = performance(t.log, &t.log.gyro_dps, cfg.tau_s, cfg.settle_s).map_err(perf_err)?;
        let floor_dph = match (t.log.is_static(), t.log.extra_f64(NOISE_COL)) {
            (true, Some(noise)) => {
                metrics::bias_stability_dph(&noise, t.log.sample_period_s(), cfg.tau_s)
                    .ok()
                    .map(|b| b.bias_stability_dph)
            }
            _ => None,
        };
        let mut methods = Vec::new();
        let mut warnings = Vec::new();
        for fit in &fits {
            let comp = compensate_log(&fit.model, t.log).map_err(|e| CompareError::Compensate {
                log: t.name.to_owned(),
                source: e.into(),
            })?;
            let performance = performance(t.log, &comp.gyro_comp_dps, cfg.tau_s, cfg.settle_s)
                .map_err(perf_err)?;
            for w in extrapolation_warnings(&fit.model, t.log) {
                let w = format!("{} ({} model): {w}", t.name, fit.model.method.as_str());
                if !warnings.contains(&w) {
                    warnings.push(w);
                }
            }
            methods.push(MethodResult {
                method: fit.model.method,
                performance,
                compensated: comp,
            });
        }
        tests.push(TestResult {
            name: t.name.to_owned(),
            is_static: t.log.is_static(),
            raw,
            floor_dph,
            methods,
            warnings,
        });
    }
    Ok(Comparison { fits, tests })
}

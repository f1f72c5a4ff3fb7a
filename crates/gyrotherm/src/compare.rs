//! Held-out comparison of compensation methods: the paper's results table for the user's logs.
//!
//! Fits linear, polynomial and LSTM models on the training logs, compensates each held-out log
//! with the flight compensator, and judges it with the standard figures: bias stability
//! (1σ of τ-means, °/h) for static logs; for rate-table logs the scale factor K(t) per segment
//! against the ideal K = 1 (ppm) and the compensated output range at each table rate. When a
//! held-out log carries simulator truth (`noise_dps`), the bias stability of the noise alone is
//! the physical floor no compensation can beat.

use crate::compensate::{compensate_log, extrapolation_warnings, Compensated};
use crate::csvlog::{TestLog, NOISE_COL};
use crate::fit::{fit_model, FitConfig, FitOutcome, NamedLog, Target};
use crate::metrics::{self, ScaleFactorOptions};
use crate::model::Method;
use crate::targets;

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
            tau_s: 100.0,
            settle_s: targets::SETTLE_S,
        }
    }
}

/// Output range at one table rate: min and max of the segment means, °/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateRange {
    pub table_dps: f64,
    pub min_dps: f64,
    pub max_dps: f64,
}

/// Figures of one output column (raw or compensated) of one held-out log.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Figures {
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
    pub figures: Figures,
    pub compensated: Compensated,
}

/// All results for one held-out log.
#[derive(Debug, Clone)]
pub struct TestResult {
    pub name: String,
    pub is_static: bool,
    pub raw: Figures,
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

/// Figures of `output_dps` on `log` (its table column decides static or rate-table).
pub fn figures(
    log: &TestLog,
    output_dps: &[f64],
    tau_s: f64,
    settle_s: f64,
) -> Result<Figures, String> {
    let mut f = Figures::default();
    if targets::is_static(log) {
        let period = log.sample_period_s();
        f.bias_stability_dph = Some(
            metrics::bias_stability_dph(output_dps, period, tau_s)
                .map_err(|e| e.to_string())?
                .bias_stability_dph,
        );
        return Ok(f);
    }
    let table = log.table_dps.as_deref().unwrap_or_default();
    let opts = ScaleFactorOptions {
        settle_s,
        ..Default::default()
    };
    let r =
        metrics::scale_factor(&log.time_s, output_dps, table, &opts).map_err(|e| e.to_string())?;
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
) -> Result<Comparison, String> {
    let mut fits = Vec::new();
    for &m in &cfg.methods {
        let fc = FitConfig {
            method: m,
            ..cfg.fit.clone()
        };
        let fit = fit_model(train, &fc, &|t, e, l| progress(m, t, e, l))
            .map_err(|e| format!("{} fit: {e}", m.as_str()))?;
        fits.push(fit);
    }
    let mut tests = Vec::new();
    for t in test {
        let raw = figures(t.log, &t.log.gyro_dps, cfg.tau_s, cfg.settle_s)
            .map_err(|e| format!("{}: {e}", t.name))?;
        let floor_dph = match (targets::is_static(t.log), t.log.extra_f64(NOISE_COL)) {
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
            let comp = compensate_log(&fit.model, t.log).map_err(|e| format!("{}: {e}", t.name))?;
            let figures = figures(t.log, &comp.gyro_comp_dps, cfg.tau_s, cfg.settle_s)
                .map_err(|e| format!("{}: {e}", t.name))?;
            for w in extrapolation_warnings(&fit.model, t.log) {
                let w = format!("{} ({} model): {w}", t.name, fit.model.method.as_str());
                if !warnings.contains(&w) {
                    warnings.push(w);
                }
            }
            methods.push(MethodResult {
                method: fit.model.method,
                figures,
                compensated: comp,
            });
        }
        tests.push(TestResult {
            name: t.name.to_owned(),
            is_static: targets::is_static(t.log),
            raw,
            floor_dph,
            methods,
            warnings,
        });
    }
    Ok(Comparison { fits, tests })
}

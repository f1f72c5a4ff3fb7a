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

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

use crate::compensate::{compensate_log, extrapolation_warnings, Compensated};
use crate::csvlog::{TestLog, NOISE_COL};
use crate::fit::{fit_model, FitConfig, FitOutcome, NamedLog, Target};
use crate::metrics::{self, MetricsError, ScaleFactorError, ScaleFactorOptions};
use crate::model::{Method, SubModel};
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

/// The comparison as `gyrotherm compare --json` prints it: per held-out log the raw and
/// per-method performance, per model what was fitted and how its training went.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonSummary {
    /// Bias-stability smoothing time, s.
    pub tau_s: f64,
    pub tests: Vec<TestSummary>,
    pub models: Vec<ModelSummary>,
}

/// One held-out log in a [`ComparisonSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TestSummary {
    pub name: String,
    #[serde(rename = "static")]
    pub is_static: bool,
    pub floor_dph: Option<f64>,
    pub raw: Performance,
    /// Keyed by method name (`"lstm"`, `"linear"`, `"poly"`).
    pub methods: BTreeMap<&'static str, Performance>,
    pub warnings: Vec<String>,
}

/// One fitted model in a [`ComparisonSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSummary {
    pub method: &'static str,
    /// Kind of the bias and scale-factor sub-models (None: not fitted).
    pub bias_model: Option<&'static str>,
    pub scale_model: Option<&'static str>,
    pub bias_epochs: Option<usize>,
    pub bias_final_loss: Option<f64>,
    pub scale_epochs: Option<usize>,
    pub scale_final_loss: Option<f64>,
    /// Why a residual LSTM was kept or left out: the relative validation-loss reduction on
    /// the validation blocks and, with `validate_on_runs`, on each left-out training run
    /// (fractions; None where not measured).
    pub bias_lstm_validation_improvement: Option<f64>,
    pub bias_lstm_run_gate: Option<Vec<f64>>,
    pub scale_lstm_validation_improvement: Option<f64>,
    pub scale_lstm_run_gate: Option<Vec<f64>>,
}

impl Comparison {
    /// The serialisable summary (no per-sample data).
    pub fn summary(&self, cfg: &CompareConfig) -> ComparisonSummary {
        ComparisonSummary {
            tau_s: cfg.tau_s,
            tests: self
                .tests
                .iter()
                .map(|t| TestSummary {
                    name: t.name.clone(),
                    is_static: t.is_static,
                    floor_dph: t.floor_dph.filter(|v| v.is_finite()),
                    raw: t.raw.clone(),
                    methods: t
                        .methods
                        .iter()
                        .map(|m| (m.method.as_str(), m.performance.clone()))
                        .collect(),
                    warnings: t.warnings.clone(),
                })
                .collect(),
            models: self
                .fits
                .iter()
                .map(|f| {
                    let (b, s) = (f.bias_training.as_ref(), f.scale_training.as_ref());
                    ModelSummary {
                        method: f.model.method.as_str(),
                        bias_model: f.model.bias.as_ref().map(|b| b.kind()),
                        scale_model: f.model.scale.as_ref().map(|b| b.kind()),
                        bias_epochs: b.map(|t| t.epochs),
                        bias_final_loss: b.map(|t| t.final_loss),
                        scale_epochs: s.map(|t| t.epochs),
                        scale_final_loss: s.map(|t| t.final_loss),
                        bias_lstm_validation_improvement: b.and_then(|t| t.val_improvement),
                        bias_lstm_run_gate: b.and_then(|t| t.run_gate.clone()),
                        scale_lstm_validation_improvement: s.and_then(|t| t.val_improvement),
                        scale_lstm_run_gate: s.and_then(|t| t.run_gate.clone()),
                    }
                })
                .collect(),
        }
    }

    /// One line per fitted model: its sub-models, and why no residual LSTM was kept when
    /// none was.
    pub fn model_lines(&self) -> Vec<String> {
        self.fits
            .iter()
            .map(|f| {
                let part = |s: &Option<SubModel>| s.as_ref().map_or("none", |s| s.kind());
                let mut line = format!(
                    "{:>6}: bias model {}, scale-factor model {}",
                    f.model.method.as_str(),
                    part(&f.model.bias),
                    part(&f.model.scale)
                );
                let lstm_kept = [&f.model.bias, &f.model.scale]
                    .iter()
                    .any(|s| matches!(s, Some(SubModel::Lstm { .. } | SubModel::Residual { .. })));
                if f.model.method == Method::Lstm && !lstm_kept {
                    line.push_str(" (no residual LSTM beat its least-squares base on the validation data, so none was kept)");
                }
                line
            })
            .collect()
    }

    /// The results table, built once for every rendering.
    pub fn table(&self, cfg: &CompareConfig) -> ComparisonTable {
        let methods: Vec<Method> = self.fits.iter().map(|f| f.model.method).collect();
        let mut columns = vec!["raw".to_owned()];
        columns.extend(methods.iter().map(|m| m.as_str().to_owned()));
        let empty = Performance::default();
        let blocks = self
            .tests
            .iter()
            .map(|t| {
                let all: Vec<&Performance> = std::iter::once(&t.raw)
                    .chain(methods.iter().map(|m| {
                        t.methods
                            .iter()
                            .find(|r| r.method == *m)
                            .map_or(&empty, |r| &r.performance)
                    }))
                    .collect();
                let cells = |f: &dyn Fn(&Performance) -> String| all.iter().map(|p| f(p)).collect();
                let mut rows = Vec::new();
                if t.is_static {
                    rows.push(TableRow {
                        figure: TableFigure::BiasStability { tau_s: cfg.tau_s },
                        cells: cells(&|p| cell(p.bias_stability_dph, 5)),
                        floor: Some(cell(t.floor_dph, 5)),
                    });
                    if let (Some(_), Some(fl)) = (t.raw.bias_stability_dph, t.floor_dph) {
                        rows.push(TableRow {
                            figure: TableFigure::TimesNoiseFloor,
                            cells: cells(&|p| cell(p.bias_stability_dph.map(|b| b / fl), 2)),
                            floor: None,
                        });
                    }
                } else {
                    rows.push(TableRow {
                        figure: TableFigure::SfError,
                        cells: cells(&|p| cell(p.sf_error_ppm, 1)),
                        floor: None,
                    });
                    rows.push(TableRow {
                        figure: TableFigure::SfThermalError,
                        cells: cells(&|p| cell(p.sf_thermal_error_ppm, 1)),
                        floor: None,
                    });
                    for (k, r) in t.raw.rate_ranges.iter().enumerate() {
                        rows.push(TableRow {
                            figure: TableFigure::OutputAt {
                                table_dps: r.table_dps,
                            },
                            cells: cells(&|p| {
                                p.rate_ranges
                                    .get(k)
                                    .map(|r| format!("{:.5}..{:.5}", r.min_dps, r.max_dps))
                                    .unwrap_or_else(|| "-".into())
                            }),
                            floor: None,
                        });
                    }
                }
                TableBlock {
                    log: t.name.clone(),
                    is_static: t.is_static,
                    has_floor: t.floor_dph.is_some(),
                    rows,
                }
            })
            .collect();
        ComparisonTable { columns, blocks }
    }
}

fn cell(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => "-".into(),
    }
}

/// The results table of a comparison: one block per held-out log, one column per output
/// (raw, then each method), cells already formatted.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonTable {
    /// Output columns: `raw`, then the method names.
    pub columns: Vec<String>,
    pub blocks: Vec<TableBlock>,
}

/// The rows of one held-out log.
#[derive(Debug, Clone, PartialEq)]
pub struct TableBlock {
    pub log: String,
    pub is_static: bool,
    /// Whether the log carries the noise-only truth column (a noise-floor column).
    pub has_floor: bool,
    pub rows: Vec<TableRow>,
}

/// One figure across the outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct TableRow {
    pub figure: TableFigure,
    /// One cell per [`ComparisonTable::columns`].
    pub cells: Vec<String>,
    /// Noise-floor cell (bias-stability row only).
    pub floor: Option<String>,
}

/// Which figure a row holds.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum TableFigure {
    /// Bias stability, °/h, over `tau_s`.
    BiasStability { tau_s: f64 },
    /// Bias stability as a multiple of the noise floor.
    TimesNoiseFloor,
    /// max |K(t) − 1|, ppm.
    SfError,
    /// max |K(t) − K(room)|, ppm.
    SfThermalError,
    /// Range of the output at one table rate, °/s.
    OutputAt { table_dps: f64 },
}

impl TableFigure {
    /// The row label.
    pub fn label(&self) -> String {
        match self {
            TableFigure::BiasStability { tau_s } => {
                format!("bias stability (°/h, τ = {} s)", fmt_num(*tau_s))
            }
            TableFigure::TimesNoiseFloor => "× noise floor".to_owned(),
            TableFigure::SfError => "SF error max |K(t) − 1| (ppm)".to_owned(),
            TableFigure::SfThermalError => "SF thermal error vs room K (ppm)".to_owned(),
            TableFigure::OutputAt { table_dps } => format!("output at {table_dps:+} °/s (°/s)"),
        }
    }
}

/// `100` rather than `100.0`.
fn fmt_num(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

impl TableBlock {
    /// `name (static)` or `name (rate table)`.
    pub fn title(&self) -> String {
        format!(
            "{} ({})",
            self.log,
            if self.is_static {
                "static"
            } else {
                "rate table"
            }
        )
    }
}

impl ComparisonTable {
    /// Plain text, fixed-width columns: per held-out log a title line, a header line and one
    /// line per figure, then a blank line.
    pub fn write_text(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        for b in &self.blocks {
            writeln!(w, "held-out log {}", b.title())?;
            write!(w, "  {:<36}", "figure")?;
            for c in &self.columns {
                write!(w, "{c:>22}")?;
            }
            if b.has_floor {
                write!(w, "{:>22}", "noise floor")?;
            }
            writeln!(w)?;
            for r in &b.rows {
                let label = match r.figure {
                    TableFigure::TimesNoiseFloor => format!("  {}", r.figure.label()),
                    _ => r.figure.label(),
                };
                write!(w, "  {label:<36}")?;
                for c in &r.cells {
                    write!(w, "{c:>22}")?;
                }
                if let (true, Some(f)) = (b.has_floor, &r.floor) {
                    write!(w, "{f:>22}")?;
                }
                writeln!(w)?;
            }
            writeln!(w)?;
        }
        Ok(())
    }
}

//! Held-out comparison of compensation methods: the paper's results table for the user's logs.
//!
//! Fits one model per [`Candidate`] on the training logs (by default linear, polynomial, the
//! default `lstm` recipe and the published recipe of He et al. 2024, each its own column),
//! compensates each held-out log with the flight compensator, and judges it with the standard figures: bias stability
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
pub mod unit;

pub use summary::{ComparisonSummary, ModelSummary, TestSummary};
pub use table::{ComparisonTable, TableBlock, TableFigure, TableRow};

use std::fmt;

use serde::Serialize;

use crate::compensate::{compensate_log, extrapolation_warnings, Compensated};
use crate::csvlog::{TestLog, NOISE_COL};
use crate::fit::{fit_model, FitConfig, FitOutcome, NamedLog, RecipeSettings, Target};
use crate::metrics::{self, MetricsError, ScaleFactorError, ScaleFactorOptions};
use crate::settings::export::{ExportTarget, EXPORT_TARGETS};
use crate::settings::fit::FitSettings;
use crate::settings::method::{Method, DEFAULT_METHOD, METHODS, METHOD_NAMES};
use crate::settings::rule::{check, Rule, SettingError};
use crate::targets;

pub use crate::metrics::BIAS_STABILITY_TAU_S;

/// One column of the comparison: a method and, for a recipe method, the recipe it trains.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    pub method: Method,
    /// The recipe (recipe methods only; None: the comparison's [`FitConfig::recipe`] when
    /// it is this method's, else the method's own).
    pub recipe: Option<RecipeSettings>,
}

impl Candidate {
    /// A column fitting `method` with the comparison's settings.
    pub fn of(method: Method) -> Self {
        Candidate {
            method,
            recipe: None,
        }
    }

    /// The `linear` fit.
    pub fn linear() -> Self {
        Self::of(Method::Linear)
    }

    /// The `poly` fit.
    pub fn poly() -> Self {
        Self::of(Method::Poly)
    }

    /// The `published` method (He et al. 2024 as published), `epochs` Adam steps (None: the
    /// published 1000).
    pub fn published(epochs: Option<usize>) -> Self {
        let mut recipe = RecipeSettings::published();
        if let Some(e) = epochs {
            recipe.epochs = e;
        }
        Candidate {
            method: Method::Published,
            recipe: Some(recipe),
        }
    }

    /// The fit settings of this column: `base` with its method and recipe.
    pub fn fit_config(&self, base: &FitConfig) -> FitConfig {
        let recipe = match &self.recipe {
            Some(r) => r.clone(),
            None if self.method.is_own_recipe() && self.method != base.recipe.kind => {
                RecipeSettings::of_kind(self.method)
            }
            None => base.recipe.clone(),
        };
        FitConfig {
            method: self.method,
            recipe,
            ..base.clone()
        }
    }

    /// The column's own label, if its method has one ([`Method::column_label`]: the
    /// published recipe's names its authors); otherwise the column is labelled by its model.
    pub(crate) fn column_label(&self, base: &FitConfig) -> Option<&'static str> {
        self.fit_config(base).model_method().column_label()
    }

    /// The column's key in `gyrotherm compare --json` and `--methods`: the method's name.
    pub fn key(&self, base: &FitConfig) -> &'static str {
        self.fit_config(base).model_method().as_str()
    }

    /// Whether fitting this column trains an LSTM (and reports its epochs).
    pub(crate) fn trains_lstm(&self, base: &FitConfig) -> bool {
        let c = self.fit_config(base);
        c.method.is_recipe()
            && c.recipe.epochs > 0
            && (c.recipe.kind != Method::Thermal || c.thermal.residual_lstm)
    }
}

/// A column asked for by name (`compare --methods`, Python's `methods=`): a method, fitted on
/// the training logs, or an autopilot's polynomial ([`ExportTarget::is_autopilot`]) fitted to
/// the steady-state bias of the comparison's own method's model, as `export --target` writes
/// it and the firmware computes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnName {
    Method(Method),
    Autopilot(ExportTarget),
}

impl ColumnName {
    /// Every name a column may be asked for by, with its help line: the methods a fit can
    /// use, then the autopilot targets.
    pub fn all() -> Vec<(&'static str, &'static str)> {
        METHODS
            .iter()
            .map(|m| (m.as_str(), m.help()))
            .chain(
                EXPORT_TARGETS
                    .iter()
                    .filter(|t| t.is_autopilot())
                    .map(|t| (t.as_str(), autopilot_column_help(*t))),
            )
            .collect()
    }
}

fn autopilot_column_help(t: ExportTarget) -> &'static str {
    match t {
        ExportTarget::Px4 => {
            "PX4's TC_G cubic in temperature, fitted to the steady-state bias of --method's \
             model (what `export --target px4` writes), as the firmware computes it"
        }
        _ => {
            "ArduPilot's INS_TCAL cubic in temperature, fitted to the steady-state bias of \
             --method's model (what `export --target ardupilot` writes), as the firmware \
             computes it"
        }
    }
}

impl std::str::FromStr for ColumnName {
    type Err = SettingError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if let Some(m) = METHODS.iter().find(|m| m.as_str() == s) {
            return Ok(ColumnName::Method(*m));
        }
        match EXPORT_TARGETS
            .iter()
            .find(|t| t.is_autopilot() && t.as_str() == s)
        {
            Some(t) => Ok(ColumnName::Autopilot(*t)),
            None => Err(SettingError::Unknown {
                setting: "methods",
                value: s.to_owned(),
                expected: column_names(),
            }),
        }
    }
}

/// The names [`ColumnName`] parses, for error messages.
fn column_names() -> &'static [&'static str] {
    static NAMES: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    NAMES.get_or_init(|| ColumnName::all().into_iter().map(|(n, _)| n).collect())
}

/// The comparison's side of the user's settings: the settings sit below the comparison and
/// know nothing of it, so the comparison builds its configuration from them here.
impl FitSettings {
    /// The comparison of `methods` (None: `linear`, `poly`, this settings' method and
    /// `published`, once) with these settings, bias stability over `tau_s`.
    pub fn compare_config(
        &self,
        columns: Option<&[ColumnName]>,
        tau_s: f64,
    ) -> Result<CompareConfig, SettingError> {
        check("tau_s", tau_s, Rule::PositiveSeconds)?;
        let fit = self.fit_config()?;
        let main = fit.model_method();
        let methods: Option<Vec<Method>> = columns.map(|c| {
            c.iter()
                .filter_map(|c| match c {
                    ColumnName::Method(m) => Some(*m),
                    ColumnName::Autopilot(_) => None,
                })
                .collect()
        });
        let autopilot: Vec<ExportTarget> = columns
            .into_iter()
            .flatten()
            .filter_map(|c| match c {
                ColumnName::Autopilot(t) => Some(*t),
                ColumnName::Method(_) => None,
            })
            .collect();
        let wanted: Vec<Method> = match methods.as_deref() {
            Some(m) => {
                // `lstm`, which older model files record, is no method a fit can use.
                if let Some(old) = m.iter().find(|m| !METHODS.contains(m)) {
                    return Err(SettingError::unknown(
                        "methods",
                        old.as_str(),
                        &METHOD_NAMES,
                    ));
                }
                m.to_vec()
            }
            None => {
                let mut all = vec![Method::Linear, Method::Poly, main];
                if main != Method::Published {
                    all.push(Method::Published);
                }
                all
            }
        };
        let candidates = wanted
            .into_iter()
            .map(|m| Candidate {
                method: m,
                recipe: m.is_own_recipe().then(|| self.recipe_for(m)),
            })
            .collect();
        Ok(CompareConfig {
            candidates,
            autopilot,
            fit,
            tau_s,
            settle_s: self.settle_s,
        })
    }
}

/// The bias-stability smoothing time for held-out logs when none was asked for:
/// [`BIAS_STABILITY_TAU_S`] when it is a whole number of sample periods of every static log
/// in `test`, otherwise the multiple of the longest such period nearest to it
/// ([`metrics::default_tau_s`]). Returns τ and, when it is not [`BIAS_STABILITY_TAU_S`], the
/// sample period it is a multiple of; a caller should say so (one sample per 15 s gives
/// τ = 105 s). Rate-table logs count only when no log is static.
pub(crate) fn default_tau_s(test: &[NamedLog]) -> (f64, Option<f64>) {
    let periods = |static_only: bool| {
        test.iter()
            .filter(move |t| !static_only || t.log.is_static())
            .map(|t| t.log.sample_period_s())
            .filter(|p| p.is_finite() && *p > 0.0)
            .fold(None, |a: Option<f64>, p| Some(a.map_or(p, |a| a.max(p))))
    };
    match periods(true).or_else(|| periods(false)) {
        Some(p) => match metrics::default_tau_s(p, BIAS_STABILITY_TAU_S) {
            (t, true) => (t, Some(p)),
            (t, false) => (t, None),
        },
        None => (BIAS_STABILITY_TAU_S, None),
    }
}

/// What to compare and how to judge.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareConfig {
    /// The columns to fit, in table order; no two with the same [`Candidate::key`].
    pub candidates: Vec<Candidate>,
    /// Autopilot polynomials to show after them, each fitted to the steady-state bias of the
    /// model of [`CompareConfig::fit`]'s method: added to a finished comparison by
    /// `export::autopilot::add_columns` (the polynomial is the export's), not by
    /// [`compare`].
    pub autopilot: Vec<ExportTarget>,
    /// Fit settings shared by all columns (method and recipe set per [`Candidate`]).
    pub fit: FitConfig,
    /// Bias-stability smoothing time, s (100 s as in He et al. 2024).
    pub tau_s: f64,
    /// Settle time dropped at each table segment start, s.
    pub settle_s: f64,
}

impl Default for CompareConfig {
    fn default() -> Self {
        CompareConfig {
            candidates: vec![
                Candidate::linear(),
                Candidate::poly(),
                Candidate::of(DEFAULT_METHOD),
                Candidate::published(None),
            ],
            autopilot: Vec::new(),
            fit: FitConfig::new(DEFAULT_METHOD),
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

/// One column's result on one held-out log.
#[derive(Debug, Clone)]
pub struct MethodResult {
    pub method: Method,
    /// The column's key ([`Candidate::key`]).
    pub key: &'static str,
    /// The column's name: what the model holds ([`ModelFile::label`](crate::model::ModelFile::label)),
    /// or the published recipe's label ([`Method::column_label`]).
    pub label: &'static str,
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
    /// Columns fitted on the training logs that could not be compensated or judged on this
    /// log, with why (absent from [`TestResult::methods`]).
    pub failed: Vec<FailedColumn>,
    /// Extrapolation warnings (test range outside the training range), per method.
    pub warnings: Vec<String>,
}

/// A column of the comparison that could not be computed, and why. The rest of the table
/// is computed without it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailedColumn {
    /// [`Candidate::key`].
    pub key: &'static str,
    /// Its name in the table: the published recipe's label ([`Method::column_label`]) or the
    /// method's name (a model that was never fitted holds nothing to name it by).
    pub label: &'static str,
    /// The error and its causes, as one line.
    pub reason: String,
}

/// The whole comparison.
#[derive(Debug, Clone)]
pub struct Comparison {
    /// One fitted model per column, in table order.
    pub fits: Vec<FitOutcome>,
    /// Key and name of each column, beside [`Comparison::fits`].
    pub columns: Vec<Column>,
    /// Columns whose fit on the training logs failed, in table order: not in
    /// [`Comparison::fits`]; the table shows them as not fitted, with why.
    pub failed: Vec<FailedColumn>,
    pub tests: Vec<TestResult>,
}

/// A column of a finished comparison: its key and its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    /// [`Candidate::key`]: `linear`, `poly`, `lstm` or `published`.
    pub key: &'static str,
    /// What the model holds, or the published recipe's label ([`Method::column_label`]).
    pub label: &'static str,
}

/// Why a comparison could not be made.
#[derive(Debug)]
#[non_exhaustive]
pub enum CompareError {
    /// No column to fit.
    NoCandidates,
    /// Two columns would fit the same thing (`key`).
    DuplicateColumn { key: &'static str },
    /// Fitting the column `key` on the training logs failed (the only column asked for).
    Fit {
        key: &'static str,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// No column could be fitted: each column and why.
    NoColumnFitted { failed: Vec<FailedColumn> },
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
            CompareError::NoCandidates => write!(f, "no method to compare: name at least one"),
            CompareError::DuplicateColumn { key } => {
                write!(
                    f,
                    "the {key} column is asked for twice; name each method once"
                )
            }
            CompareError::Fit { key, .. } => write!(f, "{key} fit"),
            CompareError::NoColumnFitted { failed } => {
                let each: Vec<String> = failed
                    .iter()
                    .map(|c| format!("{}: {}", c.key, c.reason))
                    .collect();
                write!(f, "no method could be fitted ({})", each.join("; "))
            }
            CompareError::Compensate { log, .. } => write!(f, "{log}"),
            CompareError::Performance { log, .. } => write!(f, "{log}"),
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
            CompareError::NoCandidates
            | CompareError::DuplicateColumn { .. }
            | CompareError::NoColumnFitted { .. } => None,
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

/// Fit every configured column on `train` and judge each on every log of `test`.
/// `progress(key, target, epoch, loss)` reports LSTM training ([`Candidate::key`]).
///
/// A column whose fit fails, or whose model cannot compensate or be judged on a held-out
/// log, is recorded with why ([`Comparison::failed`], [`TestResult::failed`]) and the rest
/// of the table is computed; only when no column can be fitted is it an error.
pub fn compare(
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
    progress: &(dyn Fn(&'static str, Target, usize, f64) + Sync),
) -> Result<Comparison, CompareError> {
    compare_with_stages(train, test, cfg, progress, &|_| {})
}

/// A step of [`compare_with_stages`], for a progress line.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub(crate) enum Stage<'a> {
    /// Fitting column `key` (`index` of `of`, 0-based) begins.
    Fitting {
        key: &'static str,
        index: usize,
        of: usize,
    },
    /// Column `key` was fitted (`ok`) or not, in `seconds`.
    Fitted {
        key: &'static str,
        ok: bool,
        seconds: f64,
    },
    /// Judging held-out log `log` begins.
    Judging { log: &'a str },
}

/// [`compare`], telling `stage` as each column is fitted and each held-out log judged.
pub(crate) fn compare_with_stages(
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
    progress: &(dyn Fn(&'static str, Target, usize, f64) + Sync),
    stage: &dyn Fn(Stage),
) -> Result<Comparison, CompareError> {
    if cfg.candidates.is_empty() {
        return Err(CompareError::NoCandidates);
    }
    let keys: Vec<&'static str> = cfg.candidates.iter().map(|c| c.key(&cfg.fit)).collect();
    for (i, &key) in keys.iter().enumerate() {
        if keys[..i].contains(&key) {
            return Err(CompareError::DuplicateColumn { key });
        }
    }
    let mut fits = Vec::new();
    let mut columns = Vec::new();
    let mut failed = Vec::new();
    let mut first_error = None;
    for (index, (c, &key)) in cfg.candidates.iter().zip(&keys).enumerate() {
        stage(Stage::Fitting {
            key,
            index,
            of: keys.len(),
        });
        let started = std::time::Instant::now();
        let fc = c.fit_config(&cfg.fit);
        let fit = fit_model(train, &fc, &|t, e, l| progress(key, t, e, l));
        stage(Stage::Fitted {
            key,
            ok: fit.is_ok(),
            seconds: started.elapsed().as_secs_f64(),
        });
        let fit = match fit {
            Ok(f) => f,
            Err(e) => {
                let label = c.column_label(&cfg.fit).unwrap_or(key);
                failed.push(FailedColumn {
                    key,
                    label,
                    reason: crate::error_chain::error_chain(&e),
                });
                first_error.get_or_insert((key, e));
                continue;
            }
        };
        let label = c
            .column_label(&cfg.fit)
            .unwrap_or_else(|| fit.model.label());
        columns.push(Column { key, label });
        fits.push(fit);
    }
    if fits.is_empty() {
        return Err(match (failed.len(), first_error) {
            (1, Some((key, e))) => CompareError::Fit {
                key,
                source: e.into(),
            },
            _ => CompareError::NoColumnFitted { failed },
        });
    }
    let mut tests = Vec::new();
    for t in test {
        stage(Stage::Judging { log: t.name });
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
        let mut failed_here = Vec::new();
        let mut warnings = Vec::new();
        for (fit, col) in fits.iter().zip(&columns) {
            let judged = compensate_log(&fit.model, t.log)
                .map_err(|e| crate::error_chain::error_chain(&e))
                .and_then(|comp| {
                    performance(t.log, &comp.gyro_comp_dps, cfg.tau_s, cfg.settle_s)
                        .map(|p| (comp, p))
                        .map_err(|e| {
                            format!(
                                "its output cannot be judged: {}",
                                crate::error_chain::error_chain(&e)
                            )
                        })
                });
            let (comp, performance) = match judged {
                Ok(x) => x,
                Err(reason) => {
                    failed_here.push(FailedColumn {
                        key: col.key,
                        label: col.label,
                        reason,
                    });
                    continue;
                }
            };
            for w in extrapolation_warnings(&fit.model, t.log) {
                let w = format!("{} ({} model): {w}", t.name, col.label);
                if !warnings.contains(&w) {
                    warnings.push(w);
                }
            }
            methods.push(MethodResult {
                method: fit.model.method,
                key: col.key,
                label: col.label,
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
            failed: failed_here,
            warnings,
        });
    }
    Ok(Comparison {
        fits,
        columns,
        failed,
        tests,
    })
}

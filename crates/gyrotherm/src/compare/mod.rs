//! Held-out comparison of compensation methods: the paper's results table for the user's logs.
//!
//! Fits one model per [`Candidate`] on the training logs (by default linear, polynomial, the
//! default method and the published recipe of He et al. 2024, each its own column),
//! compensates each held-out log with the flight compensator, and judges it with the standard figures: bias stability
//! (1σ of τ-means, °/h) for static logs; for rate-table logs the scale factor K(t) per segment
//! against the ideal K = 1 (ppm) and the compensated output range at each table rate. When a
//! held-out log carries simulator truth (`noise_dps`), the bias stability of the noise alone is
//! the physical floor no compensation can beat.
//!
//! The results serialise as [`ComparisonSummary`] (`gyrotherm compare --json`) and tabulate as
//! one [`ComparisonTable`], written as text ([`ComparisonTable::write_text`]) and turned into
//! the report's HTML table (`report::results_table`).

mod column;
mod performance;
mod summary;
mod table;
pub mod unit;

pub use column::{Candidate, ColumnName};
pub use performance::{performance, Performance, PerformanceError, RateRange};
pub use summary::{ComparisonSummary, ModelSummary, TestSummary};
pub use table::{ComparisonTable, TableBlock, TableFigure, TableRow};

use std::fmt;

use serde::Serialize;

use crate::compensate::{compensate_log, extrapolation_warnings, Compensated};
use crate::csvlog::NOISE_COL;
use crate::fit::{fit_model, FitConfig, FitOutcome, NamedLog, Target};
use crate::metrics;
use crate::settings::export::ExportTarget;
use crate::settings::method::{Method, DEFAULT_METHOD};
use crate::targets;

pub use crate::metrics::BIAS_STABILITY_TAU_S;

/// The bias-stability smoothing time for held-out logs when none was asked for:
/// [`BIAS_STABILITY_TAU_S`] when it is a whole number of sample periods of every static log
/// in `test`, otherwise the multiple of the longest such period nearest to it
/// ([`metrics::default_tau_s`]). Returns τ and, when it is not [`BIAS_STABILITY_TAU_S`], the
/// sample period it is a multiple of; a caller should say so (one sample per 15 s gives
/// τ = 105 s). Rate-table logs count only when no log is static.
pub(crate) fn default_tau_s(test: &[NamedLog]) -> (f64, Option<f64>) {
    tau_of_runs(
        test.iter()
            .map(|t| (t.log.time_s.as_slice(), t.log.is_static())),
    )
}

/// [`default_tau_s`] over runs given as their time column and whether each is static: what
/// the rule reads of a log, a single gyro's or a unit's.
pub(crate) fn tau_of_runs<'a>(
    runs: impl Iterator<Item = (&'a [f64], bool)> + Clone,
) -> (f64, Option<f64>) {
    let periods = |static_only: bool| {
        runs.clone()
            .filter(move |(_, is_static)| !static_only || *is_static)
            .map(|(time_s, _)| crate::csvlog::repr::median_step_s(time_s))
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

//! The standard figures of an inertial unit, axis by axis: `evaluate` (each gyro column, raw
//! and with a unit model compensated), `compare` (every method fitted and judged per axis)
//! and the table across axes that `report` and `compare` show.
//!
//! Each axis is judged as a single-axis log ([`axis_test_log`]): its gyro, the sensor its
//! model reads, the table rate only in the runs where the table turns this axis (in the
//! others the axis stands still, so they are static runs for it), and, in a simulated log,
//! the axis's truth columns under the single-axis names (`noise_dps_x` → `noise_dps`) so the
//! noise floor is the axis's own. The single-axis figures and comparison then apply as they
//! are, so a one-axis figure and its per-axis counterpart are the same number.
//!
//! With several temperature columns the comparison fits the unit as `train` with the same
//! lists and fit settings builds it (`fit_imu_with_events`): per axis the sensors
//! cross-validation keeps. Each axis's table then holds every one-sensor method fitted on
//! the sensor that axis's one-sensor choice picks (the sensor whose one-sensor fit has the
//! lowest cross-validated RMS, the unit fit's first sensor; so the one-sensor columns differ
//! only by method), and beside them the unit's own fit of the axis on all the sensors it
//! keeps (`UnitFitColumn`, named for what it holds and how many sensors it reads).

use serde::Serialize;

use crate::compare::{
    compare, performance, CompareConfig, CompareError, Comparison, ComparisonSummary,
    ComparisonTable, Performance, TableFigure,
};
use crate::compensate::unit::compensate_imu;
use crate::csvlog::{ExtraColumn, ImuLog, TestLog, GYRO_COL};
use crate::fit::unit::{fit_imu_with_events, ImuEvents, UnitFitError};
use crate::fit::{NamedLog, Target};
use crate::metrics::Evaluation;
use crate::model::unit::{ImuAxis, ImuError, ImuModel};
use crate::model::TempSensorDef;
use crate::settings::evaluate::{EvaluateError, EvaluateSettings, ResolvedTau};
use crate::spec::{self, MeasureOptions, Spec, SpecError, Verdict};
use crate::string_table::Table;

/// Why a unit's figures could not be computed.
#[derive(Debug)]
#[non_exhaustive]
pub enum ImuJudgeError {
    /// The figures of axis `gyro` (`output`: raw or compensated).
    Evaluate {
        gyro: String,
        output: &'static str,
        source: EvaluateError,
    },
    /// The comparison of axis `gyro`.
    Compare { gyro: String, source: CompareError },
    /// The unit fit's figures of axis `gyro` on held-out log `log`.
    UnitFit {
        gyro: String,
        log: String,
        source: crate::compare::PerformanceError,
    },
    /// The spec-sheet verdict of axis `gyro` (`output`: raw or compensated).
    Spec {
        gyro: String,
        output: &'static str,
        source: Box<SpecError>,
    },
    /// The unit model (compensating with it).
    Unit(ImuError),
    /// Fitting the unit model.
    Fit(UnitFitError),
    /// The logs or settings do not fit together (the message says what to do).
    Layout(String),
}

impl std::fmt::Display for ImuJudgeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ImuJudgeError::Evaluate { gyro, output, .. } => {
                write!(f, "axis {gyro} ({output} output)")
            }
            ImuJudgeError::Compare { gyro, .. } => write!(f, "axis {gyro}"),
            ImuJudgeError::UnitFit { gyro, log, .. } => {
                write!(f, "axis {gyro}, the unit's fit on held-out log {log}")
            }
            ImuJudgeError::Spec { gyro, output, .. } => {
                write!(f, "axis {gyro} ({output} output) against the spec sheet")
            }
            ImuJudgeError::Unit(_) | ImuJudgeError::Fit(_) => write!(f, "the unit model"),
            ImuJudgeError::Layout(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for ImuJudgeError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ImuJudgeError::Evaluate { source, .. } => Some(source),
            ImuJudgeError::Compare { source, .. } => Some(source),
            ImuJudgeError::UnitFit { source, .. } => Some(source),
            ImuJudgeError::Spec { source, .. } => Some(source.as_ref()),
            ImuJudgeError::Unit(e) => Some(e),
            ImuJudgeError::Fit(e) => Some(e),
            ImuJudgeError::Layout(_) => None,
        }
    }
}

/// Axis `axis` of a unit log as a single-axis log for judging (see the module doc):
/// gyro `axis`, temperature `temp`, the table rate when the table turns this axis, and the
/// pass-through columns, the axis's truth columns renamed to the single-axis names.
pub fn axis_test_log(log: &ImuLog, axis: usize, temp: usize) -> TestLog {
    let mut out = log.axis_data(axis, temp);
    let suffix = crate::sim::imu::axis_of_gyro_col(&log.gyro[axis].name).map(|a| format!("_{a}"));
    out.extra = log
        .extra
        .iter()
        .map(|c| {
            let base = suffix
                .as_deref()
                .and_then(|s| c.name.strip_suffix(s))
                .filter(|b| !b.is_empty());
            match base {
                Some(b) => ExtraColumn {
                    name: b.to_owned(),
                    values: c.values.clone(),
                },
                None => c.clone(),
            }
        })
        .collect();
    out
}

/// The figures of one axis: of the raw gyro column, and of its compensated output when a
/// unit model was given.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AxisEvaluation {
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns its model reads (empty without a model).
    pub temps: Vec<String>,
    pub raw: Evaluation,
    pub compensated: Option<Evaluation>,
    /// The axis's verdict against a spec sheet ([`evaluate_imu_spec`]): of the compensated
    /// output when a unit model was given, else of the raw column.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<Verdict>,
}

/// The unit's verdict against a spec sheet: it passes only when every axis passes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitVerdict {
    /// The spec sheet's name and SHA-256.
    pub spec: String,
    pub spec_sha256: String,
    /// Which output was judged: `compensated` (with a unit model) or `raw`.
    pub judged: &'static str,
    /// True when every limited figure of every axis passes.
    pub pass: bool,
    /// The gyro columns of the axes that missed a limit, in column order.
    pub failed_axes: Vec<String>,
}

impl UnitVerdict {
    /// The one rule of a unit's verdict: it passes only when every axis passes. `axes`: each
    /// axis's gyro column and whether it passed, in column order; `judged`: which output
    /// (`compensated` or `raw`).
    pub(crate) fn from_axes<'a>(
        spec: &str,
        spec_sha256: &str,
        judged: &'static str,
        axes: impl IntoIterator<Item = (&'a str, bool)>,
    ) -> UnitVerdict {
        let failed_axes: Vec<String> = axes
            .into_iter()
            .filter(|(_, pass)| !pass)
            .map(|(g, _)| g.to_owned())
            .collect();
        UnitVerdict {
            spec: spec.to_owned(),
            spec_sha256: spec_sha256.to_owned(),
            judged,
            pass: failed_axes.is_empty(),
            failed_axes,
        }
    }

    /// `PASS` or `FAIL`.
    pub fn word(&self) -> &'static str {
        if self.pass {
            "PASS"
        } else {
            "FAIL"
        }
    }

    /// The verdict as one text line.
    pub fn line(&self, axes: usize) -> String {
        let mut s = format!(
            "unit verdict: {} (spec {}, {axes} axes, {} output",
            self.word(),
            self.spec,
            self.judged
        );
        if !self.failed_axes.is_empty() {
            s.push_str(&format!("; failed: {}", self.failed_axes.join(", ")));
        }
        s.push(')');
        s
    }
}

/// What [`evaluate_imu_spec`] returns: the axes' figures (each with its verdict when a spec
/// sheet was given), the τ used, and the unit's verdict.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct UnitEvaluation {
    pub axes: Vec<AxisEvaluation>,
    pub tau: ResolvedTau,
    pub verdict: Option<UnitVerdict>,
}

impl UnitEvaluation {
    /// The form `gyrotherm evaluate --json` prints for a unit (and Python returns): `tau_s`,
    /// `axes` (each with its `verdict` when judged, in the single-axis verdict's form) and,
    /// when judged, the unit's `verdict` beside them.
    pub fn to_json(&self) -> serde_json::Value {
        let mut j = serde_json::json!({ "tau_s": self.tau.tau_s, "axes": self.axes });
        if let (Some(v), Some(o)) = (&self.verdict, j.as_object_mut()) {
            o.insert(
                "verdict".into(),
                serde_json::to_value(v).unwrap_or(serde_json::Value::Null),
            );
        }
        j
    }
}

/// The bias-stability τ of a unit comparison when none was asked for: the single-axis rule
/// ([`crate::compare::default_tau_s`]) on the first axis's view of the held-out logs (every
/// axis shares the time column). Returns τ and, when it is not 100 s, the sample period it
/// is a multiple of.
pub(crate) fn default_tau_s(test: &[(String, ImuLog)]) -> (f64, Option<f64>) {
    let axis0: Vec<(String, TestLog)> = test
        .iter()
        .filter(|(_, l)| !l.gyro.is_empty() && !l.temp.is_empty())
        .map(|(n, l)| (n.clone(), axis_test_log(l, 0, 0)))
        .collect();
    let named: Vec<NamedLog> = axis0
        .iter()
        .map(|(n, l)| NamedLog { name: n, log: l })
        .collect();
    crate::compare::default_tau_s(&named)
}

/// `evaluate` on a unit log: the figures of each gyro column (raw, in °/s as read), and with
/// `model` of each axis's compensated output (`G_comp`, the flight compensator's output as
/// `compensate` writes it); `settings.column` must be the default (the gyro columns are
/// named by the log's column list). With `spec`, each axis judged against the spec sheet as the
/// single-axis `evaluate --spec` judges one column (the same figures, measured on the axis's
/// single-axis log, [`axis_test_log`]): the compensated output when `model` is given (the
/// unit as it is flown), else the raw gyro column. `log_name` names the log in the
/// verdicts' lines. The unit passes only when every axis passes.
pub(crate) fn evaluate_imu_spec(
    log: &ImuLog,
    model: Option<&ImuModel>,
    settings: &EvaluateSettings,
    spec: Option<&Spec>,
    log_name: &str,
) -> Result<UnitEvaluation, ImuJudgeError> {
    if settings.column != GYRO_COL {
        return Err(ImuJudgeError::Layout(format!(
            "column {:?}: a unit log is judged per gyro column (--gyro-col lists them); leave \
             the column at its default {GYRO_COL}",
            settings.column
        )));
    }
    if log.gyro.is_empty() || log.temp.is_empty() {
        return Err(ImuJudgeError::Layout(
            "the log has no gyro or no temperature column".into(),
        ));
    }
    let comp = model
        .map(|m| compensate_imu(m, log))
        .transpose()
        .map_err(ImuJudgeError::Unit)?;
    let mut axes = Vec::with_capacity(log.gyro.len());
    let mut tau = None;
    for (k, g) in log.gyro.iter().enumerate() {
        let axis_log = axis_test_log(log, k, 0);
        let tau0_s = axis_log.sample_period_s();
        if !(tau0_s.is_finite() && tau0_s > 0.0) {
            return Err(ImuJudgeError::Layout(
                "cannot tell the sample period (need at least two samples with increasing time)"
                    .into(),
            ));
        }
        let judge = |values: &[f64], output: &'static str, name: String| {
            let (mut e, t) = settings
                .evaluate(&axis_log, values, tau0_s)
                .map_err(|source| ImuJudgeError::Evaluate {
                    gyro: g.name.clone(),
                    output,
                    source,
                })?;
            e.column = name;
            Ok::<_, ImuJudgeError>((e, t))
        };
        let (raw, t) = judge(&g.values, "raw", g.name.clone())?;
        tau.get_or_insert(t);
        // The axis's compensated output and sensors (compensate_imu returns the model's axes
        // in order; this column's is found by name), or none without a model.
        let comp_axis = match (&comp, model) {
            (Some(c), Some(m)) => {
                let i = m
                    .axes
                    .iter()
                    .position(|a| a.gyro == g.name)
                    .ok_or_else(|| {
                        ImuJudgeError::Layout(format!("the model has no axis {}", g.name))
                    })?;
                Some((c[i].gyro_comp_dps.as_slice(), &m.axes[i].temps))
            }
            _ => None,
        };
        let (compensated, temps) = match comp_axis {
            Some((values, temps)) => {
                let (e, _) = judge(values, "compensated", format!("{}_comp", g.name))?;
                (Some(e), temps.clone())
            }
            None => (None, Vec::new()),
        };
        let verdict = match spec {
            Some(sp) => {
                let (values, output) = match comp_axis {
                    Some((values, _)) => (values, "compensated"),
                    None => (g.values.as_slice(), "raw"),
                };
                Some(judge_axis(
                    sp, &axis_log, values, settings, tau0_s, log_name, &g.name, output,
                )?)
            }
            None => None,
        };
        axes.push(AxisEvaluation {
            gyro: g.name.clone(),
            temps,
            raw,
            compensated,
            verdict,
        });
    }
    let tau = tau.ok_or_else(|| ImuJudgeError::Layout("no gyro column".into()))?;
    let verdict = spec.map(|sp| {
        UnitVerdict::from_axes(
            &sp.name,
            &sp.sha256,
            if model.is_some() {
                "compensated"
            } else {
                "raw"
            },
            axes.iter()
                .map(|a| (a.gyro.as_str(), a.verdict.as_ref().is_none_or(|v| v.pass))),
        )
    });
    Ok(UnitEvaluation { axes, tau, verdict })
}

/// Every figure of one axis of a unit's compensated output on each held-out log.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AxisFigures {
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns the axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// Per held-out log, in order: its name and the figures measured on it.
    pub measured: Vec<(String, spec::Figures)>,
}

/// Every figure ([`spec::measure`] with `opts`) of each axis's compensated output (the flight
/// compensator's, as `compensate` writes it) on each held-out log, each axis measured on its
/// single-axis view of the log ([`axis_test_log`]) as `evaluate --model` measures it. The
/// logs must be read with the model's columns ([`ImuModel::read_options`]). Axes in the
/// model's order.
pub(crate) fn measure_unit(
    model: &ImuModel,
    tests: &[(String, ImuLog)],
    opts: &MeasureOptions,
) -> Result<Vec<AxisFigures>, ImuJudgeError> {
    let mut axes: Vec<AxisFigures> = model
        .axes
        .iter()
        .map(|a| AxisFigures {
            gyro: a.gyro.clone(),
            temps: a.temps.clone(),
            measured: Vec::with_capacity(tests.len()),
        })
        .collect();
    for (name, log) in tests {
        let comp = compensate_imu(model, log).map_err(ImuJudgeError::Unit)?;
        for (i, a) in axes.iter_mut().enumerate() {
            let k = log
                .gyro
                .iter()
                .position(|g| g.name == a.gyro)
                .ok_or_else(|| {
                    ImuJudgeError::Layout(format!(
                        "{name}: no gyro column {} (the model's axis {}); read the log with \
                         the model's columns",
                        a.gyro,
                        i + 1
                    ))
                })?;
            let axis_log = axis_test_log(log, k, 0);
            let f = spec::measure(&axis_log, &comp[i].gyro_comp_dps, opts).map_err(|source| {
                ImuJudgeError::Spec {
                    gyro: a.gyro.clone(),
                    output: "compensated",
                    source: Box::new(SpecError::Measure {
                        log: name.clone(),
                        source,
                    }),
                }
            })?;
            a.measured.push((name.clone(), f));
        }
    }
    Ok(axes)
}

/// Each axis of [`measure_unit`] judged against `spec` on all its held-out logs (as the
/// single-axis [`spec::judge`] judges one column), and the unit's verdict
/// ([`UnitVerdict::from_axes`]: compensated output).
pub(crate) fn judge_unit_figures(
    spec: &Spec,
    axes: &[AxisFigures],
) -> Result<(Vec<Verdict>, UnitVerdict), ImuJudgeError> {
    let verdicts = axes
        .iter()
        .map(|a| {
            spec::judge(spec, &a.measured).map_err(|source| ImuJudgeError::Spec {
                gyro: a.gyro.clone(),
                output: "compensated",
                source: Box::new(source),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let unit = UnitVerdict::from_axes(
        &spec.name,
        &spec.sha256,
        "compensated",
        axes.iter()
            .zip(&verdicts)
            .map(|(a, v)| (a.gyro.as_str(), v.pass)),
    );
    Ok((verdicts, unit))
}

/// One axis's output judged against `spec`, as `evaluate --spec` judges one column.
#[allow(clippy::too_many_arguments)]
fn judge_axis(
    spec: &Spec,
    axis_log: &TestLog,
    values: &[f64],
    settings: &EvaluateSettings,
    tau0_s: f64,
    log_name: &str,
    gyro: &str,
    output: &'static str,
) -> Result<Verdict, ImuJudgeError> {
    let (rate_dps, evaluation, _) =
        settings
            .prepare(values, tau0_s)
            .map_err(|source| ImuJudgeError::Evaluate {
                gyro: gyro.to_owned(),
                output,
                source,
            })?;
    let opts = MeasureOptions {
        evaluation,
        noise_terms: spec.needs_noise_terms(),
    };
    let spec_err = |source| ImuJudgeError::Spec {
        gyro: gyro.to_owned(),
        output,
        source: Box::new(source),
    };
    let f = spec::measure(axis_log, &rate_dps, &opts).map_err(|source| {
        spec_err(SpecError::Measure {
            log: log_name.to_owned(),
            source,
        })
    })?;
    spec::judge(spec, &[(log_name.to_owned(), f)]).map_err(spec_err)
}

/// The unit's own fit of one axis in a comparison: the model `train` with the same lists
/// builds for it, on every sensor cross-validation keeps.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct UnitFitColumn {
    /// What the model holds and what it reads, e.g. `thermal-state LS (3 sensors: temp_x_c,
    /// temp_case_c, temp_y_c)`.
    pub label: String,
    /// The column's short name in the tables, e.g. `thermal LS, 3 sensors`.
    pub header: String,
    /// The method the unit was fitted with.
    pub method: &'static str,
    /// The temperature columns the axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// Its figures on each held-out log, in order.
    pub performance: Vec<Performance>,
    /// Its compensated rate, °/s, on each held-out log, in order (for a spec verdict; not in
    /// the JSON summary).
    #[serde(skip)]
    pub compensated_dps: Vec<Vec<f64>>,
}

impl UnitFitColumn {
    /// The column of `axis` (fitted with `method`) with its figures per held-out log.
    pub fn new(
        axis: &ImuAxis,
        performance: Vec<Performance>,
        compensated_dps: Vec<Vec<f64>>,
    ) -> Self {
        let n = axis.temps.len();
        let what = axis.model.label();
        let sensors = if n == 1 { "sensor" } else { "sensors" };
        let short = if what == "thermal-state LS" {
            "thermal LS"
        } else {
            what
        };
        UnitFitColumn {
            label: format!("{what} ({n} {sensors}: {})", axis.temps.join(", ")),
            header: format!("{short}, {n} {sensors}"),
            method: axis.model.method.as_str(),
            temps: axis.temps.clone(),
            performance,
            compensated_dps,
        }
    }
}

/// One axis of a unit comparison: the single-axis logs it was judged on and the comparison.
#[derive(Debug, Clone)]
pub(crate) struct AxisComparison {
    /// The gyro column.
    pub gyro: String,
    /// The temperature column every one-sensor method of this axis reads.
    pub temp: String,
    /// The unit's own fit of this axis on all the sensors it keeps (with several
    /// temperature columns).
    pub unit_fit: Option<UnitFitColumn>,
    /// The training logs as this axis saw them (name, log).
    pub train: Vec<(String, TestLog)>,
    /// The held-out logs as this axis saw them, in order.
    pub test: Vec<(String, TestLog)>,
    pub comparison: Comparison,
}

impl AxisComparison {
    /// The training logs as named logs (what the single-axis report takes).
    pub(crate) fn train_named(&self) -> Vec<NamedLog<'_>> {
        self.train
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect()
    }

    /// The held-out logs as named logs.
    pub(crate) fn test_named(&self) -> Vec<NamedLog<'_>> {
        self.test
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect()
    }
    /// The axis's results table: the single-axis table, and the unit fit's column beside
    /// the one-sensor methods.
    pub fn table(&self, cfg: &CompareConfig) -> ComparisonTable {
        let mut t = self.comparison.table(cfg);
        if let Some(u) = &self.unit_fit {
            let floors: Vec<Option<f64>> =
                self.comparison.tests.iter().map(|r| r.floor_dph).collect();
            t.push_column(&u.header, &u.performance, &floors);
        }
        t
    }

    /// One line per fitted model, as the single-axis comparison prints them, then the unit
    /// fit's line.
    pub(crate) fn model_lines(&self) -> Vec<String> {
        let mut lines = self.comparison.model_lines();
        if let Some(u) = &self.unit_fit {
            lines.push(format!(
                "{:>16}: the unit's {} fit of this axis as train builds it: {}",
                u.header, u.method, u.label
            ));
        }
        lines
    }
}

/// A unit comparison: one comparison per axis, in gyro column order.
#[derive(Debug, Clone)]
pub(crate) struct ImuComparison {
    pub axes: Vec<AxisComparison>,
}

/// Progress of a unit comparison: axis index, then the comparison's own (column key,
/// target, epoch, loss).
pub(crate) type ImuCompareProgress<'a> =
    dyn Fn(usize, &'static str, Target, usize, f64) + Sync + 'a;

/// `compare` on unit logs: the sensor per axis from the unit fit with `cfg.fit` (skipped
/// with one temperature column; `events` tells its steps), then every column of `cfg`
/// fitted and judged per axis on that sensor, the axes on their own threads.
pub(crate) fn compare_imu(
    train: &[(String, ImuLog)],
    test: &[(String, ImuLog)],
    cfg: &CompareConfig,
    temp_sensor: &TempSensorDef,
    progress: &ImuCompareProgress,
    events: &ImuEvents,
) -> Result<ImuComparison, ImuJudgeError> {
    if train.is_empty() {
        return Err(ImuJudgeError::Layout("no training logs".into()));
    }
    let (gyro_cols, temp_cols) = ImuLog::shared_columns(train.iter().chain(test))
        .map_err(|n| {
            ImuJudgeError::Layout(format!(
                "{n}: every log must be read with the same gyro and temperature columns"
            ))
        })?
        .unwrap_or_default();
    let unit = if temp_cols.len() == 1 {
        None
    } else {
        Some(
            fit_imu_with_events(train, &cfg.fit, temp_sensor, &|_, _, _, _, _| {}, events)
                .map_err(ImuJudgeError::Fit)?,
        )
    };
    let sensors: Vec<usize> = unit
        .as_ref()
        .map_or_else(|| vec![0; gyro_cols.len()], ImuModel::sensor_index);
    // The unit's compensated output of every held-out log, all axes at once.
    let unit_out = unit
        .as_ref()
        .map(|m| {
            test.iter()
                .map(|(_, l)| compensate_imu(m, l))
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()
        .map_err(ImuJudgeError::Unit)?;
    let axes: Vec<Result<AxisComparison, ImuJudgeError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..gyro_cols.len())
            .map(|k| {
                let (gyro_cols, temp_cols, sensors) = (&gyro_cols, &temp_cols, &sensors);
                let (unit, unit_out) = (&unit, &unit_out);
                scope.spawn(move || {
                    let j = sensors[k];
                    let per_axis = |logs: &[(String, ImuLog)]| -> Vec<(String, TestLog)> {
                        logs.iter()
                            .map(|(n, l)| (n.clone(), axis_test_log(l, k, j)))
                            .collect()
                    };
                    let (train, test) = (per_axis(train), per_axis(test));
                    let comparison = {
                        let tr: Vec<NamedLog> = train
                            .iter()
                            .map(|(n, l)| NamedLog { name: n, log: l })
                            .collect();
                        let te: Vec<NamedLog> = test
                            .iter()
                            .map(|(n, l)| NamedLog { name: n, log: l })
                            .collect();
                        compare(&tr, &te, cfg, &|key, t, e, l| progress(k, key, t, e, l)).map_err(
                            |source| ImuJudgeError::Compare {
                                gyro: gyro_cols[k].clone(),
                                source,
                            },
                        )?
                    };
                    let unit_fit = match (unit.as_ref(), unit_out.as_ref()) {
                        (Some(m), Some(outs)) => {
                            let perf = test
                                .iter()
                                .zip(outs)
                                .map(|((name, l), out)| {
                                    performance(l, &out[k].gyro_comp_dps, cfg.tau_s, cfg.settle_s)
                                        .map_err(|source| ImuJudgeError::UnitFit {
                                            gyro: gyro_cols[k].clone(),
                                            log: name.clone(),
                                            source,
                                        })
                                })
                                .collect::<Result<Vec<_>, _>>()?;
                            let comp = outs.iter().map(|o| o[k].gyro_comp_dps.clone()).collect();
                            Some(UnitFitColumn::new(&m.axes[k], perf, comp))
                        }
                        _ => None,
                    };
                    Ok(AxisComparison {
                        gyro: gyro_cols[k].clone(),
                        temp: temp_cols[j].clone(),
                        unit_fit,
                        train,
                        test,
                        comparison,
                    })
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| match h.join() {
                Ok(r) => r,
                Err(p) => std::panic::resume_unwind(p),
            })
            .collect()
    });
    Ok(ImuComparison {
        axes: axes.into_iter().collect::<Result<Vec<_>, _>>()?,
    })
}

/// One axis of a unit comparison judged against a spec sheet: each method's column and the
/// unit's own fit, on the axis's held-out logs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AxisVerdicts {
    pub gyro: String,
    /// The one-sensor methods' columns, as `compare --spec` judges a single axis.
    pub columns: Vec<spec::ColumnVerdict>,
    /// The unit's own fit (its label and verdict), when the unit reads several sensors.
    pub unit_fit: Option<(String, Verdict)>,
}

impl AxisVerdicts {
    /// Whether every judged column of the axis meets every limit.
    pub fn pass(&self) -> bool {
        self.columns.iter().all(|c| c.verdict.pass)
            && self.unit_fit.as_ref().is_none_or(|(_, v)| v.pass)
    }
}

/// The name of the unit fit's column in [`unit_verdicts`] and [`verdicts_across_axes`].
pub(crate) const UNIT_FIT_COLUMN: &str = "unit fit";

/// The unit's verdict of each judged column across the axes ([`UnitVerdict::from_axes`]: a
/// column passes for the unit only when it passes on every axis), the columns in the order
/// of the tables, the unit's own fit ([`UNIT_FIT_COLUMN`]) last.
pub(crate) fn unit_verdicts(spec: &Spec, axes: &[AxisVerdicts]) -> Vec<(String, UnitVerdict)> {
    let mut names: Vec<String> = Vec::new();
    let mut per: Vec<Vec<(&str, bool)>> = Vec::new();
    for a in axes {
        let mut cols: Vec<(String, bool)> = a
            .columns
            .iter()
            .map(|c| (c.label.to_owned(), c.verdict.pass))
            .collect();
        if let Some((_, v)) = &a.unit_fit {
            cols.push((UNIT_FIT_COLUMN.to_owned(), v.pass));
        }
        for (name, pass) in cols {
            let i = match names.iter().position(|n| *n == name) {
                Some(i) => i,
                None => {
                    names.push(name);
                    per.push(Vec::new());
                    names.len() - 1
                }
            };
            per[i].push((a.gyro.as_str(), pass));
        }
    }
    names
        .into_iter()
        .zip(per)
        .map(|(n, axes)| {
            let v = UnitVerdict::from_axes(&spec.name, &spec.sha256, "compensated", axes);
            (n, v)
        })
        .collect()
}

/// One line per judged column across the axes (`unit_verdicts`): `linear: FAIL on
/// gyro_x_dps, gyro_z_dps`, `unit fit: PASS on every axis`.
pub(crate) fn verdicts_across_axes(spec: &Spec, axes: &[AxisVerdicts]) -> Vec<String> {
    unit_verdicts(spec, axes)
        .into_iter()
        .map(|(n, v)| {
            if v.pass {
                format!("{n}: PASS on every axis")
            } else {
                format!("{n}: FAIL on {}", v.failed_axes.join(", "))
            }
        })
        .collect()
}

/// Every axis of a unit comparison judged against `spec`: each column's compensated output on
/// each held-out log, with the comparison's τ and settle time (the single-axis rule,
/// [`spec::judge_comparison`]).
pub(crate) fn judge_unit_comparison(
    spec: &Spec,
    cmp: &ImuComparison,
    cfg: &CompareConfig,
) -> Result<Vec<AxisVerdicts>, ImuJudgeError> {
    let opts = MeasureOptions {
        evaluation: crate::metrics::EvaluationOptions {
            tau_s: cfg.tau_s,
            settle_s: cfg.settle_s,
            reference_scale: None,
        },
        noise_terms: spec.needs_noise_terms(),
    };
    let mut out = Vec::with_capacity(cmp.axes.len());
    for a in &cmp.axes {
        let spec_err = |output: &'static str, source| ImuJudgeError::Spec {
            gyro: a.gyro.clone(),
            output,
            source: Box::new(source),
        };
        let columns = spec::judge_comparison(spec, &a.comparison, &a.test_named(), cfg)
            .map_err(|e| spec_err("compensated", e))?;
        let unit_fit = match &a.unit_fit {
            Some(u) => {
                let mut measured = Vec::with_capacity(a.test.len());
                for ((name, log), rate) in a.test.iter().zip(&u.compensated_dps) {
                    let f = spec::measure(log, rate, &opts).map_err(|source| {
                        spec_err(
                            "compensated",
                            SpecError::Measure {
                                log: name.clone(),
                                source,
                            },
                        )
                    })?;
                    measured.push((name.clone(), f));
                }
                let v = spec::judge(spec, &measured).map_err(|e| spec_err("compensated", e))?;
                Some((u.label.clone(), v))
            }
            None => None,
        };
        out.push(AxisVerdicts {
            gyro: a.gyro.clone(),
            columns,
            unit_fit,
        });
    }
    Ok(out)
}

/// The header of the unit fit's column in the table across axes.
pub(crate) const UNIT_FIT_HEADER: &str = "unit fit (axis's sensors)";

/// One axis in `gyrotherm compare --json` for a unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AxisSummary {
    pub gyro: String,
    /// The sensor the one-sensor methods read.
    pub temp: String,
    pub comparison: ComparisonSummary,
    /// The unit's own fit of the axis (several temperature columns): its label, sensors and
    /// figures per held-out log (in the order of `comparison.tests`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit_fit: Option<UnitFitColumn>,
}

/// A unit comparison as `gyrotherm compare --json` prints it: per axis the single-axis
/// summary, then the table across axes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct ImuComparisonSummary {
    pub axes: Vec<AxisSummary>,
    pub across_axes: AcrossAxes,
}

/// The table across axes as JSON: its headers and rows of formatted cells.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AcrossAxes {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl ImuComparison {
    /// `gyrotherm compare --json` of the unit (and Python's `compare`): the
    /// [`summary`](Self::summary), with `verdicts` (each axis's, [`judge_unit_comparison`])
    /// when it was judged against a spec.
    pub(crate) fn summary_json(
        &self,
        cfg: &CompareConfig,
        verdicts: Option<&[AxisVerdicts]>,
    ) -> Result<serde_json::Value, serde_json::Error> {
        let mut j = serde_json::to_value(self.summary(cfg))?;
        if let (Some(v), Some(o)) = (verdicts, j.as_object_mut()) {
            o.insert("verdicts".into(), serde_json::to_value(v)?);
        }
        Ok(j)
    }

    /// The JSON form.
    pub fn summary(&self, cfg: &CompareConfig) -> ImuComparisonSummary {
        let t = self.across_axes(cfg);
        ImuComparisonSummary {
            axes: self
                .axes
                .iter()
                .map(|a| AxisSummary {
                    gyro: a.gyro.clone(),
                    temp: a.temp.clone(),
                    comparison: a.comparison.summary(cfg),
                    unit_fit: a.unit_fit.clone(),
                })
                .collect(),
            across_axes: AcrossAxes {
                headers: t.headers,
                rows: t.rows,
            },
        }
    }

    /// The table across axes (axis × figure): per held-out log and figure (bias stability,
    /// × noise floor, scale-factor error, SF thermal error) one row per axis, with the raw
    /// output, each method (columns named by method, the same for every axis), the unit's own
    /// fit when there is one (`UNIT_FIT_HEADER`: each axis's row reads that axis's sensors)
    /// and the noise floor. The per-rate output ranges stay in the axes' own tables.
    pub fn across_axes(&self, cfg: &CompareConfig) -> Table {
        let mut headers = vec![
            "held-out log".to_owned(),
            "figure".to_owned(),
            "axis".to_owned(),
            "raw".to_owned(),
        ];
        let keys: Vec<&'static str> = cfg.candidates.iter().map(|c| c.key(&cfg.fit)).collect();
        headers.extend(keys.iter().map(|k| (*k).to_owned()));
        // The unit's own fit reads each axis's own sensors (the axes' tables name them).
        if self.axes.iter().any(|a| a.unit_fit.is_some()) {
            headers.push(UNIT_FIT_HEADER.to_owned());
        }
        headers.push("noise floor".to_owned());
        let tables: Vec<_> = self.axes.iter().map(|a| a.table(cfg)).collect();
        let mut rows = Vec::new();
        let n_tests = tables.iter().map(|t| t.blocks.len()).max().unwrap_or(0);
        for b in 0..n_tests {
            // A table run is static for the axes it does not turn, so the axes' blocks of
            // one log may hold different figures: every figure any axis has, in order.
            let mut figures = Vec::new();
            for t in &tables {
                for row in t.blocks.get(b).into_iter().flat_map(|blk| &blk.rows) {
                    let per_rate = matches!(row.figure, TableFigure::OutputAt { .. });
                    if !per_rate && !figures.contains(&row.figure) {
                        figures.push(row.figure);
                    }
                }
            }
            let log = tables
                .iter()
                .find_map(|t| t.blocks.get(b))
                .map_or(String::new(), |blk| blk.log.clone());
            let mut first_row = true;
            for figure in figures {
                let mut first_axis = true;
                for (a, t) in self.axes.iter().zip(&tables) {
                    let Some(r) = t
                        .blocks
                        .get(b)
                        .and_then(|blk| blk.rows.iter().find(|x| x.figure == figure))
                    else {
                        continue;
                    };
                    let mut cells = vec![
                        if first_row {
                            log.clone()
                        } else {
                            String::new()
                        },
                        if first_axis {
                            figure.label()
                        } else {
                            String::new()
                        },
                        a.gyro.clone(),
                    ];
                    first_row = false;
                    first_axis = false;
                    cells.extend(r.cells.iter().cloned());
                    cells.push(r.floor.clone().unwrap_or_default());
                    rows.push(cells);
                }
            }
        }
        Table { headers, rows }
    }
}

/// `t` as aligned text: the header, a rule, the rows (columns padded to their widest cell).
pub(crate) fn write_text_table(w: &mut dyn std::io::Write, t: &Table) -> std::io::Result<()> {
    let n = t
        .headers
        .len()
        .max(t.rows.iter().map(Vec::len).max().unwrap_or(0));
    let mut width = vec![0usize; n];
    for row in std::iter::once(&t.headers).chain(&t.rows) {
        for (i, c) in row.iter().enumerate() {
            width[i] = width[i].max(c.chars().count());
        }
    }
    let line = |w: &mut dyn std::io::Write, row: &[String]| -> std::io::Result<()> {
        let cells: Vec<String> = (0..n)
            .map(|i| {
                let c = row.get(i).map_or("", String::as_str);
                let pad = width[i].saturating_sub(c.chars().count());
                if i < 3 {
                    format!("{c}{}", " ".repeat(pad))
                } else {
                    format!("{}{c}", " ".repeat(pad))
                }
            })
            .collect();
        writeln!(w, "{}", cells.join("  ").trim_end())
    };
    line(w, &t.headers)?;
    writeln!(
        w,
        "{}",
        "-".repeat(width.iter().sum::<usize>() + 2 * n.saturating_sub(1))
    )?;
    for r in &t.rows {
        line(w, r)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csvlog::NamedSeries;

    fn series(name: &str, v: &[f64]) -> NamedSeries {
        NamedSeries {
            name: name.into(),
            values: v.to_vec(),
        }
    }

    fn text(name: &str, v: &[&str]) -> ExtraColumn {
        ExtraColumn {
            name: name.into(),
            values: v.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn an_axis_sees_its_own_truth_under_the_single_axis_names() {
        let log = ImuLog {
            time_s: vec![0.0, 1.0],
            gyro: vec![
                series("gyro_x_dps", &[1.0, 2.0]),
                series("gyro_y_dps", &[3.0, 4.0]),
            ],
            temp: vec![series("temp_case_c", &[20.0, 21.0])],
            table: Some(series("table_dps", &[0.0, 20.0])),
            table_axis: Some("gyro_y_dps".into()),
            extra: vec![
                text("noise_dps_x", &["0.1", "0.2"]),
                text("noise_dps_y", &["0.3", "0.4"]),
                text("chamber_temp_c", &["22", "23"]),
            ],
        };
        let y = axis_test_log(&log, 1, 0);
        assert_eq!(y.gyro_dps, [3.0, 4.0]);
        assert_eq!(y.extra_f64("noise_dps"), Some(vec![0.3, 0.4]));
        assert_eq!(y.extra_f64("noise_dps_x"), Some(vec![0.1, 0.2]));
        assert_eq!(y.extra_f64("chamber_temp_c"), Some(vec![22.0, 23.0]));
        assert_eq!(y.table_dps.as_deref(), Some(&[0.0, 20.0][..]));
        let x = axis_test_log(&log, 0, 0);
        assert_eq!(x.extra_f64("noise_dps"), Some(vec![0.1, 0.2]));
        // The table turns y: for x the run is static.
        assert!(x.table_dps.is_none());
        // Gyro names the simulator did not write get no renaming.
        let mut other = log.clone();
        other.gyro[1].name = "gy".into();
        other.table_axis = Some("gy".into());
        assert!(axis_test_log(&other, 1, 0).extra_f64("noise_dps").is_none());
    }

    #[test]
    fn the_table_across_axes_aligns_its_columns() {
        let t = Table {
            headers: vec![
                "held-out log".into(),
                "figure".into(),
                "axis".into(),
                "raw".into(),
            ],
            rows: vec![vec![
                "a.csv".into(),
                "bias".into(),
                "gx".into(),
                "0.5".into(),
            ]],
        };
        let mut out = Vec::new();
        write_text_table(&mut out, &t).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "held-out log  figure  axis  raw");
        assert_eq!(lines[1], "-".repeat(31));
        assert_eq!(lines[2], "a.csv         bias    gx    0.5");
    }

    #[test]
    fn evaluate_refuses_a_column_other_than_the_gyros() {
        let log = ImuLog {
            time_s: vec![0.0, 1.0],
            gyro: vec![series("gx", &[1.0, 2.0])],
            temp: vec![series("t", &[20.0, 21.0])],
            ..Default::default()
        };
        let s = EvaluateSettings {
            column: "other_dps".into(),
            ..Default::default()
        };
        let e = evaluate_imu_spec(&log, None, &s, None, "")
            .unwrap_err()
            .to_string();
        assert!(e.contains("judged per gyro column"), "{e}");
    }
}

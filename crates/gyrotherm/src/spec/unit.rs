//! An inertial unit judged against a spec sheet, axis by axis: each axis as the single-axis
//! verdicts judge one column ([`crate::spec`]), and the unit, which passes only when every
//! axis passes.

use serde::Serialize;

use crate::compare::unit::{axis_test_log, ImuComparison, UnitCompareError};
use crate::compare::CompareConfig;
use crate::compare::CompareError;
use crate::compensate::unit::compensate_imu;
use crate::csvlog::ImuLog;
use crate::fit::unit::UnitFitError;
use crate::model::unit::{ImuError, ImuModel};
use crate::settings::evaluate::EvaluateError;
use crate::spec::{self, MeasureOptions, Spec, SpecError, Verdict};

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

impl From<UnitCompareError> for ImuJudgeError {
    fn from(e: UnitCompareError) -> Self {
        match e {
            UnitCompareError::Compare { gyro, source } => ImuJudgeError::Compare { gyro, source },
            UnitCompareError::UnitFit { gyro, log, source } => {
                ImuJudgeError::UnitFit { gyro, log, source }
            }
            UnitCompareError::Unit(e) => ImuJudgeError::Unit(e),
            UnitCompareError::Fit(e) => ImuJudgeError::Fit(e),
            UnitCompareError::Layout(m) => ImuJudgeError::Layout(m),
        }
    }
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

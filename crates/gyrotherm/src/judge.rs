//! The held-out judgement of a job (`compare`, `report`): every method fitted on the training
//! logs and judged on the held-out ones, with a spec sheet's verdicts, for a single gyro or for
//! each axis of a unit. One entry ([`judge`]) for either form of logs; the result is written
//! as text or JSON, or drawn as a report, without the caller asking which form it holds.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::compare::unit::{self as compare_unit, ImuComparison};
use crate::compare::{compare_with_stages, CompareConfig, CompareError, Comparison, Stage};
use crate::csvlog::{ImuLog, LogSet, LogSetForm, TestLog};
use crate::export::ExportTarget;
use crate::fit::{NamedLog, Target};
use crate::model::TempSensorDef;
use crate::report::ReportError;
use crate::spec::unit::{self as spec_unit, AxisVerdicts, ImuJudgeError};
use crate::spec::{ColumnVerdict, Spec, SpecError};
use crate::told::Told;

/// What a judgement tells as it runs (from the fits' threads).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum JudgeEvent {
    /// The LSTM of the column labelled `label` ([`progress_bars`]) finished epoch `epoch`
    /// (0-based) with this loss.
    Epoch {
        label: String,
        target: Target,
        epoch: usize,
        loss: f64,
    },
    /// A step of the work, or a column that could not be fitted or judged.
    Told(Told),
}

/// Why a judgement could not be made.
#[derive(Debug)]
#[non_exhaustive]
pub enum JudgeError {
    /// A single gyro's comparison.
    Compare(CompareError),
    /// The autopilot columns of a single gyro's comparison.
    Autopilot(CompareError),
    /// A unit's comparison.
    Unit(ImuJudgeError),
    /// The autopilot columns are asked of a unit's logs.
    AutopilotOnUnit(ExportTarget),
    /// The spec sheet's verdicts.
    Spec(SpecError),
    /// The training and held-out logs were read in different forms.
    Forms,
}

impl std::fmt::Display for JudgeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JudgeError::Compare(_) | JudgeError::Unit(_) => f.write_str("comparison failed"),
            JudgeError::Autopilot(_) => f.write_str("the autopilot columns failed"),
            JudgeError::AutopilotOnUnit(t) => write!(
                f,
                "--methods {t}: the autopilot columns are for single-gyro logs; for a unit, \
                 export --target {t} writes the unit's parameters"
            ),
            JudgeError::Spec(e) => e.fmt(f),
            JudgeError::Forms => f.write_str(
                "the training and held-out logs must be read alike (both a single gyro's, or \
                 both a unit's)",
            ),
        }
    }
}

impl std::error::Error for JudgeError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            JudgeError::Compare(e) | JudgeError::Autopilot(e) => Some(e),
            JudgeError::Unit(e) => Some(e),
            // Transparent: the sheet's error is this error's own.
            JudgeError::Spec(e) => e.source(),
            JudgeError::AutopilotOnUnit(_) | JudgeError::Forms => None,
        }
    }
}

/// A judged job: the comparison in the form of its logs, with its verdicts.
#[derive(Debug)]
pub struct Judgement<'a> {
    cfg: &'a CompareConfig,
    spec: Option<&'a Spec>,
    form: Judged<'a>,
}

#[derive(Debug)]
enum Judged<'a> {
    Single {
        train: Vec<NamedLog<'a>>,
        test: Vec<NamedLog<'a>>,
        cmp: Comparison,
        verdicts: Option<Vec<ColumnVerdict>>,
        gap_warnings: &'a [String],
    },
    Unit {
        cmp: ImuComparison,
        verdicts: Option<Vec<AxisVerdicts>>,
    },
}

fn named(logs: &[(String, TestLog)]) -> Vec<NamedLog<'_>> {
    logs.iter()
        .map(|(n, l)| NamedLog { name: n, log: l })
        .collect()
}

/// The bias-stability smoothing time: `given`, else 100 s or the multiple of the held-out
/// logs' sample period nearest it, with a line saying so when it is not 100 s.
pub fn tau_s(test: &LogSet, given: Option<f64>) -> (f64, Option<Told>) {
    if let Some(t) = given {
        return (t, None);
    }
    let (t, adjusted_to) = match test.form() {
        LogSetForm::Single(logs) => crate::compare::default_tau_s(&named(logs)),
        LogSetForm::Unit(logs) => compare_unit::default_tau_s(logs),
    };
    let told = adjusted_to.map(|period| {
        Told::Line(format!(
            "τ = {t} s, the multiple of the {period} s sample period nearest 100 s (100 s is \
             not one; give --tau-s to choose)"
        ))
    });
    (t, told)
}

/// The progress bars a judgement's LSTMs fill: one label per column that trains an LSTM
/// (per axis of a unit: `GYRO KEY`), and the most epochs any of them runs.
pub fn progress_bars(train: &LogSet, cfg: &CompareConfig) -> (Vec<String>, usize) {
    let training: Vec<&'static str> = cfg
        .candidates
        .iter()
        .filter(|c| c.trains_lstm(&cfg.fit))
        .map(|c| c.key(&cfg.fit))
        .collect();
    let epochs = cfg
        .candidates
        .iter()
        .filter(|c| c.trains_lstm(&cfg.fit))
        .map(|c| c.fit_config(&cfg.fit).recipe.epochs)
        .max()
        .unwrap_or(0);
    let labels = match train.form() {
        LogSetForm::Single(_) => training.iter().map(|k| (*k).to_owned()).collect(),
        LogSetForm::Unit(logs) => gyro_names(logs)
            .iter()
            .flat_map(|g| training.iter().map(move |k| format!("{g} {k}")))
            .collect(),
    };
    (labels, epochs)
}

fn gyro_names(logs: &[(String, ImuLog)]) -> Vec<String> {
    logs.first()
        .map(|(_, l)| l.column_names().0)
        .unwrap_or_default()
}

/// Fit every column of `cfg` on `train` and judge it on `test` (a unit: each axis, on the
/// sensor its unit fit chose), then against `spec` when given.
pub fn judge<'a>(
    train: &'a LogSet,
    test: &'a LogSet,
    cfg: &'a CompareConfig,
    spec: Option<&'a Spec>,
    events: &(dyn Fn(JudgeEvent) + Sync),
) -> Result<Judgement<'a>, JudgeError> {
    let form = match (train.form(), test.form()) {
        (LogSetForm::Single(tr), LogSetForm::Single(te)) => {
            judge_single(named(tr), named(te), cfg, spec, test.gap_warnings(), events)?
        }
        (LogSetForm::Unit(tr), LogSetForm::Unit(te)) => judge_unit(tr, te, cfg, spec, events)?,
        _ => return Err(JudgeError::Forms),
    };
    Ok(Judgement { cfg, spec, form })
}

fn judge_single<'a>(
    train: Vec<NamedLog<'a>>,
    test: Vec<NamedLog<'a>>,
    cfg: &CompareConfig,
    spec: Option<&Spec>,
    gap_warnings: &'a [String],
    events: &(dyn Fn(JudgeEvent) + Sync),
) -> Result<Judged<'a>, JudgeError> {
    let line = |l: String| events(JudgeEvent::Told(Told::Line(l)));
    let warn = |l: String| events(JudgeEvent::Told(Told::Warning(l)));
    // A comparison fits several models and can run for minutes: each step is told, as
    // `train` tells what it fitted, so a long run is never silent.
    let stage = |s: Stage| match s {
        Stage::Fitting { key, index, of } => line(format!(
            "fitting {key} ({} of {of}) on {} training log{}…",
            index + 1,
            train.len(),
            if train.len() == 1 { "" } else { "s" }
        )),
        Stage::Fitted { key, ok, seconds } => line(format!(
            "{key} {} in {seconds:.1} s",
            if ok { "fitted" } else { "could not be fitted" }
        )),
        Stage::Judging { log } => line(format!("judging {log}…")),
    };
    let mut cmp = compare_with_stages(
        &train,
        &test,
        cfg,
        &|key, target, epoch, loss| {
            events(JudgeEvent::Epoch {
                label: key.to_owned(),
                target,
                epoch,
                loss,
            })
        },
        &stage,
    )
    .map_err(JudgeError::Compare)?;
    // The rest of the table is computed: each column that has no figures is told, naming
    // the method and the cause.
    for f in &cmp.failed {
        warn(format!("the {} column was not fitted: {}", f.key, f.reason));
    }
    for t in &cmp.tests {
        for f in &t.failed {
            warn(format!(
                "the {} column failed on {}: {}",
                f.key, t.name, f.reason
            ));
        }
    }
    let before = cmp.failed.len();
    crate::export::autopilot::add_columns(&mut cmp, &train, &test, cfg)
        .map_err(JudgeError::Autopilot)?;
    for f in &cmp.failed[before..] {
        warn(format!("the {} column was not fitted: {}", f.key, f.reason));
    }
    let verdicts = spec
        .map(|s| crate::spec::judge_comparison(s, &cmp, &test, cfg))
        .transpose()
        .map_err(JudgeError::Spec)?;
    Ok(Judged::Single {
        train,
        test,
        cmp,
        verdicts,
        gap_warnings,
    })
}

fn judge_unit<'a>(
    train: &[(String, ImuLog)],
    test: &[(String, ImuLog)],
    cfg: &CompareConfig,
    spec: Option<&Spec>,
    events: &(dyn Fn(JudgeEvent) + Sync),
) -> Result<Judged<'a>, JudgeError> {
    if let Some(t) = cfg.autopilot.first() {
        return Err(JudgeError::AutopilotOnUnit(*t));
    }
    let started = std::time::Instant::now();
    let sensors = train.first().map_or(0, |(_, l)| l.temp.len());
    if sensors > 1 {
        events(JudgeEvent::Told(Told::Line(format!(
            "choosing each axis's sensor as train does ({} fit, {sensors} sensors)",
            cfg.fit.model_method().as_str()
        ))));
    }
    let step = |s: crate::train::AxisStep| events(JudgeEvent::Told(Told::Line(s.line)));
    let steps = crate::train::step_lines(started, train, &step);
    let gyro = gyro_names(train);
    let cmp = compare_unit::compare_imu(
        train,
        test,
        cfg,
        &TempSensorDef::default(),
        &|k, key, target, epoch, loss| {
            if let Some(g) = gyro.get(k) {
                events(JudgeEvent::Epoch {
                    label: format!("{g} {key}"),
                    target,
                    epoch,
                    loss,
                });
            }
        },
        &steps,
    )
    .map_err(|e| JudgeError::Unit(e.into()))?;
    let verdicts = spec
        .map(|s| spec_unit::judge_unit_comparison(s, &cmp, cfg))
        .transpose()
        .map_err(JudgeError::Unit)?;
    Ok(Judged::Unit { cmp, verdicts })
}

impl Judgement<'_> {
    /// Whether every judged column meets the spec sheet (true without one).
    pub fn pass(&self) -> bool {
        match &self.form {
            Judged::Single { verdicts, .. } => verdicts.iter().flatten().all(|c| c.verdict.pass),
            Judged::Unit { verdicts, .. } => verdicts.iter().flatten().all(|a| a.pass()),
        }
    }

    /// The results as text: the models fitted and a table per held-out log (a unit: per axis,
    /// then the table across axes), then each column's verdict.
    pub fn write_text(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let cfg = self.cfg;
        match &self.form {
            Judged::Single { cmp, verdicts, .. } => {
                write_comparison(w, cmp, cfg)?;
                if let Some(v) = verdicts {
                    write_column_verdicts(w, v)?;
                }
            }
            Judged::Unit { cmp, verdicts } => {
                write_unit_tables(w, cmp, cfg)?;
                if let (Some(vs), Some(s)) = (verdicts, self.spec) {
                    write_unit_verdicts(w, s, vs)?;
                }
            }
        }
        Ok(())
    }

    /// The results as JSON (`compare --json`), with the verdicts when judged.
    pub fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        match &self.form {
            Judged::Single { cmp, verdicts, .. } => {
                let mut j = serde_json::to_value(cmp.summary(self.cfg))?;
                if let (Some(v), Some(o)) = (verdicts, j.as_object_mut()) {
                    o.insert("verdicts".into(), serde_json::to_value(v)?);
                }
                Ok(j)
            }
            Judged::Unit { cmp, verdicts } => cmp.summary_json(self.cfg, verdicts.as_deref()),
        }
    }

    /// Each extrapolation finding once, naming the models (and the axis) it concerns, as the
    /// report page says it.
    pub fn findings(&self) -> Vec<Told> {
        match &self.form {
            Judged::Single { test, cmp, .. } => crate::report::grouped_warnings(test, cmp)
                .into_iter()
                .map(Told::Warning)
                .collect(),
            Judged::Unit { cmp, .. } => cmp
                .axes
                .iter()
                .flat_map(|a| {
                    crate::report::grouped_warnings(&a.test_named(), &a.comparison)
                        .into_iter()
                        .map(|w| Told::Warning(format!("{}: {w}", a.gyro)))
                        .collect::<Vec<_>>()
                })
                .collect(),
        }
    }

    /// Per held-out log of a single gyro, the share of its samples outside (and at the edge
    /// of) each model's training region; models without a coverage map are left out.
    pub fn coverage(&self) -> Result<Vec<Told>, crate::compensate::CompensateError> {
        let Judged::Single { test, cmp, .. } = &self.form else {
            return Ok(Vec::new());
        };
        let mut out = Vec::new();
        for t in test {
            let mut parts = Vec::new();
            for (fit, col) in cmp.fits.iter().zip(&cmp.columns) {
                if let Some([_, edge, outside]) = crate::coverage::shares(&fit.model, t.log)? {
                    parts.push(format!(
                        "{} outside {:.1} % (edge {:.1} %)",
                        col.label,
                        100.0 * outside,
                        100.0 * edge
                    ));
                }
            }
            if !parts.is_empty() {
                out.push(Told::Line(format!(
                    "coverage of {}: {}",
                    t.name,
                    parts.join("; ")
                )));
            }
        }
        Ok(out)
    }

    /// The model of each column fitted on a single gyro's logs, with the column's key (a
    /// unit's comparison fits per axis and holds no unit model: none).
    pub fn fitted(&self) -> Vec<(&'static str, &crate::model::ModelFile)> {
        match &self.form {
            Judged::Single { cmp, .. } => cmp
                .fits
                .iter()
                .zip(&cmp.columns)
                .map(|(f, c)| (c.key, &f.model))
                .collect(),
            Judged::Unit { .. } => Vec::new(),
        }
    }

    /// Draw the report in `dir` (a unit: its page and a full page per axis): returns the
    /// index page.
    pub fn write_report(&self, dir: &Path) -> Result<PathBuf, ReportError> {
        match &self.form {
            Judged::Single {
                train,
                test,
                cmp,
                gap_warnings,
                ..
            } => crate::report::write_full_report_with(
                dir,
                train,
                test,
                cmp,
                self.cfg,
                gap_warnings,
                None,
            ),
            Judged::Unit { cmp, verdicts } => {
                let judged = self.spec.zip(verdicts.as_deref());
                crate::report::unit::write_unit_report(dir, cmp, self.cfg, &[], judged)
            }
        }
    }
}

/// A single gyro's table: the notes, the models fitted, then one block per held-out log.
fn write_comparison(
    w: &mut dyn Write,
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> std::io::Result<()> {
    for line in cmp.headline(cfg) {
        writeln!(w, "NOTE: {line}")?;
    }
    for line in cmp.model_lines() {
        writeln!(w, "{line}")?;
    }
    writeln!(w)?;
    cmp.table(cfg).write_text(w)
}

/// A verdict as text, one line per figure and log, then the overall line.
fn write_verdict(w: &mut dyn Write, v: &crate::spec::Verdict) -> std::io::Result<()> {
    for line in v.lines() {
        writeln!(w, "{line}")?;
    }
    Ok(())
}

/// Each column's verdict as text.
fn write_column_verdicts(w: &mut dyn Write, vs: &[ColumnVerdict]) -> std::io::Result<()> {
    for c in vs {
        writeln!(w, "\n{} ({}):", c.label, c.key)?;
        write_verdict(w, &c.verdict)?;
    }
    Ok(())
}

/// Per axis the single-axis table, then the table across axes.
fn write_unit_tables(
    w: &mut dyn Write,
    cmp: &ImuComparison,
    cfg: &CompareConfig,
) -> std::io::Result<()> {
    for (k, a) in cmp.axes.iter().enumerate() {
        match &a.unit_fit {
            None => {
                writeln!(w, "axis {}: {} (temperature {})", k + 1, a.gyro, a.temp)?;
                write_comparison(w, &a.comparison, cfg)?;
            }
            Some(u) => {
                writeln!(
                    w,
                    "axis {}: {} (one-sensor methods on {}, the sensor whose one-sensor fit \
                     cross-validates best; the unit's fit on {})",
                    k + 1,
                    a.gyro,
                    a.temp,
                    u.temps.join(", ")
                )?;
                for line in a.model_lines() {
                    writeln!(w, "{line}")?;
                }
                writeln!(w)?;
                a.table(cfg).write_text(w)?;
            }
        }
        writeln!(w)?;
    }
    writeln!(w, "across axes:")?;
    compare_unit::write_text_table(w, &cmp.across_axes(cfg))
}

/// Each axis's verdicts (every column, then the unit's own fit), then the unit's verdict of
/// each column across the axes.
fn write_unit_verdicts(
    w: &mut dyn Write,
    spec: &Spec,
    verdicts: &[AxisVerdicts],
) -> std::io::Result<()> {
    for (k, a) in verdicts.iter().enumerate() {
        writeln!(w, "\naxis {} ({}) against the spec:", k + 1, a.gyro)?;
        write_column_verdicts(w, &a.columns)?;
        if let Some((label, v)) = &a.unit_fit {
            writeln!(w, "\n{label} (unit fit):")?;
            write_verdict(w, v)?;
        }
    }
    writeln!(w, "\nspec {} across the axes:", spec.name.escape_debug())?;
    for line in spec_unit::verdicts_across_axes(spec, verdicts) {
        writeln!(w, "  {line}")?;
    }
    Ok(())
}

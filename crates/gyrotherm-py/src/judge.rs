//! The jobs that judge logs, each one entry for a single gyro and a unit, as the CLI runs
//! them: `evaluate` (`gyrotherm evaluate --json`, `gyrotherm::evaluate`) and `compare`
//! (`gyrotherm compare --json`, `gyrotherm::judge`).

use std::path::PathBuf;

use gyrotherm::evaluate::{EvaluateJob, EvaluateJobError};
use gyrotherm::told::Told;
use pyo3::prelude::*;

use crate::logs::LogOptions;
use crate::model::FitArgs;
use crate::model::RawModel;
use crate::{py_err, FitError, LogError, MetricsError};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}

/// What a job told, as the lines Python warns with.
fn lines(told: &[Told]) -> Vec<String> {
    told.iter()
        .map(|t| match t {
            Told::Line(l) | Told::Note(l) | Told::Warning(l) | Told::Item(l) => l.clone(),
        })
        .collect()
}

fn load_spec(spec: Option<PathBuf>) -> PyResult<Option<gyrotherm::spec::Spec>> {
    spec.map(|p| gyrotherm::spec::Spec::load(&p))
        .transpose()
        .map_err(py_err::<MetricsError>)
}

/// A log's figures as `gyrotherm evaluate --json` prints them: a single gyro's `column`, or
/// each axis of a unit's log (column lists, an autopilot log, or a `model`, whose columns
/// are read and whose output is judged beside the raw one). Returns the JSON text and the
/// lines to warn with (what reading did, the τ used when it is not the one asked for).
#[pyfunction]
#[pyo3(signature = (path, options, column, model=None, spec=None, tau_s=None, settle_s=None, reference_scale=None))]
#[allow(clippy::too_many_arguments)]
fn evaluate(
    py: Python<'_>,
    path: PathBuf,
    options: LogOptions,
    column: String,
    model: Option<PyRef<'_, RawModel>>,
    spec: Option<PathBuf>,
    tau_s: Option<f64>,
    settle_s: Option<f64>,
    reference_scale: Option<f64>,
) -> PyResult<(String, Vec<String>)> {
    let model = model.map(|m| m.model().clone());
    let spec = load_spec(spec)?;
    let read = options.read_options()?;
    let settings = gyrotherm::settings::EvaluateSettings {
        column,
        tau_s,
        settle_s: settle_s.unwrap_or(gyrotherm::settings::EvaluateSettings::default().settle_s),
        reference_scale,
    };
    py.detach(|| {
        let name = path.display().to_string();
        let evaluated = gyrotherm::evaluate::evaluate(&EvaluateJob {
            input: &path,
            read: &read,
            table_axis: options.table_axis.as_deref(),
            model: model.as_ref(),
            settings: &settings,
            spec: spec.as_ref(),
        })
        .map_err(|e| match &e {
            EvaluateJobError::Read { .. } => LogError::new_err(gyrotherm::error_chain(&e)),
            // These name no log of their own.
            EvaluateJobError::Evaluate(_) | EvaluateJobError::Spec(_) => {
                MetricsError::new_err(format!("{name}: {}", gyrotherm::error_chain(&e)))
            }
            _ => MetricsError::new_err(gyrotherm::error_chain(&e)),
        })?;
        let j = evaluated
            .to_json()
            .map_err(|e| MetricsError::new_err(e.to_string()))?;
        Ok((j.to_string(), lines(&evaluated.told)))
    })
}

/// Every method fitted on `train` and judged on `test`, as `gyrotherm compare --json` prints
/// it: a single gyro's table, or per axis of a unit (the one-sensor methods on the sensor the
/// one-sensor choice picks and, with several sensors, the unit's own fit). `methods`: names
/// as in `compare --methods` (None: the library's default list). Returns the JSON text and
/// the lines to warn with.
#[pyfunction]
#[pyo3(signature = (train, test, settings, options, methods=None, tau_s=None, spec=None))]
#[allow(clippy::too_many_arguments)]
fn compare(
    py: Python<'_>,
    train: Vec<PathBuf>,
    test: Vec<PathBuf>,
    settings: FitArgs,
    options: LogOptions,
    methods: Option<Vec<String>>,
    tau_s: Option<f64>,
    spec: Option<PathBuf>,
) -> PyResult<(String, Vec<String>)> {
    let spec = load_spec(spec)?;
    let methods: Option<Vec<gyrotherm::compare::ColumnName>> = methods
        .map(|m| {
            m.iter()
                .map(|n| match n.parse() {
                    // A method's name is checked as `fit(method=…)` checks it.
                    Ok(gyrotherm::compare::ColumnName::Method(_)) => {
                        crate::model::parse_method(n).map(gyrotherm::compare::ColumnName::Method)
                    }
                    other => other.map_err(py_err::<FitError>),
                })
                .collect::<PyResult<_>>()
        })
        .transpose()?;
    let fit = settings.settings()?;
    let read = options.read_options()?;
    py.detach(|| {
        let mut notes = Vec::new();
        let mut sets = Vec::new();
        for r in gyrotherm::csvlog::read_log_sets(
            &[&train[..], &test[..]],
            &read,
            options.table_axis.as_deref(),
        ) {
            notes.extend(r.files.iter().flat_map(|f| lines(&f.told)));
            if let Some(f) = r.files.into_iter().find(|f| f.error.is_some()) {
                let e = f
                    .error
                    .map(|e| gyrotherm::error_chain(&e))
                    .unwrap_or_default();
                return Err(LogError::new_err(format!(
                    "cannot use log {}: {e}",
                    f.path.display()
                )));
            }
            sets.push(r.set.map_err(|e| LogError::new_err(e.to_string()))?);
        }
        let (train, test) = (&sets[0], &sets[1]);
        let (tau_s, told) = gyrotherm::judge::tau_s(test, tau_s);
        notes.extend(lines(&told.into_iter().collect::<Vec<_>>()));
        let cfg = fit
            .compare_config(methods.as_deref(), tau_s)
            .map_err(py_err::<FitError>)?;
        // Columns that could not be fitted are in the JSON's `failed`; the steps go untold.
        let judged = gyrotherm::judge::judge(train, test, &cfg, spec.as_ref(), &|_| {}).map_err(
            |e| match &e {
                gyrotherm::judge::JudgeError::Spec(_) => {
                    MetricsError::new_err(gyrotherm::error_chain(&e))
                }
                _ => FitError::new_err(gyrotherm::error_chain(&e)),
            },
        )?;
        notes.extend(lines(&judged.findings()));
        let j = judged
            .to_json()
            .map_err(|e| FitError::new_err(e.to_string()))?;
        Ok((j.to_string(), notes))
    })
}

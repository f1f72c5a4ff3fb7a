//! Training from Python, as `gyrotherm train` does: one binding (`fit`) for a single gyro's
//! logs and a unit's (`gyrotherm::train`), returning the model class of the form trained.

use std::path::PathBuf;
use std::sync::Mutex;

use gyrotherm::fit::unit::ImuFitEvent;
use gyrotherm::model::TempSensorDef;
use gyrotherm::told::Told;
use gyrotherm::train::{train, TrainEvent};
use pyo3::prelude::*;

use crate::logs::LogOptions;
use crate::model::{FitArgs, RawModel};
use crate::{FitError, LogError};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    Ok(())
}

/// A call of the progress callback, made with the GIL taken.
type ProgressCall<'a> = Box<dyn FnOnce(Python<'_>) -> PyResult<Py<PyAny>> + 'a>;

/// Fit a model to logs, as `gyrotherm train --input S… --input T…` does (same defaults, same
/// checks, same file): `static_logs` train the bias model, `table_logs` the scale-factor
/// model. One gyro's logs give a model of one axis; a unit's (column lists, or an autopilot
/// log) one of each of its axes. `progress` is called with the GIL taken, from the training threads: a
/// single gyro's `(target, epoch, loss)`, a unit's `(event, gyro, temp, cv_rms)` per axis and
/// sensor (`"axis_start"` with `temp` None, `"start"`, `"done"`, `"axis"`; under `auto` also
/// `"scoring"`, `temp` None, as each left-out run's fold starts, and `"lstm"` as a
/// `thermal-lstm` training on sensor `temp` starts).
#[pyfunction]
#[pyo3(signature = (static_logs, table_logs, settings, options, progress=None))]
fn fit(
    py: Python<'_>,
    static_logs: Vec<PathBuf>,
    table_logs: Vec<PathBuf>,
    settings: FitArgs,
    options: LogOptions,
    progress: Option<Py<PyAny>>,
) -> PyResult<RawModel> {
    let cfg = settings.config()?;
    let opts = options.read_options()?;
    let failed: Mutex<Option<PyErr>> = Mutex::new(None);
    let call = |args: ProgressCall<'_>| {
        Python::attach(|py| {
            if let Err(e) = args(py) {
                let mut slot = failed.lock().unwrap_or_else(|p| p.into_inner());
                slot.get_or_insert(e);
            }
        });
    };
    let trained = py.detach(|| -> PyResult<_> {
        let paths: Vec<PathBuf> = static_logs.iter().chain(&table_logs).cloned().collect();
        let read = gyrotherm::csvlog::read_log_set(&paths, &opts, options.table_axis.as_deref());
        if let Some(f) = read.files.into_iter().find(|f| f.error.is_some()) {
            let e = f.error.map(|e| gyrotherm::error_chain(&e)).unwrap_or_default();
            return Err(LogError::new_err(e));
        }
        let logs = read.set.map_err(|e| LogError::new_err(e.to_string()))?;
        // Each log where the caller put it: a static run in static=[...], a table run in
        // table=[...].
        for (k, (p, is_static)) in paths.iter().zip(logs.is_static()).enumerate() {
            let want_static = k < static_logs.len();
            if want_static != is_static {
                let (name, col) = (p.display(), &opts.table_col);
                return Err(FitError::new_err(if want_static {
                    format!("{name}: given as a static log but its {col} column has non-zero rates; pass it in table=[...]")
                } else {
                    format!("{name}: given as a rate-table log but it has no non-zero {col} rate; pass it in static=[...]")
                }));
            }
        }
        let events = |e: TrainEvent| {
            let Some(cb) = &progress else { return };
            match e {
                TrainEvent::Epoch {
                    target,
                    epoch,
                    loss,
                } => call(Box::new(move |py| cb.call1(py, (target.as_str(), epoch, loss)))),
                TrainEvent::Axis(s) => {
                    let (what, cv) = match s.event {
                        ImuFitEvent::AxisStarted { .. } => ("axis_start", None),
                        ImuFitEvent::SensorStarted { .. } => ("start", None),
                        ImuFitEvent::SensorFinished { cv_rms, .. } => ("done", cv_rms),
                        ImuFitEvent::AxisFinished { .. } => ("axis", None),
                        ImuFitEvent::Scoring { .. } => ("scoring", None),
                        ImuFitEvent::LstmTraining { .. } => ("lstm", None),
                        _ => return,
                    };
                    call(Box::new(move |py| cb.call1(py, (what, s.gyro, s.temp, cv))))
                }
                _ => {}
            }
        };
        train(&logs, &cfg, &TempSensorDef::default(), &opts, &events).map_err(|e| {
            FitError::new_err(format!("training failed: {}", gyrotherm::error_chain(&e)))
        })
    })?;
    if let Some(e) = failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    // What the fit did, told in the library's words.
    let notes: Vec<String> = trained
        .told(std::path::Path::new(""), 0.0)
        .into_iter()
        .filter_map(|t| match t {
            Told::Item(l) => Some(l.trim_start().to_owned()),
            _ => None,
        })
        .collect();
    Ok(RawModel::trained(trained.model, notes))
}

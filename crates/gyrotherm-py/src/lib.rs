//! `gyrotherm._gyrotherm`: the compiled half of the Python package `gyrotherm`.
//!
//! Thin bindings over the ground library: every function here converts arguments, calls one
//! library function with the GIL released, and converts the result or the error. The
//! Python half (`python/gyrotherm/`) holds what is Python-specific: the allantools τ
//! generator and tuple layout, pandas, warnings and progress printing.
//!
//! Errors become exceptions derived from `gyrotherm.GyrothermError` (both a `ValueError` and
//! a `RuntimeError`, as allantools raises for the same faults) with the library's message,
//! the one the CLI prints.

use pyo3::create_exception;
use pyo3::import_exception;
use pyo3::prelude::*;

mod allan;
mod export;
mod figures;
mod judge;
mod logs;
mod lot;
mod model;
mod train;

// The base class has two bases (`ValueError`, `RuntimeError`), which `create_exception!`
// cannot express: it is defined in `python/gyrotherm/_errors.py` and imported here.
import_exception!(gyrotherm._errors, GyrothermError);
create_exception!(
    gyrotherm,
    LogError,
    GyrothermError,
    "A test log that cannot be read (file, line, column and the fix in the message)."
);
create_exception!(
    gyrotherm,
    ModelError,
    GyrothermError,
    "A model file that cannot be read, written or used."
);
create_exception!(
    gyrotherm,
    AllanError,
    GyrothermError,
    "An Allan-family deviation that cannot be computed (data, rate or τ)."
);
create_exception!(
    gyrotherm,
    MetricsError,
    GyrothermError,
    "A gyro figure (bias stability, scale factor) that cannot be computed."
);
create_exception!(
    gyrotherm,
    FitError,
    GyrothermError,
    "A compensation model that cannot be fitted."
);
create_exception!(
    gyrotherm,
    CompensationError,
    GyrothermError,
    "A sample the compensator refuses (non-finite input, time not increasing)."
);

/// A Python exception of type `E` carrying a library error's message (what the CLI prints).
pub(crate) fn py_err<E: pyo3::PyTypeInfo>(e: impl std::error::Error + 'static) -> PyErr {
    PyErr::new::<E, _>(gyrotherm::error_chain(&e))
}

#[pymodule]
fn _gyrotherm(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GyrothermError", py.get_type::<GyrothermError>())?;
    m.add("LogError", py.get_type::<LogError>())?;
    m.add("ModelError", py.get_type::<ModelError>())?;
    m.add("AllanError", py.get_type::<AllanError>())?;
    m.add("MetricsError", py.get_type::<MetricsError>())?;
    m.add("FitError", py.get_type::<FitError>())?;
    m.add("CompensationError", py.get_type::<CompensationError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ONE_SIGMA_CI", gyrotherm::allan::ONE_SIGMA_CI)?;
    m.add("BIAS_WINDOW_S", gyrotherm::targets::BIAS_WINDOW_S)?;
    m.add("SETTLE_S", gyrotherm::targets::SETTLE_S)?;
    // The library's defaults and name lists: Python states none of them itself.
    m.add("FIT_DEFAULTS", model::fit_defaults(py)?)?;
    m.add("READ_DEFAULTS", logs::read_defaults(py)?)?;
    let evaluate = gyrotherm::settings::EvaluateSettings::default();
    let evaluate_defaults = pyo3::types::PyDict::new(py);
    evaluate_defaults.set_item("column", &evaluate.column)?;
    evaluate_defaults.set_item("tau_s", evaluate.tau_s)?;
    evaluate_defaults.set_item("settle_s", evaluate.settle_s)?;
    evaluate_defaults.set_item("reference_scale", evaluate.reference_scale)?;
    m.add("EVALUATE_DEFAULTS", evaluate_defaults)?;
    m.add("METHOD_NAMES", gyrotherm::settings::METHOD_NAMES.to_vec())?;
    m.add(
        "GYRO_UNIT_NAMES",
        gyrotherm::settings::read::GYRO_UNIT_NAMES.to_vec(),
    )?;
    m.add(
        "DELIMITER_NAMES",
        gyrotherm::settings::read::DELIMITER_NAMES.to_vec(),
    )?;
    m.add(
        "SETTINGS_JSON",
        gyrotherm::settings::describe::describe_json(),
    )?;
    m.add(
        "STATUS_NAMES",
        model::status_names()
            .into_iter()
            .collect::<std::collections::BTreeMap<_, _>>(),
    )?;
    m.add(
        "COVERAGE_NAMES",
        model::coverage_names()
            .into_iter()
            .collect::<std::collections::BTreeMap<_, _>>(),
    )?;
    m.add("NO_COVERAGE", gyrotherm::unit_model::NO_COVERAGE)?;
    allan::register(m)?;
    figures::register(m)?;
    judge::register(m)?;
    logs::register(m)?;
    lot::register(m)?;
    model::register(m)?;
    train::register(m)?;
    Ok(())
}

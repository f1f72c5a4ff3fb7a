//! A lot database read into columns: one row per figure measured on one log of one run.

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::GyrothermError;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_lot, m)?)?;
    Ok(())
}

/// Every run of the lot at `db` (an SQLite file or a postgres:// URL) as a dict of columns,
/// the rows of `lot.csv` (`gyrotherm lot report`): numbers as float arrays (NaN where a
/// figure has no limit), text as lists of str; an inertial unit's rows name the axis (`axis`,
/// its gyro column) and the axis's verdict (`axis_verdict`), None on a single-axis run.
#[pyfunction]
fn read_lot<'py>(py: Python<'py>, db: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let db = db.display().to_string();
    let runs = py
        .detach(|| {
            let mut store = gyrotherm::lot::open_store(&db, false, 30_000)?;
            store.runs()
        })
        .map_err(|e| PyErr::new::<GyrothermError, _>(e.to_string()))?;
    let n: usize = runs.iter().map(|r| r.figures.len()).sum();
    let mut run_id = Vec::with_capacity(n);
    let mut unit = Vec::with_capacity(n);
    let mut tested_at = Vec::with_capacity(n);
    let mut latest = Vec::with_capacity(n);
    let mut run_verdict = Vec::with_capacity(n);
    let mut station = Vec::with_capacity(n);
    let mut model_sha = Vec::with_capacity(n);
    let mut log = Vec::with_capacity(n);
    let mut figure = Vec::with_capacity(n);
    let mut value = Vec::with_capacity(n);
    let mut limit_min = Vec::with_capacity(n);
    let mut limit_max = Vec::with_capacity(n);
    let mut verdict = Vec::with_capacity(n);
    let mut margin = Vec::with_capacity(n);
    let mut axis = Vec::with_capacity(n);
    let mut axis_verdict = Vec::with_capacity(n);
    for r in &runs {
        let at = r.tested_at();
        for f in &r.figures {
            run_id.push(r.id);
            unit.push(r.unit.clone());
            tested_at.push(at.clone());
            latest.push(r.latest);
            run_verdict.push(r.verdict.as_str());
            station.push(r.station.clone());
            model_sha.push(r.model_content_sha256.clone());
            log.push(
                r.inputs
                    .iter()
                    .find(|i| i.position == f.position)
                    .map_or(String::new(), |i| i.path.clone()),
            );
            figure.push(f.figure.clone());
            value.push(f.value);
            limit_min.push(f.limit_min.unwrap_or(f64::NAN));
            limit_max.push(f.limit_max.unwrap_or(f64::NAN));
            verdict.push(f.pass.map(|p| if p { "pass" } else { "fail" }));
            margin.push(f.margin.unwrap_or(f64::NAN));
            // An inertial unit's axis (its gyro column) and the axis's verdict.
            let a = r.axis_of(f.axis);
            axis.push(a.map(|a| a.gyro.clone()));
            axis_verdict.push(a.map(|a| a.verdict.as_str()));
        }
    }
    let d = PyDict::new(py);
    d.set_item("run_id", run_id.into_pyarray(py))?;
    d.set_item("unit", unit)?;
    d.set_item("tested_at", tested_at)?;
    d.set_item("latest", latest.into_pyarray(py))?;
    d.set_item("run_verdict", run_verdict)?;
    d.set_item("station", station)?;
    d.set_item("model_content_sha256", model_sha)?;
    d.set_item("log", log)?;
    d.set_item("figure", figure)?;
    d.set_item("value", value.into_pyarray(py))?;
    d.set_item("limit_min", limit_min.into_pyarray(py))?;
    d.set_item("limit_max", limit_max.into_pyarray(py))?;
    d.set_item("verdict", verdict)?;
    d.set_item("margin", margin.into_pyarray(py))?;
    d.set_item("axis", axis)?;
    d.set_item("axis_verdict", axis_verdict)?;
    Ok(d)
}

//! Allan family: deviations at given averaging factors (the τ list itself is made on the
//! Python side, the way allantools makes it), Greenhall EDF and χ² quantiles.

use gyrotherm::allan::{self, AllanError as LibAllanError, DevKind, NoiseModel, TauSet};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::AllanError;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(dev_phase, m)?)?;
    m.add_function(wrap_pyfunction!(dev_freq, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_bounds, m)?)?;
    m.add_function(wrap_pyfunction!(edf_greenhall, m)?)?;
    m.add_function(wrap_pyfunction!(chi2_inv, m)?)?;
    Ok(())
}

pub(crate) fn allan_err(e: LibAllanError) -> PyErr {
    AllanError::new_err(gyrotherm::error_chain(&e))
}

fn kind_of(name: &str) -> PyResult<DevKind> {
    name.parse().map_err(allan_err)
}

/// A contiguous f64 view (the Python side passes `np.ascontiguousarray(..., float)`).
pub(crate) fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, what: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| AllanError::new_err(format!("{what}: need a contiguous float64 array")))
}

fn finite(x: &[f64]) -> PyResult<()> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(allan_err(LibAllanError::NonFinite { index })),
        None => Ok(()),
    }
}

type Curve<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// Deviation of phase data `x` at each averaging factor: (σ in units of x per sample
/// period, number of terms). Multiply σ by the sample rate for allantools' units.
#[pyfunction]
fn dev_phase<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    kind: &str,
    ms: Vec<usize>,
) -> PyResult<Curve<'py>> {
    let kind = kind_of(kind)?;
    let x = slice(&x, "data")?;
    finite(x)?;
    let (devs, ns): (Vec<f64>, Vec<f64>) = py.detach(|| {
        ms.iter()
            .map(|&m| match allan::deviation_from_phase(x, kind, m) {
                Some((d, n)) => (d, n as f64),
                None => (f64::NAN, 0.0),
            })
            .unzip()
    });
    Ok((devs.into_pyarray(py), ns.into_pyarray(py)))
}

fn seconds(ms: &[usize]) -> TauSet {
    TauSet::Seconds(ms.iter().map(|&m| m as f64).collect())
}

/// Deviation of rate / fractional-frequency data `y` at each averaging factor: (σ in units
/// of y, number of terms). The library's own path (mean removed, compensated integration,
/// one blocked pass for OADEV).
#[pyfunction]
fn dev_freq<'py>(
    py: Python<'py>,
    y: PyReadonlyArray1<'py, f64>,
    kind: &str,
    ms: Vec<usize>,
) -> PyResult<Curve<'py>> {
    let kind = kind_of(kind)?;
    let y = slice(&y, "data")?;
    // τ0 = 1 and τ = m: the deviation does not depend on τ0 for rate data.
    let points = py
        .detach(|| allan::deviation(y, 1.0, kind, &seconds(&ms), NoiseModel::Alpha(0)))
        .map_err(allan_err)?;
    let devs: Vec<f64> = points.iter().map(|p| p.dev).collect();
    let ns: Vec<f64> = points.iter().map(|p| p.n as f64).collect();
    Ok((devs.into_pyarray(py), ns.into_pyarray(py)))
}

/// Deviation of rate data with noise identification, Greenhall EDF and 68.3 % bounds at each
/// averaging factor (`alpha`: a fixed noise exponent instead of identification). A dict of
/// arrays: m, dev, n, alpha, edf, lo, hi.
#[pyfunction]
#[pyo3(signature = (y, kind, ms, alpha=None))]
fn deviation_bounds<'py>(
    py: Python<'py>,
    y: PyReadonlyArray1<'py, f64>,
    kind: &str,
    ms: Vec<usize>,
    alpha: Option<i32>,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = kind_of(kind)?;
    let y = slice(&y, "data")?;
    let noise = alpha.map_or(NoiseModel::Identify, NoiseModel::Alpha);
    let points = py
        .detach(|| allan::deviation(y, 1.0, kind, &seconds(&ms), noise))
        .map_err(allan_err)?;
    let d = PyDict::new(py);
    let col = |f: fn(&allan::AllanPoint) -> f64| -> Vec<f64> { points.iter().map(f).collect() };
    d.set_item("m", col(|p| p.m as f64).into_pyarray(py))?;
    d.set_item("dev", col(|p| p.dev).into_pyarray(py))?;
    d.set_item("n", col(|p| p.n as f64).into_pyarray(py))?;
    d.set_item("alpha", col(|p| p.alpha as f64).into_pyarray(py))?;
    d.set_item("edf", col(|p| p.edf).into_pyarray(py))?;
    d.set_item("lo", col(|p| p.lo).into_pyarray(py))?;
    d.set_item("hi", col(|p| p.hi).into_pyarray(py))?;
    Ok(d)
}

/// Greenhall & Riley (2003) EDF; NaN where the algorithm is undefined.
#[pyfunction]
fn edf_greenhall(alpha: i32, d: u32, m: usize, n: usize, overlapping: bool, modified: bool) -> f64 {
    allan::edf_greenhall(alpha, d, m, n, overlapping, modified).unwrap_or(f64::NAN)
}

/// Quantile p of the χ² distribution with `dof` degrees of freedom.
#[pyfunction]
fn chi2_inv(p: f64, dof: f64) -> f64 {
    allan::chi2_inv(p, dof)
}

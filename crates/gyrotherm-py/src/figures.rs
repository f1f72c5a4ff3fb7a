//! Gyro figures: bias stability, noise terms from the OADEV curve, scale-factor figures.

use gyrotherm::allan::{self, DevKind, NoiseModel, TauSet};
use gyrotherm::metrics::{self, ScaleFactorOptions};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::allan::{allan_err, slice};
use crate::MetricsError;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(bias_stability, m)?)?;
    m.add_function(wrap_pyfunction!(noise_terms, m)?)?;
    m.add_function(wrap_pyfunction!(scale_factor, m)?)?;
    Ok(())
}

fn metrics_err(e: impl std::error::Error + 'static) -> PyErr {
    MetricsError::new_err(gyrotherm::error_chain(&e))
}

fn sample_period(rate_hz: f64) -> PyResult<f64> {
    if rate_hz.is_finite() && rate_hz > 0.0 {
        Ok(1.0 / rate_hz)
    } else {
        Err(MetricsError::new_err(format!(
            "rate_hz = {rate_hz} is not a positive finite sample rate"
        )))
    }
}

/// (bias stability °/h, number of τ-means, samples per mean).
#[pyfunction]
fn bias_stability(
    py: Python<'_>,
    rate_dps: PyReadonlyArray1<'_, f64>,
    rate_hz: f64,
    tau_s: f64,
) -> PyResult<(f64, usize, usize)> {
    let x = slice(&rate_dps, "rate_dps")?;
    let period = sample_period(rate_hz)?;
    let b = py
        .detach(|| metrics::bias_stability_dph(x, period, tau_s))
        .map_err(metrics_err)?;
    Ok((b.bias_stability_dph, b.means, b.samples_per_mean))
}

/// Noise terms of a rate column (°/s) read off its octave OADEV curve, as JSON text: the
/// library's `NoiseTerms` serialised, the `noise` object of `gyrotherm allan --json`.
#[pyfunction]
fn noise_terms(
    py: Python<'_>,
    rate_dps: PyReadonlyArray1<'_, f64>,
    rate_hz: f64,
) -> PyResult<String> {
    let x = slice(&rate_dps, "rate_dps")?;
    let period = sample_period(rate_hz)?;
    let terms = py
        .detach(|| {
            allan::deviation(
                x,
                period,
                DevKind::Oadev,
                &TauSet::Octave,
                NoiseModel::Identify,
            )
            .map(|points| allan::noise_terms(&points, metrics::DPS_TO_DPH))
        })
        .map_err(allan_err)?;
    serde_json::to_string(&terms).map_err(metrics_err)
}

/// Scale-factor figures of a rate-table log, in the layout of `gyrotherm evaluate --json`.
#[pyfunction]
#[pyo3(signature = (time_s, gyro_dps, table_dps, settle_s, reference_scale=None))]
fn scale_factor<'py>(
    py: Python<'py>,
    time_s: PyReadonlyArray1<'py, f64>,
    gyro_dps: PyReadonlyArray1<'py, f64>,
    table_dps: PyReadonlyArray1<'py, f64>,
    settle_s: f64,
    reference_scale: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, g, w) = (
        slice(&time_s, "time_s")?,
        slice(&gyro_dps, "gyro_dps")?,
        slice(&table_dps, "table_dps")?,
    );
    let opts = ScaleFactorOptions {
        settle_s,
        reference_scale,
        ..Default::default()
    };
    let r = py
        .detach(|| metrics::scale_factor(t, g, w, &opts))
        .map_err(metrics_err)?;
    let fin = |v: f64| v.is_finite().then_some(v);
    let d = PyDict::new(py);
    d.set_item("scale_factor", fin(r.scale_factor))?;
    d.set_item("intercept_dps", fin(r.intercept_dps))?;
    d.set_item("nonlinearity_ppm", fin(r.nonlinearity_ppm))?;
    d.set_item("asymmetry_ppm", r.asymmetry_ppm.and_then(fin))?;
    d.set_item("scale_positive", r.scale_positive.and_then(fin))?;
    d.set_item("scale_negative", r.scale_negative.and_then(fin))?;
    d.set_item("sf_thermal_error_ppm", fin(r.sf_thermal_error_ppm))?;
    d.set_item("reference_scale", fin(r.reference_scale))?;
    d.set_item("settle_s", settle_s)?;
    let points = PyList::empty(py);
    for (w, f) in &r.rate_points {
        let p = PyDict::new(py);
        p.set_item("table_dps", fin(*w))?;
        p.set_item("mean_output_dps", fin(*f))?;
        points.append(p)?;
    }
    d.set_item("rate_points", points)?;
    let over = PyList::empty(py);
    for s in &r.scale_over_time {
        let p = PyDict::new(py);
        p.set_item("time_s", fin(s.time_s))?;
        p.set_item("table_dps", fin(s.table_dps))?;
        p.set_item("scale", fin(s.scale))?;
        p.set_item("deviation_ppm", fin(s.deviation_ppm))?;
        over.append(p)?;
    }
    d.set_item("scale_over_time", over)?;
    Ok(d)
}

//! Test logs: reading with the CLI's column mapping, unit and gap options.

use std::path::PathBuf;

use gyrotherm::csvlog::{self, ColumnValues, GyroUnit, ReadOptions};
use gyrotherm::settings::read;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{py_err, LogError};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_log, m)?)?;
    Ok(())
}

/// How to read a log; the Python side passes every key (its defaults are
/// [`read_defaults`], the library's).
#[derive(Debug, Clone, FromPyObject)]
#[pyo3(from_item_all)]
pub struct LogOptions {
    /// With several gyro columns, the one a table log's table column drives (None: found).
    pub table_axis: Option<String>,
    pub time_col: String,
    pub gyro_col: String,
    pub temp_col: String,
    pub table_col: String,
    pub gyro_unit: String,
    pub fill_gaps_max_s: Option<f64>,
    pub sample_period_s: Option<f64>,
    pub delimiter: String,
    pub format: Option<String>,
    pub instance: u8,
}

impl LogOptions {
    /// The library's read options, parsed and checked by the library.
    pub fn read_options(&self) -> PyResult<ReadOptions> {
        let gyro_unit: GyroUnit = self.gyro_unit.parse().map_err(LogError::new_err)?;
        let opts = ReadOptions {
            time_col: self.time_col.clone(),
            gyro_col: self.gyro_col.clone(),
            temp_col: self.temp_col.clone(),
            table_col: self.table_col.clone(),
            gyro_unit,
            fill_gaps_max_s: self.fill_gaps_max_s,
            sample_period_s: self.sample_period_s,
            delimiter: read::parse_delimiter(&self.delimiter).map_err(py_err::<LogError>)?,
            format: self
                .format
                .as_deref()
                .map(str::parse)
                .transpose()
                .map_err(py_err::<LogError>)?,
            instance: self.instance,
        };
        opts.validate().map_err(py_err::<LogError>)?;
        Ok(opts)
    }
}

/// The library's defaults for reading a log, keyed as Python's log options.
pub fn read_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = ReadOptions::default();
    let out = PyDict::new(py);
    // First, as the library lists the log options (`settings::describe::log_options`).
    out.set_item("table_axis", None::<String>)?;
    out.set_item("time_col", &d.time_col)?;
    out.set_item("gyro_col", &d.gyro_col)?;
    out.set_item("temp_col", &d.temp_col)?;
    out.set_item("table_col", &d.table_col)?;
    out.set_item("gyro_unit", d.gyro_unit.as_str())?;
    out.set_item("fill_gaps_max_s", d.fill_gaps_max_s)?;
    out.set_item("sample_period_s", d.sample_period_s)?;
    out.set_item("delimiter", read::delimiter_name(d.delimiter))?;
    out.set_item("format", d.format.map(|f| f.as_str()))?;
    out.set_item("instance", d.instance)?;
    Ok(out)
}

/// Read a log into a dict of numpy arrays (extra columns: float arrays when every value is a
/// number, else lists of str) and a report dict, through the library's one entry
/// ([`csvlog::read_log_columns`]): a single gyro's, or an inertial unit's when the options
/// name several columns or the file holds a unit (the library says which); a unit's report
/// also names its gyro and temperature columns and the table's axis.
#[pyfunction]
fn read_log<'py>(
    py: Python<'py>,
    path: PathBuf,
    options: LogOptions,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let opts = options.read_options()?;
    let log = py
        .detach(|| csvlog::read_log_columns(&path, &opts, options.table_axis.as_deref()))
        .map_err(|e| LogError::new_err(gyrotherm::error_chain(&e)))?;
    let cols = PyDict::new(py);
    let rep = PyDict::new(py);
    if log.unit {
        rep.set_item("gyro_cols", &log.gyro_cols)?;
        rep.set_item("temp_cols", &log.temp_cols)?;
        rep.set_item("table_axis", &log.table_axis)?;
    }
    for (name, values) in log.columns {
        match values {
            ColumnValues::Numbers(v) => cols.set_item(name, v.into_pyarray(py))?,
            ColumnValues::Text(t) => cols.set_item(name, t)?,
        }
    }
    let report = log.report;
    rep.set_item("rows", report.rows)?;
    rep.set_item("filled_samples", report.filled_samples)?;
    rep.set_item("filled_gaps", report.filled_gaps)?;
    rep.set_item("sample_period_s", log.sample_period_s)?;
    rep.set_item("sample_period_estimated", report.sample_period_estimated)?;
    rep.set_item("path", path.display().to_string())?;
    Ok((cols, rep))
}

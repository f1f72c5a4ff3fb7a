//! Fitting and model files: `fit` (the CLI's `train`), the model file (the CLI's JSON), and
//! compensation with the flight compensator (the CLI's `compensate`).

use std::path::PathBuf;

use gyrotherm::compensate::{compensator, extrapolation_warnings, CompensateError};
use gyrotherm::compensate_lines::compensate_file;
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::FitConfig;
use gyrotherm::model::{GivenColumns, ModelFile};
use gyrotherm::settings::{FitSettings, Method, SettingError, METHODS, METHOD_NAMES};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::allan::slice;
use crate::logs::LogOptions;
use crate::{py_err, CompensationError, FitError, ModelError};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RawModel>()?;
    Ok(())
}

/// A model file in memory, with what training said when it came from `fit`.
#[pyclass(module = "gyrotherm._gyrotherm", name = "RawModel", frozen)]
pub struct RawModel {
    file: ModelFile,
    /// One line per fitted target (LSTM epochs, loss and verdict), from `fit` only.
    training_notes: Vec<String>,
    /// What loading the file said (an unsealed file), from `load` only.
    load_warnings: Vec<String>,
}

impl RawModel {
    /// A model read from a file, with what to tell about it.
    pub(crate) fn loaded(file: ModelFile, load_warnings: Vec<String>) -> RawModel {
        RawModel {
            file,
            training_notes: Vec::new(),
            load_warnings,
        }
    }

    /// A model just trained, with what the fit did (`training_notes`).
    pub(crate) fn trained(file: ModelFile, training_notes: Vec<String>) -> RawModel {
        RawModel {
            file,
            training_notes,
            load_warnings: Vec::new(),
        }
    }
}

/// The time, gyro and temperature arrays of one log, checked to hold one value per sample.
fn samples<'a>(
    time_s: &'a PyReadonlyArray1<'_, f64>,
    gyro_dps: &'a PyReadonlyArray1<'_, f64>,
    temp_c: &'a PyReadonlyArray1<'_, f64>,
) -> PyResult<(&'a [f64], &'a [f64], &'a [f64])> {
    let (t, g, c) = (
        slice(time_s, "time_s")?,
        slice(gyro_dps, "gyro_dps")?,
        slice(temp_c, "temp_c")?,
    );
    if t.len() != g.len() || t.len() != c.len() {
        return Err(CompensationError::new_err(format!(
            "time_s, gyro_dps and temp_c differ in length ({}, {}, {}); give one value per sample in each",
            t.len(),
            g.len(),
            c.len()
        )));
    }
    Ok((t, g, c))
}

fn model_err(e: impl std::error::Error + 'static) -> PyErr {
    ModelError::new_err(gyrotherm::error_chain(&e))
}

type Compensated<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<u8>>,
    Vec<String>,
);

#[pymethods]
impl RawModel {
    /// Read and check a model file (`load_warnings` says when it has no content checksum).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<RawModel> {
        let (file, seal) = py
            .detach(|| ModelFile::load_sealed(&path))
            .map_err(model_err)?;
        Ok(RawModel {
            file,
            training_notes: Vec::new(),
            load_warnings: seal.warning(&path).into_iter().collect(),
        })
    }

    /// Parse and check model JSON text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<RawModel> {
        let file = ModelFile::from_json(text).map_err(py_err::<ModelError>)?;
        Ok(RawModel {
            file,
            training_notes: Vec::new(),
            load_warnings: Vec::new(),
        })
    }

    /// Write the model file atomically (the bytes `gyrotherm train` writes).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.file.save(&path)).map_err(model_err)
    }

    fn to_json(&self) -> PyResult<String> {
        let mut text = self.file.to_json().map_err(py_err::<ModelError>)?;
        text.push('\n');
        Ok(text)
    }

    #[getter]
    fn method(&self) -> &'static str {
        self.file.method.as_str()
    }

    #[getter]
    fn bias_kind(&self) -> Option<&'static str> {
        self.file.bias.as_ref().map(|s| s.kind())
    }

    #[getter]
    fn scale_kind(&self) -> Option<&'static str> {
        self.file.scale.as_ref().map(|s| s.kind())
    }

    #[getter]
    fn training_notes(&self) -> Vec<String> {
        self.training_notes.clone()
    }

    #[getter]
    fn load_warnings(&self) -> Vec<String> {
        self.load_warnings.clone()
    }

    /// Training facts of the file as a dict.
    #[getter]
    fn training<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = &self.file.training;
        let d = PyDict::new(py);
        d.set_item("temp_range_c", (t.temp_range_c.min, t.temp_range_c.max))?;
        d.set_item(
            "rate_range_c_per_s",
            (t.rate_range_c_per_s.min, t.rate_range_c_per_s.max),
        )?;
        d.set_item("data_digest_sha256", &t.data_digest_sha256)?;
        d.set_item("epochs", t.epochs)?;
        d.set_item("final_loss", t.final_loss)?;
        d.set_item("seed", t.seed)?;
        d.set_item("created_by", &t.created_by)?;
        d.set_item("inputs", PyList::new(py, &t.inputs)?)?;
        Ok(d)
    }

    /// Compensate arrays sample by sample with the flight compensator: (bias °/s, scale,
    /// compensated rate °/s, status, extrapolation warnings).
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        gyro_dps: PyReadonlyArray1<'py, f64>,
        temp_c: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Compensated<'py>> {
        let (t, g, c) = samples(&time_s, &gyro_dps, &temp_c)?;
        let log = TestLog {
            time_s: t.to_vec(),
            gyro_dps: g.to_vec(),
            temp_c: c.to_vec(),
            ..Default::default()
        };
        let (out, warnings) = py
            .detach(|| {
                compensate_with_status(&self.file, &log)
                    .map(|out| (out, extrapolation_warnings(&self.file, &log)))
            })
            .map_err(py_err::<CompensationError>)?;
        let (bias, scale, rate, status) = out;
        Ok((
            bias.into_pyarray(py),
            scale.into_pyarray(py),
            rate.into_pyarray(py),
            status.into_pyarray(py),
            warnings,
        ))
    }

    /// Per-sample coverage verdict (code: `Coverage as u8`, 255 where there is none) and σ
    /// (°/h, NaN where there is none), as the `coverage` and `sigma_dph` columns of
    /// `gyrotherm compensate`; and the note when the model file has no coverage map.
    fn coverage<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        gyro_dps: PyReadonlyArray1<'py, f64>,
        temp_c: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<CoverageColumns<'py>> {
        let (t, g, c) = samples(&time_s, &gyro_dps, &temp_c)?;
        let (codes, sigma) = py
            .detach(|| coverage_columns(&self.file, t, g, c))
            .map_err(py_err::<CompensationError>)?;
        Ok((
            codes.into_pyarray(py),
            sigma.into_pyarray(py),
            gyrotherm::coverage::missing_note(&self.file),
        ))
    }

    /// Compensate a CSV log into a CSV file exactly as `gyrotherm compensate --input --out`
    /// does (same code, same bytes; the column options not in `given` are the model's own);
    /// returns (rows, ok, held, degraded, invalid, warnings).
    fn compensate_csv(
        &self,
        py: Python<'_>,
        input: PathBuf,
        out: PathBuf,
        options: LogOptions,
        given: Vec<String>,
    ) -> PyResult<(u64, u64, u64, u64, u64, Vec<String>)> {
        let named = |k: &str| given.iter().any(|g| g == k);
        let given = GivenColumns {
            time_col: named("time_col"),
            gyro_col: named("gyro_col"),
            temp_col: named("temp_col"),
            table_col: named("table_col"),
            gyro_unit: named("gyro_unit"),
        };
        let opts = self
            .file
            .read_options(&options.read_options()?, given)
            .map_err(py_err::<ModelError>)?;
        let summary = py.detach(|| compensate_file(&self.file, &input, &out, &opts));
        let s = summary.map_err(|e| CompensationError::new_err(gyrotherm::error_chain(&e)))?;
        Ok((s.rows, s.ok, s.held, s.degraded, s.invalid, s.warnings))
    }

    /// Write the model for `target` (`c`, `rust`, `ardupilot`, `px4`) into the folder `out`:
    /// the lines `gyrotherm export` prints, and its warnings.
    #[pyo3(signature = (target, out, instance=None, axis=None, device_id=None))]
    fn export(
        &self,
        py: Python<'_>,
        target: &str,
        out: PathBuf,
        instance: Option<u8>,
        axis: Option<&str>,
        device_id: Option<u32>,
    ) -> PyResult<crate::export::Written> {
        crate::export::write(
            py,
            gyrotherm::unit_model::Model::from_single(self.file.clone()),
            target,
            out,
            instance,
            axis,
            device_id,
        )
    }

    /// A human-readable description of the model.
    fn summary(&self) -> PyResult<String> {
        let m = &self.file;
        let t = &m.training;
        let spec = m.feature_spec().map_err(py_err::<ModelError>)?;
        let mut s = format!(
            "gyrotherm model (format {}, method {})\n",
            m.format_version,
            m.method.as_str()
        );
        s += &format!(
            "  bias model: {}\n  scale-factor model: {}\n",
            m.bias.as_ref().map_or("none (no static log)", |b| b.kind()),
            m.scale
                .as_ref()
                .map_or("none (no rate-table log)", |b| b.kind())
        );
        s += &format!(
            "  inputs: {} features, stepped every {} s (rate lag {} s)\n",
            spec.n_features(),
            m.features.step_period_s,
            m.features.rate_lag_s
        );
        // From `fit`: what training said (`gyrotherm train`'s lines, the training range
        // first); from a file: what the file tells.
        if self.training_notes.is_empty() {
            s += &format!(
                "  training range: temperature {:.2} to {:.2} °C, rate {:.3} to {:.3} °C/min\n",
                t.temp_range_c.min,
                t.temp_range_c.max,
                t.rate_range_c_per_s.min * 60.0,
                t.rate_range_c_per_s.max * 60.0
            );
            for line in m.describe() {
                s += &format!("{line}\n");
            }
        }
        if let Some(seed) = t.seed {
            s += &format!("  seed: {seed}\n");
        }
        s += &format!(
            "  trained on: {}\n  written by: {}\n",
            t.inputs.join(", "),
            t.created_by
        );
        for n in &self.training_notes {
            s += &format!("  {n}\n");
        }
        Ok(s)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(method={:?}, bias={:?}, scale={:?})",
            self.file.method.as_str(),
            self.file.bias.as_ref().map(|s| s.kind()),
            self.file.scale.as_ref().map(|s| s.kind())
        )
    }
}

type Columns = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<u8>);

/// `compensate_log` with each sample's status code (`Status as u8`): the same flight
/// compensator stepped over the same samples.
fn compensate_with_status(model: &ModelFile, log: &TestLog) -> Result<Columns, CompensateError> {
    let mut comp = compensator(model)?;
    let n = log.len();
    let mut out: Columns = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for i in 0..n {
        let c = comp.step(log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        out.0.push(c.bias_dps);
        out.1.push(c.scale);
        out.2.push(c.rate_dps);
        out.3.push(c.status as u8);
    }
    Ok(out)
}

type CoverageColumns<'py> = (
    Bound<'py, PyArray1<u8>>,
    Bound<'py, PyArray1<f64>>,
    Option<String>,
);

/// Code of "no verdict" in [`coverage_columns`].
pub const NO_COVERAGE: u8 = 255;

/// The flight compensator stepped over the samples with the model's coverage map: the
/// verdict of each sample's latest step, as `compensate_lines` writes it.
fn coverage_columns(
    model: &ModelFile,
    t: &[f64],
    g: &[f64],
    c: &[f64],
) -> Result<(Vec<u8>, Vec<f64>), CompensateError> {
    let mut comp = compensator(model)?;
    // The file's map was checked when it was loaded.
    let map = model.coverage.as_ref().and_then(|m| m.to_core().ok());
    let mut codes = Vec::with_capacity(t.len());
    let mut sigma = Vec::with_capacity(t.len());
    for i in 0..t.len() {
        comp.step(t[i], g[i], c[i]);
        match map.as_ref().and_then(|m| m.verdict_of(comp.features())) {
            Some(v) => {
                codes.push(v.coverage as u8);
                sigma.push(v.sigma_dph);
            }
            None => {
                codes.push(NO_COVERAGE);
                sigma.push(f64::NAN);
            }
        }
    }
    Ok((codes, sigma))
}

/// Coverage code → name, as in the `coverage` column of `gyrotherm compensate`.
pub fn coverage_names() -> Vec<(u8, &'static str)> {
    use gyrotherm_core::coverage::Coverage;
    [Coverage::Inside, Coverage::Edge, Coverage::Outside]
        .into_iter()
        .map(|c| (c as u8, c.as_str()))
        .collect()
}

/// Status code → name, as in the `status` column of the CLI's streaming output.
pub fn status_names() -> Vec<(u8, &'static str)> {
    use gyrotherm_core::compensator::Status;
    Status::ALL
        .into_iter()
        .map(|s| (s as u8, s.as_str()))
        .collect()
}

/// Fitting settings as Python passes them (every key; the defaults are [`fit_defaults`],
/// the library's); parsed and checked by the library.
#[derive(Debug, Clone, FromPyObject)]
#[pyo3(from_item_all)]
pub struct FitArgs {
    method: String,
    epochs: Option<usize>,
    seed: u64,
    hidden: Option<usize>,
    bias_window_s: f64,
    settle_s: f64,
    poly_temp_degree: u8,
    poly_rate_degree: u8,
    cross: bool,
    validate_on_runs: bool,
}

impl FitArgs {
    /// The library's fit configuration.
    pub(crate) fn config(&self) -> PyResult<FitConfig> {
        self.settings()?.fit_config().map_err(py_err::<FitError>)
    }

    /// The library's fit settings these arguments name.
    pub(crate) fn settings(&self) -> PyResult<FitSettings> {
        Ok(FitSettings {
            method: parse_method(&self.method)?,
            epochs: self.epochs,
            seed: self.seed,
            hidden: self.hidden,
            bias_window_s: self.bias_window_s,
            settle_s: self.settle_s,
            poly_temp_degree: self.poly_temp_degree,
            poly_rate_degree: self.poly_rate_degree,
            cross: self.cross,
            validate_on_runs: self.validate_on_runs,
        })
    }
}

/// A method a fit can use, by name ([`METHOD_NAMES`]). The library also parses `lstm`, the
/// method older model files record; as a setting that spelling is gone.
pub(crate) fn parse_method(name: &str) -> PyResult<Method> {
    let method: Method = name.parse().map_err(py_err::<FitError>)?;
    if !METHODS.contains(&method) {
        return Err(py_err::<FitError>(SettingError::Unknown {
            setting: "method",
            value: name.to_owned(),
            expected: &METHOD_NAMES,
        }));
    }
    Ok(method)
}

/// The library's fit defaults, keyed as `fit()`'s keywords.
pub fn fit_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = FitSettings::default();
    let out = PyDict::new(py);
    out.set_item("method", d.method.as_str())?;
    out.set_item("epochs", d.epochs)?;
    out.set_item("seed", d.seed)?;
    out.set_item("hidden", d.hidden)?;
    out.set_item("bias_window_s", d.bias_window_s)?;
    out.set_item("settle_s", d.settle_s)?;
    out.set_item("poly_temp_degree", d.poly_temp_degree)?;
    out.set_item("poly_rate_degree", d.poly_rate_degree)?;
    out.set_item("cross", d.cross)?;
    out.set_item("validate_on_runs", d.validate_on_runs)?;
    Ok(out)
}

//! Fitting and model files: `fit` (the CLI's `train`), the model file (the CLI's JSON), and
//! compensation with the flight compensator (the CLI's `compensate`).

use std::path::PathBuf;

use gyrotherm::csvlog::{ImuLog, NamedSeries, ReadOptions};
use gyrotherm::fit::FitConfig;
use gyrotherm::model::{GivenColumns, ModelFile};
use gyrotherm::settings::{FitSettings, Method, SettingError, METHODS, METHOD_NAMES};
use gyrotherm::unit_model::Model;
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

/// A model file of either form in memory (`gyrotherm::unit_model::Model`: a single gyro is a
/// unit of one axis), with what training said when it came from `fit`.
#[pyclass(module = "gyrotherm._gyrotherm", name = "RawModel", frozen)]
pub struct RawModel {
    model: Model,
    /// The lines the fit told (training range, LSTM epochs, loss, choice), from `fit` only.
    training_notes: Vec<String>,
    /// What loading the file said (an unsealed file), from `load` only.
    load_warnings: Vec<String>,
}

impl RawModel {
    /// A model just trained, with what the fit told (`training_notes`).
    pub(crate) fn trained(model: Model, training_notes: Vec<String>) -> RawModel {
        RawModel {
            model,
            training_notes,
            load_warnings: Vec::new(),
        }
    }

    /// The model.
    pub(crate) fn model(&self) -> &Model {
        &self.model
    }

    /// The value `f` gives for every axis's model file, when every axis gives the same; else
    /// None.
    fn shared<T: PartialEq>(&self, f: impl Fn(&ModelFile) -> Option<T>) -> Option<T> {
        let base = ReadOptions::default();
        let axes = self.model.axes(&base);
        let mut values = axes.iter().map(|a| f(a.model));
        let first = values.next()??;
        values.all(|v| v.as_ref() == Some(&first)).then_some(first)
    }

    /// `time_s` and the arrays of `gyro` and `temp` (in the model's column orders) as a log
    /// holding the model's columns, each checked to hold one value per sample.
    fn log<'py>(
        &self,
        time_s: &PyReadonlyArray1<'py, f64>,
        gyro: &[PyReadonlyArray1<'py, f64>],
        temp: &[PyReadonlyArray1<'py, f64>],
    ) -> PyResult<ImuLog> {
        let (gyro_cols, temp_cols) = self.model.columns();
        let t = slice(time_s, "time_s")?;
        let count = |what: &str, got: usize, want: &[String]| {
            if got == want.len() {
                Ok(())
            } else {
                Err(CompensationError::new_err(format!(
                    "{what}: {got} arrays given, the model needs {} ({})",
                    want.len(),
                    want.join(", ")
                )))
            }
        };
        count("gyro", gyro.len(), &gyro_cols)?;
        count("temp", temp.len(), &temp_cols)?;
        let series = |arrays: &[PyReadonlyArray1<'py, f64>], names: &[String]| {
            arrays
                .iter()
                .zip(names)
                .map(|(a, n)| {
                    let v = slice(a, n)?;
                    if v.len() != t.len() {
                        return Err(CompensationError::new_err(format!(
                            "{n}: {} values but {} times; give one value per sample",
                            v.len(),
                            t.len()
                        )));
                    }
                    Ok(NamedSeries {
                        name: n.clone(),
                        values: v.to_vec(),
                    })
                })
                .collect::<PyResult<Vec<_>>>()
        };
        Ok(ImuLog {
            time_s: t.to_vec(),
            gyro: series(gyro, &gyro_cols)?,
            temp: series(temp, &temp_cols)?,
            ..Default::default()
        })
    }
}

fn model_err(e: impl std::error::Error + 'static) -> PyErr {
    ModelError::new_err(gyrotherm::error_chain(&e))
}

type AxisColumns<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<u8>>,
);

type AxisCoverage<'py> = (Bound<'py, PyArray1<u8>>, Bound<'py, PyArray1<f64>>);

/// The training facts of a model file as a dict.
fn training_dict<'py>(py: Python<'py>, m: &ModelFile) -> PyResult<Bound<'py, PyDict>> {
    let t = &m.training;
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

#[pymethods]
impl RawModel {
    /// Read and check a model file of either form (`load_warnings` says when it has no
    /// content checksum).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<RawModel> {
        let model = py.detach(|| Model::load(&path)).map_err(model_err)?;
        let load_warnings = model.load_warning(&path).into_iter().collect();
        Ok(RawModel {
            model,
            training_notes: Vec::new(),
            load_warnings,
        })
    }

    /// Parse and check model JSON text of either form.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<RawModel> {
        let model = Model::from_json(text).map_err(py_err::<ModelError>)?;
        Ok(RawModel {
            model,
            training_notes: Vec::new(),
            load_warnings: Vec::new(),
        })
    }

    /// Write the model file atomically (the bytes `gyrotherm train` writes).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.model.save(&path)).map_err(model_err)
    }

    fn to_json(&self) -> PyResult<String> {
        self.model.to_json().map_err(py_err::<ModelError>)
    }

    /// The method every axis was fitted with (None where the axes differ).
    #[getter]
    fn method(&self) -> Option<&'static str> {
        self.shared(|m| Some(m.method.as_str()))
    }

    /// What every axis's bias model is made of (None: none, or the axes differ).
    #[getter]
    fn bias_kind(&self) -> Option<&'static str> {
        self.shared(|m| m.bias.as_ref().map(|s| s.kind()))
    }

    /// What every axis's scale-factor model is made of (None: none, or the axes differ).
    #[getter]
    fn scale_kind(&self) -> Option<&'static str> {
        self.shared(|m| m.scale.as_ref().map(|s| s.kind()))
    }

    #[getter]
    fn training_notes(&self) -> Vec<String> {
        self.training_notes.clone()
    }

    #[getter]
    fn load_warnings(&self) -> Vec<String> {
        self.load_warnings.clone()
    }

    /// The training facts of a model of one axis as a dict (None for a unit of several:
    /// each axis has its own, under `axes`).
    #[getter]
    fn training<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let base = ReadOptions::default();
        match self.model.axes(&base).as_slice() {
            [one] => training_dict(py, one.model).map(Some),
            _ => Ok(None),
        }
    }

    #[getter]
    fn gyro_cols(&self) -> Vec<String> {
        self.model.columns().0
    }

    #[getter]
    fn temp_cols(&self) -> Vec<String> {
        self.model.columns().1
    }

    /// Per axis: gyro, the sensors it reads, the score of each sensor tried, the method, the
    /// kinds of its bias and scale-factor models and its training facts.
    #[getter]
    fn axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for a in &self.model.to_unit(&ReadOptions::default()).axes {
            let d = PyDict::new(py);
            d.set_item("gyro", &a.gyro)?;
            d.set_item("temps", &a.temps)?;
            let scores = PyDict::new(py);
            for s in &a.scores {
                scores.set_item(&s.temp, s.cv_rms)?;
            }
            d.set_item("cv_rms", scores)?;
            d.set_item("method", a.model.method.as_str())?;
            d.set_item("bias_kind", a.model.bias.as_ref().map(|s| s.kind()))?;
            d.set_item("scale_kind", a.model.scale.as_ref().map(|s| s.kind()))?;
            d.set_item("training", training_dict(py, &a.model)?)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// Compensate samples with each axis's flight compensator: `gyro` one array per gyro
    /// column and `temp` one per temperature column, in the model's orders. Per axis (bias
    /// °/s, scale, compensated rate °/s, status), the numbers `gyrotherm compensate` writes,
    /// and the extrapolation warnings it tells.
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        gyro: Vec<PyReadonlyArray1<'py, f64>>,
        temp: Vec<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<(Vec<AxisColumns<'py>>, Vec<String>)> {
        let log = self.log(&time_s, &gyro, &temp)?;
        let (out, warnings) = py
            .detach(|| self.model.compensate_log(&log))
            .map_err(py_err::<CompensationError>)?;
        let axes = out
            .into_iter()
            .map(|c| {
                (
                    c.bias_dps.into_pyarray(py),
                    c.scale.into_pyarray(py),
                    c.gyro_comp_dps.into_pyarray(py),
                    c.status
                        .into_iter()
                        .map(|s| s as u8)
                        .collect::<Vec<_>>()
                        .into_pyarray(py),
                )
            })
            .collect();
        Ok((axes, warnings))
    }

    /// Per axis, each sample's coverage verdict (code: `Coverage as u8`, 255 where there is
    /// none) and σ (°/h, NaN where there is none), as the `coverage` and `sigma_dph` columns
    /// of `gyrotherm compensate`; and a note per axis without a verdict.
    fn coverage<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        gyro: Vec<PyReadonlyArray1<'py, f64>>,
        temp: Vec<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<(Vec<AxisCoverage<'py>>, Vec<String>)> {
        let log = self.log(&time_s, &gyro, &temp)?;
        let (out, notes) = py
            .detach(|| self.model.coverage_log(&log))
            .map_err(py_err::<CompensationError>)?;
        let axes = out
            .into_iter()
            .map(|c| (c.codes.into_pyarray(py), c.sigma_dph.into_pyarray(py)))
            .collect();
        Ok((axes, notes))
    }

    /// Compensate a log into a CSV file exactly as `gyrotherm compensate --input --out` does
    /// (same code, same bytes; the column options not in `given` are the model's own).
    /// Returns the lines written, per axis the lines per status (ok, held, degraded, invalid,
    /// fallback) and the warnings.
    fn compensate_csv(
        &self,
        py: Python<'_>,
        input: PathBuf,
        out: PathBuf,
        options: LogOptions,
        given: Vec<String>,
    ) -> PyResult<(u64, Vec<[u64; 5]>, Vec<String>)> {
        let named = |k: &str| given.iter().any(|g| g == k);
        let given = GivenColumns {
            time_col: named("time_col"),
            gyro_col: named("gyro_col"),
            temp_col: named("temp_col"),
            table_col: named("table_col"),
            gyro_unit: named("gyro_unit"),
        };
        let opts = self
            .model
            .read_options(&options.read_options()?, given)
            .map_err(py_err::<ModelError>)?;
        let done = py.detach(|| self.model.compensate_file(&input, &out, &opts));
        let c = done.map_err(|e| CompensationError::new_err(gyrotherm::error_chain(&e)))?;
        Ok((c.rows(), c.per_axis(), c.warnings().to_vec()))
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
        crate::export::write(py, &self.model, target, out, instance, axis, device_id)
    }

    /// A human-readable description of the model.
    fn summary(&self) -> PyResult<String> {
        self.model
            .summary(&self.training_notes)
            .map_err(py_err::<ModelError>)
    }

    fn __repr__(&self) -> String {
        let (gyro_cols, temp_cols) = self.model.columns();
        format!(
            "Model(gyro_cols={gyro_cols:?}, temp_cols={temp_cols:?}, method={:?})",
            self.method()
        )
    }
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
    windows: Option<usize>,
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
            windows: self.windows,
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
    out.set_item("windows", d.windows)?;
    out.set_item("bias_window_s", d.bias_window_s)?;
    out.set_item("settle_s", d.settle_s)?;
    out.set_item("poly_temp_degree", d.poly_temp_degree)?;
    out.set_item("poly_rate_degree", d.poly_rate_degree)?;
    out.set_item("cross", d.cross)?;
    out.set_item("validate_on_runs", d.validate_on_runs)?;
    Ok(out)
}

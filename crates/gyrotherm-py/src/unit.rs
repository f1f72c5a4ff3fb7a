//! Inertial units: the unit model file (`RawUnitModel`: load, save, compensate per axis).

use std::path::PathBuf;

use gyrotherm::csvlog::{ImuLog, NamedSeries};
use gyrotherm::imu_model::{self, ImuModel};
use gyrotherm::unit_model::{Form, Model};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::allan::slice;
use crate::model::RawModel;
use crate::{py_err, CompensationError, ModelError};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RawUnitModel>()?;
    m.add_function(wrap_pyfunction!(load_model, m)?)?;
    Ok(())
}

/// Read and check a model file of either form (`gyrotherm::unit_model::Model::load`): a
/// `RawModel` for a single-gyro file, a `RawUnitModel` for an inertial unit's, each with
/// `load_warnings` saying when the file has no content checksum.
#[pyfunction]
fn load_model(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyAny>> {
    let model = py.detach(|| Model::load(&path)).map_err(model_err)?;
    let load_warnings: Vec<String> = model.load_warning(&path).into_iter().collect();
    // Python keeps a class per form.
    Ok(match model.into_form() {
        Form::Single(file) => Py::new(py, RawModel::loaded(*file, load_warnings))?.into_any(),
        Form::Unit(file) => Py::new(py, RawUnitModel::loaded(file, load_warnings))?.into_any(),
    })
}

/// A unit model file in memory.
#[pyclass(module = "gyrotherm._gyrotherm", name = "RawUnitModel", frozen)]
pub struct RawUnitModel {
    file: ImuModel,
    /// What to tell the user about the file as loaded (no content checksum).
    load_warnings: Vec<String>,
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

impl RawUnitModel {
    /// A unit model read from a file, with what to tell about it.
    pub(crate) fn loaded(file: ImuModel, load_warnings: Vec<String>) -> RawUnitModel {
        RawUnitModel {
            file,
            load_warnings,
        }
    }

    /// The unit's model file.
    pub(crate) fn file(&self) -> &ImuModel {
        &self.file
    }
}

#[pymethods]
impl RawUnitModel {
    /// Read and check a unit model file (`load_warnings` says when it has no content
    /// checksum).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<RawUnitModel> {
        let (file, seal) = py
            .detach(|| ImuModel::load_sealed(&path))
            .map_err(model_err)?;
        Ok(RawUnitModel {
            file,
            load_warnings: seal.warning(&path).into_iter().collect(),
        })
    }

    #[staticmethod]
    fn from_json(text: &str) -> PyResult<RawUnitModel> {
        let file = ImuModel::from_json(text).map_err(py_err::<ModelError>)?;
        Ok(RawUnitModel {
            file,
            load_warnings: Vec::new(),
        })
    }

    #[getter]
    fn load_warnings(&self) -> Vec<String> {
        self.load_warnings.clone()
    }

    /// Write the file atomically (the bytes `gyrotherm train` writes).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.file.save(&path)).map_err(model_err)
    }

    fn to_json(&self) -> PyResult<String> {
        self.file.to_json().map_err(py_err::<ModelError>)
    }

    #[getter]
    fn gyro_cols(&self) -> Vec<String> {
        self.file.gyro_cols.clone()
    }

    #[getter]
    fn temp_cols(&self) -> Vec<String> {
        self.file.temp_cols.clone()
    }

    /// Per axis: gyro, the sensors it reads, the score of each sensor tried, the method and
    /// the kinds of its bias and scale-factor models.
    #[getter]
    fn axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for a in &self.file.axes {
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
            out.append(d)?;
        }
        Ok(out)
    }

    /// Compensate a unit's samples: `gyro` one array per gyro column and `temp` one per
    /// temperature column, in the model's orders; per axis (bias °/s, scale, compensated
    /// rate °/s, status), the numbers `gyrotherm compensate` writes as G_bias … G_status.
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        gyro: Vec<PyReadonlyArray1<'py, f64>>,
        temp: Vec<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Vec<AxisColumns<'py>>> {
        let m = &self.file;
        let t = slice(&time_s, "time_s")?;
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
        count("gyro", gyro.len(), &m.gyro_cols)?;
        count("temp", temp.len(), &m.temp_cols)?;
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
        let log = ImuLog {
            time_s: t.to_vec(),
            gyro: series(&gyro, &m.gyro_cols)?,
            temp: series(&temp, &m.temp_cols)?,
            ..Default::default()
        };
        let out = py
            .detach(|| imu_model::compensate_imu(m, &log))
            .map_err(py_err::<CompensationError>)?;
        Ok(out
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
            .collect())
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
            gyrotherm::unit_model::Model::from_unit(self.file.clone()),
            target,
            out,
            instance,
            axis,
            device_id,
        )
    }

    /// A human-readable description.
    fn summary(&self) -> String {
        let m = &self.file;
        let mut s = format!(
            "gyrotherm unit model ({} axes; gyro columns {}; temperature columns {})\n",
            m.axes.len(),
            m.gyro_cols.join(", "),
            m.temp_cols.join(", ")
        );
        for a in &m.axes {
            s += &format!(
                "  {}: reads {} (method {}, bias: {}, scale factor: {})\n",
                a.gyro,
                a.temps.join(", "),
                a.model.method.as_str(),
                a.model.bias.as_ref().map_or("none", |b| b.kind()),
                a.model.scale.as_ref().map_or("none", |b| b.kind())
            );
        }
        s
    }

    fn __repr__(&self) -> String {
        format!(
            "UnitModel(gyro_cols={:?}, temp_cols={:?})",
            self.file.gyro_cols, self.file.temp_cols
        )
    }
}

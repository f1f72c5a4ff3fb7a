//! Writing a model as flight code or as an autopilot's parameter file: the CLI's `export`
//! (`gyrotherm::unit_model::Model::write_export`), for either model class.

use std::path::PathBuf;

use gyrotherm::export::ExportTarget;
use gyrotherm::settings::autopilot::{AutopilotSettings, GyroAxis};
use gyrotherm::unit_model::{Model, Told};
use pyo3::prelude::*;

use crate::{py_err, ModelError};

/// What an export wrote and said: the lines the CLI prints (warnings apart, for Python's
/// warning machinery).
pub(crate) type Written = (Vec<String>, Vec<String>);

/// Write `model` for `target` into `out`; the autopilot options only for `ardupilot` and
/// `px4` (the library's defaults where None).
pub(crate) fn write(
    py: Python<'_>,
    model: &Model,
    target: &str,
    out: PathBuf,
    instance: Option<u8>,
    axis: Option<&str>,
    device_id: Option<u32>,
) -> PyResult<Written> {
    let target: ExportTarget = target.parse().map_err(py_err::<ModelError>)?;
    if target.lang().is_some() {
        for (given, option) in [
            (instance.is_some(), "instance"),
            (axis.is_some(), "axis"),
            (device_id.is_some(), "device_id"),
        ] {
            if given {
                return Err(ModelError::new_err(format!(
                    "{option} is for target ardupilot or px4, not {target}"
                )));
            }
        }
    }
    let d = AutopilotSettings::default();
    let settings = AutopilotSettings {
        instance: instance.unwrap_or(d.instance),
        axis: axis
            .map(str::parse::<GyroAxis>)
            .transpose()
            .map_err(py_err::<ModelError>)?
            .unwrap_or(d.axis),
        device_id: device_id.or(d.device_id),
    };
    let (told, written) = py.detach(|| model.write_export(target, &settings, axis.is_some(), &out));
    written.map_err(py_err::<ModelError>)?;
    let (mut lines, mut warnings) = (Vec::new(), Vec::new());
    for t in told {
        match t {
            Told::Warning(w) => warnings.push(w),
            Told::Line(l) | Told::Note(l) => lines.push(l),
            Told::Item(i) => lines.push(format!("  {i}")),
        }
    }
    Ok((lines, warnings))
}

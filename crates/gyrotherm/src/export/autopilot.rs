//! The autopilot targets, `--target ardupilot` ([`super::ardupilot`]) and `--target px4`
//! ([`super::px4`]): a model's parameter file for either, with its fit ([`generate`]), and
//! writing it ([`write()`]). What the two share, the steady-state bias and the cubic fitted to
//! it, is [`super::steady_bias`] (its names are re-exported here).

use std::path::{Path, PathBuf};

pub use super::steady_bias::{
    cubic, fit_cubic, steady_bias, AutopilotError, AutopilotExport, FitError, ModelRef, SteadyBias,
    GRID_POINTS, MIN_RANGE_C, RAD_PER_DEG,
};
use super::{ExportError, ExportTarget};
use crate::settings::autopilot::AutopilotSettings;

/// The parameter file of `model` for an autopilot `target` (ArduPilot or PX4), with its fit
/// (see the module doc). Nothing is written.
pub fn generate(
    model: ModelRef<'_>,
    target: ExportTarget,
    settings: &AutopilotSettings,
) -> Result<AutopilotExport, ExportError> {
    // The settings are checked before the (longer) steady-state computation.
    let check = |instances| {
        settings
            .validate(instances)
            .map_err(AutopilotError::Setting)
    };
    match target {
        ExportTarget::Ardupilot => check(crate::settings::autopilot::ARDUPILOT_INSTANCES)?,
        ExportTarget::Px4 => {
            check(crate::settings::autopilot::PX4_INSTANCES)?;
            settings.device_id.ok_or(AutopilotError::NoDeviceId)?;
        }
        ExportTarget::C | ExportTarget::Rust => {
            return Err(AutopilotError::NotAutopilot(target).into())
        }
    }
    let steady = steady_bias(model, settings)?;
    match target {
        ExportTarget::Px4 => super::px4::generate(steady, settings),
        _ => super::ardupilot::generate(steady, settings),
    }
}

/// Write `export` into `dir` (created if missing), atomically; returns the path.
pub fn write(export: &AutopilotExport, dir: &Path) -> Result<PathBuf, ExportError> {
    let files = vec![(export.file_name, export.text.clone())];
    let mut paths = super::write_files(files, dir)?;
    paths.pop().ok_or_else(|| ExportError::Io {
        path: dir.to_path_buf(),
        source: std::io::Error::other("nothing written"),
    })
}

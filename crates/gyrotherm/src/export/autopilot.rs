//! The autopilot targets, `--target ardupilot` ([`super::ardupilot`]) and `--target px4`
//! ([`super::px4`]): a model's parameter file for either, with its fit ([`generate`]), and
//! writing it ([`write()`]). What the two share, the steady-state bias and the cubic fitted to
//! it, is [`super::steady_bias`] (its names are re-exported here).

use std::path::{Path, PathBuf};

pub use super::steady_bias::{
    cubic, steady_bias, AutopilotError, AutopilotExport, FitError, ModelRef, SteadyBias,
    GRID_POINTS, MIN_RANGE_C,
};

use super::{ExportError, ExportTarget};
use crate::compare::{
    performance, Column, CompareConfig, CompareError, Comparison, FailedColumn, MethodResult,
};
use crate::compensate::Compensated;
use crate::fit::{fit_model, NamedLog};
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

/// Add the comparison's autopilot columns ([`CompareConfig::autopilot`]) to a finished
/// comparison of single-gyro logs: each autopilot's polynomial, fitted to the steady-state
/// bias of the model of the comparison's own method (the column of that method, or a fit of
/// it on `train` when it has none), subtracted from each held-out log's gyro output at its
/// temperature as the firmware does ([`Correction`](super::steady_bias::Correction)), and
/// judged with the same figures. The scale factor is left as it is (the autopilots correct
/// the offset only). A polynomial that cannot be fitted is a failed column, with why.
pub fn add_columns(
    cmp: &mut Comparison,
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
) -> Result<(), CompareError> {
    if cfg.autopilot.is_empty() {
        return Ok(());
    }
    let method = cfg.fit.model_method();
    let source = match cmp.fits.iter().find(|f| f.model.method == method) {
        Some(f) => f.clone(),
        None => fit_model(train, &cfg.fit, &|_, _, _| {}).map_err(|e| CompareError::Fit {
            key: method.as_str(),
            source: e.into(),
        })?,
    };
    // The id names the gyro in PX4's file; the comparison writes no file.
    let settings = AutopilotSettings {
        device_id: Some(0),
        ..AutopilotSettings::default()
    };
    let axis = settings.axis.index();
    for &target in &cfg.autopilot {
        let key = target.as_str();
        let label = target.column_label();
        if cmp.columns.iter().any(|c| c.key == key) {
            return Err(CompareError::DuplicateColumn { key });
        }
        let export = match generate(ModelRef::Single(&source.model), target, &settings) {
            Ok(e) => e,
            Err(e) => {
                cmp.failed.push(FailedColumn {
                    key,
                    label,
                    reason: crate::error_chain::error_chain(&e),
                });
                continue;
            }
        };
        for (t, result) in test.iter().zip(&mut cmp.tests) {
            let bias_dps: Vec<f64> = t
                .log
                .temp_c
                .iter()
                .map(|&c| export.correction.offset_dps(axis, c))
                .collect();
            let gyro_comp_dps: Vec<f64> = t
                .log
                .gyro_dps
                .iter()
                .zip(&bias_dps)
                .map(|(g, b)| g - b)
                .collect();
            match performance(t.log, &gyro_comp_dps, cfg.tau_s, cfg.settle_s) {
                Ok(performance) => result.methods.push(MethodResult {
                    method,
                    key,
                    label,
                    performance,
                    compensated: Compensated {
                        scale: vec![1.0; bias_dps.len()],
                        bias_dps,
                        gyro_comp_dps,
                    },
                }),
                Err(e) => result.failed.push(FailedColumn {
                    key,
                    label,
                    reason: format!(
                        "its output cannot be judged: {}",
                        crate::error_chain::error_chain(&e)
                    ),
                }),
            }
        }
        cmp.columns.push(Column { key, label });
        cmp.fits.push(source.clone());
    }
    Ok(())
}

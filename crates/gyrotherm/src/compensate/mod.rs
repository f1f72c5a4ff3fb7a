//! Apply a fitted model to a log: the ground side of the flight [`Compensator`](gyrotherm_core::compensator::Compensator).
//!
//! Batch compensation runs the same `gyrotherm-core` compensator sample by sample that
//! `compensate --stream` and flight code run, so the numbers are identical by construction.

use crate::flight_size::build_sized;
use crate::flight_size::FlightCompensator;

use crate::csvlog::TestLog;
use crate::model::boxed_compensator;
use crate::model::ModelFile;
pub use crate::model::{hidden_size, CompensateError};

pub mod unit;

/// Compensated series of one log, one value per sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Compensated {
    /// Predicted bias B, °/s.
    pub bias_dps: Vec<f64>,
    /// Predicted scale factor K, dimensionless.
    pub scale: Vec<f64>,
    /// G = (Ĝ - B) / K, °/s.
    pub gyro_comp_dps: Vec<f64>,
}

/// The flight compensator of a model file (bias 0 °/s and K = 1 where a target is absent), at
/// the size of its LSTMs ([`hidden_size`]). An inertial unit's: [`unit`](mod@unit).
pub fn compensator(model: &ModelFile) -> Result<FlightCompensator, CompensateError> {
    let size = hidden_size([model.bias.as_ref(), model.scale.as_ref()])?;
    Ok(build_sized!(FlightCompensator, size, H => boxed_compensator::<H>(model)?))
}

/// Compensate a whole log with the flight compensator. The error names the sample.
pub fn compensate_log(model: &ModelFile, log: &TestLog) -> Result<Compensated, CompensateError> {
    let mut comp = compensator(model)?;
    let n = log.len();
    let mut out = Compensated {
        bias_dps: Vec::with_capacity(n),
        scale: Vec::with_capacity(n),
        gyro_comp_dps: Vec::with_capacity(n),
    };
    for i in 0..n {
        let c = comp.step(log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        out.bias_dps.push(c.bias_dps);
        out.scale.push(c.scale);
        out.gyro_comp_dps.push(c.rate_dps);
    }
    Ok(out)
}

/// Warnings, with the numbers, when `log` leaves the model's training temperature or
/// temperature-rate range (the model then extrapolates).
pub(crate) fn extrapolation_warnings(model: &ModelFile, log: &TestLog) -> Vec<String> {
    let Ok(spec) = model.feature_spec() else {
        return Vec::new();
    };
    let Ok(table) = crate::features::extract(log, &spec) else {
        return Vec::new();
    };
    match (table.range(0), table.range(1)) {
        (Some(t), Some(r)) => range_warnings(model, t, r),
        _ => Vec::new(),
    }
}

/// Warnings for a seen temperature range (°C) and temperature-rate range (°C/s) outside the
/// model's training ranges. A margin of 2 % of the training span absorbs sensor noise.
pub(crate) fn range_warnings(
    model: &ModelFile,
    temp_c: (f64, f64),
    rate_c_per_s: (f64, f64),
) -> Vec<String> {
    let t = &model.training;
    // Name the rate by its window: the model's dT is not the rate a report or `plan` shows
    // (those smooth over 100 s), and the two differ on a fast shock.
    let rate = match model.feature_spec() {
        Ok(spec) => format!(
            "temperature rate (the model's dT over {} s)",
            crate::csvlog::short_f64(spec.rate_lag_s)
        ),
        Err(_) => "temperature rate".to_owned(),
    };
    let checks = [
        ("temperature".to_owned(), "°C", temp_c, t.temp_range_c, 1.0),
        (rate, "°C/min", rate_c_per_s, t.rate_range_c_per_s, 60.0),
    ];
    let mut out = Vec::new();
    for (what, unit, (lo, hi), range, scale) in checks {
        let margin = 0.02 * (range.max - range.min);
        if lo < range.min - margin || hi > range.max + margin {
            out.push(format!(
                "{what} {:.3} to {:.3} {unit} leaves the training range {:.3} to {:.3} {unit}; the model extrapolates there",
                lo * scale,
                hi * scale,
                range.min * scale,
                range.max * scale
            ));
        }
    }
    out
}

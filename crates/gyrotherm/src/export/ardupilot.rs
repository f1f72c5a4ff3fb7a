//! `--target ardupilot`: ArduPilot's gyro temperature calibration, as a parameter file of
//! `NAME value` lines (`gyro_tcal.parm`, loaded by Mission Planner, MAVProxy and QGroundControl;
//! `#` lines are comments).
//!
//! **The firmware's use** (`libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp`,
//! `TCal::correct_sensor` and `TCal::polynomial_eval`): with `INS_TCAL{n}_ENABLE` = 1, each
//! gyro sample of IMU n (from 1) is corrected by
//!
//! ```text
//! gyro -= p(T) - p(T_cal),   p(T) = (GYR1 + (GYR2 + GYR3·x)·x)·x · 1e-6  rad/s,
//! x = clamp(T, TMIN, TMAX) - 35 °C
//! ```
//!
//! per axis (`GYR{k}_X`, `_Y`, `_Z`), where T_cal (also clamped) is the temperature of the
//! last gyro calibration. p has no constant term: the constant is the gyro offset the firmware
//! measures at that calibration (at boot), so the written polynomial is the fit's cubic
//! without its constant, and its fit error is reported after the best constant.
//!
//! Only the gyro coefficients are written; the accelerometer's (`INS_TCAL{n}_ACC*`) are left
//! as they are on the vehicle.

use super::steady_bias::{
    fit_cubic, AutopilotExport, Correction, FitError, SteadyBias, RAD_PER_DEG,
};
use super::ExportError;
use crate::settings::autopilot::{AutopilotSettings, ARDUPILOT_INSTANCES};

use super::steady_bias::AutopilotError;

/// The file written.
pub(crate) const FILE_NAME: &str = "gyro_tcal.parm";
/// The firmware's reference temperature, °C (`TEMP_REFERENCE`).
pub(crate) const TEMP_REFERENCE_C: f64 = 35.0;
/// The firmware's coefficient scale (`SCALE_FACTOR`): the parameters hold 1e6 × rad/s per
/// °C^k.
pub(crate) const SCALE_FACTOR: f64 = 1.0e6;

/// The parameter file of `steady` for ArduPilot's IMU `settings.instance + 1`.
pub fn generate(
    steady: SteadyBias,
    settings: &AutopilotSettings,
) -> Result<AutopilotExport, ExportError> {
    settings
        .validate(ARDUPILOT_INSTANCES)
        .map_err(AutopilotError::Setting)?;
    let n = u32::from(settings.instance) + 1;
    let x: Vec<f64> = steady
        .temps_c
        .iter()
        .map(|t| t - TEMP_REFERENCE_C)
        .collect();
    // GYR1..GYR3 per axis, as stored (f32).
    let mut gyr = [[0.0f32; 3]; 3];
    let mut fit = [None; 3];
    for (axis, b) in steady.bias_dps.iter().enumerate() {
        let Some(b) = b else { continue };
        let y: Vec<f64> = b.iter().map(|v| v * RAD_PER_DEG).collect();
        let c = fit_cubic(&x, &y).ok_or(AutopilotError::Fit)?;
        for k in 0..3 {
            gyr[k][axis] = (c[k + 1] * SCALE_FACTOR) as f32;
        }
        let g = gyr.map(|row| f64::from(row[axis]));
        let p = |x: f64| (g[0] + (g[1] + g[2] * x) * x) * x / SCALE_FACTOR;
        // The constant the boot-time calibration takes out: the best one (least squares).
        let r: Vec<f64> = x.iter().zip(&y).map(|(&x, &y)| y - p(x)).collect();
        let c0 = r.iter().sum::<f64>() / r.len() as f64;
        let resid_dps: Vec<f64> = r.iter().map(|v| (v - c0) / RAD_PER_DEG).collect();
        fit[axis] = Some(FitError::of(&resid_dps));
    }
    if gyr.iter().flatten().any(|v| !v.is_finite()) {
        return Err(AutopilotError::Fit.into());
    }
    let (t_min_c, t_max_c) = (f64::from(steady.temp_min_c), f64::from(steady.temp_max_c));
    let mut export = AutopilotExport {
        file_name: FILE_NAME,
        text: String::new(),
        fit,
        steady,
        error_means: "error after the best constant, which the firmware's boot-time gyro \
                      calibration takes out: with the error at the boot temperature, up to twice \
                      this",
        correction: Correction {
            // No constant: the firmware's p(T_cal) and boot calibration stand in for it.
            coef_rad: [0, 1, 2].map(|axis| {
                [0.0, 1.0, 2.0, 3.0].map(|k: f64| match k as usize {
                    0 => 0.0,
                    k => f64::from(gyr[k - 1][axis]) / SCALE_FACTOR,
                })
            }),
            t_min_c,
            t_max_c,
            t_ref_c: TEMP_REFERENCE_C,
        },
    };
    let mut text = export.header(
        "ArduPilot gyro temperature calibration, written by gyrotherm export --target ardupilot",
        &[
            "firmware (AP_InertialSensor_tempcal.cpp): gyro -= p(T) - p(T_cal),",
            "  p(T) = (GYR1 + (GYR2 + GYR3*x)*x)*x*1e-6 rad/s, x = clamp(T, TMIN, TMAX) - 35 degC",
            "accelerometer coefficients (ACC*) are not written: they stay as on the vehicle",
        ],
    );
    let mut line = |name: String, v: String| {
        text.push_str(&name);
        text.push(' ');
        text.push_str(&v);
        text.push('\n');
    };
    line(format!("INS_TCAL{n}_ENABLE"), "1".to_owned());
    line(
        format!("INS_TCAL{n}_TMIN"),
        export.steady.temp_min_c.to_string(),
    );
    line(
        format!("INS_TCAL{n}_TMAX"),
        export.steady.temp_max_c.to_string(),
    );
    for (k, row) in gyr.iter().enumerate() {
        for (axis, v) in ["X", "Y", "Z"].iter().zip(row) {
            // f32 Display: the shortest decimal that reads back as the same f32, no exponent.
            line(format!("INS_TCAL{n}_GYR{}_{axis}", k + 1), v.to_string());
        }
    }
    export.text = text;
    Ok(export)
}

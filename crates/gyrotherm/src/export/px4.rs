//! `--target px4`: PX4's gyro thermal compensation, as a QGroundControl parameter file
//! (`gyro_tc.params`): `#` comment lines, then one tab-separated line per parameter,
//! `vehicle-id  component-id  name  value  type` (type 6: INT32, 9: REAL32, MAVLink's
//! `MAV_PARAM_TYPE`), as PX4's own `Tools/process_sensor_caldata.py` writes it.
//!
//! **The firmware's use** (`src/modules/temperature_compensation/TemperatureCompensation.cpp`,
//! `calc_thermal_offsets_3D`): with `TC_G_ENABLE` = 1, the gyro whose device id equals
//! `TC_G{n}_ID` gets the offset
//!
//! ```text
//! offset = X0 + X1·ΔT + X2·ΔT² + X3·ΔT³  rad/s,   ΔT = clip(T, TMIN, TMAX) - TREF
//! ```
//!
//! per axis (`TC_G{n}_X{k}_0`, `_1`, `_2` for X, Y, Z), subtracted from its output. The offset
//! is absolute, so X0 is written and the fit error includes it. TREF is the middle of the
//! training range.

use super::steady_bias::{
    cubic, fit_cubic, AutopilotError, AutopilotExport, Correction, FitError, SteadyBias,
    RAD_PER_DEG,
};
use super::ExportError;
use crate::settings::autopilot::{AutopilotSettings, PX4_INSTANCES};

/// The file written.
pub(crate) const FILE_NAME: &str = "gyro_tc.params";
/// MAVLink `MAV_PARAM_TYPE_INT32`.
pub(crate) const TYPE_INT32: u8 = 6;
/// MAVLink `MAV_PARAM_TYPE_REAL32`.
pub(crate) const TYPE_REAL32: u8 = 9;

/// The parameter file of `steady` for PX4's gyro slot `settings.instance`.
pub fn generate(
    steady: SteadyBias,
    settings: &AutopilotSettings,
) -> Result<AutopilotExport, ExportError> {
    settings
        .validate(PX4_INSTANCES)
        .map_err(AutopilotError::Setting)?;
    let device_id = settings.device_id.ok_or(AutopilotError::NoDeviceId)?;
    let n = settings.instance;
    let tref = (0.5 * (f64::from(steady.temp_min_c) + f64::from(steady.temp_max_c))) as f32;
    let dt: Vec<f64> = steady.temps_c.iter().map(|t| t - f64::from(tref)).collect();
    // X0..X3 per axis, as stored (f32).
    let mut xk = [[0.0f32; 3]; 4];
    let mut fit = [None; 3];
    for (axis, b) in steady.bias_dps.iter().enumerate() {
        let Some(b) = b else { continue };
        let y: Vec<f64> = b.iter().map(|v| v * RAD_PER_DEG).collect();
        let c = fit_cubic(&dt, &y).ok_or(AutopilotError::Fit)?;
        for k in 0..4 {
            xk[k][axis] = c[k] as f32;
        }
        let stored = xk.map(|row| f64::from(row[axis]));
        let resid_dps: Vec<f64> = dt
            .iter()
            .zip(&y)
            .map(|(&d, &y)| (y - cubic(&stored, d)) / RAD_PER_DEG)
            .collect();
        fit[axis] = Some(FitError::of(&resid_dps));
    }
    if xk.iter().flatten().any(|v| !v.is_finite()) {
        return Err(AutopilotError::Fit.into());
    }
    let (t_min_c, t_max_c) = (f64::from(steady.temp_min_c), f64::from(steady.temp_max_c));
    let mut export = AutopilotExport {
        file_name: FILE_NAME,
        text: String::new(),
        fit,
        steady,
        error_means: "error of the absolute offset, X0 included",
        correction: Correction {
            coef_rad: [0, 1, 2].map(|axis| [0, 1, 2, 3].map(|k| f64::from(xk[k][axis]))),
            t_min_c,
            t_max_c,
            t_ref_c: f64::from(tref),
        },
    };
    let mut text = export.header(
        "Sensor thermal compensation parameters, written by gyrotherm export --target px4",
        &[
            "firmware (TemperatureCompensation.cpp): gyro offset subtracted,",
            "  X0 + X1*dT + X2*dT^2 + X3*dT^3 rad/s, dT = clip(T, TMIN, TMAX) - TREF",
            "PX4 also subtracts CAL_GYROn_xOFF: calibrate the gyro again after loading",
            "",
            "Vehicle-Id Component-Id Name Value Type",
        ],
    );
    let mut line = |name: String, v: String, ty: u8| {
        text.push_str(&format!("1\t1\t{name}\t{v}\t{ty}\n"));
    };
    line("TC_G_ENABLE".to_owned(), "1".to_owned(), TYPE_INT32);
    // PX4 keeps the id in an INT32 parameter and compares its 32 bits with the device id.
    line(
        format!("TC_G{n}_ID"),
        (device_id as i32).to_string(),
        TYPE_INT32,
    );
    line(
        format!("TC_G{n}_TMAX"),
        export.steady.temp_max_c.to_string(),
        TYPE_REAL32,
    );
    line(
        format!("TC_G{n}_TMIN"),
        export.steady.temp_min_c.to_string(),
        TYPE_REAL32,
    );
    line(format!("TC_G{n}_TREF"), tref.to_string(), TYPE_REAL32);
    for (k, row) in xk.iter().enumerate() {
        for (axis, v) in row.iter().enumerate() {
            // f32 Display: the shortest decimal that reads back as the same f32, no exponent.
            line(format!("TC_G{n}_X{k}_{axis}"), v.to_string(), TYPE_REAL32);
        }
    }
    export.text = text;
    Ok(export)
}

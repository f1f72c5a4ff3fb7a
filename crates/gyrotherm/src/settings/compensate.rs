//! Compensation settings: which temperature readings the flight compensator believes. They
//! are [`TempSensorDef`](crate::model::TempSensorDef) (stored in the model file by `train`,
//! used by `compensate`); the defaults are the core's [`TempLimits::DEFAULT`].

use gyrotherm_core::compensator::TempLimits;

/// `(setting name, default)` of each temperature-sensor limit, in `--help` order.
pub(crate) fn temp_sensor_defaults() -> [(&'static str, f64); 5] {
    let d = TempLimits::DEFAULT;
    [
        ("temp_min_c", d.min_c),
        ("temp_max_c", d.max_c),
        ("temp_max_rate_c_per_s", d.max_rate_c_per_s),
        ("temp_step_allowance_c", d.step_allowance_c),
        ("degraded_after_s", d.degraded_after_s),
    ]
}

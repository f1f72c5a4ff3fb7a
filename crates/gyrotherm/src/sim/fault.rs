//! Optional fault injection, to exercise readers and compensators on imperfect logs.
//!
//! Faults start as Poisson events (probability rate·Δt per sample, own ChaCha streams):
//! - dropout: `dropout_s` seconds of samples are missing from the log (a time gap; every
//!   column, truth included, loses those rows);
//! - stuck temperature: the logged `temp_c` repeats its last reading for `stuck_temp_s`
//!   seconds (a sensor that stopped converting; gyro and truth unaffected);
//! - temperature spike: one sample's `temp_c` is replaced, in turn, by 85.0 (the DS18B20's
//!   power-on register value, returned on a failed conversion), −127.0 (its bus-error value)
//!   and the true reading plus 10–40 °C of either sign (a corrupted read);
//! - NaN burst: `nan_burst_s` seconds of `temp_c` are NaN (no reading at all);
//! - stuck value: `temp_c` reads the fixed `stuck_value_c` (85.0 by default) for
//!   `stuck_value_s` seconds (a sensor that keeps failing its conversions).
//!
//! All rates 0 (the default) leaves the run untouched, bit for bit; the dropout and stuck
//! faults draw from their own stream, so adding the others does not move them. A log with NaN
//! temperatures is written by [`write_log`] (the strict [`crate::csvlog::write_log`] refuses
//! non-finite values).

use serde::{Deserialize, Serialize};

use crate::csvlog::LogError;

use super::noise::Gauss;
use super::SimSeries;

/// Fault rates and lengths.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FaultParams {
    /// Mean number of dropouts per hour of log.
    pub dropouts_per_hour: f64,
    /// Length of each dropout, s.
    pub dropout_s: f64,
    /// Mean number of stuck-temperature episodes per hour.
    pub stuck_temp_per_hour: f64,
    /// Length of each stuck-temperature episode, s.
    pub stuck_temp_s: f64,
    /// Mean number of single-sample temperature spikes per hour.
    pub spikes_per_hour: f64,
    /// Mean number of NaN bursts per hour.
    pub nan_bursts_per_hour: f64,
    /// Length of each NaN burst, s.
    pub nan_burst_s: f64,
    /// Mean number of stuck-value episodes per hour.
    pub stuck_value_per_hour: f64,
    /// Length of each stuck-value episode, s.
    pub stuck_value_s: f64,
    /// The reading of a stuck-value episode, °C (None: 85.0, the DS18B20 power-on value).
    pub stuck_value_c: Option<f64>,
}

/// The DS18B20's power-on register value, °C: what it returns after a failed conversion.
pub(crate) const POWER_ON_VALUE_C: f64 = 85.0;
/// The value a DS18B20 driver reports on a bus error, °C.
pub(crate) const BUS_ERROR_VALUE_C: f64 = -127.0;

impl FaultParams {
    /// True when no fault can occur.
    pub(crate) fn is_off(&self) -> bool {
        self.dropouts_per_hour == 0.0
            && self.stuck_temp_per_hour == 0.0
            && self.spikes_per_hour == 0.0
            && self.nan_bursts_per_hour == 0.0
            && self.stuck_value_per_hour == 0.0
    }

    pub(crate) fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("dropouts_per_hour", self.dropouts_per_hour),
            ("dropout_s", self.dropout_s),
            ("stuck_temp_per_hour", self.stuck_temp_per_hour),
            ("stuck_temp_s", self.stuck_temp_s),
            ("spikes_per_hour", self.spikes_per_hour),
            ("nan_bursts_per_hour", self.nan_bursts_per_hour),
            ("nan_burst_s", self.nan_burst_s),
            ("stuck_value_per_hour", self.stuck_value_per_hour),
            ("stuck_value_s", self.stuck_value_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("fault {name} = {v} must be finite and >= 0"));
            }
        }
        for (rate, len, name) in [
            (self.dropouts_per_hour, self.dropout_s, "dropout_s"),
            (self.stuck_temp_per_hour, self.stuck_temp_s, "stuck_temp_s"),
            (self.nan_bursts_per_hour, self.nan_burst_s, "nan_burst_s"),
            (
                self.stuck_value_per_hour,
                self.stuck_value_s,
                "stuck_value_s",
            ),
        ] {
            if rate > 0.0 && len <= 0.0 {
                return Err(format!("fault {name} must be > 0 when its rate is set"));
            }
        }
        if let Some(v) = self.stuck_value_c {
            if v.is_nan() {
                return Err("fault stuck_value_c must not be NaN".to_owned());
            }
        }
        Ok(())
    }
}

/// Apply the faults to a finished run (sample period `dt_s`).
pub(crate) fn apply(s: &mut SimSeries, f: &FaultParams, dt_s: f64, seed: u64) {
    if f.is_off() {
        return;
    }
    let mut g = Gauss::new(seed, 30);
    let n = s.time_s.len();
    let p_drop = f.dropouts_per_hour / 3600.0 * dt_s;
    let p_stuck = f.stuck_temp_per_hour / 3600.0 * dt_s;
    let drop_len = (f.dropout_s / dt_s).round().max(1.0) as usize;
    let stuck_len = (f.stuck_temp_s / dt_s).round().max(1.0) as usize;
    sensor_faults(&mut s.temp_c, f, dt_s, seed);
    let mut keep = vec![true; n];
    let mut stuck_left = 0usize;
    // Never drop the first or last sample: the log keeps its start and length.
    let mut i = 1;
    while i + 1 < n {
        if stuck_left > 0 {
            s.temp_c[i] = s.temp_c[i - 1];
            stuck_left -= 1;
        } else if g.uniform() < p_stuck {
            stuck_left = stuck_len - 1;
            s.temp_c[i] = s.temp_c[i - 1];
        }
        if g.uniform() < p_drop {
            let end = (i + drop_len).min(n - 1);
            keep[i..end].iter_mut().for_each(|k| *k = false);
            i = end;
            continue;
        }
        i += 1;
    }
    let filter = |v: &mut Vec<f64>| {
        let mut k = keep.iter();
        v.retain(|_| *k.next().unwrap_or(&true));
    };
    for v in s.sample_columns_mut() {
        filter(v);
    }
    if let Some(t) = &mut s.table_dps {
        filter(t);
    }
}

/// Spikes, NaN bursts and stuck values on the temperature column (own stream; never the first
/// or last sample).
fn sensor_faults(temp_c: &mut [f64], f: &FaultParams, dt_s: f64, seed: u64) {
    if f.spikes_per_hour == 0.0 && f.nan_bursts_per_hour == 0.0 && f.stuck_value_per_hour == 0.0 {
        return;
    }
    let mut g = Gauss::new(seed, 31);
    let n = temp_c.len();
    let p_spike = f.spikes_per_hour / 3600.0 * dt_s;
    let p_nan = f.nan_bursts_per_hour / 3600.0 * dt_s;
    let p_value = f.stuck_value_per_hour / 3600.0 * dt_s;
    let nan_len = (f.nan_burst_s / dt_s).round().max(1.0) as usize;
    let value_len = (f.stuck_value_s / dt_s).round().max(1.0) as usize;
    let stuck_value = f.stuck_value_c.unwrap_or(POWER_ON_VALUE_C);
    let mut spikes = 0u64;
    let mut i = 1;
    while i + 1 < n {
        let (u_spike, u_nan, u_value, u_kind) =
            (g.uniform(), g.uniform(), g.uniform(), g.uniform());
        let end = |len: usize| (i + len).min(n - 1);
        if u_nan < p_nan {
            let e = end(nan_len);
            temp_c[i..e].iter_mut().for_each(|v| *v = f64::NAN);
            i = e;
            continue;
        }
        if u_value < p_value {
            let e = end(value_len);
            temp_c[i..e].iter_mut().for_each(|v| *v = stuck_value);
            i = e;
            continue;
        }
        if u_spike < p_spike {
            temp_c[i] = match spikes % 3 {
                0 => POWER_ON_VALUE_C,
                1 => BUS_ERROR_VALUE_C,
                _ => {
                    let size = 10.0 + 30.0 * u_kind;
                    temp_c[i] + if u_kind < 0.5 { size } else { -size }
                }
            };
            spikes += 1;
        }
        i += 1;
    }
}

/// Write a simulated log as CSV like [`crate::csvlog::write_log`], but with non-finite
/// temperatures allowed and written as `NaN`: the temperature-sensor faults above. The other
/// columns must be finite.
pub fn write_log(path: &std::path::Path, log: &crate::csvlog::TestLog) -> Result<(), LogError> {
    let opts = crate::csvlog::WriteOptions {
        allow_nan_temperature: true,
    };
    crate::csvlog::write_log_with(path, log, opts)
}

//! Optional fault injection, to exercise readers and compensators on imperfect logs.
//!
//! Faults start as Poisson events (probability rate·Δt per sample, own ChaCha stream):
//! - dropout: `dropout_s` seconds of samples are missing from the log (a time gap; every
//!   column, truth included, loses those rows);
//! - stuck temperature: the logged `temp_c` repeats its last reading for `stuck_temp_s`
//!   seconds (a sensor that stopped converting; gyro and truth unaffected).
//!
//! All rates 0 (the default) leaves the run untouched, bit for bit.

use serde::{Deserialize, Serialize};

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
}

impl FaultParams {
    /// True when no fault can occur.
    pub fn is_off(&self) -> bool {
        self.dropouts_per_hour == 0.0 && self.stuck_temp_per_hour == 0.0
    }

    pub(crate) fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("dropouts_per_hour", self.dropouts_per_hour),
            ("dropout_s", self.dropout_s),
            ("stuck_temp_per_hour", self.stuck_temp_per_hour),
            ("stuck_temp_s", self.stuck_temp_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("fault {name} = {v} must be finite and >= 0"));
            }
        }
        for (rate, len, name) in [
            (self.dropouts_per_hour, self.dropout_s, "dropout_s"),
            (self.stuck_temp_per_hour, self.stuck_temp_s, "stuck_temp_s"),
        ] {
            if rate > 0.0 && len <= 0.0 {
                return Err(format!("fault {name} must be > 0 when its rate is set"));
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

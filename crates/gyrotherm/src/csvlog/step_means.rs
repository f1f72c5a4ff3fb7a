//! An autopilot's three-axis gyro reduced, while it is read, to one row per model step.
//!
//! Autopilot logs sample the gyro at about 1 kHz, and the model steps once a second: a
//! 45-minute log holds millions of samples, the fit needs thousands. Each step of
//! [`STEP_S`] becomes one row: the mean time, the mean rate of each axis in °/s (the file's
//! rad/s converted as `--gyro-unit rad/s` does), the mean temperature, and the number of
//! samples it averages (the pass-through column [`SAMPLES_COL`]). A step without samples
//! (a dropout) has no row.

use std::path::Path;

use super::error::{LogError, LogErrorKind as Kind};
use super::{ExtraColumn, GyroUnit, ImuLog, NamedSeries, ReadReport, TEMP_COL};

/// The model's step, s: the length of the time slice one row of a reduced log averages.
pub(crate) const STEP_S: f64 = 1.0;

/// The gyro columns of an autopilot's three-axis sensor, as a unit's CSV names its axes.
pub const SENSOR_GYRO_COLS: [&str; 3] = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"];

/// The column of a reduced log that counts the samples each row averages.
pub const SAMPLES_COL: &str = "samples";

const STEP_US: u64 = 1_000_000;

/// A sample the reducer refuses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Refused {
    /// Its time is not after the previous sample's (µs).
    Backwards { previous_us: u64 },
    /// A rate or the temperature is NaN or infinite.
    NotFinite,
}

/// The running means of the current step and the rows of the steps before it.
#[derive(Debug, Default)]
pub(crate) struct StepMeans {
    /// Start of the first step, µs.
    start_us: Option<u64>,
    /// Index of the step being summed.
    step: u64,
    last_us: Option<u64>,
    /// Sums of the current step: time since its start (µs), three rates (rad/s), temperature.
    sum: [f64; 5],
    count: u64,
    time_s: Vec<f64>,
    gyro: [Vec<f64>; 3],
    temp: Vec<f64>,
    counts: Vec<u64>,
    /// Samples taken.
    pub(crate) samples: u64,
}

impl StepMeans {
    /// Add a sample: time in µs, rates in rad/s, temperature in °C.
    pub(crate) fn push(
        &mut self,
        t_us: u64,
        rate_rad_s: [f64; 3],
        temp_c: f64,
    ) -> Result<(), Refused> {
        if let Some(previous_us) = self.last_us {
            if t_us <= previous_us {
                return Err(Refused::Backwards { previous_us });
            }
        }
        if !(rate_rad_s.iter().all(|r| r.is_finite()) && temp_c.is_finite()) {
            return Err(Refused::NotFinite);
        }
        self.last_us = Some(t_us);
        let start = *self.start_us.get_or_insert(t_us);
        let step = (t_us - start) / STEP_US;
        if step != self.step {
            self.close();
            self.step = step;
        }
        let since_step_us = (t_us - start - step * STEP_US) as f64;
        self.sum[0] += since_step_us;
        for (s, r) in self.sum[1..4].iter_mut().zip(rate_rad_s) {
            *s += r;
        }
        self.sum[4] += temp_c;
        self.count += 1;
        self.samples += 1;
        Ok(())
    }

    /// End the current step: its means become a row.
    fn close(&mut self) {
        if self.count == 0 {
            return;
        }
        let n = self.count as f64;
        let start = self.start_us.unwrap_or(0);
        let step_start_us = start + self.step * STEP_US;
        self.time_s
            .push((step_start_us as f64 + self.sum[0] / n) * 1e-6);
        let dps = GyroUnit::RadPerS.dps_per_unit();
        for (g, s) in self.gyro.iter_mut().zip(&self.sum[1..4]) {
            g.push(s / n * dps);
        }
        self.temp.push(self.sum[4] / n);
        self.counts.push(self.count);
        self.sum = [0.0; 5];
        self.count = 0;
    }

    /// The unit log of the rows (the last step closed).
    pub(crate) fn finish(mut self) -> ImuLog {
        self.close();
        let [x, y, z] = self.gyro;
        ImuLog {
            time_s: self.time_s,
            gyro: SENSOR_GYRO_COLS
                .iter()
                .zip([x, y, z])
                .map(|(name, values)| NamedSeries {
                    name: (*name).to_owned(),
                    values,
                })
                .collect(),
            temp: vec![NamedSeries {
                name: TEMP_COL.to_owned(),
                values: self.temp,
            }],
            table: None,
            table_axis: None,
            extra: vec![ExtraColumn {
                name: SAMPLES_COL.to_owned(),
                values: self.counts.iter().map(u64::to_string).collect(),
            }],
        }
    }
}

/// The unit log and report of the messages read, or the error of a log without them.
pub(crate) fn reduced_log(
    path: &Path,
    means: StepMeans,
    instance: u8,
    instances: &[u8],
    what: &str,
    truncated_at: Option<u64>,
) -> Result<(ImuLog, ReadReport), LogError> {
    if means.samples == 0 {
        let mut found: Vec<String> = instances.iter().map(u8::to_string).collect();
        found.sort();
        let held = if found.is_empty() {
            format!("the log holds no {what} messages")
        } else {
            format!(
                "the log holds instance(s) {}; pick one with --instance",
                found.join(", ")
            )
        };
        return Err(LogError::new(
            Kind::NoData,
            path,
            None,
            None,
            format!("no {what} samples of instance {instance}: {held}"),
        ));
    }
    let rows = means.samples;
    let log = means.finish();
    let report = ReadReport {
        rows,
        sample_period_s: Some(STEP_S),
        truncated_at_byte: truncated_at,
        ..ReadReport::default()
    };
    Ok((log, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_row_per_second_with_means_and_counts() {
        let mut m = StepMeans::default();
        // 1000 Hz for 2.5 s from t = 10 s: rates 1 rad/s on x, temperature rising.
        for k in 0..2500u64 {
            let t = 10_000_000 + k * 1000;
            m.push(t, [1.0, 0.0, -2.0], 20.0 + k as f64 * 1e-3).unwrap();
        }
        assert_eq!(m.samples, 2500);
        let log = m.finish();
        assert_eq!(log.len(), 3);
        assert_eq!(log.extra[0].values, ["1000", "1000", "500"]);
        let dps = 180.0 / std::f64::consts::PI;
        assert!((log.gyro[0].values[0] - dps).abs() < 1e-12);
        assert!((log.gyro[2].values[1] + 2.0 * dps).abs() < 1e-12);
        // Mean of 0, 1 ms, …, 999 ms after 10 s; temperature the mean of its ramp.
        assert!((log.time_s[0] - 10.4995).abs() < 1e-9);
        assert!((log.temp[0].values[1] - (20.0 + 1.4995)).abs() < 1e-9);
        assert!((log.time_s[2] - 12.2495).abs() < 1e-9);
    }

    #[test]
    fn refuses_time_going_back_and_non_finite_values() {
        let mut m = StepMeans::default();
        m.push(5, [0.0; 3], 20.0).unwrap();
        assert_eq!(
            m.push(5, [0.0; 3], 20.0),
            Err(Refused::Backwards { previous_us: 5 })
        );
        assert_eq!(
            m.push(6, [f64::NAN, 0.0, 0.0], 20.0),
            Err(Refused::NotFinite)
        );
    }
}

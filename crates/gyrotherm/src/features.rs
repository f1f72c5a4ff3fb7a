//! Ground-side features over a whole log: the flight pipeline
//! ([`gyrotherm_core::features::FeaturePipeline`]) run sample by sample, so training and
//! flight see bit-identical numbers. The centred moving average that smooths the bias target
//! (100 s in He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004) lives in
//! `crate::moving_average` and is re-exported here.

use crate::csvlog::TestLog;
use crate::moving_average::windowed_mean;
pub use crate::moving_average::{centred_moving_average, MovingAverageError, Smoothed};
use gyrotherm_core::error::InputError;
pub use gyrotherm_core::features::{
    FeatureKind, FeaturePipeline, FeatureSpec, LagOutputs, SpecError, MAX_FEATURES, MAX_LAGS,
};

/// The longest sample period a model with feature spec `spec` runs at, s: its dT window
/// (`rate_lag_s`, 20 s published), and at least its step period. The model steps on the time
/// axis and reads dT as the temperature difference over the window; a log sampled more
/// sparsely has no sample inside a window, so every step bridges a gap.
pub(crate) fn max_sample_period_s(spec: &FeatureSpec) -> f64 {
    spec.rate_lag_s.max(spec.step_period_s)
}

/// Per-step model inputs of one log.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureTable {
    /// The definition that made them.
    pub spec: FeatureSpec,
    /// Features per row (`spec.n_features()`).
    pub n_features: usize,
    /// Short name of each feature (`T`, `dT`, `T_ma20`, `T_lag300`, `T-T_lag300`).
    pub names: Vec<String>,
    /// Unit of each feature (`°C` or `°C/s`).
    pub units: Vec<&'static str>,
    /// Step boundary time `t0 + k·P`, s, per row.
    pub step_time_s: Vec<f64>,
    /// Index of the log sample that made each step (its value is held until the next row's).
    pub sample_index: Vec<usize>,
    /// Row-major features, `rows.len() == n_rows() · n_features`.
    pub rows: Vec<f64>,
}

impl FeatureTable {
    /// Number of steps.
    pub fn n_rows(&self) -> usize {
        self.step_time_s.len()
    }
    /// Features of step `r`.
    pub fn row(&self, r: usize) -> &[f64] {
        &self.rows[r * self.n_features..(r + 1) * self.n_features]
    }
    /// Column `c` over all steps.
    pub fn column(&self, c: usize) -> Vec<f64> {
        self.rows
            .iter()
            .skip(c)
            .step_by(self.n_features.max(1))
            .copied()
            .collect()
    }
    /// A per-sample series (e.g. the smoothed gyro output as bias target) picked at the sample
    /// each step came from, one value per row. None if `series` is shorter than the log the
    /// table was made from.
    pub fn at_steps(&self, series: &[f64]) -> Option<Vec<f64>> {
        self.sample_index
            .iter()
            .map(|&i| series.get(i).copied())
            .collect()
    }
    /// (min, max) of column `c` over all steps (None when there are no steps).
    pub fn range(&self, c: usize) -> Option<(f64, f64)> {
        let col = self.column(c);
        if col.is_empty() {
            return None;
        }
        Some(
            col.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                }),
        )
    }
    /// For every log sample (of a log with `n_samples` samples), the row whose value it holds:
    /// the latest step made at or before it. Flight code holds the same way.
    pub fn row_of_sample(&self, n_samples: usize) -> Vec<usize> {
        let mut out = Vec::with_capacity(n_samples);
        let mut r = 0usize;
        for i in 0..n_samples {
            while r + 1 < self.sample_index.len() && self.sample_index[r + 1] <= i {
                r += 1;
            }
            out.push(r);
        }
        out
    }
}

/// Why features could not be made.
#[derive(Debug, Clone, PartialEq)]
pub enum FeatureError {
    /// The spec is unusable.
    Spec(SpecError),
    /// Sample `index` (time `time_s`) was refused by the pipeline.
    Sample {
        index: usize,
        time_s: f64,
        error: InputError,
    },
    /// `time_s` and `temp_c` have different lengths.
    Length { time: usize, temp: usize },
}

impl std::fmt::Display for FeatureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FeatureError::Spec(e) => write!(f, "feature definition: {e}"),
            FeatureError::Sample {
                index,
                time_s,
                error,
            } => write!(
                f,
                "sample {index} (time_s {time_s}): {error}; fix or remove that sample (time must increase, values must be finite)"
            ),
            FeatureError::Length { time, temp } => write!(
                f,
                "{time} time stamps but {temp} temperatures: the columns must have the same length"
            ),
        }
    }
}

impl std::error::Error for FeatureError {}

impl From<SpecError> for FeatureError {
    fn from(e: SpecError) -> Self {
        FeatureError::Spec(e)
    }
}

/// Name and unit of each feature of `spec`.
pub(crate) fn feature_names(spec: &FeatureSpec) -> (Vec<String>, Vec<&'static str>) {
    let mut names = Vec::new();
    let mut units = Vec::new();
    for i in 0..spec.n_features() {
        let (n, u) = match spec.kind(i) {
            Some(FeatureKind::Temperature) => ("T".to_owned(), "°C"),
            Some(FeatureKind::Rate) => ("dT".to_owned(), "°C/s"),
            Some(FeatureKind::MovingAverage) => (format!("T_ma{}", spec.smoothing_window_s), "°C"),
            Some(FeatureKind::Lag(j)) => (format!("T_lag{}", spec.lag_tau_s[j as usize]), "°C"),
            Some(FeatureKind::LagDiff(j)) => {
                (format!("T-T_lag{}", spec.lag_tau_s[j as usize]), "°C")
            }
            None => (format!("x{i}"), ""),
        };
        names.push(n);
        units.push(u);
    }
    (names, units)
}

/// Run the core pipeline over `time_s`/`temp_c` sample by sample.
pub fn extract_series(
    time_s: &[f64],
    temp_c: &[f64],
    spec: &FeatureSpec,
) -> Result<FeatureTable, FeatureError> {
    if time_s.len() != temp_c.len() {
        return Err(FeatureError::Length {
            time: time_s.len(),
            temp: temp_c.len(),
        });
    }
    let mut pipe = FeaturePipeline::new(*spec)?;
    let nf = spec.n_features();
    let (names, units) = feature_names(spec);
    // Sized ahead: a step is a sample, at most one per step period, so the table never
    // grows by copying (on a long log that copying is most of the extraction's cost).
    let steps = step_bound(time_s, spec.step_period_s);
    let mut table = FeatureTable {
        spec: *spec,
        n_features: nf,
        names,
        units,
        step_time_s: Vec::with_capacity(steps),
        sample_index: Vec::with_capacity(steps),
        rows: Vec::with_capacity(steps.saturating_mul(nf)),
    };
    for (i, (&t, &c)) in time_s.iter().zip(temp_c).enumerate() {
        match pipe.push(t, c) {
            Ok(Some(step)) => {
                table.step_time_s.push(step.time_s);
                table.sample_index.push(i);
                table.rows.extend_from_slice(step.features.as_slice());
            }
            Ok(None) => {}
            Err(error) => {
                return Err(FeatureError::Sample {
                    index: i,
                    time_s: t,
                    error,
                })
            }
        }
    }
    Ok(table)
}

/// At most how many steps the pipeline makes of samples at `time_s`: one per sample, and no
/// more than one per period `p` over the time they span (every sample when that span is not
/// a finite number of periods, which the pipeline refuses anyway).
fn step_bound(time_s: &[f64], p: f64) -> usize {
    let n = time_s.len();
    match (time_s.first(), time_s.last()) {
        (Some(&a), Some(&b)) => {
            let periods = (b - a) / p;
            if periods.is_finite() && periods >= 0.0 && periods < n as f64 {
                // Two more: the first sample's step and the last's rounding.
                (periods as usize).saturating_add(2).min(n)
            } else {
                n
            }
        }
        _ => 0,
    }
}

/// Run the core pipeline over a whole log.
pub fn extract(log: &TestLog, spec: &FeatureSpec) -> Result<FeatureTable, FeatureError> {
    extract_series(&log.time_s, &log.temp_c, spec)
}

/// Smoothing of the gyro temperature before it is differentiated (report figure 1, `plan`), s.
pub const TEMP_RATE_SMOOTHING_S: f64 = 100.0;
/// Half-span of the central difference of the smoothed temperature, s.
const TEMP_RATE_HALF_SPAN_S: f64 = 5.0;

/// Gyro temperature rate, °C/min: the `TEMP_RATE_SMOOTHING_S` centred moving average
/// ([`centred_moving_average`]) differentiated
/// by a central difference over ±`TEMP_RATE_HALF_SPAN_S` (one-sided at the ends).
pub(crate) fn temperature_rate_c_per_min(time_s: &[f64], temp_c: &[f64]) -> Vec<f64> {
    let n = time_s.len().min(temp_c.len());
    // The symmetric shrinking window keeps a ramp unbiased up to the ends; a log it refuses
    // (non-finite or non-increasing samples) gets the plain windowed mean.
    let smooth = centred_moving_average(&time_s[..n], &temp_c[..n], TEMP_RATE_SMOOTHING_S)
        .map(|s| s.values)
        .unwrap_or_else(|_| windowed_mean(&time_s[..n], &temp_c[..n], TEMP_RATE_SMOOTHING_S));
    let dt = if n >= 2 {
        (time_s[n - 1] - time_s[0]) / (n - 1) as f64
    } else {
        1.0
    };
    let k = if dt.is_finite() && dt > 0.0 {
        ((TEMP_RATE_HALF_SPAN_S / dt).round() as usize).max(1)
    } else {
        1
    };
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(k), (i + k).min(n.saturating_sub(1)));
            let span = time_s[b] - time_s[a];
            if b > a && span > 0.0 {
                (smooth[b] - smooth[a]) / span * 60.0
            } else {
                f64::NAN
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table is sized ahead from `step_bound`: it must never be below the steps the core
    /// pipeline makes (counted by the pipeline itself), or the table grows by copying.
    #[test]
    fn step_bound_covers_every_step_the_pipeline_makes() {
        let spec = FeatureSpec::THERMAL_STATE;
        let cases: Vec<Vec<f64>> = vec![
            (0..500).map(f64::from).collect(), // 1 Hz: a step per sample
            (0..5000).map(|i| f64::from(i) * 0.1).collect(), // 10 Hz: one in ten
            (0..300).map(|i| f64::from(i) * 2.0).collect(), // 0.5 Hz: gaps between steps
            (0..800).map(|i| f64::from(i) * 0.37 + 1e6).collect(), // off the grid, late start
            (0..600)
                .map(|i| f64::from(i) + if i > 300 { 900.0 } else { 0.0 })
                .collect(), // a 15-minute gap
            vec![42.0],
        ];
        for t in cases {
            let temp: Vec<f64> = t.iter().map(|x| 20.0 + (x * 1e-3).sin()).collect();
            let table = extract_series(&t, &temp, &spec).expect("a valid series");
            let bound = step_bound(&t, spec.step_period_s);
            assert!(table.n_rows() >= 1 && table.n_rows() <= bound);
            assert!(bound <= t.len());
        }
        assert_eq!(step_bound(&[], 1.0), 0);
    }

    #[test]
    fn temperature_rate_of_a_ramp() {
        // T = 20 + 0.05·t (°C, t in s) is 3 °C/min everywhere
        // (a linear trend passes the symmetric centred average unchanged, ends included).
        let t: Vec<f64> = (0..2000).map(|i| i as f64).collect();
        let temp: Vec<f64> = t.iter().map(|x| 20.0 + 0.05 * x).collect();
        let rate = temperature_rate_c_per_min(&t, &temp);
        for (i, r) in rate.iter().enumerate() {
            assert!((r - 3.0).abs() < 1e-9, "sample {i}: want 3 °C/min got {r}");
        }
    }
}

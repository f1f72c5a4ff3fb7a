//! Training targets from test logs, on the model's feature steps.
//!
//! - Bias (°/s), from static logs: the gyro output smoothed by a centred moving average
//!   (100 s in He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, §3), taken at each
//!   feature step. Steps whose window did not fit inside the log are masked out of the loss.
//! - Scale factor K (dimensionless), from rate-table logs: at each step inside a rate segment
//!   (after its settle time) K(t) = (F(t) - B(t)) / Ω, with F the output smoothed by a centred
//!   moving average confined to the segment, and B(t) the bias interpolated linearly in time
//!   between the means of the neighbouring stop segments. Steps with no label (stops, settle
//!   time, a rate segment with no stop segment beside it) are masked out, not invented.

use std::fmt;

use crate::csvlog::TestLog;
use crate::features::{extract, FeatureError, FeatureSpec, FeatureTable};
use crate::moving_average::{centred_moving_average, MovingAverageError};
use crate::table_segments::{segments, Segment, RATE_TOLERANCE_DPS};

/// Why training targets could not be made from a log.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TargetError {
    /// The features of the log could not be computed.
    Features(FeatureError),
    /// The gyro output could not be smoothed.
    Smoothing(MovingAverageError),
    /// A scale-factor target was asked of a log without a table column.
    NoTable,
}

impl fmt::Display for TargetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TargetError::Features(e) => write!(f, "{e}"),
            TargetError::Smoothing(e) => write!(f, "{e}"),
            TargetError::NoTable => write!(
                f,
                "the log has no table_dps column: a scale-factor target needs a rate-table log"
            ),
        }
    }
}

impl std::error::Error for TargetError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the message is the inner error's own.
            TargetError::Features(e) => e.source(),
            TargetError::Smoothing(e) => e.source(),
            TargetError::NoTable => None,
        }
    }
}

/// One run's training data for one target: features per step, the target per step and which
/// steps count in the loss.
#[derive(Debug, Clone)]
pub struct TargetSet {
    /// Features at each step.
    pub table: FeatureTable,
    /// Target per step (NaN where masked).
    pub target: Vec<f64>,
    /// True where the step has a label.
    pub mask: Vec<bool>,
}

impl TargetSet {
    /// Number of labelled steps.
    pub fn labelled(&self) -> usize {
        self.mask.iter().filter(|m| **m).count()
    }
}

/// Default bias smoothing window, s (He et al. 2024, §3: 100 s moving average).
pub const BIAS_WINDOW_S: f64 = 100.0;
/// Default settle time excluded at the start of each table segment, s.
pub const SETTLE_S: f64 = 10.0;
/// Default smoothing window of the output inside a rate segment, s.
pub(crate) const SCALE_WINDOW_S: f64 = 60.0;

/// True when a log is a static test ([`TestLog::is_static`]: no table column, or a table
/// column that is zero throughout).
pub fn is_static(log: &TestLog) -> bool {
    log.is_static()
}

/// Bias target of a static log: centred `window_s` moving average of the gyro output at each
/// feature step.
pub fn bias_targets(
    log: &TestLog,
    spec: &FeatureSpec,
    window_s: f64,
) -> Result<TargetSet, TargetError> {
    let table = extract(log, spec).map_err(TargetError::Features)?;
    Ok(bias_samples(log, window_s)?.at_steps(table))
}

/// A target per sample of a log, from its gyro column (and table rate) only: NaN where
/// unlabelled. The features' steps pick from it ([`GyroSamples::at_steps`]), so a log read
/// with several temperature columns smooths its gyro column once.
#[derive(Debug, Clone)]
pub(crate) struct GyroSamples {
    target: Vec<f64>,
    ok: Vec<bool>,
}

impl GyroSamples {
    /// The target set at `table`'s steps.
    pub(crate) fn at_steps(&self, table: FeatureTable) -> TargetSet {
        let (target, mask) = self.pick(&table.sample_index);
        TargetSet {
            table,
            target,
            mask,
        }
    }

    /// Target and mask at the samples `index`.
    pub(crate) fn pick(&self, index: &[usize]) -> (Vec<f64>, Vec<bool>) {
        (
            index.iter().map(|&i| self.target[i]).collect(),
            index.iter().map(|&i| self.ok[i]).collect(),
        )
    }
}

/// [`bias_targets`] (`scale` false) or [`scale_targets`] (`scale` true) with the per-sample
/// part made ahead ([`bias_samples`] or [`scale_samples`] of the same gyro column and
/// settings): the same result, the same error first.
pub(crate) fn targets_from(
    log: &TestLog,
    spec: &FeatureSpec,
    samples: &Result<GyroSamples, TargetError>,
    scale: bool,
) -> Result<TargetSet, TargetError> {
    if scale && log.table_dps.is_none() {
        return Err(TargetError::NoTable);
    }
    let table = extract(log, spec).map_err(TargetError::Features)?;
    Ok(samples.as_ref().map_err(Clone::clone)?.at_steps(table))
}

/// [`bias_targets`]' per-sample part: the centred moving average of the gyro column.
pub(crate) fn bias_samples(log: &TestLog, window_s: f64) -> Result<GyroSamples, TargetError> {
    let smoothed = centred_moving_average(&log.time_s, &log.gyro_dps, window_s)
        .map_err(TargetError::Smoothing)?;
    let target = smoothed
        .values
        .iter()
        .zip(&smoothed.full_window)
        .map(|(v, ok)| if *ok { *v } else { f64::NAN })
        .collect();
    Ok(GyroSamples {
        target,
        ok: smoothed.full_window,
    })
}

fn settled_start(log: &TestLog, seg: &Segment, settle_s: f64) -> usize {
    let t0 = log.time_s[seg.start];
    (seg.start..seg.end)
        .find(|&i| log.time_s[i] - t0 >= settle_s)
        .unwrap_or(seg.end)
}

/// Scale-factor target of a rate-table log (see the module doc).
pub(crate) fn scale_targets(
    log: &TestLog,
    spec: &FeatureSpec,
    settle_s: f64,
    window_s: f64,
) -> Result<TargetSet, TargetError> {
    if log.table_dps.is_none() {
        return Err(TargetError::NoTable);
    }
    let table = extract(log, spec).map_err(TargetError::Features)?;
    Ok(scale_samples(log, settle_s, window_s)?.at_steps(table))
}

/// [`scale_targets`]' per-sample part: the scale factor from the gyro column and the table
/// rate.
pub(crate) fn scale_samples(
    log: &TestLog,
    settle_s: f64,
    window_s: f64,
) -> Result<GyroSamples, TargetError> {
    let Some(table_dps) = &log.table_dps else {
        return Err(TargetError::NoTable);
    };
    let segs = segments(table_dps, RATE_TOLERANCE_DPS);
    // Stop segments: (centre time, mean output).
    let stops: Vec<(f64, f64)> = segs
        .iter()
        .filter(|s| s.is_stop(RATE_TOLERANCE_DPS))
        .filter_map(|s| {
            let a = settled_start(log, s, settle_s);
            (a < s.end).then(|| {
                let n = (s.end - a) as f64;
                let mean = log.gyro_dps[a..s.end].iter().sum::<f64>() / n;
                (0.5 * (log.time_s[a] + log.time_s[s.end - 1]), mean)
            })
        })
        .collect();
    let bias_at = |t: f64| -> Option<f64> {
        let after = stops.iter().position(|s| s.0 >= t);
        match after {
            Some(0) => None,
            Some(k) => {
                let (t0, b0) = stops[k - 1];
                let (t1, b1) = stops[k];
                Some(b0 + (b1 - b0) * (t - t0) / (t1 - t0))
            }
            None => None,
        }
    };
    let mut k_sample = vec![f64::NAN; log.len()];
    for s in segs.iter().filter(|s| !s.is_stop(RATE_TOLERANCE_DPS)) {
        let a = settled_start(log, s, settle_s);
        if a >= s.end {
            continue;
        }
        let sm = centred_moving_average(&log.time_s[a..s.end], &log.gyro_dps[a..s.end], window_s)
            .map_err(TargetError::Smoothing)?;
        for (j, f) in sm.values.iter().enumerate() {
            let i = a + j;
            if let Some(b) = bias_at(log.time_s[i]) {
                k_sample[i] = (f - b) / s.rate_dps;
            }
        }
    }
    let ok = k_sample.iter().map(|v| v.is_finite()).collect();
    Ok(GyroSamples {
        target: k_sample,
        ok,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log(
        n: usize,
        gyro: impl Fn(f64, f64) -> f64,
        table: Option<&dyn Fn(f64) -> f64>,
    ) -> TestLog {
        let time_s: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let temp_c: Vec<f64> = time_s.iter().map(|t| 20.0 + t / 100.0).collect();
        let table_dps = table.map(|f| time_s.iter().map(|t| f(*t)).collect::<Vec<f64>>());
        let gyro_dps = time_s
            .iter()
            .enumerate()
            .map(|(i, t)| gyro(*t, table_dps.as_ref().map_or(0.0, |v| v[i])))
            .collect();
        TestLog {
            time_s,
            gyro_dps,
            temp_c,
            table_dps,
            extra: Vec::new(),
        }
    }

    #[test]
    fn bias_target_of_a_linear_drift_is_the_drift_and_edges_are_masked() {
        // A centred average passes a linear trend unchanged (independent: the formula).
        let l = log(1000, |t, _| 1e-3 + 1e-6 * t, None);
        let ts = bias_targets(&l, &FeatureSpec::PUBLISHED, 100.0).unwrap();
        assert_eq!(ts.target.len(), 1000);
        assert!(!ts.mask[0] && !ts.mask[49] && ts.mask[50] && ts.mask[949] && !ts.mask[950]);
        for i in 50..950 {
            let want = 1e-3 + 1e-6 * i as f64;
            assert!(
                (ts.target[i] - want).abs() < 1e-15,
                "step {i}: {} vs {want}",
                ts.target[i]
            );
        }
    }

    #[test]
    fn scale_target_recovers_k_with_bias_from_stop_segments() {
        // 4 × 100 s segments: stop, +10 °/s, stop, -10 °/s, ... ; Ĝ = B(t) + K·Ω with a bias
        // drifting linearly in time and K = 1.0002: the label must be K exactly where a stop
        // segment lies on both sides (linear interpolation of a linear bias is exact).
        let k_true = 1.0002;
        let rate = |t: f64| match (t as usize / 100) % 4 {
            1 => 10.0,
            3 => -10.0,
            _ => 0.0,
        };
        let l = log(1200, |t, w| 2e-3 + 1e-7 * t + k_true * w, Some(&rate));
        let ts = scale_targets(&l, &FeatureSpec::PUBLISHED, 5.0, 20.0).unwrap();
        let labelled = ts.labelled();
        // Rate segments at 100-199, 300-399, 500-599, 700-799, 900-999 (1100-1199: no stop after).
        assert_eq!(labelled, 5 * 95, "labelled steps");
        for (i, (&k, &m)) in ts.target.iter().zip(&ts.mask).enumerate() {
            if m {
                assert!((k - k_true).abs() < 1e-12, "step {i}: K {k}");
                assert!(rate(i as f64) != 0.0);
            }
        }
    }

    #[test]
    fn a_noisy_table_column_segments_the_same_for_targets_and_metrics() {
        // A logged command column with round-off jitter (±1e-12 °/s, below
        // RATE_TOLERANCE_DPS): the targets and the scale-factor figures must both see the
        // 12 segments of 100 s that were commanded, not one segment per sample.
        let rate = |t: f64| match (t as usize / 100) % 4 {
            1 => 10.0,
            3 => -10.0,
            _ => 0.0,
        };
        let noisy = |t: f64| rate(t) + if (t as usize) % 2 == 0 { 1e-12 } else { -1e-12 };
        let l = log(1200, |t, w| 2e-3 + 1e-7 * t + 1.0002 * w, Some(&noisy));
        let ts = scale_targets(&l, &FeatureSpec::PUBLISHED, 5.0, 20.0).unwrap();
        assert_eq!(ts.labelled(), 5 * 95, "labelled steps");
        let table = l.table_dps.as_deref().unwrap();
        let opts = crate::metrics::ScaleFactorOptions {
            settle_s: 5.0,
            ..Default::default()
        };
        let sf = crate::metrics::scale_factor(&l.time_s, &l.gyro_dps, table, &opts).unwrap();
        let ours: Vec<(usize, usize)> = segments(table, RATE_TOLERANCE_DPS)
            .iter()
            .map(|s| (s.start, s.end))
            .collect();
        let theirs: Vec<(usize, usize)> = sf.segments.iter().map(|s| (s.start, s.end)).collect();
        assert_eq!(ours.len(), 12);
        assert_eq!(ours, theirs);
        assert_eq!(sf.scale_over_time.len(), 6);
    }

    #[test]
    fn scale_target_needs_a_table() {
        let l = log(100, |_, _| 0.0, None);
        let e = scale_targets(&l, &FeatureSpec::PUBLISHED, 5.0, 20.0).unwrap_err();
        assert_eq!(e, TargetError::NoTable);
        assert!(e.to_string().contains("table_dps"), "{e}");
    }
}

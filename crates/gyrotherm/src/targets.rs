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

use crate::csvlog::TestLog;
use crate::features::{centred_moving_average, extract, FeatureSpec, FeatureTable};

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
pub const SCALE_WINDOW_S: f64 = 60.0;

/// True when a log is a static test (no table column, or a table column that is zero
/// throughout).
pub fn is_static(log: &TestLog) -> bool {
    log.table_dps
        .as_ref()
        .is_none_or(|t| t.iter().all(|v| *v == 0.0))
}

/// Bias target of a static log: centred `window_s` moving average of the gyro output at each
/// feature step.
pub fn bias_targets(log: &TestLog, spec: &FeatureSpec, window_s: f64) -> Result<TargetSet, String> {
    let table = extract(log, spec).map_err(|e| e.to_string())?;
    let smoothed = centred_moving_average(&log.time_s, &log.gyro_dps, window_s)?;
    let mut target = Vec::with_capacity(table.n_rows());
    let mut mask = Vec::with_capacity(table.n_rows());
    for &i in &table.sample_index {
        let ok = smoothed.full_window[i];
        target.push(if ok { smoothed.values[i] } else { f64::NAN });
        mask.push(ok);
    }
    Ok(TargetSet {
        table,
        target,
        mask,
    })
}

/// A run of samples with one commanded table rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// First sample index.
    pub start: usize,
    /// One past the last sample index.
    pub end: usize,
    /// Commanded rate, °/s.
    pub rate_dps: f64,
}

/// Runs of equal commanded rate in `table_dps`.
pub fn segments(table_dps: &[f64]) -> Vec<Segment> {
    let mut out: Vec<Segment> = Vec::new();
    for (i, &r) in table_dps.iter().enumerate() {
        match out.last_mut() {
            Some(s) if s.rate_dps == r => s.end = i + 1,
            _ => out.push(Segment {
                start: i,
                end: i + 1,
                rate_dps: r,
            }),
        }
    }
    out
}

/// First sample of `seg` at least `settle_s` after its start.
fn settled_start(log: &TestLog, seg: &Segment, settle_s: f64) -> usize {
    let t0 = log.time_s[seg.start];
    (seg.start..seg.end)
        .find(|&i| log.time_s[i] - t0 >= settle_s)
        .unwrap_or(seg.end)
}

/// Scale-factor target of a rate-table log (see the module doc).
pub fn scale_targets(
    log: &TestLog,
    spec: &FeatureSpec,
    settle_s: f64,
    window_s: f64,
) -> Result<TargetSet, String> {
    let Some(table_dps) = &log.table_dps else {
        return Err(
            "the log has no table_dps column: a scale-factor target needs a rate-table log".into(),
        );
    };
    let table = extract(log, spec).map_err(|e| e.to_string())?;
    let segs = segments(table_dps);
    // Stop segments: (centre time, mean output).
    let stops: Vec<(f64, f64)> = segs
        .iter()
        .filter(|s| s.rate_dps == 0.0)
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
    for s in segs.iter().filter(|s| s.rate_dps != 0.0) {
        let a = settled_start(log, s, settle_s);
        if a >= s.end {
            continue;
        }
        let sm = centred_moving_average(&log.time_s[a..s.end], &log.gyro_dps[a..s.end], window_s)?;
        for (j, f) in sm.values.iter().enumerate() {
            let i = a + j;
            if let Some(b) = bias_at(log.time_s[i]) {
                k_sample[i] = (f - b) / s.rate_dps;
            }
        }
    }
    let target: Vec<f64> = table.sample_index.iter().map(|&i| k_sample[i]).collect();
    let mask = target.iter().map(|v| v.is_finite()).collect();
    Ok(TargetSet {
        table,
        target,
        mask,
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
    fn scale_target_needs_a_table() {
        let l = log(100, |_, _| 0.0, None);
        let e = scale_targets(&l, &FeatureSpec::PUBLISHED, 5.0, 20.0).unwrap_err();
        assert!(e.contains("table_dps"), "{e}");
    }
}

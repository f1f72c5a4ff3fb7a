//! The centred moving average on a time axis, the one smoothing every part of the library
//! uses: the bias and scale-factor targets, the report's figures and its temperature rate.
//!
//! `centred_mean` is the one implementation: for each sample the mean of the included,
//! finite values within `±W/2` on the time axis, with a policy at the ends of the run
//! (`Edges`). [`centred_moving_average`] is its strict form for training targets (every
//! value must be finite, time strictly increasing; the window shrinks symmetrically at the
//! ends); `windowed_mean` its lenient form for figures (non-finite values skipped, the
//! window cut off at the ends).

use std::fmt;

/// What the window does near the ends of the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Edges {
    /// Shrinks symmetrically (`h = min(W/2, t − t_first, t_last − t)`) so it stays centred:
    /// a linear trend passes through unbiased; the first and last values are the raw samples.
    Shrink,
    /// Keeps `±W/2` and averages what lies inside the run.
    Truncate,
}

/// A centred moving average and where it had its full window.
#[derive(Debug, Clone, PartialEq)]
pub struct Smoothed {
    /// The smoothed series, one value per input sample (NaN where the window held no
    /// included value).
    pub values: Vec<f64>,
    /// True where the whole window `t ± W/2` lay inside the run.
    pub full_window: Vec<bool>,
}

/// Why the strict moving average refused its input.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MovingAverageError {
    /// The window is not finite and > 0, s.
    BadWindow(f64),
    /// Time and values differ in length.
    LengthMismatch { times: usize, values: usize },
    /// Sample `index` has a non-finite time or value.
    NonFinite { index: usize },
    /// Time at sample `index` does not increase.
    NotIncreasing {
        index: usize,
        time_s: f64,
        previous_s: f64,
    },
}

impl fmt::Display for MovingAverageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MovingAverageError::BadWindow(w) => {
                write!(f, "moving-average window {w} s: must be finite and > 0")
            }
            MovingAverageError::LengthMismatch { times, values } => write!(
                f,
                "{times} time stamps but {values} values: the columns must have the same length"
            ),
            MovingAverageError::NonFinite { index } => {
                write!(f, "sample {index}: non-finite time or value")
            }
            MovingAverageError::NotIncreasing {
                index,
                time_s,
                previous_s,
            } => write!(
                f,
                "sample {index}: time {time_s} s does not increase from {previous_s} s"
            ),
        }
    }
}

impl std::error::Error for MovingAverageError {}

/// Centred mean of `x` over `±window_s/2` around each sample on the time axis `time_s`
/// (non-decreasing), over the samples `j` with `include(j)` and a finite `x[j]` only; a
/// 1e-9·W tolerance absorbs time-stamp round-off. O(N): two pointers over prefix sums of
/// `x − x_0` (the offset keeps the sums small). The inputs are cut to the shorter length.
pub(crate) fn centred_mean(
    time_s: &[f64],
    x: &[f64],
    window_s: f64,
    edges: Edges,
    include: impl Fn(usize) -> bool,
) -> Smoothed {
    let n = time_s.len().min(x.len());
    if n == 0 {
        return Smoothed {
            values: Vec::new(),
            full_window: Vec::new(),
        };
    }
    let used = |j: usize| include(j) && x[j].is_finite();
    let x0 = (0..n).find(|&j| used(j)).map_or(0.0, |j| x[j]);
    let mut prefix = Vec::with_capacity(n + 1);
    let mut counts = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    counts.push(0usize);
    let (mut acc, mut cnt) = (0.0, 0usize);
    for (j, &v) in x.iter().enumerate().take(n) {
        if used(j) {
            acc += v - x0;
            cnt += 1;
        }
        prefix.push(acc);
        counts.push(cnt);
    }
    let half = window_s / 2.0;
    let tol = 1e-9 * window_s;
    let (t_first, t_last) = (time_s[0], time_s[n - 1]);
    let mut values = Vec::with_capacity(n);
    let mut full_window = Vec::with_capacity(n);
    // Window [lo, hi) in indices; both bounds are non-decreasing in i.
    let (mut lo, mut hi) = (0usize, 0usize);
    for i in 0..n {
        let t = time_s[i];
        let h = match edges {
            Edges::Shrink => half.min(t - t_first).min(t_last - t),
            Edges::Truncate => half,
        };
        while lo < i && time_s[lo] < t - h - tol {
            lo += 1;
        }
        if hi < i + 1 {
            hi = i + 1;
        }
        while hi < n && time_s[hi] <= t + h + tol {
            hi += 1;
        }
        let count = counts[hi] - counts[lo];
        values.push(if count == 0 {
            f64::NAN
        } else {
            x0 + (prefix[hi] - prefix[lo]) / count as f64
        });
        full_window.push(t - t_first >= half && t_last - t >= half);
    }
    Smoothed {
        values,
        full_window,
    }
}

/// The strict centred moving average of training targets: `y_i` = mean of the `x_j` with
/// `|t_j − t_i| ≤ h_i` (inclusive, with a 1e-9·W tolerance for time-stamp round-off), where
/// `h_i = min(W/2, t_i − t_0, t_end − t_i)` (`Edges::Shrink`). [`Smoothed::full_window`]
/// marks the samples with the whole window, for callers that mask the edges out of a loss.
///
/// At 1 Hz, `W = 100 s` averages 101 samples (t-50 … t+50).
///
/// Errors: window not finite and > 0, different lengths, non-finite values, time not
/// strictly increasing (each names the sample).
pub fn centred_moving_average(
    time_s: &[f64],
    x: &[f64],
    window_s: f64,
) -> Result<Smoothed, MovingAverageError> {
    if !(window_s.is_finite() && window_s > 0.0) {
        return Err(MovingAverageError::BadWindow(window_s));
    }
    if time_s.len() != x.len() {
        return Err(MovingAverageError::LengthMismatch {
            times: time_s.len(),
            values: x.len(),
        });
    }
    for i in 0..x.len() {
        if !time_s[i].is_finite() || !x[i].is_finite() {
            return Err(MovingAverageError::NonFinite { index: i });
        }
        if i > 0 && time_s[i] <= time_s[i - 1] {
            return Err(MovingAverageError::NotIncreasing {
                index: i,
                time_s: time_s[i],
                previous_s: time_s[i - 1],
            });
        }
    }
    Ok(centred_mean(time_s, x, window_s, Edges::Shrink, |_| true))
}

/// The lenient centred moving average of figures: each output is the mean of the finite
/// `y[j]` with `|t[j] − t[i]| <= window_s / 2` (NaN where there are none), the window cut
/// off at the ends ([`Edges::Truncate`]). `time_s` must be non-decreasing.
pub(crate) fn windowed_mean(time_s: &[f64], y: &[f64], window_s: f64) -> Vec<f64> {
    centred_mean(time_s, y, window_s, Edges::Truncate, |_| true).values
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windowed_mean_matches_direct_mean() {
        // Independent computation: direct O(n·w) mean over the same window, NaN skipped.
        let t: Vec<f64> = (0..500).map(|i| i as f64 * 0.5).collect();
        let mut y: Vec<f64> = t.iter().map(|x| (x * 0.37).sin() + 0.01 * x).collect();
        y[17] = f64::NAN;
        let w = 10.0;
        let got = windowed_mean(&t, &y, w);
        for i in 0..t.len() {
            let v: Vec<f64> = (0..t.len())
                .filter(|&j| (t[j] - t[i]).abs() <= w / 2.0 && y[j].is_finite())
                .map(|j| y[j])
                .collect();
            let want = v.iter().sum::<f64>() / v.len() as f64;
            assert!((got[i] - want).abs() < 1e-12, "{i}: {} vs {want}", got[i]);
        }
    }

    #[test]
    fn masked_steps_are_left_out_of_the_mean() {
        // Step axis, width 5 (±2 steps), steps 3 and 4 excluded: direct mean of the rest.
        let t: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let x: Vec<f64> = (0..10).map(|i| (i * i) as f64).collect();
        let s = centred_mean(&t, &x, 4.0, Edges::Truncate, |j| j != 3 && j != 4);
        // Sample 5: steps 3..=7 minus 3 and 4 → (25 + 36 + 49) / 3.
        assert!((s.values[5] - 110.0 / 3.0).abs() < 1e-12);
        // Sample 0: steps 0..=2.
        assert!((s.values[0] - 5.0 / 3.0).abs() < 1e-12);
    }
}

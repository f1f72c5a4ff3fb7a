//! Axes of the figures: which values can be drawn, ranges, tick labels and log-axis ticks.

use super::*;

/// Largest magnitude drawn: plotters 0.3.7's tick arithmetic never ends on an axis spanning
/// ±1e300 (found by test), and no gyro quantity comes near 1e200 in any unit.
pub(super) const MAX_DRAWN_MAGNITUDE: f64 = 1e200;

/// Finite, within ±[`MAX_DRAWN_MAGNITUDE`], and on a log axis at least its inverse.
pub(super) fn usable(v: f64, log: bool) -> bool {
    v.is_finite() && v.abs() <= MAX_DRAWN_MAGNITUDE && (!log || v >= 1.0 / MAX_DRAWN_MAGNITUDE)
}

/// Range of the usable values, padded: 4 % of the span on a linear axis, a factor on a log
/// axis; a single value gets a span of its own.
pub(super) fn padded_range(values: impl Iterator<Item = f64>, log: bool, pad: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|&v| usable(v, log)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        if hi / lo < 1.0001 {
            return (lo / 2.0, hi * 2.0);
        }
        let f = if pad { (hi / lo).powf(0.04) } else { 1.0 };
        (lo / f, hi * f)
    } else {
        let span = hi - lo;
        if span <= 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
            let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            return (lo - d, hi + d);
        }
        let p = if pad { 0.04 * span } else { 0.0 };
        (lo - p, hi + p)
    }
}

/// Index ranges of the maximal runs of points with finite x and y.
pub(super) fn finite_runs(x: &[f64], y: &[f64]) -> Vec<std::ops::Range<usize>> {
    let n = x.len().min(y.len());
    let mut runs = Vec::new();
    let mut start = None;
    for i in 0..n {
        let finite = x[i].is_finite() && y[i].is_finite();
        match (finite, start) {
            (true, None) => start = Some(i),
            (false, Some(s0)) => {
                runs.push(s0..i);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s0) = start {
        runs.push(s0..n);
    }
    runs
}

/// Tick text: plain decimals without trailing zeros (`2000`, `0.5`), scientific outside
/// 1e-3..1e5 (`1.5e5`); values within 1e-12 of zero (tick arithmetic) print as `0`.
pub(crate) fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a < 1e-12 {
        return "0".to_owned();
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.3e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = trim_zeros(mantissa);
        return format!("{mantissa}e{exponent}");
    }
    trim_zeros(&format!("{v:.6}")).to_owned()
}

pub(super) fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// Mantissa ladders for log-axis ticks, sparsest first: decades, 1-2-5, then every integer
/// mantissa, then a finer set for ranges well under a decade.
pub(super) const LOG_TICK_LADDERS: [&[f64]; 4] = [
    &[1.0],
    &[1.0, 2.0, 5.0],
    &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    &[1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
];

/// Fewest labelled ticks a log axis gets when its range allows: one label alone cannot be
/// read as a scale.
pub(super) const MIN_LOG_TICKS: usize = 3;
/// Most labelled ticks before the labels crowd each other.
pub(super) const MAX_LOG_TICKS: usize = 12;

/// Labelled ticks of a log axis over `[lo, hi]` (`0 < lo < hi`): the sparsest ladder of
/// [`LOG_TICK_LADDERS`] giving at least [`MIN_LOG_TICKS`] ticks; on a range of many decades,
/// every k-th decade so there are at most [`MAX_LOG_TICKS`].
pub(crate) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Vec::new();
    }
    let ticks_of = |ladder: &[f64]| -> Vec<f64> {
        let first = lo.log10().floor() as i32;
        let last = hi.log10().ceil() as i32;
        let mut t = Vec::new();
        for e in first..=last {
            let p = 10f64.powi(e);
            for m in ladder {
                // The product is rounded through a decimal string so labels read "0.2", not
                // "0.20000000000000004".
                let v: f64 = format!("{:.12e}", m * p).parse().unwrap_or(m * p);
                if v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12) {
                    t.push(v);
                }
            }
        }
        t
    };
    let decades = ticks_of(LOG_TICK_LADDERS[0]);
    if decades.len() > MAX_LOG_TICKS {
        let step = decades.len().div_ceil(MAX_LOG_TICKS);
        return decades.into_iter().step_by(step).collect();
    }
    let mut best = decades;
    for ladder in LOG_TICK_LADDERS {
        if best.len() >= MIN_LOG_TICKS {
            break;
        }
        let t = ticks_of(ladder);
        if t.len() > MAX_LOG_TICKS && !best.is_empty() {
            break;
        }
        best = t;
    }
    best
}

/// A log axis over `[lo, hi]` labelled at [`log_ticks`].
pub(super) fn log_axis(lo: f64, hi: f64) -> WithKeyPoints<LogCoord<f64>> {
    let ticks = log_ticks(lo, hi);
    (lo..hi)
        .log_scale()
        .with_key_points(ticks.clone())
        .with_light_points(ticks)
}

//! Scale factor from a rate-table log (IEEE Std 952 / GJB 2426A; docs/method.md definitions).
//!
//! 1. Segments: runs of constant commanded table rate `table_dps`; the first `settle_s`
//!    seconds of each are dropped, the rest averaged to F (mean output, °/s).
//! 2. Per distinct table rate Ω_j the segment means are averaged to F_j; least squares over
//!    (Ω_j, F_j) gives the scale factor K and the intercept F0 (F = K·Ω + F0).
//! 3. Nonlinearity = max_j |F_j − (K·Ω_j + F0)| / max_j |F_j|, ppm.
//! 4. Asymmetry = |K+ − K−| / ((K+ + K−)/2), ppm. K+ is fitted by least squares on the positive
//!    rates together with the zero-rate (stop) segments, K− on the negative rates with the stop
//!    segments. A side with only one distinct rate and no stop segment uses the slope through
//!    the overall intercept, mean of (F_j − F0)/Ω_j.
//! 5. K(t): for every rate segment, K_seg = (F_seg − B_local)/Ω_seg with B_local the mean of
//!    the stop segments just before and just after it (either one if only one exists; F0 if
//!    the log has no stop segment). The scale-factor thermal error is
//!    max_seg |K_seg − K_ref| / |K_ref| in ppm, K_ref the first rate segment's K (the run
//!    starts at room temperature) or a given reference. Note: with the default reference, a
//!    +/− asymmetry also shows up in this figure.

use std::fmt;

/// Options of the scale-factor evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleFactorOptions {
    /// Time dropped at the start of each segment while the table rate settles, s.
    pub settle_s: f64,
    /// Two table rates closer than this are the same command, °/s.
    pub rate_tol_dps: f64,
    /// Room-temperature scale factor to judge K(t) against (None: the first rate segment's).
    pub reference_scale: Option<f64>,
}

impl Default for ScaleFactorOptions {
    fn default() -> Self {
        ScaleFactorOptions {
            settle_s: 10.0,
            rate_tol_dps: crate::table_segments::RATE_TOLERANCE_DPS,
            reference_scale: None,
        }
    }
}

/// One run of constant commanded rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateSegment {
    /// Sample index range [start, end) of the whole run.
    pub start: usize,
    pub end: usize,
    /// Commanded table rate, °/s.
    pub table_dps: f64,
    /// Time of the first and last sample of the run, s.
    pub start_time_s: f64,
    pub end_time_s: f64,
    /// Samples left after the settle time.
    pub used_samples: usize,
    /// Mean gyro output over the used samples, °/s (NaN if none).
    pub mean_output_dps: f64,
}

/// K of one rate segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentScale {
    /// Middle of the segment, s.
    pub time_s: f64,
    pub table_dps: f64,
    /// Local bias from the neighbouring stop segments, °/s.
    pub local_bias_dps: f64,
    /// (F − B_local)/Ω, dimensionless (output °/s per input °/s).
    pub scale: f64,
    /// (K_seg − K_ref)/K_ref, ppm.
    pub deviation_ppm: f64,
}

/// All scale-factor figures of a rate-table log.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleFactorReport {
    /// Least-squares K (output °/s per table °/s).
    pub scale_factor: f64,
    /// Intercept F0, °/s.
    pub intercept_dps: f64,
    /// Distinct table rates with their mean outputs: (Ω_j °/s, F_j °/s).
    pub rate_points: Vec<(f64, f64)>,
    pub nonlinearity_ppm: f64,
    /// K+ and K−; None when the log has no rate of that sign.
    pub scale_positive: Option<f64>,
    pub scale_negative: Option<f64>,
    /// None without both signs.
    pub asymmetry_ppm: Option<f64>,
    pub segments: Vec<RateSegment>,
    /// K per rate segment across the run.
    pub scale_over_time: Vec<SegmentScale>,
    /// K_ref used for the thermal error.
    pub reference_scale: f64,
    /// max |K_seg − K_ref|/|K_ref|, ppm.
    pub sf_thermal_error_ppm: f64,
}

/// Why the scale factor could not be evaluated.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ScaleFactorError {
    /// Slices of different lengths.
    LengthMismatch {
        time: usize,
        output: usize,
        table: usize,
    },
    /// NaN or infinite value.
    NonFinite { column: &'static str, index: usize },
    /// Fewer than two distinct rates (one non-zero) with samples left after settling.
    TooFewRates { rates: usize },
    /// Bad option.
    BadOption(String),
}

impl fmt::Display for ScaleFactorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScaleFactorError::LengthMismatch { time, output, table } => write!(
                f,
                "columns differ in length (time {time}, output {output}, table {table})"
            ),
            ScaleFactorError::NonFinite { column, index } => {
                write!(f, "{column} sample {index} is NaN or infinite; clean the log first")
            }
            ScaleFactorError::TooFewRates { rates } => write!(
                f,
                "{rates} usable table rate(s) after the settle time; need two distinct rates, one non-zero (shorten the settle time or check table_dps)"
            ),
            ScaleFactorError::BadOption(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for ScaleFactorError {}

/// Runs of constant commanded rate ([`crate::table_segments::segments`] with tolerance
/// `rate_tol_dps`), each averaged after dropping `settle_s`.
pub(crate) fn detect_segments(
    time_s: &[f64],
    output_dps: &[f64],
    table_dps: &[f64],
    settle_s: f64,
    rate_tol_dps: f64,
) -> Vec<RateSegment> {
    let n = time_s.len().min(output_dps.len()).min(table_dps.len());
    crate::table_segments::segments(&table_dps[..n], rate_tol_dps)
        .into_iter()
        .map(|seg| {
            let (start, end) = (seg.start, seg.end);
            let t_settled = time_s[start] + settle_s;
            let used: Vec<f64> = (start..end)
                .filter(|&i| time_s[i] >= t_settled)
                .map(|i| output_dps[i])
                .collect();
            RateSegment {
                start,
                end,
                table_dps: seg.rate_dps,
                start_time_s: time_s[start],
                end_time_s: time_s[end - 1],
                used_samples: used.len(),
                mean_output_dps: if used.is_empty() {
                    f64::NAN
                } else {
                    super::mean(&used)
                },
            }
        })
        .collect()
}

/// Least squares F = K·Ω + F0; None with fewer than two distinct Ω.
fn fit_line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let k = sxy / sxx;
    Some((k, my - k * mx))
}

/// Scale-factor figures from time, gyro output (°/s) and commanded table rate (°/s).
pub fn scale_factor(
    time_s: &[f64],
    output_dps: &[f64],
    table_dps: &[f64],
    opts: &ScaleFactorOptions,
) -> Result<ScaleFactorReport, ScaleFactorError> {
    if time_s.len() != output_dps.len() || time_s.len() != table_dps.len() {
        return Err(ScaleFactorError::LengthMismatch {
            time: time_s.len(),
            output: output_dps.len(),
            table: table_dps.len(),
        });
    }
    for (column, v) in [
        ("time_s", time_s),
        ("gyro", output_dps),
        ("table_dps", table_dps),
    ] {
        if let Some(index) = v.iter().position(|x| !x.is_finite()) {
            return Err(ScaleFactorError::NonFinite { column, index });
        }
    }
    if !(opts.settle_s.is_finite() && opts.settle_s >= 0.0) {
        return Err(ScaleFactorError::BadOption(format!(
            "settle time {} s must be a finite number ≥ 0",
            opts.settle_s
        )));
    }
    let tol = opts.rate_tol_dps.max(0.0);
    let segments = detect_segments(time_s, output_dps, table_dps, opts.settle_s, tol);
    let usable: Vec<&RateSegment> = segments.iter().filter(|s| s.used_samples > 0).collect();

    // Distinct rates, each the mean of its segments' means.
    let mut rate_points: Vec<(f64, f64, usize)> = Vec::new();
    for s in &usable {
        match rate_points
            .iter_mut()
            .find(|p| (p.0 - s.table_dps).abs() <= tol)
        {
            Some(p) => {
                p.1 += s.mean_output_dps;
                p.2 += 1;
            }
            None => rate_points.push((s.table_dps, s.mean_output_dps, 1)),
        }
    }
    let mut rate_points: Vec<(f64, f64)> = rate_points
        .into_iter()
        .map(|(r, sum, c)| (r, sum / c as f64))
        .collect();
    rate_points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let nonzero = rate_points.iter().any(|p| p.0.abs() > tol);
    let (k, f0) = match fit_line(&rate_points) {
        Some(fit) if nonzero => fit,
        _ => {
            return Err(ScaleFactorError::TooFewRates {
                rates: rate_points.len(),
            })
        }
    };
    let f_max = rate_points.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    let max_resid = rate_points
        .iter()
        .map(|p| (p.1 - (k * p.0 + f0)).abs())
        .fold(0.0, f64::max);
    let nonlinearity_ppm = max_resid / f_max * 1e6;

    let side = |positive: bool| -> Option<f64> {
        let signed: Vec<(f64, f64)> = rate_points
            .iter()
            .copied()
            .filter(|p| if positive { p.0 > tol } else { p.0 < -tol })
            .collect();
        if signed.is_empty() {
            return None;
        }
        let mut with_zero = signed.clone();
        with_zero.extend(rate_points.iter().copied().filter(|p| p.0.abs() <= tol));
        match fit_line(&with_zero) {
            Some((k, _)) => Some(k),
            None => {
                Some(signed.iter().map(|p| (p.1 - f0) / p.0).sum::<f64>() / signed.len() as f64)
            }
        }
    };
    let scale_positive = side(true);
    let scale_negative = side(false);
    let asymmetry_ppm = match (scale_positive, scale_negative) {
        (Some(kp), Some(kn)) => Some((kp - kn).abs() / ((kp + kn) / 2.0).abs() * 1e6),
        _ => None,
    };

    // K(t) per rate segment with the local bias of neighbouring stop segments.
    let stops: Vec<(usize, f64)> = usable
        .iter()
        .enumerate()
        .filter(|(_, s)| s.table_dps.abs() <= tol)
        .map(|(i, s)| (i, s.mean_output_dps))
        .collect();
    let mut scale_over_time: Vec<SegmentScale> = Vec::new();
    for (i, s) in usable.iter().enumerate() {
        if s.table_dps.abs() <= tol {
            continue;
        }
        let before = stops.iter().rev().find(|(j, _)| *j < i).map(|p| p.1);
        let after = stops.iter().find(|(j, _)| *j > i).map(|p| p.1);
        let local_bias_dps = match (before, after) {
            (Some(a), Some(b)) => 0.5 * (a + b),
            (Some(a), None) | (None, Some(a)) => a,
            (None, None) => f0,
        };
        scale_over_time.push(SegmentScale {
            time_s: 0.5 * (s.start_time_s + s.end_time_s),
            table_dps: s.table_dps,
            local_bias_dps,
            scale: (s.mean_output_dps - local_bias_dps) / s.table_dps,
            deviation_ppm: f64::NAN,
        });
    }
    let reference_scale = opts
        .reference_scale
        .or_else(|| scale_over_time.first().map(|s| s.scale))
        .unwrap_or(k);
    let mut sf_thermal_error_ppm = 0.0f64;
    for s in &mut scale_over_time {
        s.deviation_ppm = (s.scale - reference_scale) / reference_scale.abs() * 1e6;
        sf_thermal_error_ppm = sf_thermal_error_ppm.max(s.deviation_ppm.abs());
    }
    Ok(ScaleFactorReport {
        scale_factor: k,
        intercept_dps: f0,
        rate_points,
        nonlinearity_ppm,
        scale_positive,
        scale_negative,
        asymmetry_ppm,
        segments,
        scale_over_time,
        reference_scale,
        sf_thermal_error_ppm,
    })
}

//! One rate column of a test log judged with the standard figures: bias and bias stability
//! (from the stop segments only on a rate-table log) and, when the log has a table column,
//! the scale-factor figures. This is what `gyrotherm evaluate` prints; the result serialises
//! to the JSON it prints with `--json` (non-finite numbers become `null`).

use std::fmt;

use serde::Serialize;

use super::{
    bias_dph, bias_stability_dph, scale_factor, stop_segment_bias_dph, MetricsError,
    ScaleFactorError, ScaleFactorOptions, ScaleFactorReport,
};

/// Settings of an evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvaluationOptions {
    /// Smoothing time of the bias stability, s (100 s per docs/method.md).
    pub tau_s: f64,
    /// Time dropped at the start of each rate-table segment, s.
    pub settle_s: f64,
    /// Room-temperature scale factor for the thermal error (None: the first rate segment's).
    pub reference_scale: Option<f64>,
}

impl Default for EvaluationOptions {
    fn default() -> Self {
        EvaluationOptions {
            tau_s: 100.0,
            settle_s: ScaleFactorOptions::default().settle_s,
            reference_scale: None,
        }
    }
}

/// The standard figures of one rate column.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluation {
    /// Name of the column judged.
    pub column: String,
    pub samples: usize,
    pub sample_period_s: f64,
    /// Bias B0, °/h (stop segments only on a rate-table log).
    pub bias_dph: f64,
    /// 1σ of the τ-means, °/h.
    pub bias_stability_dph: f64,
    /// τ of the bias stability, s.
    pub tau_s: f64,
    /// Number of τ-means.
    pub means: usize,
    /// True when bias and bias stability come from the stop segments of a rate-table log.
    #[serde(skip)]
    pub stop_segments_only: bool,
    /// Scale-factor figures of a log with a table column.
    #[serde(flatten)]
    pub scale: Option<ScaleFactorFigures>,
}

/// The scale-factor part of an [`Evaluation`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScaleFactorFigures {
    pub scale_factor: f64,
    pub intercept_dps: f64,
    pub nonlinearity_ppm: f64,
    pub asymmetry_ppm: Option<f64>,
    pub scale_positive: Option<f64>,
    pub scale_negative: Option<f64>,
    pub sf_thermal_error_ppm: f64,
    pub reference_scale: f64,
    pub settle_s: f64,
    pub rate_points: Vec<RatePoint>,
    pub scale_over_time: Vec<ScaleAtTime>,
}

/// Mean output at one distinct table rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RatePoint {
    pub table_dps: f64,
    pub mean_output_dps: f64,
}

/// K of one rate segment across the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ScaleAtTime {
    pub time_s: f64,
    pub table_dps: f64,
    pub scale: f64,
    pub deviation_ppm: f64,
}

impl ScaleFactorFigures {
    fn new(r: &ScaleFactorReport, settle_s: f64) -> Self {
        ScaleFactorFigures {
            scale_factor: r.scale_factor,
            intercept_dps: r.intercept_dps,
            nonlinearity_ppm: r.nonlinearity_ppm,
            asymmetry_ppm: r.asymmetry_ppm,
            scale_positive: r.scale_positive,
            scale_negative: r.scale_negative,
            sf_thermal_error_ppm: r.sf_thermal_error_ppm,
            reference_scale: r.reference_scale,
            settle_s,
            rate_points: r
                .rate_points
                .iter()
                .map(|&(table_dps, mean_output_dps)| RatePoint {
                    table_dps,
                    mean_output_dps,
                })
                .collect(),
            scale_over_time: r
                .scale_over_time
                .iter()
                .map(|s| ScaleAtTime {
                    time_s: s.time_s,
                    table_dps: s.table_dps,
                    scale: s.scale,
                    deviation_ppm: s.deviation_ppm,
                })
                .collect(),
        }
    }
}

/// Which figure of an evaluation failed.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum EvaluationError {
    /// Bias of the column.
    Bias(MetricsError),
    /// Bias stability of the column.
    BiasStability(MetricsError),
    /// Bias and bias stability over the stop segments of a rate-table log.
    StopSegments(MetricsError),
    /// Scale factor from the table column.
    ScaleFactor(ScaleFactorError),
    /// Finite rates so large that a figure is beyond f64 (e.g. °/h of a rate near f64::MAX);
    /// the sample of largest magnitude (index from 0, its time and value in °/s).
    TooLarge {
        index: usize,
        time_s: f64,
        value_dps: f64,
    },
}

impl fmt::Display for EvaluationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvaluationError::Bias(_) => write!(f, "bias"),
            EvaluationError::BiasStability(_) => write!(f, "bias stability"),
            EvaluationError::StopSegments(_) => write!(f, "bias over the stop segments"),
            EvaluationError::ScaleFactor(_) => write!(f, "scale factor from table_dps"),
            EvaluationError::TooLarge {
                index,
                time_s,
                value_dps,
            } => write!(
                f,
                "sample {} (time {time_s} s) is {value_dps:e} °/s: too large for the figures to \
                 be represented; check the column's unit or remove the outlier",
                index + 1
            ),
        }
    }
}

impl std::error::Error for EvaluationError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            EvaluationError::Bias(e)
            | EvaluationError::BiasStability(e)
            | EvaluationError::StopSegments(e) => Some(e),
            EvaluationError::ScaleFactor(e) => Some(e),
            EvaluationError::TooLarge { .. } => None,
        }
    }
}

/// Judge `rate_dps` (°/s, one value per sample of `time_s`, sampled every
/// `sample_period_s`) named `column`; `table_dps` is the log's table column, if any.
pub fn evaluate(
    column: &str,
    time_s: &[f64],
    rate_dps: &[f64],
    sample_period_s: f64,
    table_dps: Option<&[f64]>,
    opts: &EvaluationOptions,
) -> Result<Evaluation, EvaluationError> {
    // Rates of extreme magnitude are judged divided by a power of two (exact: every figure
    // is proportional to the rates or independent of their scale), so no sum overflows or
    // underflows; a figure still beyond f64 once scaled back is refused.
    if let Some(s) = crate::allan::rescale_for_range(rate_dps) {
        let scaled: Vec<f64> = rate_dps.iter().map(|v| v / s).collect();
        let scaled_opts = EvaluationOptions {
            reference_scale: opts.reference_scale.map(|k| k / s),
            ..*opts
        };
        let mut e = evaluate(
            column,
            time_s,
            &scaled,
            sample_period_s,
            table_dps,
            &scaled_opts,
        )?;
        e.scale_rates(s);
        if !e.is_finite() {
            let index = (0..rate_dps.len())
                .max_by(|&a, &b| rate_dps[a].abs().total_cmp(&rate_dps[b].abs()))
                .unwrap_or(0);
            return Err(EvaluationError::TooLarge {
                index,
                time_s: time_s.get(index).copied().unwrap_or(f64::NAN),
                value_dps: rate_dps[index],
            });
        }
        return Ok(e);
    }
    // A rate-table log's bias comes from its stop segments only.
    let stop_segments_only = table_dps.is_some_and(|t| t.iter().any(|w| *w != 0.0));
    let (bias, stab) = match table_dps {
        Some(table) if stop_segments_only => {
            stop_segment_bias_dph(time_s, rate_dps, table, opts.settle_s, opts.tau_s)
                .map_err(EvaluationError::StopSegments)?
        }
        _ => (
            bias_dph(rate_dps).map_err(EvaluationError::Bias)?,
            bias_stability_dph(rate_dps, sample_period_s, opts.tau_s)
                .map_err(EvaluationError::BiasStability)?,
        ),
    };
    let scale = match table_dps {
        None => None,
        Some(table) => {
            let sf_opts = ScaleFactorOptions {
                settle_s: opts.settle_s,
                reference_scale: opts.reference_scale,
                ..Default::default()
            };
            let r = scale_factor(time_s, rate_dps, table, &sf_opts)
                .map_err(EvaluationError::ScaleFactor)?;
            Some(ScaleFactorFigures::new(&r, opts.settle_s))
        }
    };
    Ok(Evaluation {
        column: column.to_owned(),
        samples: rate_dps.len(),
        sample_period_s,
        bias_dph: bias,
        bias_stability_dph: stab.bias_stability_dph,
        tau_s: stab.tau_s,
        means: stab.means,
        stop_segments_only: scale.is_some(),
        scale,
    })
}

impl Evaluation {
    /// Multiply every figure in the unit of the rates by `s` (ratios and ppm stay).
    fn scale_rates(&mut self, s: f64) {
        self.bias_dph *= s;
        self.bias_stability_dph *= s;
        if let Some(f) = &mut self.scale {
            f.scale_factor *= s;
            f.intercept_dps *= s;
            f.scale_positive = f.scale_positive.map(|k| k * s);
            f.scale_negative = f.scale_negative.map(|k| k * s);
            f.reference_scale *= s;
            for p in &mut f.rate_points {
                p.mean_output_dps *= s;
            }
            for p in &mut f.scale_over_time {
                p.scale *= s;
            }
        }
    }

    /// Whether every figure that was computed is finite.
    fn is_finite(&self) -> bool {
        let mut v = vec![self.bias_dph, self.bias_stability_dph];
        if let Some(f) = &self.scale {
            v.extend([
                f.scale_factor,
                f.intercept_dps,
                f.nonlinearity_ppm,
                f.sf_thermal_error_ppm,
                f.reference_scale,
            ]);
            v.extend(f.scale_positive);
            v.extend(f.scale_negative);
            v.extend(f.asymmetry_ppm);
            v.extend(f.rate_points.iter().map(|p| p.mean_output_dps));
            v.extend(f.scale_over_time.iter().map(|p| p.scale));
        }
        v.iter().all(|x| x.is_finite())
    }
}

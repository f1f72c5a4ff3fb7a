//! The named figures of the report (after the figures of He et al. 2024,
//! DOI 10.19452/j.issn1007-5453.2024.02.004), each a function over plain data, and the Allan
//! figure that `gyrotherm allan --plot` reuses. Every function takes a path (with or
//! without `.png`/`.svg`, see `figure_paths`) and writes the
//! PNG and the SVG.
//!
//! Units: time s, temperature °C, temperature rate °C/min, gyro output °/h, rate-table rate
//! °/s, scale factor ppm.

use crate::moving_average::windowed_mean;
use std::path::Path;

use super::plot::{
    write_figure, Figure, FigureFiles, Panel, Series, SeriesStyle, FIGURE_HEIGHT_2_PANELS_PX,
    FIGURE_HEIGHT_PX, FIGURE_WIDTH_PX,
};
use super::ReportError;

const TIME_LABEL: &str = "time (s)";
const GREY: (u8, u8, u8) = (150, 150, 150);
const BLUE: (u8, u8, u8) = (0, 90, 170);
const ORANGE: (u8, u8, u8) = (213, 94, 0);
const GREEN: (u8, u8, u8) = (0, 140, 100);

fn one_panel(title: &str, x_label: &str, panel: Panel) -> Figure {
    Figure {
        title: title.to_owned(),
        x_label: x_label.to_owned(),
        log_x: false,
        width_px: FIGURE_WIDTH_PX,
        height_px: FIGURE_HEIGHT_PX,
        panels: vec![panel],
    }
}

fn two_panels(title: &str, x_label: &str, top: Panel, bottom: Panel) -> Figure {
    Figure {
        title: title.to_owned(),
        x_label: x_label.to_owned(),
        log_x: false,
        width_px: FIGURE_WIDTH_PX,
        height_px: FIGURE_HEIGHT_2_PANELS_PX,
        panels: vec![top, bottom],
    }
}

fn panel(y_label: &str, series: Vec<Series>) -> Panel {
    Panel {
        y_label: y_label.to_owned(),
        log_y: false,
        series,
    }
}

/// Data of figure 1: the temperature cycle.
#[derive(Debug, Clone, Copy)]
pub struct TemperatureData<'a> {
    pub time_s: &'a [f64],
    /// Gyro (sensor) temperature, °C.
    pub gyro_temp_c: &'a [f64],
    /// Chamber temperature, °C, when logged.
    pub chamber_temp_c: Option<&'a [f64]>,
    /// Rate of change of the gyro temperature, °C/min.
    pub temp_rate_c_per_min: &'a [f64],
}

/// Figure 1: chamber and gyro temperature (°C, top) and temperature rate (°C/min, bottom)
/// against time (s). 1000 × 800 px.
pub fn temperature_figure(path: &Path, d: &TemperatureData) -> Result<FigureFiles, ReportError> {
    let mut temps = Vec::new();
    if let Some(chamber) = d.chamber_temp_c {
        temps.push(Series::line("chamber", d.time_s, chamber).with_color(ORANGE));
    }
    temps.push(Series::line("gyro", d.time_s, d.gyro_temp_c).with_color(BLUE));
    let rate = vec![
        Series::line("gyro temperature rate", d.time_s, d.temp_rate_c_per_min).with_color(GREEN),
    ];
    write_figure(
        path,
        &two_panels(
            "Temperature cycle",
            TIME_LABEL,
            panel("temperature (°C)", temps),
            panel("temperature rate (°C/min)", rate),
        ),
    )
}

/// Data of figure 2: the raw gyro output.
#[derive(Debug, Clone, Copy)]
pub struct RawOutputData<'a> {
    pub time_s: &'a [f64],
    /// Gyro output, °/h.
    pub gyro_dph: &'a [f64],
    /// Moving-average window, s (the report uses 100 s).
    pub window_s: f64,
}

/// Figure 2: raw output (°/h) and its centred moving average over `window_s` against time.
/// 1000 × 600 px.
pub fn raw_output_figure(path: &Path, d: &RawOutputData) -> Result<FigureFiles, ReportError> {
    check_window(d.window_s, "raw output figure")?;
    check_len("raw output: gyro_dph", d.time_s, d.gyro_dph)?;
    let avg = windowed_mean(d.time_s, d.gyro_dph, d.window_s);
    let series = vec![
        Series::line("raw output", d.time_s, d.gyro_dph).with_color(GREY),
        Series::line(
            format!("{} s moving average", fmt_num(d.window_s)),
            d.time_s,
            &avg,
        )
        .with_color(ORANGE),
    ];
    write_figure(
        path,
        &one_panel(
            "Raw gyro output",
            TIME_LABEL,
            panel("gyro output (°/h)", series),
        ),
    )
}

/// One training-loss curve of figure 3.
#[derive(Debug, Clone, Copy)]
pub struct LossCurve<'a> {
    /// e.g. "bias network, training".
    pub label: &'a str,
    /// Loss per epoch, epoch 1 first.
    pub loss: &'a [f64],
}

/// Figure 3: training loss (log scale) against epoch for each curve (both networks, training
/// and validation as the caller chooses). Non-positive losses are left out (log axis).
/// 1000 × 600 px.
pub fn loss_figure(path: &Path, curves: &[LossCurve]) -> Result<FigureFiles, ReportError> {
    let series = curves
        .iter()
        .map(|c| {
            let epoch: Vec<f64> = (1..=c.loss.len()).map(|e| e as f64).collect();
            Series::line(c.label, &epoch, c.loss)
        })
        .collect();
    let mut p = panel("loss (mean squared error)", series);
    p.log_y = true;
    write_figure(path, &one_panel("Training loss", "epoch", p))
}

/// Data of figure 4: each model's bias prediction on the held-out run.
#[derive(Debug, Clone, Copy)]
pub struct BiasData<'a> {
    pub time_s: &'a [f64],
    /// Measured bias, °/h.
    pub measured_dph: &'a [f64],
    /// Predicted bias, °/h, one series per model (the default model's first), each labelled
    /// by the model's name.
    pub predicted: &'a [NamedSeries<'a>],
}

/// Colours of the models' series in figure 4, one per model in order (the measured bias
/// is grey).
const MODEL_COLORS: [(u8, u8, u8); 7] = [
    ORANGE,
    BLUE,
    GREEN,
    (150, 80, 150),
    (200, 150, 0),
    (86, 160, 220),
    (180, 40, 40),
];

/// Figure 4: each model's predicted and the measured bias (°/h, top) and each residual
/// measured − predicted (°/h, bottom) against time. 1000 × 800 px.
pub fn bias_figure(path: &Path, d: &BiasData) -> Result<FigureFiles, ReportError> {
    check_len("bias: measured_dph", d.time_s, d.measured_dph)?;
    for p in d.predicted {
        check_len(
            &format!("bias: predicted_dph of {}", p.label),
            d.time_s,
            p.values_dph,
        )?;
    }
    let residuals: Vec<Vec<f64>> = d
        .predicted
        .iter()
        .map(|p| {
            d.measured_dph
                .iter()
                .zip(p.values_dph)
                .map(|(m, p)| m - p)
                .collect()
        })
        .collect();
    let color = |i: usize| MODEL_COLORS[i % MODEL_COLORS.len()];
    let mut top = vec![Series::line("measured", d.time_s, d.measured_dph).with_color(GREY)];
    top.extend(d.predicted.iter().enumerate().map(|(i, p)| {
        Series::line(format!("{} predicted", p.label), d.time_s, p.values_dph).with_color(color(i))
    }));
    let bottom = d
        .predicted
        .iter()
        .zip(&residuals)
        .enumerate()
        .map(|(i, (p, r))| {
            Series::line(format!("measured − {}", p.label), d.time_s, r).with_color(color(i))
        })
        .collect();
    write_figure(
        path,
        &two_panels(
            "Bias: predicted against measured (held-out run)",
            TIME_LABEL,
            panel("bias (°/h)", top),
            panel("residual (°/h)", bottom),
        ),
    )
}

/// Data of figure 5: scale factor per rate-table segment.
#[derive(Debug, Clone, Copy)]
pub struct ScaleFactorData<'a> {
    /// Time of each segment (e.g. its midpoint), s.
    pub time_s: &'a [f64],
    /// Measured scale-factor deviation, ppm.
    pub measured_ppm: &'a [f64],
    /// Predicted scale-factor deviation, ppm.
    pub predicted_ppm: &'a [f64],
}

/// Figure 5: predicted and measured scale factor (ppm) per segment against segment time.
/// 1000 × 600 px.
pub fn scale_factor_figure(path: &Path, d: &ScaleFactorData) -> Result<FigureFiles, ReportError> {
    let series = vec![
        Series::line("measured", d.time_s, d.measured_ppm)
            .with_style(SeriesStyle::LinePoints)
            .with_color(GREY),
        Series::line("predicted", d.time_s, d.predicted_ppm)
            .with_style(SeriesStyle::LinePoints)
            .with_color(ORANGE),
    ];
    write_figure(
        path,
        &one_panel(
            "Scale factor: predicted against measured",
            "segment time (s)",
            panel("scale-factor deviation (ppm)", series),
        ),
    )
}

/// The abscissa of figure 6.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RateAxis {
    /// Time, s.
    TimeS,
    /// Gyro temperature, °C.
    TempC,
}

/// One rate-table segment of figure 6.
#[derive(Debug, Clone, Copy)]
pub struct RateSegment<'a> {
    /// Table rate, °/s (e.g. +20 or −20).
    pub rate_dps: f64,
    /// Abscissa: time (s) or gyro temperature (°C), see [`RateTableData::axis`].
    pub x: &'a [f64],
    /// Output minus table rate before compensation, °/h.
    pub before_dph: &'a [f64],
    /// Output minus table rate after compensation, °/h.
    pub after_dph: &'a [f64],
}

/// Data of figure 6.
#[derive(Debug, Clone, Copy)]
pub struct RateTableData<'a> {
    pub axis: RateAxis,
    /// One panel each, top to bottom (1 to 4 segments).
    pub segments: &'a [RateSegment<'a>],
}

/// Figure 6: output error at each table rate (output − table rate, °/h) before and after
/// compensation, one panel per rate, against time or temperature. 1000 × 400·n px (at least
/// 600).
pub fn rate_table_figure(path: &Path, d: &RateTableData) -> Result<FigureFiles, ReportError> {
    if d.segments.is_empty() || d.segments.len() > 4 {
        return Err(ReportError::Data {
            what: format!(
                "rate-table figure: {} segments given; give 1 to 4 (e.g. +20 °/s and −20 °/s)",
                d.segments.len()
            ),
        });
    }
    let x_label = match d.axis {
        RateAxis::TimeS => TIME_LABEL,
        RateAxis::TempC => "gyro temperature (°C)",
    };
    let panels = d
        .segments
        .iter()
        .map(|s| {
            panel(
                &format!("error at {:+} °/s (°/h)", s.rate_dps),
                vec![
                    Series::line("before compensation", s.x, s.before_dph).with_color(GREY),
                    Series::line("after compensation", s.x, s.after_dph).with_color(BLUE),
                ],
            )
        })
        .collect::<Vec<_>>();
    let height = (400 * panels.len() as u32).max(FIGURE_HEIGHT_PX);
    write_figure(
        path,
        &Figure {
            title: "Rate-table output before and after compensation".to_owned(),
            x_label: x_label.to_owned(),
            log_x: false,
            width_px: FIGURE_WIDTH_PX,
            height_px: height,
            panels,
        },
    )
}

/// One named output series of figure 7.
#[derive(Debug, Clone, Copy)]
pub struct NamedSeries<'a> {
    /// e.g. "raw", "linear", "polynomial", "LSTM".
    pub label: &'a str,
    /// Output, °/h, one value per time sample.
    pub values_dph: &'a [f64],
}

/// Data of figure 7: the held-out run before and after each compensation.
#[derive(Debug, Clone, Copy)]
pub struct CompensationData<'a> {
    pub time_s: &'a [f64],
    /// Raw first, then each method.
    pub series: &'a [NamedSeries<'a>],
    /// Averaging window, s (the report uses 100 s).
    pub window_s: f64,
}

/// Figure 7: held-out output (°/h) before and after compensation, each series as means over
/// consecutive `window_s` windows (drawn at the window centres). 1000 × 600 px.
pub fn compensation_figure(path: &Path, d: &CompensationData) -> Result<FigureFiles, ReportError> {
    check_window(d.window_s, "compensation figure")?;
    let mut series = Vec::with_capacity(d.series.len());
    for s in d.series {
        check_len(
            &format!("compensation: {}", s.label),
            d.time_s,
            s.values_dph,
        )?;
        let (t, m) = window_means(d.time_s, s.values_dph, d.window_s);
        series.push(Series::line(s.label, &t, &m));
    }
    write_figure(
        path,
        &one_panel(
            "Held-out run before and after compensation",
            TIME_LABEL,
            panel(
                &format!("output, {} s means (°/h)", fmt_num(d.window_s)),
                series,
            ),
        ),
    )
}

/// One point of an Allan curve with its confidence interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AllanPointPlot {
    /// Averaging time τ, s.
    pub tau_s: f64,
    /// Allan deviation σ(τ), in the figure's unit.
    pub dev: f64,
    /// Lower and upper ends of the confidence interval of σ(τ).
    pub lo: f64,
    pub hi: f64,
}

/// One Allan deviation curve.
#[derive(Debug, Clone, PartialEq)]
pub struct AllanCurve {
    pub label: String,
    pub points: Vec<AllanPointPlot>,
}

/// A noise term identified on the Allan curve (IEEE Std 952-1997 annex C; docs/method.md), in the
/// figure's unit `u` with τ in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoiseTerm {
    /// Angle random walk N (u·√s): σ(τ) = N / √τ, slope −1/2, σ(1 s) = N.
    /// (In °/√h: N[°/h·√s] / 60.)
    AngleRandomWalk { n: f64 },
    /// Bias instability B (u): flat line σ = 0.6643·B (0.6643 = √(2 ln 2 / π)).
    BiasInstability { b: f64 },
    /// Rate random walk K (u/√s): σ(τ) = K·√(τ/3), slope +1/2, σ(3 s) = K.
    RateRandomWalk { k: f64 },
    /// Quantization noise Q (u·s): σ(τ) = √3·Q / τ, slope −1.
    Quantization { q: f64 },
}

impl NoiseTerm {
    /// σ(τ) of this term alone.
    pub fn sigma(&self, tau_s: f64) -> f64 {
        match *self {
            NoiseTerm::AngleRandomWalk { n } => n / tau_s.sqrt(),
            NoiseTerm::BiasInstability { b } => BIAS_INSTABILITY_FACTOR * b,
            NoiseTerm::RateRandomWalk { k } => k * (tau_s / 3.0).sqrt(),
            NoiseTerm::Quantization { q } => 3f64.sqrt() * q / tau_s,
        }
    }
}

/// √(2 ln 2 / π), IEEE Std 952-1997 eq. C.19: the flat floor of σ(τ) is 0.6643·B.
pub(crate) const BIAS_INSTABILITY_FACTOR: f64 = 0.664_282_470_267_960_1;

/// A noise term drawn as a dashed slope line across the τ range of the curves.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseLine {
    /// Legend text, e.g. "ARW N = 0.012 °/√h".
    pub label: String,
    pub term: NoiseTerm,
}

/// Figure 8 (and `gyrotherm allan --plot`): Allan deviation σ(τ) of each curve on log-log
/// axes with its confidence bars (`lo`..`hi` per point), and each noise term as a dashed
/// slope line. `unit_label` is the unit of σ, e.g. `"°/h"`. Points with non-positive or
/// non-finite values are left out (log axes). 1000 × 600 px.
pub fn allan_figure(
    path: &Path,
    curves: &[AllanCurve],
    noise_lines: &[NoiseLine],
    unit_label: &str,
) -> Result<FigureFiles, ReportError> {
    let mut series = Vec::new();
    let (mut tau_min, mut tau_max) = (f64::INFINITY, 0.0f64);
    for c in curves {
        let tau: Vec<f64> = c.points.iter().map(|p| p.tau_s).collect();
        for &t in tau.iter().filter(|t| t.is_finite() && **t > 0.0) {
            tau_min = tau_min.min(t);
            tau_max = tau_max.max(t);
        }
        let dev: Vec<f64> = c.points.iter().map(|p| p.dev).collect();
        let lo: Vec<f64> = c.points.iter().map(|p| p.lo).collect();
        let hi: Vec<f64> = c.points.iter().map(|p| p.hi).collect();
        let mut s = Series::line(c.label.as_str(), &tau, &dev).with_style(SeriesStyle::LinePoints);
        s.bars = Some((lo, hi));
        series.push(s);
    }
    if tau_min <= tau_max {
        const LINE_COLORS: [(u8, u8, u8); 4] =
            [(120, 120, 120), (180, 40, 40), (90, 60, 160), (40, 120, 40)];
        for (i, l) in noise_lines.iter().enumerate() {
            // 64 points, evenly spaced in log τ, over the curves' τ range.
            let n = 64;
            let ratio = tau_max / tau_min;
            let tau: Vec<f64> = (0..n)
                .map(|j| tau_min * ratio.powf(j as f64 / (n - 1) as f64))
                .collect();
            let sigma: Vec<f64> = tau.iter().map(|&t| l.term.sigma(t)).collect();
            series.push(
                Series::line(l.label.as_str(), &tau, &sigma)
                    .with_style(SeriesStyle::Dashed)
                    .with_color(LINE_COLORS[i % LINE_COLORS.len()]),
            );
        }
    }
    let figure = Figure {
        title: "Allan deviation".to_owned(),
        x_label: "averaging time τ (s)".to_owned(),
        log_x: true,
        width_px: FIGURE_WIDTH_PX,
        height_px: FIGURE_HEIGHT_PX,
        panels: vec![Panel {
            y_label: format!("Allan deviation σ(τ) ({unit_label})"),
            log_y: true,
            series,
        }],
    };
    write_figure(path, &figure)
}

/// Means of `y` over consecutive windows of `window_s` starting at `time_s[0]`: returns the
/// window centres (s) and the means of the finite samples in each; empty windows are
/// skipped. `time_s` must be non-decreasing.
pub(crate) fn window_means(time_s: &[f64], y: &[f64], window_s: f64) -> (Vec<f64>, Vec<f64>) {
    let n = time_s.len().min(y.len());
    let (mut centres, mut means) = (Vec::new(), Vec::new());
    let Some(&t0) = time_s.first() else {
        return (centres, means);
    };
    let mut i = 0;
    while i < n {
        let k = ((time_s[i] - t0) / window_s).floor();
        let end_t = t0 + (k + 1.0) * window_s;
        let (mut sum, mut count) = (0.0, 0usize);
        while i < n && time_s[i] < end_t {
            if y[i].is_finite() {
                sum += y[i];
                count += 1;
            }
            i += 1;
        }
        if count > 0 {
            centres.push(t0 + (k + 0.5) * window_s);
            means.push(sum / count as f64);
        }
        if !time_s.get(i).is_some_and(|t| t.is_finite()) && i < n {
            // A non-finite time cannot be placed in a window: skip it.
            i += 1;
        }
    }
    (centres, means)
}

fn check_len(what: &str, time_s: &[f64], y: &[f64]) -> Result<(), ReportError> {
    if time_s.len() != y.len() {
        return Err(ReportError::Data {
            what: format!(
                "{what} has {} values but time_s has {}; give one value per time sample",
                y.len(),
                time_s.len()
            ),
        });
    }
    Ok(())
}

fn check_window(window_s: f64, what: &str) -> Result<(), ReportError> {
    if !(window_s.is_finite() && window_s > 0.0) {
        return Err(ReportError::Data {
            what: format!("{what}: averaging window {window_s} s must be a positive number"),
        });
    }
    Ok(())
}

/// `100` rather than `100.0`, `0.5` as is.
pub(crate) fn fmt_num(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_means_of_a_ramp_are_its_centres() {
        // y = t sampled every 1 s from 0: the mean over [100k, 100k+100) is 100k + 49.5.
        let t: Vec<f64> = (0..1000).map(|i| i as f64).collect();
        let (c, m) = window_means(&t, &t, 100.0);
        assert_eq!(c.len(), 10);
        for k in 0..10 {
            let want = 100.0 * k as f64 + 49.5;
            assert!(
                (m[k] - want).abs() < 1e-9,
                "window {k}: want {want} got {}",
                m[k]
            );
            assert_eq!(c[k], 100.0 * k as f64 + 50.0);
        }
    }

    #[test]
    fn noise_terms_follow_ieee952() {
        // IEEE Std 952 annex C: σ_ARW(1 s) = N, σ_RRW(3 s) = K, floor 0.6643·B.
        let n = NoiseTerm::AngleRandomWalk { n: 0.3 };
        assert!((n.sigma(1.0) - 0.3).abs() < 1e-15);
        assert!((n.sigma(4.0) - 0.15).abs() < 1e-15);
        let k = NoiseTerm::RateRandomWalk { k: 0.02 };
        assert!((k.sigma(3.0) - 0.02).abs() < 1e-15);
        let want = (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt();
        assert!(
            (BIAS_INSTABILITY_FACTOR - want).abs() < 1e-15,
            "want {want}"
        );
    }
}

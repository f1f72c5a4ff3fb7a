//! The full report of a held-out comparison (`gyrotherm report`): the eight figures of
//! issue 6 computed from the logs and the [`Comparison`], the comparison table, the model
//! metadata and the warnings, written as `DIR/index.html` beside one PNG and SVG per figure.
//!
//! Figures that cannot apply to the data given (no rate-table held-out log, no LSTM fitted,
//! ...) are left out with a note on the page, never an error.
//!
//! Which log each figure shows: figures 1, 2 and 7 the first static held-out log (else the
//! first held-out log), figures 4 and 8 the first static held-out log, figures 5 and 6 the
//! first rate-table held-out log. "Compensated" means the LSTM model's output through the
//! flight compensator (`MethodResult::compensated`).

use std::path::{Path, PathBuf};

use super::figure::FigureFiles;
use super::figures::{
    allan_figure, bias_figure, compensation_figure, loss_figure, rate_table_figure,
    raw_output_figure, scale_factor_figure, temperature_figure, AllanCurve, AllanPointPlot,
    BiasData, CompensationData, LossCurve, NamedSeries, NoiseLine, NoiseTerm, RateAxis,
    RateSegment, RateTableData, RawOutputData, ScaleFactorData, TemperatureData,
};
use super::html::{write_report, ReportContent, ReportFigure, Table};
use super::ReportError;
use crate::allan::{self, AllanPoint, DevKind, NoiseModel, NoiseTerms, TauSet};
use crate::compare::{CompareConfig, Comparison, MethodResult, TestResult};
use crate::csvlog::TestLog;
use crate::features::feature_names;
use crate::fit::NamedLog;
use crate::metrics::{self, ScaleFactorOptions, DPS_TO_DPH};
use crate::model::{Method, ModelFile};
use crate::moving_average::{centred_moving_average, windowed_mean};
use crate::sim::CHAMBER_TEMP_COL;

/// Averaging window of the raw-output and compensation figures, s (He et al. 2024 use 100 s).
pub const FIGURE_WINDOW_S: f64 = 100.0;
/// Smoothing of the gyro temperature before differentiating it for figure 1, s.
const TEMP_RATE_SMOOTHING_S: f64 = 100.0;
/// Half-span of the central difference of the smoothed temperature, s.
const TEMP_RATE_HALF_SPAN_S: f64 = 5.0;

/// File stems of the figures, in report order.
pub const FIGURE_STEMS: [&str; 8] = [
    "fig1_temperature",
    "fig2_raw_output",
    "fig3_training_loss",
    "fig4_bias",
    "fig5_scale_factor",
    "fig6_rate_table",
    "fig7_compensation",
    "fig8_allan",
];

/// [`write_full_report_with`] without extra warnings.
pub fn write_full_report(
    dir: &Path,
    train: &[NamedLog],
    test: &[NamedLog],
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> Result<PathBuf, ReportError> {
    write_full_report_with(dir, train, test, cmp, cfg, &[])
}

/// Write the figures, then `dir/index.html` (creating `dir`), and return the page's path.
/// `test` must be the held-out logs `cmp` was computed on, in the same order; `train` the
/// training logs (named on the page). `extra_warnings` (e.g. gaps filled on reading) are
/// listed after the extrapolation warnings of `cmp`.
pub fn write_full_report_with(
    dir: &Path,
    train: &[NamedLog],
    test: &[NamedLog],
    cmp: &Comparison,
    cfg: &CompareConfig,
    extra_warnings: &[String],
) -> Result<PathBuf, ReportError> {
    if test.len() != cmp.tests.len() {
        return Err(ReportError::Data {
            what: format!(
                "{} held-out logs given but the comparison has {}; pass the logs it was run on",
                test.len(),
                cmp.tests.len()
            ),
        });
    }
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let pairs: Vec<(&NamedLog, &TestResult)> = test.iter().zip(&cmp.tests).collect();
    let static_pair = pairs.iter().copied().find(|(_, r)| r.is_static);
    let table_pair = pairs.iter().copied().find(|(_, r)| !r.is_static);
    let main_pair = static_pair.or(pairs.first().copied());

    let mut b = Builder {
        dir,
        figures: Vec::new(),
        notes: Vec::new(),
    };

    // 1. Temperature cycle.
    match main_pair {
        Some((l, _)) => {
            let rate = temperature_rate_c_per_min(&l.log.time_s, &l.log.temp_c);
            let chamber = l.log.extra_f64(CHAMBER_TEMP_COL);
            let files = temperature_figure(
                &b.path(0),
                &TemperatureData {
                    time_s: &l.log.time_s,
                    gyro_temp_c: &l.log.temp_c,
                    chamber_temp_c: chamber.as_deref(),
                    temp_rate_c_per_min: &rate,
                },
            )?;
            let chamber_note = if chamber.is_some() {
                "chamber and gyro temperature"
            } else {
                "gyro temperature (the log has no chamber_temp_c column)"
            };
            b.add(
                &files,
                format!(
                    "Temperature cycle of {}: {chamber_note} (°C) and the gyro temperature rate \
                     (°C/min, central difference of the {} s moving average).",
                    l.name,
                    fmt_num(TEMP_RATE_SMOOTHING_S)
                ),
            );
        }
        None => b.note(1, "no held-out log given"),
    }

    // 2. Raw output.
    if let Some((l, _)) = main_pair {
        let dph = to_dph(&l.log.gyro_dps);
        let files = raw_output_figure(
            &b.path(1),
            &RawOutputData {
                time_s: &l.log.time_s,
                gyro_dph: &dph,
                window_s: FIGURE_WINDOW_S,
            },
        )?;
        b.add(
            &files,
            format!(
                "Raw gyro output of {} (°/h) and its centred {} s moving average.",
                l.name,
                fmt_num(FIGURE_WINDOW_S)
            ),
        );
    } else {
        b.note(2, "no held-out log given");
    }

    // 3. Training loss.
    let lstm_fit = cmp.fits.iter().find(|f| f.model.method == Method::Lstm);
    match lstm_fit {
        None => b.note(
            3,
            "no LSTM model was fitted, so there is no training loss to show",
        ),
        Some(fit) => {
            let mut curves = Vec::new();
            if let Some(t) = fit
                .bias_training
                .as_ref()
                .filter(|t| !t.loss_history.is_empty())
            {
                curves.push(LossCurve {
                    label: "bias network",
                    loss: &t.loss_history,
                });
            }
            if let Some(t) = fit
                .scale_training
                .as_ref()
                .filter(|t| !t.loss_history.is_empty())
            {
                curves.push(LossCurve {
                    label: "scale-factor network",
                    loss: &t.loss_history,
                });
            }
            if curves.is_empty() {
                b.note(3, "the LSTM fit recorded no loss history");
            } else {
                let files = loss_figure(&b.path(2), &curves)?;
                let which: Vec<&str> = curves.iter().map(|c| c.label).collect();
                b.add(
                    &files,
                    format!(
                        "LSTM training loss (normalised mean squared error) against epoch: {}.",
                        which.join(" and ")
                    ),
                );
            }
        }
    }

    // 4. Predicted against measured bias.
    match (static_pair, static_pair.and_then(|(_, r)| lstm_result(r))) {
        (None, _) => b.note(4, "no static held-out log given"),
        (Some(_), None) => b.note(4, "no LSTM model was fitted"),
        (Some((l, _)), Some(m)) => {
            match centred_moving_average(&l.log.time_s, &l.log.gyro_dps, cfg.fit.bias_window_s) {
                Err(e) => b.note(4, &format!("cannot smooth {}: {e}", l.name)),
                Ok(s) => {
                    let measured = to_dph(&s.values);
                    let predicted = to_dph(&m.compensated.bias_dps);
                    let files = bias_figure(
                        &b.path(3),
                        &BiasData {
                            time_s: &l.log.time_s,
                            measured_dph: &measured,
                            predicted_dph: &predicted,
                        },
                    )?;
                    b.add(
                        &files,
                        format!(
                            "Bias of {} (°/h): measured (centred {} s moving average of the raw \
                             output) against predicted (LSTM bias network through the flight \
                             compensator), and the residual.",
                            l.name,
                            fmt_num(cfg.fit.bias_window_s)
                        ),
                    );
                }
            }
        }
    }

    // 5 and 6. Rate-table held-out log.
    match (
        table_pair,
        table_pair.and_then(|(_, r)| compensated_result(r)),
    ) {
        (None, _) => {
            b.note(5, "no rate-table held-out log given");
            b.note(6, "no rate-table held-out log given");
        }
        (Some(_), None) => {
            b.note(5, "no compensation method was fitted");
            b.note(6, "no compensation method was fitted");
        }
        (Some((l, _)), Some(m)) => {
            rate_table_figures(&mut b, l, m, cfg)?;
        }
    }

    // 7. Before and after compensation.
    if let Some((l, r)) = main_pair {
        // Each series minus its mean: a constant offset (Earth rate, turn-on bias) of many
        // °/h would otherwise flatten the thermal drift the figure is about.
        let (raw, raw_mean) = minus_mean(&to_dph(&l.log.gyro_dps));
        let mut means = vec![format!("raw {}", sig(raw_mean))];
        let comp: Vec<(String, Vec<f64>)> = r
            .methods
            .iter()
            .map(|m| {
                let label = method_label(m.method);
                let (v, mean) = minus_mean(&to_dph(&m.compensated.gyro_comp_dps));
                means.push(format!("{label} {}", sig(mean)));
                (label.to_owned(), v)
            })
            .collect();
        let mut series = vec![NamedSeries {
            label: "raw",
            values_dph: &raw,
        }];
        series.extend(comp.iter().map(|(label, v)| NamedSeries {
            label,
            values_dph: v,
        }));
        let files = compensation_figure(
            &b.path(6),
            &CompensationData {
                time_s: &l.log.time_s,
                series: &series,
                window_s: FIGURE_WINDOW_S,
            },
        )?;
        let names: Vec<&str> = series.iter().map(|s| s.label).collect();
        b.add(
            &files,
            format!(
                "Output of {} before and after compensation ({}), means over {} s, each \
                 series minus its mean over the run (°/h; means removed: {} °/h).",
                l.name,
                names.join(" / "),
                fmt_num(FIGURE_WINDOW_S),
                means.join(", ")
            ),
        );
    } else {
        b.note(7, "no held-out log given");
    }

    // 8. Allan deviation.
    match static_pair {
        None => b.note(8, "no static held-out log given"),
        Some((l, r)) => allan_report_figure(&mut b, l, r)?,
    }

    let mut warnings: Vec<String> = cmp
        .tests
        .iter()
        .flat_map(|t| t.warnings.iter().cloned())
        .collect();
    warnings.extend(extra_warnings.iter().cloned());

    let content = ReportContent {
        title: "gyrotherm report: thermal compensation of held-out logs".to_owned(),
        table: Some(comparison_table(cmp, cfg)),
        metadata: metadata(train, cmp, cfg),
        warnings,
        figures: b.figures,
        notes: b.notes,
    };
    write_report(dir, &content)
}

/// Collects the figures written and the notes for those left out.
struct Builder<'a> {
    dir: &'a Path,
    figures: Vec<ReportFigure>,
    notes: Vec<String>,
}

impl Builder<'_> {
    fn path(&self, index: usize) -> PathBuf {
        self.dir.join(FIGURE_STEMS[index])
    }
    fn add(&mut self, files: &FigureFiles, caption: String) {
        self.figures.push(ReportFigure::from_files(files, caption));
    }
    /// Figure `number` (1-based) was not drawn, because of `why`.
    fn note(&mut self, number: usize, why: &str) {
        let name = [
            "temperature cycle",
            "raw output",
            "training loss",
            "predicted against measured bias",
            "predicted against measured scale factor",
            "output at the table rates",
            "output before and after compensation",
            "Allan deviation",
        ];
        self.notes.push(format!(
            "Figure {number} ({}) not drawn: {why}.",
            name[number - 1]
        ));
    }
}

fn to_dph(dps: &[f64]) -> Vec<f64> {
    dps.iter().map(|v| v * DPS_TO_DPH).collect()
}

/// `v` minus the mean of its finite values, and that mean (0 when there are none).
fn minus_mean(v: &[f64]) -> (Vec<f64>, f64) {
    let finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    let mean = if finite.is_empty() {
        0.0
    } else {
        finite.iter().sum::<f64>() / finite.len() as f64
    };
    (v.iter().map(|x| x - mean).collect(), mean)
}

fn lstm_result(r: &TestResult) -> Option<&MethodResult> {
    r.methods.iter().find(|m| m.method == Method::Lstm)
}

/// The LSTM result, else the last method's (the most capable fitted).
fn compensated_result(r: &TestResult) -> Option<&MethodResult> {
    lstm_result(r).or(r.methods.last())
}

fn method_label(m: Method) -> &'static str {
    match m {
        Method::Lstm => "LSTM",
        Method::Linear => "linear",
        Method::Poly => "polynomial",
    }
}

/// Gyro temperature rate, °C/min: the `TEMP_RATE_SMOOTHING_S` centred moving average
/// ([`centred_moving_average`]) differentiated
/// by a central difference over ±`TEMP_RATE_HALF_SPAN_S` (one-sided at the ends).
pub fn temperature_rate_c_per_min(time_s: &[f64], temp_c: &[f64]) -> Vec<f64> {
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

/// Figure 5's data: one point per usable rate segment.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScalePoints {
    /// Middle of each rate segment, s.
    pub time_s: Vec<f64>,
    /// Measured K − 1, ppm: K = (segment mean − local bias) / table rate of the raw output
    /// ([`metrics::scale_factor`], `scale_over_time`).
    pub measured_ppm: Vec<f64>,
    /// Predicted K − 1, ppm: mean of `scale` over the samples the measurement used (the
    /// segment after its settle time).
    pub predicted_ppm: Vec<f64>,
}

/// Measured against predicted scale factor of a rate-table log: `scale` is the predicted K
/// per sample (e.g. `Compensated::scale`), `settle_s` the time dropped at each segment start.
/// Errors: no table column, `scale` of another length, or a log the scale-factor metric
/// refuses (its message).
pub fn scale_factor_points(
    log: &TestLog,
    scale: &[f64],
    settle_s: f64,
) -> Result<ScalePoints, String> {
    let Some(table) = log.table_dps.as_deref() else {
        return Err("the log has no table_dps column".to_owned());
    };
    if scale.len() != log.len() {
        return Err(format!(
            "{} predicted scale factors for {} samples",
            scale.len(),
            log.len()
        ));
    }
    let opts = ScaleFactorOptions {
        settle_s,
        ..Default::default()
    };
    let r = metrics::scale_factor(&log.time_s, &log.gyro_dps, table, &opts)
        .map_err(|e| e.to_string())?;
    // `scale_over_time` has one entry per usable non-stop segment, in order; the used
    // samples are the tail of the segment (the settle time is dropped at its start).
    let rate_segs = r
        .segments
        .iter()
        .filter(|s| s.used_samples > 0 && s.table_dps.abs() > opts.rate_tol_dps);
    let mut out = ScalePoints::default();
    for (seg, k) in rate_segs.zip(&r.scale_over_time) {
        let used = &scale[seg.end - seg.used_samples..seg.end];
        let mean = used.iter().sum::<f64>() / used.len() as f64;
        out.time_s.push(k.time_s);
        out.measured_ppm.push((k.scale - 1.0) * 1e6);
        out.predicted_ppm.push((mean - 1.0) * 1e6);
    }
    Ok(out)
}

/// Figures 5 and 6 on a rate-table log, `m` the compensation shown.
fn rate_table_figures(
    b: &mut Builder,
    l: &NamedLog,
    m: &MethodResult,
    cfg: &CompareConfig,
) -> Result<(), ReportError> {
    let log: &TestLog = l.log;
    let Some(table) = log.table_dps.as_deref() else {
        b.note(5, "the rate-table log has no table_dps column");
        b.note(6, "the rate-table log has no table_dps column");
        return Ok(());
    };
    let label = method_label(m.method);
    match scale_factor_points(log, &m.compensated.scale, cfg.settle_s) {
        Err(e) => b.note(5, &format!("{}: {e}", l.name)),
        Ok(ScalePoints {
            time_s: t,
            measured_ppm: measured,
            predicted_ppm: predicted,
        }) => {
            if t.is_empty() {
                b.note(5, &format!("{} has no usable rate segment", l.name));
            } else {
                let files = scale_factor_figure(
                    &b.path(4),
                    &ScaleFactorData {
                        time_s: &t,
                        measured_ppm: &measured,
                        predicted_ppm: &predicted,
                    },
                )?;
                b.add(
                    &files,
                    format!(
                        "Scale factor of {} per rate segment, as K − 1 in ppm: measured \
                         ((segment mean − local bias) / table rate, raw output, first {} s of \
                         each segment dropped) against predicted ({label} model's K, mean over \
                         the same samples).",
                        l.name,
                        fmt_num(cfg.settle_s)
                    ),
                );
            }
        }
    }

    // 6: the highest positive and the lowest negative table rate.
    let mut rates: Vec<f64> = table.iter().copied().filter(|w| *w != 0.0).collect();
    rates.sort_by(f64::total_cmp);
    rates.dedup();
    let mut chosen = Vec::new();
    if let Some(&w) = rates.last().filter(|w| **w > 0.0) {
        chosen.push(w);
    }
    if let Some(&w) = rates.first().filter(|w| **w < 0.0) {
        chosen.push(w);
    }
    if chosen.is_empty() {
        b.note(6, &format!("{} has no non-zero table rate", l.name));
        return Ok(());
    }
    let tol = crate::table_segments::RATE_TOLERANCE_DPS;
    let segs = crate::table_segments::segments(table, tol);
    // (table rate °/s, time s, error before °/h, error after °/h)
    type RateErrors = (f64, Vec<f64>, Vec<f64>, Vec<f64>);
    let mut data: Vec<RateErrors> = Vec::new();
    for &w in &chosen {
        let (mut x, mut before, mut after) = (Vec::new(), Vec::new(), Vec::new());
        for s in segs.iter().filter(|s| (s.rate_dps - w).abs() <= tol) {
            if !x.is_empty() {
                // A gap between segments: the figure breaks its lines at non-finite values.
                x.push(f64::NAN);
                before.push(f64::NAN);
                after.push(f64::NAN);
            }
            let t0 = log.time_s[s.start];
            for i in s.start..s.end {
                if log.time_s[i] - t0 < cfg.settle_s {
                    continue;
                }
                x.push(log.time_s[i]);
                before.push((log.gyro_dps[i] - w) * DPS_TO_DPH);
                after.push((m.compensated.gyro_comp_dps[i] - w) * DPS_TO_DPH);
            }
        }
        if x.iter().any(|t| t.is_finite()) {
            data.push((w, x, before, after));
        }
    }
    if data.is_empty() {
        b.note(
            6,
            &format!("{}: no samples left after the settle time", l.name),
        );
        return Ok(());
    }
    let segments: Vec<RateSegment> = data
        .iter()
        .map(|(w, x, before, after)| RateSegment {
            rate_dps: *w,
            x,
            before_dph: before,
            after_dph: after,
        })
        .collect();
    let files = rate_table_figure(
        &b.path(5),
        &RateTableData {
            axis: RateAxis::TimeS,
            segments: &segments,
        },
    )?;
    let rates: Vec<String> = chosen.iter().map(|w| format!("{w:+} °/s")).collect();
    b.add(
        &files,
        format!(
            "Output error (output − table rate, °/h) of {} at {} before and after {label} \
             compensation; first {} s of each segment dropped.",
            l.name,
            rates.join(" and "),
            fmt_num(cfg.settle_s)
        ),
    );
    Ok(())
}

/// Figure 8: OADEV (octave τ) of the raw and compensated output of a static log.
fn allan_report_figure(b: &mut Builder, l: &NamedLog, r: &TestResult) -> Result<(), ReportError> {
    let tau0 = l.log.sample_period_s();
    let oadev = |v: &[f64]| {
        allan::deviation(
            v,
            tau0,
            DevKind::Oadev,
            &TauSet::Octave,
            NoiseModel::Identify,
        )
    };
    let raw = match oadev(&l.log.gyro_dps) {
        Ok(p) => p,
        Err(e) => {
            b.note(8, &format!("{}: {e}", l.name));
            return Ok(());
        }
    };
    let mut curves = vec![allan_curve("raw", &raw, DPS_TO_DPH)];
    let mut lines = noise_lines(&allan::noise_terms(&raw, DPS_TO_DPH), "raw");
    let mut terms_from = "raw";
    if let Some(m) = compensated_result(r) {
        match oadev(&m.compensated.gyro_comp_dps) {
            Ok(p) => {
                let label = method_label(m.method);
                curves.push(allan_curve(&format!("{label} compensated"), &p, DPS_TO_DPH));
                lines = noise_lines(&allan::noise_terms(&p, DPS_TO_DPH), label);
                terms_from = label;
            }
            Err(e) => b.note(8, &format!("compensated curve of {} left out: {e}", l.name)),
        }
    }
    let files = allan_figure(&b.path(7), &curves, &lines, "°/h")?;
    b.add(
        &files,
        format!(
            "Overlapping Allan deviation (octave τ) of {} (°/h), 68.3 % confidence bars; dashed \
             lines: noise terms identified on the {terms_from} curve (IEEE Std 952 annex C).",
            l.name
        ),
    );
    Ok(())
}

/// An Allan curve for [`allan_figure`], each σ and bound multiplied by `to_unit` (3600 for
/// °/s samples drawn in °/h).
pub fn allan_curve(label: &str, points: &[AllanPoint], to_unit: f64) -> AllanCurve {
    AllanCurve {
        label: label.to_owned(),
        points: points
            .iter()
            .map(|p| AllanPointPlot {
                tau_s: p.tau_s,
                dev: p.dev * to_unit,
                lo: p.lo * to_unit,
                hi: p.hi * to_unit,
            })
            .collect(),
    }
}

/// Slope lines (in °/h, τ in s) of the noise terms read by [`allan::noise_terms`], labelled
/// with their values and `source` (e.g. "raw"). Conversions (IEEE Std 952 annex C):
/// N[°/h·√s] = 60·N[°/√h]; B in °/h as is; K[°/h/√s] = K[°/h/√h] / 60;
/// Q[°/h·s] = Q[arcsec] (σ = √3·Q/τ). The rate ramp has no line.
pub fn noise_lines(terms: &NoiseTerms, source: &str) -> Vec<NoiseLine> {
    let suffix = if source.is_empty() {
        String::new()
    } else {
        format!(" ({source})")
    };
    let mut out = Vec::new();
    if let Some(t) = terms.arw_deg_rt_h {
        out.push(NoiseLine {
            label: format!("ARW N = {} °/√h{suffix}", sig(t.value)),
            term: NoiseTerm::AngleRandomWalk { n: 60.0 * t.value },
        });
    }
    if let Some(t) = terms.bias_instability_dph {
        out.push(NoiseLine {
            label: format!("bias instability B = {} °/h{suffix}", sig(t.value)),
            term: NoiseTerm::BiasInstability { b: t.value },
        });
    }
    if let Some(t) = terms.rrw_deg_h_rt_h {
        out.push(NoiseLine {
            label: format!("RRW K = {} °/h/√h{suffix}", sig(t.value)),
            term: NoiseTerm::RateRandomWalk { k: t.value / 60.0 },
        });
    }
    if let Some(t) = terms.quantization_arcsec {
        out.push(NoiseLine {
            label: format!("quantization Q = {} arcsec{suffix}", sig(t.value)),
            term: NoiseTerm::Quantization { q: t.value },
        });
    }
    out
}

/// Three significant digits.
fn sig(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() < 1e-3 || v.abs() >= 1e5) {
        format!("{v:.2e}")
    } else {
        let digits = if v == 0.0 || !v.is_finite() {
            3
        } else {
            (2 - v.abs().log10().floor() as i32).max(0) as usize
        };
        format!("{v:.digits$}")
    }
}

/// `100` rather than `100.0`.
fn fmt_num(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

/// The comparison table of `gyrotherm compare` ([`Comparison::table`]) as the report's HTML
/// table: one row per figure, the held-out log named on its first row, a noise-floor column.
pub fn comparison_table(cmp: &Comparison, cfg: &CompareConfig) -> Table {
    let t = cmp.table(cfg);
    let mut headers = vec!["held-out log".to_owned(), "figure".to_owned()];
    headers.extend(t.columns.iter().cloned());
    headers.push("noise floor".to_owned());
    let mut rows = Vec::new();
    for block in &t.blocks {
        for (k, r) in block.rows.iter().enumerate() {
            let mut row = vec![
                if k == 0 { block.title() } else { String::new() },
                r.figure.label(),
            ];
            row.extend(r.cells.iter().cloned());
            row.push(r.floor.clone().unwrap_or_default());
            rows.push(row);
        }
    }
    Table { headers, rows }
}

/// Key-value facts of the models: method, recipe and epochs, seed, training ranges, data
/// digest, inputs.
pub fn metadata(
    train: &[NamedLog],
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> Vec<(String, String)> {
    let mut md = vec![
        (
            "training logs".to_owned(),
            train.iter().map(|l| l.name).collect::<Vec<_>>().join(", "),
        ),
        (
            "bias-stability smoothing τ".to_owned(),
            format!("{} s", fmt_num(cfg.tau_s)),
        ),
        (
            "bias target window".to_owned(),
            format!("{} s", fmt_num(cfg.fit.bias_window_s)),
        ),
        (
            "settle time per table segment".to_owned(),
            format!("{} s", fmt_num(cfg.settle_s)),
        ),
    ];
    for f in &cmp.fits {
        model_metadata(&mut md, &f.model, cfg);
        for (name, t) in [
            ("bias network", &f.bias_training),
            ("scale-factor network", &f.scale_training),
        ] {
            if let Some(t) = t {
                md.push((
                    format!("{} {name}", f.model.method.as_str()),
                    format!("{} epochs, final loss {:.4e}", t.epochs, t.final_loss),
                ));
            }
        }
    }
    md
}

fn model_metadata(md: &mut Vec<(String, String)>, m: &ModelFile, cfg: &CompareConfig) {
    let p = m.method.as_str();
    let ti = &m.training;
    let targets = match (m.bias.is_some(), m.scale.is_some()) {
        (true, true) => "bias and scale factor",
        (true, false) => "bias only (no static training log)",
        (false, true) => "scale factor only (no rate-table training log)",
        (false, false) => "none",
    };
    md.push((
        format!("{p} model"),
        format!("{} — {targets}", method_label(m.method)),
    ));
    if m.method == Method::Lstm {
        md.push((
            format!("{p} recipe"),
            format!(
                "{:?}, {} epochs",
                cfg.fit.recipe.kind, cfg.fit.recipe.epochs
            ),
        ));
    }
    if let Ok(spec) = m.feature_spec() {
        md.push((format!("{p} inputs"), feature_names(&spec).0.join(", ")));
    }
    md.push((
        format!("{p} training range"),
        format!(
            "temperature {:.2} to {:.2} °C, rate {:.3} to {:.3} °C/min",
            ti.temp_range_c.min,
            ti.temp_range_c.max,
            ti.rate_range_c_per_s.min * 60.0,
            ti.rate_range_c_per_s.max * 60.0
        ),
    ));
    if let Some(e) = ti.epochs {
        md.push((format!("{p} epochs"), e.to_string()));
    }
    if let Some(s) = ti.seed {
        md.push((format!("{p} seed"), s.to_string()));
    }
    md.push((
        format!("{p} data digest (SHA-256)"),
        ti.data_digest_sha256.clone(),
    ));
    md.push((format!("{p} training inputs"), ti.inputs.join(", ")));
    md.push((format!("{p} written by"), ti.created_by.clone()));
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn noise_line_units_follow_ieee952() {
        // IEEE Std 952 annex C: σ(1 s) = N[°/h·√s] = 60·N[°/√h]; σ(3 s) = K[°/h/√s]
        // = K[°/h/√h] / 60; σ(√3 s) = Q[°/h·s] = Q[arcsec]; flat 0.6643·B.
        let term = |value| allan::NoiseTerm {
            value,
            tau_read_s: 1.0,
            fit_tau_min_s: 1.0,
            fit_tau_max_s: 2.0,
        };
        let terms = NoiseTerms {
            arw_deg_rt_h: Some(term(0.01)),
            bias_instability_dph: Some(term(0.02)),
            rrw_deg_h_rt_h: Some(term(0.6)),
            quantization_arcsec: Some(term(0.5)),
            rate_ramp_deg_h2: None,
        };
        let lines = noise_lines(&terms, "raw");
        assert_eq!(lines.len(), 4);
        let want = [
            (1.0, 0.6),
            (10.0, 0.6643 * 0.02),
            (3.0, 0.01),
            (3f64.sqrt(), 0.5),
        ];
        for (l, (tau, sigma)) in lines.iter().zip(want) {
            let got = l.term.sigma(tau);
            // 0.6643 is rounded to 4 digits in the standard: 1e-4 relative.
            assert!(
                (got - sigma).abs() <= 1e-4 * sigma,
                "{}: want σ({tau} s) = {sigma} got {got}",
                l.label
            );
        }
        assert!(lines[0].label.contains("0.0100 °/√h"), "{}", lines[0].label);
    }
}

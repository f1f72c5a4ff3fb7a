//! The full report of a held-out comparison (`gyrotherm report`): the ten figures
//! ([`FIGURE_STEMS`]) computed from the logs and the [`Comparison`], the comparison table, the model
//! metadata and the warnings, written as `DIR/index.html` beside one PNG and SVG per figure.
//!
//! Figures that cannot apply to the data given (no rate-table held-out log, no LSTM fitted,
//! ...) are left out with a note on the page, never an error.
//!
//! Which log each figure shows: figures 1, 2 and 7 the first static held-out log (else the
//! first held-out log), figures 4 and 8 the first static held-out log, figures 5 and 6 the
//! first rate-table held-out log, figure 9 the main log (as figure 1) and figure 10 the
//! first static held-out log, both under the coverage map of the model the report is about.
//! "Compensated" means the LSTM model's output through the flight compensator
//! (`MethodResult::compensated`).

mod allan_figure;
mod coverage;
mod rate_table;
mod tables;
mod warnings;

pub use allan_figure::{allan_curve, noise_lines};
pub use rate_table::{scale_factor_points, ScalePoints};
pub use tables::input_names;
pub(crate) use tables::{model_table, results_table, shared_settings};
pub(crate) use warnings::grouped_warnings;

use allan_figure::allan_report_figure;
use rate_table::rate_table_figures;

use std::path::{Path, PathBuf};

pub(super) use super::figures::fmt_num;
use super::figures::{
    bias_figure, compensation_figure, loss_figure, raw_output_figure, temperature_figure, BiasData,
    CompensationData, LossCurve, NamedSeries, RawOutputData, TemperatureData,
};
use super::html::{write_report, ReportContent, ReportFigure};
use super::plot::FigureFiles;
use super::ReportError;
use crate::compare::{CompareConfig, Comparison, MethodResult, TestResult};
pub(crate) use crate::features::temperature_rate_c_per_min;
pub use crate::features::TEMP_RATE_SMOOTHING_S;
use crate::fit::NamedLog;
use crate::metrics::DPS_TO_DPH;
use crate::moving_average::centred_moving_average;
use crate::sim::CHAMBER_TEMP_COL;

/// Averaging window of the raw-output and compensation figures, s (He et al. 2024 use 100 s).
pub(crate) const FIGURE_WINDOW_S: f64 = 100.0;

/// File stems of the figures, in report order.
pub const FIGURE_STEMS: [&str; 10] = [
    "fig1_temperature",
    "fig2_raw_output",
    "fig3_training_loss",
    "fig4_bias",
    "fig5_scale_factor",
    "fig6_rate_table",
    "fig7_compensation",
    "fig8_allan",
    "fig9_coverage",
    "fig10_sigma",
];

/// `write_full_report_with` without extra warnings.
pub fn write_full_report(
    dir: &Path,
    train: &[NamedLog],
    test: &[NamedLog],
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> Result<PathBuf, ReportError> {
    write_full_report_with(dir, train, test, cmp, cfg, &[], None)
}

/// The model a report's coverage figures (9 and 10) are about when it is not one of the
/// comparison's columns: an inertial unit's axis fitted on several sensors, whose map is its
/// first sensor's cells with σ scaled to the several-sensor fit, and its compensated output
/// on each held-out log (in the comparison's order).
pub(crate) struct CoverageModel<'a> {
    pub label: &'a str,
    pub model: &'a crate::model::ModelFile,
    pub compensated_dps: &'a [Vec<f64>],
}

/// Write the figures, then `dir/index.html` (creating `dir`), and return the page's path.
/// `test` must be the held-out logs `cmp` was computed on, in the same order; `train` the
/// training logs (named on the page). `extra_warnings` (e.g. gaps filled on reading) are
/// listed after the extrapolation warnings of `cmp` (each finding once per held-out log,
/// naming the models it concerns). With `coverage_model`, figures 9 and 10 draw it instead of
/// a column of `cmp`.
pub(crate) fn write_full_report_with(
    dir: &Path,
    train: &[NamedLog],
    test: &[NamedLog],
    cmp: &Comparison,
    cfg: &CompareConfig,
    extra_warnings: &[String],
    coverage_model: Option<&CoverageModel>,
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

    fig_temperature_cycle(&mut b, main_pair)?;
    fig_raw_output(&mut b, main_pair)?;
    fig_training_loss(&mut b, cmp)?;
    fig_bias(&mut b, static_pair, cfg)?;
    fig_rate_table(&mut b, table_pair, cfg)?;
    fig_before_after(&mut b, main_pair)?;
    fig_allan(&mut b, static_pair)?;
    let static_index = cmp.tests.iter().position(|r| r.is_static);
    coverage::coverage_figures(
        &mut b,
        main_pair,
        static_pair.zip(static_index),
        cmp,
        coverage_model,
    )?;

    let mut warnings = grouped_warnings(test, cmp);
    warnings.extend(extra_warnings.iter().cloned());

    let table = cmp.table(cfg);
    let mut table_notes = table.notes.clone();
    for b in &table.blocks {
        table_notes.extend(b.notes.iter().map(|n| format!("{}: {n}", b.log)));
    }
    let content = ReportContent {
        title: "gyrotherm report: thermal compensation of held-out logs".to_owned(),
        headline: cmp.headline(cfg),
        table: Some(tables::results_table(&table)),
        table_notes,
        metadata: shared_settings(train, cmp, cfg),
        models: Some(model_table(cmp, cfg)),
        warnings,
        figures: b.figures,
        notes: b.notes,
    };
    write_report(dir, &content)
}

/// Figure 1: the temperature cycle of the main held-out log.
fn fig_temperature_cycle(
    b: &mut Builder,
    main_pair: Option<(&NamedLog, &TestResult)>,
) -> Result<(), ReportError> {
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
    Ok(())
}

/// Figure 2: the raw output of the main held-out log.
fn fig_raw_output(
    b: &mut Builder,
    main_pair: Option<(&NamedLog, &TestResult)>,
) -> Result<(), ReportError> {
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
    Ok(())
}

/// Figure 3: the LSTM training loss of the first column that trained one.
fn fig_training_loss(b: &mut Builder, cmp: &Comparison) -> Result<(), ReportError> {
    let trained = |t: &Option<crate::fit::TrainSummary>| {
        t.as_ref().is_some_and(|t| !t.loss_history.is_empty())
    };
    let lstm_fit = cmp
        .fits
        .iter()
        .zip(&cmp.columns)
        .find(|(f, _)| trained(&f.bias_training) || trained(&f.scale_training));
    match lstm_fit {
        None => b.note(
            3,
            "no model in this comparison trained an LSTM, so there is no training loss to show",
        ),
        Some((fit, col)) => {
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
                        "LSTM training loss of the {} model (normalised mean squared error) \
                         against epoch: {}.",
                        col.label,
                        which.join(" and ")
                    ),
                );
            }
        }
    }
    Ok(())
}

/// Figure 4: predicted against measured bias on the static held-out log, for every model
/// of the comparison (the report's main column first, so the default model is never left
/// out for an LSTM).
fn fig_bias(
    b: &mut Builder,
    static_pair: Option<(&NamedLog, &TestResult)>,
    cfg: &CompareConfig,
) -> Result<(), ReportError> {
    let Some((l, r)) = static_pair else {
        b.note(4, "no static held-out log given");
        return Ok(());
    };
    let main = compensated_result(r);
    let shown: Vec<&MethodResult> = main
        .into_iter()
        .chain(
            r.methods
                .iter()
                .filter(|m| main.is_none_or(|s| s.key != m.key)),
        )
        .collect();
    if shown.is_empty() {
        b.note(4, "no compensation method was fitted");
        return Ok(());
    }
    match centred_moving_average(&l.log.time_s, &l.log.gyro_dps, cfg.fit.bias_window_s) {
        Err(e) => b.note(4, &format!("cannot smooth {}: {e}", l.name)),
        Ok(s) => {
            let measured = to_dph(&s.values);
            let predicted: Vec<Vec<f64>> = shown
                .iter()
                .map(|m| to_dph(&m.compensated.bias_dps))
                .collect();
            let series: Vec<NamedSeries> = shown
                .iter()
                .zip(&predicted)
                .map(|(m, v)| NamedSeries {
                    label: m.label,
                    values_dph: v,
                })
                .collect();
            let files = bias_figure(
                &b.path(3),
                &BiasData {
                    time_s: &l.log.time_s,
                    measured_dph: &measured,
                    predicted: &series,
                },
            )?;
            let names: Vec<&str> = shown.iter().map(|m| m.label).collect();
            b.add(
                &files,
                format!(
                    "Bias of {} (°/h): measured (centred {} s moving average of the raw \
                     output) against predicted by each model's bias part through the flight \
                     compensator ({}), and the residuals.",
                    l.name,
                    fmt_num(cfg.fit.bias_window_s),
                    names.join(", ")
                ),
            );
        }
    }
    Ok(())
}

/// Figures 5 and 6 on the rate-table held-out log.
fn fig_rate_table(
    b: &mut Builder,
    table_pair: Option<(&NamedLog, &TestResult)>,
    cfg: &CompareConfig,
) -> Result<(), ReportError> {
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
            rate_table_figures(b, l, m, cfg)?;
        }
    }
    Ok(())
}

/// Figure 7: the output before and after compensation.
fn fig_before_after(
    b: &mut Builder,
    main_pair: Option<(&NamedLog, &TestResult)>,
) -> Result<(), ReportError> {
    if let Some((l, r)) = main_pair {
        // Each series minus its mean: a constant offset (Earth rate, turn-on bias) of many
        // °/h would otherwise flatten the thermal drift the figure is about.
        let (raw, raw_mean) = minus_mean(&to_dph(&l.log.gyro_dps));
        let mut means = vec![format!("raw {}", sig(raw_mean))];
        let comp: Vec<(String, Vec<f64>)> = r
            .methods
            .iter()
            .map(|m| {
                let label = m.label;
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
    Ok(())
}

/// Figure 8: the Allan deviation of the static held-out log.
fn fig_allan(
    b: &mut Builder,
    static_pair: Option<(&NamedLog, &TestResult)>,
) -> Result<(), ReportError> {
    match static_pair {
        None => b.note(8, "no static held-out log given"),
        Some((l, r)) => allan_report_figure(b, l, r)?,
    }
    Ok(())
}

/// Collects the figures written and the notes for those left out.
pub(super) struct Builder<'a> {
    dir: &'a Path,
    figures: Vec<ReportFigure>,
    notes: Vec<String>,
}

impl Builder<'_> {
    pub(super) fn path(&self, index: usize) -> PathBuf {
        self.dir.join(FIGURE_STEMS[index])
    }
    /// A figure written at [`Builder::path`], numbered as its place in [`FIGURE_STEMS`]
    /// (the numbers [`Builder::note`] uses).
    pub(super) fn add(&mut self, files: &FigureFiles, caption: String) {
        let mut f = ReportFigure::from_files(files, caption);
        let stem = files.png.file_stem().and_then(|s| s.to_str());
        f.number = FIGURE_STEMS
            .iter()
            .position(|s| Some(*s) == stem)
            .map(|i| i + 1);
        self.figures.push(f);
    }
    /// Figure `number` (1-based) was not drawn, because of `why`.
    pub(super) fn note(&mut self, number: usize, why: &str) {
        let name = [
            "temperature cycle",
            "raw output",
            "training loss",
            "predicted against measured bias",
            "predicted against measured scale factor",
            "output at the table rates",
            "output before and after compensation",
            "Allan deviation",
            "coverage of the training region",
            "residual and its 1σ estimate",
        ];
        self.notes.push(format!(
            "Figure {number} ({}) not drawn: {why}.",
            name[number - 1]
        ));
    }
}

pub(super) fn to_dph(dps: &[f64]) -> Vec<f64> {
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

/// The result of the first recipe-method column other than `published` (the default:
/// `thermal`): the model the report is about, beside the classic fits and the paper's.
pub(super) fn lstm_result(r: &TestResult) -> Option<&MethodResult> {
    r.methods.iter().find(|m| {
        m.key
            .parse::<crate::settings::Method>()
            .is_ok_and(|k| k.is_recipe() && k != crate::settings::Method::Published)
    })
}

/// That column's result ([`lstm_result`]), else the last column's.
pub(super) fn compensated_result(r: &TestResult) -> Option<&MethodResult> {
    lstm_result(r).or(r.methods.last())
}

/// Three significant digits.
pub(super) fn sig(v: f64) -> String {
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

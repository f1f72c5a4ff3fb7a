//! The coverage figures of the report: where a held-out run went against the region the
//! training logs covered (the (T, dT) plane), and the per-sample 1σ estimate `compensate`
//! writes beside the residual it is meant to describe (docs/experiments/coverage.md).
//!
//! Colours of the verdicts are the same in both figures: inside blue, edge orange, outside
//! red, so a reader matches a stretch of the run in one figure with the other.

use std::path::Path;

use gyrotherm_core::coverage::Coverage;

use super::figures::{fmt_num, window_means};
use super::plot::{
    write_figure, Figure, FigureFiles, Panel, Series, SeriesStyle, FIGURE_HEIGHT_2_PANELS_PX,
    FIGURE_HEIGHT_PX, FIGURE_WIDTH_PX,
};
use super::ReportError;

const CELL_GREY: (u8, u8, u8) = (150, 150, 150);
/// Colour of the samples inside the training region.
pub(crate) const INSIDE: (u8, u8, u8) = (0, 90, 170);
/// Colour of the samples at its edge.
pub(crate) const EDGE: (u8, u8, u8) = (213, 140, 0);
/// Colour of the samples outside it (and of the ±1σ band).
pub const OUTSIDE: (u8, u8, u8) = (200, 30, 30);
const RESIDUAL: (u8, u8, u8) = (60, 60, 60);

/// The three verdicts with their legend text and colour, in drawing order.
const VERDICTS: [(Coverage, &str, (u8, u8, u8)); 3] = [
    (Coverage::Inside, "inside", INSIDE),
    (Coverage::Edge, "edge (within one cell)", EDGE),
    (Coverage::Outside, "outside", OUTSIDE),
];

/// One covered cell, in the figure's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CellRect {
    /// Temperature span, °C.
    pub temp_c: (f64, f64),
    /// Temperature-rate span, °C/min.
    pub rate_c_per_min: (f64, f64),
}

/// Data of the coverage-map figure.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CoverageMapData<'a> {
    /// The training region's covered cells.
    pub cells: &'a [CellRect],
    /// The held-out run: temperature (°C), its rate (°C/min) and verdict per sample.
    pub temp_c: &'a [f64],
    pub rate_c_per_min: &'a [f64],
    pub coverage: &'a [Option<Coverage>],
    /// Name of the held-out run, for the legend.
    pub run: &'a str,
}

/// The coverage map: the covered cells outlined in grey and the held-out run's path over
/// them, one colour per verdict (a stretch of one verdict is one line; the path breaks where
/// the verdict changes). Temperature (°C) across, its rate (°C/min) up. 1000 × 600 px.
pub(crate) fn coverage_map_figure(
    path: &Path,
    d: &CoverageMapData,
) -> Result<FigureFiles, ReportError> {
    let n = d.temp_c.len();
    if d.rate_c_per_min.len() != n || d.coverage.len() != n {
        return Err(ReportError::Data {
            what: format!(
                "coverage map: {n} temperatures, {} rates and {} verdicts; give one of each per \
                 sample",
                d.rate_c_per_min.len(),
                d.coverage.len()
            ),
        });
    }
    // All cells in one series: each outline a closed run of five corners, NaN between runs.
    let (mut cx, mut cy) = (Vec::new(), Vec::new());
    for c in d.cells {
        let (t0, t1) = c.temp_c;
        let (r0, r1) = c.rate_c_per_min;
        cx.extend_from_slice(&[t0, t1, t1, t0, t0, f64::NAN]);
        cy.extend_from_slice(&[r0, r0, r1, r1, r0, f64::NAN]);
    }
    let mut series =
        vec![Series::line("covered by training (cells)", &cx, &cy).with_color(CELL_GREY)];
    for (which, label, colour) in VERDICTS {
        let pick = |v: &[f64]| -> Vec<f64> {
            v.iter()
                .zip(d.coverage)
                .map(|(&x, c)| if *c == Some(which) { x } else { f64::NAN })
                .collect()
        };
        let (x, y) = (pick(d.temp_c), pick(d.rate_c_per_min));
        if x.iter().any(|v| v.is_finite()) {
            series.push(Series::line(format!("{}: {label}", d.run), &x, &y).with_color(colour));
        }
    }
    write_figure(
        path,
        &Figure {
            title: "Coverage: the training region and the held-out run".to_owned(),
            x_label: "temperature (°C)".to_owned(),
            log_x: false,
            width_px: FIGURE_WIDTH_PX,
            height_px: FIGURE_HEIGHT_PX,
            panels: vec![Panel {
                y_label: "temperature rate (°C/min)".to_owned(),
                log_y: false,
                series,
            }],
        },
    )
}

/// Data of the σ figure.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SigmaData<'a> {
    pub time_s: &'a [f64],
    /// Compensated output minus the true rate, °/h, per sample.
    pub residual_dph: &'a [f64],
    /// σ per sample, °/h (NaN without a verdict).
    pub sigma_dph: &'a [f64],
    pub coverage: &'a [Option<Coverage>],
    /// Window of the residual's means, s (the coverage record judges 100 s windows).
    pub window_s: f64,
}

/// σ beside the residual: top, the residual's means over consecutive `window_s` windows
/// with the band ±σ (σ averaged over the same windows, as docs/experiments/coverage.md
/// judges it); bottom, σ per sample, one colour per verdict. 1000 × 800 px.
pub(crate) fn sigma_figure(path: &Path, d: &SigmaData) -> Result<FigureFiles, ReportError> {
    let n = d.time_s.len();
    if d.residual_dph.len() != n || d.sigma_dph.len() != n || d.coverage.len() != n {
        return Err(ReportError::Data {
            what: format!(
                "σ figure: {n} times, {} residuals, {} σ and {} verdicts; give one of each per \
                 sample",
                d.residual_dph.len(),
                d.sigma_dph.len(),
                d.coverage.len()
            ),
        });
    }
    if !(d.window_s.is_finite() && d.window_s > 0.0) {
        return Err(ReportError::Data {
            what: format!("σ figure: window {} s must be positive", d.window_s),
        });
    }
    let (tr, mean) = window_means(d.time_s, d.residual_dph, d.window_s);
    let (ts, sigma) = window_means(d.time_s, d.sigma_dph, d.window_s);
    let neg: Vec<f64> = sigma.iter().map(|s| -s).collect();
    let top = vec![
        Series::line(
            format!("residual, {} s means", fmt_num(d.window_s)),
            &tr,
            &mean,
        )
        .with_color(RESIDUAL),
        Series::line("±1σ", &ts, &sigma)
            .with_style(SeriesStyle::Dashed)
            .with_color(OUTSIDE),
        // The lower edge of the band: the same entry in the legend, so no label.
        Series::line("", &ts, &neg)
            .with_style(SeriesStyle::Dashed)
            .with_color(OUTSIDE),
    ];
    let mut bottom = Vec::new();
    for (which, label, colour) in VERDICTS {
        let y: Vec<f64> = d
            .sigma_dph
            .iter()
            .zip(d.coverage)
            .map(|(&s, c)| if *c == Some(which) { s } else { f64::NAN })
            .collect();
        if y.iter().any(|v| v.is_finite()) {
            bottom.push(Series::line(format!("σ, {label}"), d.time_s, &y).with_color(colour));
        }
    }
    write_figure(
        path,
        &Figure {
            title: "Residual bias and the 1σ estimate of compensate".to_owned(),
            x_label: "time (s)".to_owned(),
            log_x: false,
            width_px: FIGURE_WIDTH_PX,
            height_px: FIGURE_HEIGHT_2_PANELS_PX,
            panels: vec![
                Panel {
                    y_label: "residual (°/h)".to_owned(),
                    log_y: false,
                    series: top,
                },
                Panel {
                    y_label: "σ (°/h)".to_owned(),
                    log_y: false,
                    series: bottom,
                },
            ],
        },
    )
}

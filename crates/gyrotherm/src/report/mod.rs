//! Figures and the HTML report: the pictures a gyro engineer looks at.
//!
//! Everything here works over plain data (slices of `f64` and small structs), so the report
//! does not depend on how the numbers were made.
//! - `plot`: the generic plot writer ([`write_figure`]: time series, x-y, log-log; one or
//!   more stacked panels, each legend below its panel so it hides no data), written as PNG
//!   and SVG of a stated size, atomically.
//! - [`figures`]: the eight figures of the report after He et al. and the Allan figure that
//!   `gyrotherm allan --plot` reuses, each a function over plain data.
//! - [`coverage_figures`]: the training region with a held-out run over it, and the 1σ
//!   estimate beside the residual.
//! - [`html`]: `DIR/index.html`, self-contained (inline CSS, no script, no network).
//! - `job`: the full report of a held-out comparison ([`write_full_report`], used by
//!   `gyrotherm report`), from the logs and a [`crate::compare::Comparison`].
//! - [`unit`](mod@unit): the report of an inertial unit: the table across axes, a section per axis,
//!   and each axis's full report in its own folder.
//! - `decimate`: min/max per pixel column, so long runs draw fast without losing extremes.
//! - `font`: the embedded DejaVu Sans font; no system font or graphics library is used.

pub mod coverage_figures;
pub(crate) mod decimate;
pub mod figures;
pub(crate) mod font;
pub mod html;
pub(crate) mod job;
pub(crate) mod plot;
pub mod unit;

use std::fmt;
use std::path::PathBuf;

pub use decimate::decimate_min_max;
pub use figures::{
    allan_figure, bias_figure, compensation_figure, loss_figure, rate_table_figure,
    raw_output_figure, scale_factor_figure, temperature_figure, AllanCurve, AllanPointPlot,
    BiasData, CompensationData, LossCurve, NamedSeries, NoiseLine, NoiseTerm, RateAxis,
    RateSegment, RateTableData, RawOutputData, ScaleFactorData, TemperatureData,
};
pub use html::{write_report, ReportContent, ReportFigure, Table};
pub use job::{
    allan_curve, input_names, noise_lines, scale_factor_points, write_full_report, ScalePoints,
    FIGURE_STEMS, TEMP_RATE_SMOOTHING_S,
};
pub(crate) use job::{grouped_warnings, results_table, write_full_report_with, CoverageModel};
pub use plot::{
    figure_layout, write_figure, Figure, FigureFiles, Panel, PanelLayout, PixelRect, Series,
    SeriesStyle, FIGURE_HEIGHT_PX, FIGURE_WIDTH_PX, LEGEND_BORDER_RGB,
};

/// Why a figure or report could not be written.
#[derive(Debug)]
#[non_exhaustive]
pub enum ReportError {
    /// Reading or writing `path` failed.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The plotting library failed while drawing `path`.
    Draw { path: PathBuf, message: String },
    /// The data handed in cannot be drawn (for example x and y of different lengths).
    Data { what: String },
    /// The embedded font could not be registered.
    Font(String),
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReportError::Io { path, .. } => write!(f, "{}", path.display()),
            ReportError::Draw { path, message } => {
                write!(f, "{}: drawing failed: {message}", path.display())
            }
            ReportError::Data { what } => write!(f, "cannot draw: {what}"),
            ReportError::Font(msg) => write!(f, "embedded font: {msg}"),
        }
    }
}

impl std::error::Error for ReportError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ReportError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

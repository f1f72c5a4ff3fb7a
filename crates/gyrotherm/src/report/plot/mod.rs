//! The generic figure writer: one or more stacked panels sharing an x axis, linear or log
//! axes, lines / dashed lines / points with optional error bars, a legend per panel. Every
//! figure is written twice, as PNG and as SVG of the same size, each atomically
//! ([`crate::atomic_file`]).
//!
//! Legends sit below their panel's x axis, outside the plotting area, so they never hide
//! data (a legend inside the plot covers whatever the data does in that corner);
//! [`figure_layout`] gives the boxes, for tests and for callers placing annotations.

use std::path::{Path, PathBuf};

use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::decimate::decimate_min_max;
use super::font::{ensure_font, GlyphFix, FONT_FAMILY};
use super::ReportError;
use crate::atomic_file::write_bytes_atomically;

mod axes;
mod legend;

use axes::*;
use legend::*;

/// Default figure width, pixels (PNG) and user units (SVG).
pub const FIGURE_WIDTH_PX: u32 = 1000;
/// Default height of a one-panel figure.
pub const FIGURE_HEIGHT_PX: u32 = 600;
/// Default height of a two-panel figure.
pub(crate) const FIGURE_HEIGHT_2_PANELS_PX: u32 = 800;

const LEGEND_FONT_PX: u32 = 15;
const TICK_FONT_PX: u32 = 15;
const AXIS_FONT_PX: u32 = 17;
const TITLE_FONT_PX: u32 = 22;

/// Legend geometry, pixels: the line sample's length, the gap between sample and text, the
/// gap between entries on a row, the height of a row, the padding inside the box and the
/// gap between the x-axis title and the box.
const LEGEND_SAMPLE_PX: i32 = 22;
const LEGEND_SAMPLE_GAP_PX: i32 = 6;
const LEGEND_ENTRY_GAP_PX: i32 = 18;
const LEGEND_ROW_PX: i32 = LEGEND_FONT_PX as i32 + 7;
const LEGEND_PAD_PX: i32 = 6;
const LEGEND_GAP_PX: i32 = 4;
/// Colour of the legend's border; no series or grid line uses it.
pub const LEGEND_BORDER_RGB: (u8, u8, u8) = (120, 120, 120);
/// Space the chart keeps around its plotting area: outer margin, x-axis label band,
/// y-axis label band.
const CHART_MARGIN_PX: i32 = 12;
const X_LABEL_AREA_PX: i32 = 48;
const Y_LABEL_AREA_PX: i32 = 90;

/// A rectangle in figure pixels: `x0..x1` by `y0..y1` (the ends excluded), origin at the
/// top left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: i32,
    pub y0: i32,
    pub x1: i32,
    pub y1: i32,
}

impl PixelRect {
    /// Whether the two rectangles share a pixel.
    pub fn overlaps(&self, other: &PixelRect) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }

    /// Whether `(x, y)` lies inside.
    pub fn contains(&self, x: i32, y: i32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }
}

/// Where one panel was drawn: its plotting area (the data, inside the axes) and its legend
/// box, if it has labelled series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PanelLayout {
    pub plot: PixelRect,
    pub legend: Option<PixelRect>,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A solid line.
    Line,
    /// A dashed line (model lines, fits).
    Dashed,
    /// Markers only.
    Points,
    /// A solid line with markers.
    LinePoints,
}

/// One named curve.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Abscissa, same unit as the figure's x label.
    pub x: Vec<f64>,
    /// Ordinate, same unit as the panel's y label.
    pub y: Vec<f64>,
    pub style: SeriesStyle,
    /// Colour as RGB; `None` takes the next colour of the palette.
    pub color: Option<(u8, u8, u8)>,
    /// Optional error bars: lower and upper ends per point (same length as `x`).
    pub bars: Option<(Vec<f64>, Vec<f64>)>,
}

impl Series {
    /// A solid line with a palette colour and no error bars.
    pub fn line(label: impl Into<String>, x: &[f64], y: &[f64]) -> Self {
        Series {
            label: label.into(),
            x: x.to_vec(),
            y: y.to_vec(),
            style: SeriesStyle::Line,
            color: None,
            bars: None,
        }
    }

    /// The same series drawn in another style.
    pub(crate) fn with_style(mut self, style: SeriesStyle) -> Self {
        self.style = style;
        self
    }

    /// The same series in a fixed colour.
    pub fn with_color(mut self, rgb: (u8, u8, u8)) -> Self {
        self.color = Some(rgb);
        self
    }
}

/// One plot area: its y axis and the series drawn in it.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Quantity and unit, e.g. `"temperature (°C)"`.
    pub y_label: String,
    pub log_y: bool,
    pub series: Vec<Series>,
}

/// A figure: a title, a shared x axis and one or more panels stacked top to bottom.
#[derive(Debug, Clone)]
pub struct Figure {
    pub title: String,
    /// Quantity and unit, e.g. `"time (s)"`.
    pub x_label: String,
    pub log_x: bool,
    pub width_px: u32,
    pub height_px: u32,
    pub panels: Vec<Panel>,
}

/// The two files written for one figure, and their size in pixels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FigureFiles {
    pub png: PathBuf,
    pub svg: PathBuf,
    pub width_px: u32,
    pub height_px: u32,
    /// Where each panel's plotting area and legend were drawn, top panel first.
    pub layout: Vec<PanelLayout>,
}

/// The PNG and SVG paths for `path`: a trailing `.png` or `.svg` is replaced, any other name
/// gets the extensions appended (`out/fig1` and `out/fig1.png` both give `out/fig1.png` and
/// `out/fig1.svg`).
pub(crate) fn figure_paths(path: &Path) -> (PathBuf, PathBuf) {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let stem = match ext.as_deref() {
        Some("png") | Some("svg") => path.with_extension(""),
        _ => path.to_path_buf(),
    };
    let mut png = stem.clone().into_os_string();
    png.push(".png");
    let mut svg = stem.into_os_string();
    svg.push(".svg");
    (PathBuf::from(png), PathBuf::from(svg))
}

/// Draw `fig` and write it as PNG and SVG beside each other (see `figure_paths`); the
/// folder must exist. Lines longer than twice the plot width are decimated to min/max per
/// pixel column first. Errors: series with x, y (or bars) of different lengths, a figure
/// without panels or with a zero size, and any I/O failure, each naming the file or series.
pub fn write_figure(path: &Path, fig: &Figure) -> Result<FigureFiles, ReportError> {
    validate(fig)?;
    ensure_font()?;
    let (png_path, svg_path) = figure_paths(path);
    let (w, h) = (fig.width_px, fig.height_px);

    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    let layout = {
        let root = GlyphFix::new(BitMapBackend::with_buffer(&mut rgb, (w, h))).into_drawing_area();
        let layout = draw_figure(&root, fig).map_err(|message| ReportError::Draw {
            path: png_path.clone(),
            message,
        })?;
        root.present().map_err(|e| ReportError::Draw {
            path: png_path.clone(),
            message: e.to_string(),
        })?;
        layout
    };
    let mut png = Vec::new();
    {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&rgb, w, h, image::ColorType::Rgb8)
            .map_err(|e| ReportError::Draw {
                path: png_path.clone(),
                message: format!("PNG encoding: {e}"),
            })?;
    }
    write_bytes_atomically(&png_path, &png).map_err(|source| ReportError::Io {
        path: png_path.clone(),
        source,
    })?;

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        draw_figure(&root, fig).map_err(|message| ReportError::Draw {
            path: svg_path.clone(),
            message,
        })?;
        root.present().map_err(|e| ReportError::Draw {
            path: svg_path.clone(),
            message: e.to_string(),
        })?;
    }
    write_bytes_atomically(&svg_path, svg.as_bytes()).map_err(|source| ReportError::Io {
        path: svg_path.clone(),
        source,
    })?;
    Ok(FigureFiles {
        png: png_path,
        svg: svg_path,
        width_px: w,
        height_px: h,
        layout,
    })
}

/// Where [`write_figure`] puts each panel's plotting area and legend, top panel first: the
/// figure is drawn the same way, into memory, and nothing is written.
pub fn figure_layout(fig: &Figure) -> Result<Vec<PanelLayout>, ReportError> {
    validate(fig)?;
    ensure_font()?;
    let (w, h) = (fig.width_px, fig.height_px);
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    let root = GlyphFix::new(BitMapBackend::with_buffer(&mut rgb, (w, h))).into_drawing_area();
    draw_figure(&root, fig).map_err(|message| ReportError::Draw {
        path: PathBuf::from(format!("(layout of \"{}\")", fig.title)),
        message,
    })
}

fn validate(fig: &Figure) -> Result<(), ReportError> {
    let data_err = |what: String| ReportError::Data {
        what: format!("figure \"{}\": {what}", fig.title),
    };
    if fig.panels.is_empty() {
        return Err(data_err("no panels to draw".into()));
    }
    if fig.width_px < 200 || fig.height_px < 150 * fig.panels.len() as u32 {
        return Err(data_err(format!(
            "size {}x{} px is too small for {} panel(s); use at least 200 x 150 per panel",
            fig.width_px,
            fig.height_px,
            fig.panels.len()
        )));
    }
    for s in fig.panels.iter().flat_map(|p| &p.series) {
        if s.x.len() != s.y.len() {
            return Err(data_err(format!(
                "series \"{}\" has {} x values but {} y values",
                s.label,
                s.x.len(),
                s.y.len()
            )));
        }
        if let Some((lo, hi)) = &s.bars {
            if lo.len() != s.x.len() || hi.len() != s.x.len() {
                return Err(data_err(format!(
                    "series \"{}\" has {} points but {} / {} error-bar ends",
                    s.label,
                    s.x.len(),
                    lo.len(),
                    hi.len()
                )));
            }
        }
    }
    Ok(())
}

/// Colour-blind-safe palette (Okabe & Ito 2008), darkened a little for thin lines.
const PALETTE: [(u8, u8, u8); 8] = [
    (0, 90, 170),   // blue
    (213, 94, 0),   // vermillion
    (0, 140, 100),  // bluish green
    (150, 80, 150), // reddish purple
    (200, 150, 0),  // dark yellow
    (60, 60, 60),   // grey
    (86, 160, 220), // sky blue
    (180, 40, 40),  // red
];

fn color_of(s: &Series, index: usize) -> RGBColor {
    let (r, g, b) = s.color.unwrap_or(PALETTE[index % PALETTE.len()]);
    RGBColor(r, g, b)
}

fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
) -> Result<Vec<PanelLayout>, String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let body = root
        .titled(&fig.title, (FONT_FAMILY, TITLE_FONT_PX).into_font())
        .map_err(|e| e.to_string())?;
    let areas = body.split_evenly((fig.panels.len(), 1));
    // The x range is shared by all panels; lines run edge to edge, markers get a margin.
    let has_markers = fig
        .panels
        .iter()
        .flat_map(|p| &p.series)
        .any(|s| matches!(s.style, SeriesStyle::Points | SeriesStyle::LinePoints));
    let xs = fig
        .panels
        .iter()
        .flat_map(|p| &p.series)
        .flat_map(|s| s.x.iter().copied());
    let (mut x0, mut x1) = padded_range(xs, fig.log_x, fig.log_x || has_markers);
    if !(fig.log_x || has_markers) {
        // A line starting or ending on the first or last x would lie on the frame, its
        // 2 px stroke crossing it: a margin of 1 % of the span keeps it inside.
        let m = 0.01 * (x1 - x0);
        (x0, x1) = (x0 - m, x1 + m);
    }
    let legend_font: TextStyle = (FONT_FAMILY, LEGEND_FONT_PX).into_font().into();
    let mut layouts = Vec::with_capacity(fig.panels.len());
    for (area, panel) in areas.iter().zip(&fig.panels) {
        let ys = panel.series.iter().flat_map(|s| {
            let bars = s
                .bars
                .iter()
                .flat_map(|(lo, hi)| lo.iter().chain(hi.iter()).copied());
            s.y.iter().copied().chain(bars)
        });
        let (y0, y1) = padded_range(ys, panel.log_y, true);

        // The legend takes a band below the chart, at most as wide as the plotting area.
        let labelled: Vec<(usize, &Series)> = panel
            .series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.label.is_empty())
            .collect();
        let (area_w, area_h) = area.dim_in_pixel();
        let plot_w = area_w as i32 - 2 * CHART_MARGIN_PX - Y_LABEL_AREA_PX;
        let legend = if labelled.is_empty() {
            None
        } else {
            let widths = labelled
                .iter()
                .map(|(_, s)| {
                    area.estimate_text_size(&s.label, &legend_font)
                        .map(|(w, _)| w as i32)
                        .map_err(|e| e.to_string())
                })
                .collect::<Result<Vec<i32>, String>>()?;
            Some(legend_layout(&widths, plot_w.max(1)))
        };
        let band = legend.as_ref().map_or(0, |l| l.height + 1 + LEGEND_GAP_PX);
        let chart_h = (area_h as i32 - band).max(1);
        let (chart_area, legend_area) = area.split_vertically(chart_h);

        let mut builder = ChartBuilder::on(&chart_area);
        builder
            .margin(CHART_MARGIN_PX)
            .x_label_area_size(X_LABEL_AREA_PX)
            .y_label_area_size(Y_LABEL_AREA_PX);
        let columns = area.dim_in_pixel().0.saturating_sub(110).max(50) as usize;
        let plot = match (fig.log_x, panel.log_y) {
            (false, false) => draw_panel(
                builder
                    .build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(|e| e.to_string())?,
                fig,
                panel,
                columns,
            ),
            (false, true) => draw_panel(
                builder
                    .build_cartesian_2d(x0..x1, log_axis(y0, y1))
                    .map_err(|e| e.to_string())?,
                fig,
                panel,
                columns,
            ),
            (true, false) => draw_panel(
                builder
                    .build_cartesian_2d(log_axis(x0, x1), y0..y1)
                    .map_err(|e| e.to_string())?,
                fig,
                panel,
                columns,
            ),
            (true, true) => draw_panel(
                builder
                    .build_cartesian_2d(log_axis(x0, x1), log_axis(y0, y1))
                    .map_err(|e| e.to_string())?,
                fig,
                panel,
                columns,
            ),
        }?;
        let legend_rect = match &legend {
            Some(l) => Some(draw_legend(
                &legend_area,
                &legend_font,
                l,
                &labelled,
                plot.x0,
            )?),
            None => None,
        };
        layouts.push(PanelLayout {
            plot,
            legend: legend_rect,
        });
    }
    Ok(layouts)
}

fn draw_panel<'a, DB, X, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    fig: &Figure,
    panel: &Panel,
    columns: usize,
) -> Result<PixelRect, String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    chart
        .configure_mesh()
        .x_desc(fig.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style((FONT_FAMILY, TICK_FONT_PX))
        .axis_desc_style((FONT_FAMILY, AXIS_FONT_PX))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .x_labels(10)
        .y_labels(8)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .draw()
        .map_err(err)?;

    for (i, s) in panel.series.iter().enumerate() {
        let color = color_of(s, i);
        let log_x = fig.log_x;
        let log_y = panel.log_y;
        let ok = |&(x, y): &(f64, f64)| usable(x, log_x) && usable(y, log_y);
        // Lines are drawn as runs: a non-finite x or y is a gap that breaks the line (e.g.
        // between rate-table segments), each run decimated on its own.
        let runs: Vec<Vec<(f64, f64)>> = match s.style {
            SeriesStyle::Line | SeriesStyle::Dashed => finite_runs(&s.x, &s.y)
                .into_iter()
                .map(|r| {
                    let mut p = decimate_min_max(&s.x[r.clone()], &s.y[r], columns);
                    p.retain(ok);
                    p
                })
                .filter(|p| !p.is_empty())
                .collect(),
            SeriesStyle::Points | SeriesStyle::LinePoints => vec![s
                .x
                .iter()
                .copied()
                .zip(s.y.iter().copied())
                .filter(ok)
                .collect()],
        };
        let points: Vec<(f64, f64)> = runs.iter().flatten().copied().collect();
        // plotters draws lines wider than 1 px as polygons with mitred joins, which spike far
        // outside the plot on the sharp, short zig-zags of a dense noisy series: a line with
        // more than one point per 4 px that reverses direction at more than a quarter of its
        // points is drawn 1 px wide.
        let reversals = points
            .windows(3)
            .filter(|w| (w[1].1 - w[0].1) * (w[2].1 - w[1].1) < 0.0)
            .count();
        let dense = points.len() > columns / 4;
        let width = if dense && reversals * 4 > points.len() {
            1
        } else {
            2
        };
        let line_style = color.stroke_width(width);
        // Every run but the last is drawn here, the last one below.
        let last_run = runs.len().saturating_sub(1);
        for run in &runs[..last_run] {
            match s.style {
                SeriesStyle::Line => {
                    chart
                        .draw_series(LineSeries::new(run.iter().copied(), line_style))
                        .map_err(err)?;
                }
                SeriesStyle::Dashed => {
                    chart
                        .draw_series(DashedLineSeries::new(
                            run.iter().copied(),
                            10,
                            6,
                            line_style,
                        ))
                        .map_err(err)?;
                }
                SeriesStyle::Points | SeriesStyle::LinePoints => {}
            }
        }
        let last: &[(f64, f64)] = runs.get(last_run).map(Vec::as_slice).unwrap_or(&[]);
        match s.style {
            SeriesStyle::Line => {
                chart
                    .draw_series(LineSeries::new(last.iter().copied(), line_style))
                    .map_err(err)?;
            }
            SeriesStyle::Dashed => {
                chart
                    .draw_series(DashedLineSeries::new(
                        last.iter().copied(),
                        10,
                        6,
                        line_style,
                    ))
                    .map_err(err)?;
            }
            SeriesStyle::Points => {
                chart
                    .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                    .map_err(err)?;
            }
            SeriesStyle::LinePoints => {
                chart
                    .draw_series(LineSeries::new(points.iter().copied(), line_style))
                    .map_err(err)?;
                chart
                    .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                    .map_err(err)?;
            }
        }
        if let Some((lo, hi)) = &s.bars {
            // Vertical bar from lo to hi with 8 px caps.
            let bar_style = color.stroke_width(1);
            for ((&x, &y), (&l, &h)) in s.x.iter().zip(&s.y).zip(lo.iter().zip(hi)) {
                if !(usable(x, log_x) && usable(y, log_y) && usable(l, log_y) && usable(h, log_y)) {
                    continue;
                }
                let (l, h) = (l.min(y), h.max(y));
                let cap = |v: f64| {
                    EmptyElement::at((x, v)) + PathElement::new(vec![(-4, 0), (4, 0)], bar_style)
                };
                chart
                    .draw_series([PathElement::new(vec![(x, l), (x, h)], bar_style)])
                    .map_err(err)?;
                chart.draw_series([cap(l), cap(h)]).map_err(err)?;
            }
        }
    }

    let (xr, yr) = chart.plotting_area().get_pixel_range();
    Ok(PixelRect {
        x0: xr.start,
        y0: yr.start,
        x1: xr.end,
        y1: yr.end,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        for (v, want) in [
            (2000.0, "2000"),
            (0.5, "0.5"),
            (-10.0, "-10"),
            (0.1 + 0.2, "0.3"),
            (-1.1e-16, "0"),
            (150_000.0, "1.5e5"),
            (2e-5, "2e-5"),
            (0.001, "0.001"),
        ] {
            assert_eq!(tick_label(v), want, "tick_label({v})");
        }
    }

    /// Ticks are checked against the 1-2-5 rule by hand: a range under a decade (the
    /// training-loss figure's 0.8…3) gets more than one label, every tick lies in the range,
    /// and a range of many decades gets at most a dozen.
    #[test]
    fn log_axes_get_readable_ticks() {
        assert_eq!(log_ticks(0.8, 3.0), vec![0.8, 0.9, 1.0, 2.0, 3.0]);
        assert_eq!(log_ticks(0.05, 3.0), vec![0.05, 0.1, 0.2, 0.5, 1.0, 2.0]);
        assert_eq!(log_ticks(1.0, 1e3), vec![1.0, 10.0, 100.0, 1000.0]);
        assert_eq!(log_ticks(3.0, 150.0), vec![5.0, 10.0, 20.0, 50.0, 100.0]);
        assert_eq!(
            log_ticks(1e-3, 1e4),
            vec![1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4]
        );
        assert_eq!(log_ticks(1.1, 1.9), vec![1.2, 1.5]);
        let many = log_ticks(1e-15, 1e15);
        assert!(
            many.len() <= MAX_LOG_TICKS && many.len() >= MIN_LOG_TICKS,
            "{many:?}"
        );
        for (lo, hi) in [(0.3, 0.9), (2.0, 7.0), (1e-4, 3e-2), (123.0, 4567.0)] {
            let t = log_ticks(lo, hi);
            assert!(t.len() >= MIN_LOG_TICKS, "[{lo}, {hi}]: {t:?}");
            assert!(t.iter().all(|&v| v >= lo && v <= hi), "[{lo}, {hi}]: {t:?}");
        }
        assert!(log_ticks(0.0, 1.0).is_empty());
    }

    /// Entries flow left to right and wrap before passing the width; the box encloses them.
    #[test]
    fn legend_entries_wrap_into_rows() {
        let entry = |tw: i32| LEGEND_SAMPLE_PX + LEGEND_SAMPLE_GAP_PX + tw;
        let one_row = legend_layout(&[40, 60], 1000);
        assert_eq!(
            one_row.entries,
            vec![
                (LEGEND_PAD_PX, LEGEND_PAD_PX),
                (
                    LEGEND_PAD_PX + entry(40) + LEGEND_ENTRY_GAP_PX,
                    LEGEND_PAD_PX
                )
            ]
        );
        assert_eq!(one_row.height, LEGEND_ROW_PX + 2 * LEGEND_PAD_PX);
        // Three entries of 300 px text in 700 px: two on the first row, one on the second.
        let wrapped = legend_layout(&[300, 300, 300], 700);
        assert_eq!(
            wrapped.entries[2],
            (LEGEND_PAD_PX, LEGEND_PAD_PX + LEGEND_ROW_PX)
        );
        assert_eq!(wrapped.height, 2 * LEGEND_ROW_PX + 2 * LEGEND_PAD_PX);
        assert!(wrapped.width <= 700, "{wrapped:?}");
        // An entry wider than the room gets its own row rather than vanishing.
        let wide = legend_layout(&[900, 10], 500);
        assert_eq!(wide.entries.len(), 2);
        assert_eq!(wide.entries[1].1, LEGEND_PAD_PX + LEGEND_ROW_PX);
    }

    #[test]
    fn paths_from_stem_or_extension() {
        let (p, s) = figure_paths(Path::new("out/fig1"));
        assert_eq!(
            (p.as_path(), s.as_path()),
            (Path::new("out/fig1.png"), Path::new("out/fig1.svg"))
        );
        let (p, s) = figure_paths(Path::new("adev.PNG"));
        assert_eq!(
            (p.as_path(), s.as_path()),
            (Path::new("adev.png"), Path::new("adev.svg"))
        );
        let (p, _) = figure_paths(Path::new("run.2024"));
        assert_eq!(p, Path::new("run.2024.png"));
    }
}

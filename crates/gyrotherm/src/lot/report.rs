//! `lot report`: the lot's page (`DIR/index.html`) and its data (`DIR/lot.csv`).
//!
//! The page gives the yield (units whose newest run passed, of those judged; an inertial unit
//! passes only when every axis passes), each figure's distribution across units (an inertial
//! unit by its worst axis) and over test date with its limits drawn, the worst units
//! (smallest margin first) and, when the lot holds inertial units, each unit's axes with
//! their verdicts and worst figures. Only each unit's newest run counts; `lot.csv` holds every run,
//! one row per figure and log, with its `latest` mark. The figures are drawn with the
//! report's plotting helpers ([`crate::report::write_figure`]); every text from the
//! database is escaped on the page, and CSV fields are quoted by the csv writer.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::atomic_file::write_bytes_atomically;
use crate::report::html::escape;
use crate::report::{
    write_figure, Figure, Panel, ReportError, Series, SeriesStyle, FIGURE_HEIGHT_PX,
    FIGURE_WIDTH_PX,
};
use crate::spec::FIGURES;

use super::{FigureRow, Run, RunVerdict};

/// How many units the "worst units" table lists.
pub(crate) const WORST_UNITS: usize = 10;

/// The lot's yield over each unit's newest run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Yield {
    pub units: usize,
    pub passed: usize,
    pub failed: usize,
    /// Units whose newest run was judged without a spec.
    pub not_judged: usize,
}

impl Yield {
    /// Passed over judged, or None when none was judged.
    pub fn fraction(&self) -> Option<f64> {
        let judged = self.passed + self.failed;
        (judged > 0).then(|| self.passed as f64 / judged as f64)
    }
}

/// The yield of `runs` (newest run of each unit; an inertial unit counts as passed only when
/// every axis passed).
pub fn lot_yield(runs: &[Run]) -> Yield {
    let latest = runs.iter().filter(|r| r.latest);
    let mut y = Yield {
        units: 0,
        passed: 0,
        failed: 0,
        not_judged: 0,
    };
    for r in latest {
        y.units += 1;
        // A unit's verdict is its axes' (made so when judged, checked when read back).
        match r.verdict {
            RunVerdict::Pass => y.passed += 1,
            RunVerdict::Fail => y.failed += 1,
            RunVerdict::None => y.not_judged += 1,
        }
    }
    y
}

/// A unit's smallest margin over its limited figures (None: nothing limited).
fn min_margin(r: &Run) -> Option<f64> {
    r.figures
        .iter()
        .filter_map(|f| f.margin)
        .min_by(f64::total_cmp)
}

/// The cells of the figure with the smallest margin among `figures` (name, value, margin;
/// empty when none has a margin), its name as `name` gives it.
fn worst_cells<'a>(
    figures: impl Iterator<Item = &'a FigureRow>,
    name: impl Fn(&FigureRow) -> String,
) -> (String, String, String) {
    figures
        .filter(|f| f.margin.is_some())
        .min_by(|a, b| a.margin.unwrap_or(0.0).total_cmp(&b.margin.unwrap_or(0.0)))
        .map_or((String::new(), String::new(), String::new()), |f| {
            (
                name(f),
                format!("{:.4e}", f.value),
                format!("{:+.3e}", f.margin.unwrap_or(f64::NAN)),
            )
        })
}

/// A CSV text field that a spreadsheet would run as a formula gets a leading `'`.
fn csv_text(s: &str) -> String {
    if s.starts_with(['=', '+', '@', '\t', '\r']) {
        format!("'{s}")
    } else {
        s.to_string()
    }
}

/// Every run as CSV: one row per figure and log (and axis, for an inertial unit: `axis` names
/// its gyro column and `axis_verdict` gives the axis's verdict; both empty for a single-axis
/// run).
pub(crate) fn lot_csv(runs: &[Run]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "run_id",
        "unit",
        "tested_at",
        "latest",
        "run_verdict",
        "station",
        "model_content_sha256",
        "log",
        "figure",
        "value",
        "limit_min",
        "limit_max",
        "verdict",
        "margin",
        "axis",
        "axis_verdict",
    ])?;
    let num = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    for r in runs {
        let at = r.tested_at();
        for f in &r.figures {
            let log = r
                .inputs
                .iter()
                .find(|i| i.position == f.position)
                .map_or("", |i| i.path.as_str());
            w.write_record([
                r.id.to_string(),
                csv_text(&r.unit),
                at.clone(),
                r.latest.to_string(),
                r.verdict.as_str().to_string(),
                csv_text(&r.station),
                r.model_content_sha256.clone(),
                csv_text(log),
                f.figure.clone(),
                num(Some(f.value)),
                num(f.limit_min),
                num(f.limit_max),
                f.pass
                    .map_or("", |p| if p { "pass" } else { "fail" })
                    .to_string(),
                num(f.margin),
                csv_text(r.gyro_of(f.axis).unwrap_or("")),
                r.axis_of(f.axis)
                    .map_or("", |a| a.verdict.as_str())
                    .to_string(),
            ])?;
        }
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// Write `dir/index.html`, `dir/lot.csv` and a PNG and SVG per figure; returns the page.
pub fn write_lot_report(dir: &Path, title: &str, runs: &[Run]) -> Result<PathBuf, ReportError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ReportError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let csv_path = dir.join("lot.csv");
    let csv = lot_csv(runs).map_err(|e| ReportError::Data {
        what: format!("lot.csv: {e}"),
    })?;
    write_bytes_atomically(&csv_path, &csv).map_err(io(&csv_path))?;

    let latest: Vec<&Run> = runs.iter().filter(|r| r.latest).collect();
    let y = lot_yield(runs);
    let t0 = latest
        .iter()
        .map(|r| r.tested_at_unix_ms)
        .min()
        .unwrap_or(0);
    let mut h = String::with_capacity(16 * 1024);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{t}</title>\n\
         <style>{CSS}</style>\n</head>\n<body>\n<h1>{t}</h1>\n",
        t = escape(title)
    );
    h.push_str("<h2>Yield</h2>\n<table id=\"yield\">\n<thead><tr><th>units</th><th>passed</th>\
                <th>failed</th><th>not judged</th><th>yield</th><th>runs</th></tr></thead>\n<tbody>");
    let _ = writeln!(
        h,
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n</tbody>\n</table>",
        y.units,
        y.passed,
        y.failed,
        y.not_judged,
        y.fraction()
            .map_or("-".to_string(), |f| format!("{:.1} %", 100.0 * f)),
        runs.len()
    );
    h.push_str(
        "<p>Each unit counts once, by its newest run; <a href=\"lot.csv\">lot.csv</a> holds \
         every run.</p>\n",
    );

    // Worst units: failing first, then by smallest margin.
    let mut ranked: Vec<(&Run, Option<f64>)> = latest.iter().map(|r| (*r, min_margin(r))).collect();
    ranked.retain(|(_, m)| m.is_some());
    ranked.sort_by(|a, b| a.1.unwrap_or(0.0).total_cmp(&b.1.unwrap_or(0.0)));
    h.push_str("<h2>Worst units</h2>\n");
    if ranked.is_empty() {
        h.push_str("<p>No unit was judged against a spec.</p>\n");
    } else {
        h.push_str(
            "<table id=\"worst\">\n<thead><tr><th>unit</th><th>verdict</th><th>tested at</th>\
             <th>worst figure</th><th>value</th><th>margin</th></tr></thead>\n<tbody>\n",
        );
        for (r, _) in ranked.iter().take(WORST_UNITS) {
            let (fig, val, mar) = worst_cells(r.figures.iter(), |f| match r.gyro_of(f.axis) {
                Some(g) => format!("{} ({g})", f.figure),
                None => f.figure.clone(),
            });
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&r.unit),
                r.verdict.as_str(),
                escape(&r.tested_at()),
                escape(&fig),
                val,
                mar
            );
        }
        h.push_str("</tbody>\n</table>\n");
    }

    // Inertial units: each axis's verdict and its worst figure (single-axis lots have none).
    let units: Vec<&&Run> = latest.iter().filter(|r| r.is_unit()).collect();
    if !units.is_empty() {
        h.push_str(
            "<h2>Axes of each inertial unit</h2>\n<p>A unit passes only when every axis \
             passes.</p>\n<table id=\"axes\">\n<thead><tr><th>unit</th><th>unit verdict</th>\
             <th>axis</th><th>sensors</th><th>axis verdict</th><th>worst figure</th>\
             <th>value</th><th>margin</th></tr></thead>\n<tbody>\n",
        );
        for r in units {
            for a in &r.axes {
                let on_axis = r.figures.iter().filter(|f| f.axis == Some(a.axis));
                let (fig, val, mar) = worst_cells(on_axis, |f| f.figure.clone());
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>\
                     <td>{}</td><td>{}</td></tr>",
                    escape(&r.unit),
                    r.verdict.as_str(),
                    escape(&a.gyro),
                    escape(&a.temps.join(", ")),
                    a.verdict.as_str(),
                    escape(&fig),
                    val,
                    mar
                );
            }
        }
        h.push_str("</tbody>\n</table>\n");
    }

    // One distribution and one over-date figure per figure any unit has.
    h.push_str(
        "<h2>Figures</h2>\n<table id=\"figures\">\n<thead><tr><th>figure</th><th>unit</th>\
                <th>units</th><th>min</th><th>median</th><th>max</th><th>limit min</th>\
                <th>limit max</th><th>failed</th></tr></thead>\n<tbody>\n",
    );
    let mut figs = Vec::new();
    for def in FIGURES {
        let mut pts: Vec<(f64, f64, Option<bool>)> = Vec::new();
        let (mut lo, mut hi) = (None, None);
        for r in &latest {
            if let Some(f) = r.worst(def.key) {
                let hours = (r.tested_at_unix_ms - t0) as f64 / 3.6e6;
                pts.push((hours, f.value, f.pass));
                lo = lo.or(f.limit_min);
                hi = hi.or(f.limit_max);
            }
        }
        if pts.is_empty() {
            continue;
        }
        let mut sorted: Vec<f64> = pts.iter().map(|p| p.1).collect();
        sorted.sort_by(f64::total_cmp);
        let failed = pts.iter().filter(|p| p.2 == Some(false)).count();
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x}"));
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td>\
             <td>{}</td><td>{}</td><td>{}</td></tr>",
            def.key,
            escape(def.unit),
            sorted.len(),
            sorted[0],
            sorted[sorted.len() / 2],
            sorted[sorted.len() - 1],
            opt(lo),
            opt(hi),
            failed
        );
        figs.push((def, pts, sorted, lo, hi));
    }
    h.push_str("</tbody>\n</table>\n");

    for (def, pts, sorted, lo, hi) in figs {
        let limit_series = |x0: f64, x1: f64| {
            let mut s = Vec::new();
            for (name, v) in [("limit min", lo), ("limit max", hi)] {
                if let Some(v) = v {
                    s.push(
                        Series::line(name, &[x0, x1], &[v, v])
                            .with_style(SeriesStyle::Dashed)
                            .with_color((200, 30, 30)),
                    );
                }
            }
            s
        };
        let ranks: Vec<f64> = (1..=sorted.len()).map(|i| i as f64).collect();
        let mut series =
            vec![Series::line("units", &ranks, &sorted).with_style(SeriesStyle::Points)];
        series.extend(limit_series(1.0, sorted.len().max(2) as f64));
        let y_label = format!("{} ({})", def.key, def.unit);
        let dist = Figure {
            title: format!("{}: distribution across units", def.what),
            x_label: "unit rank (smallest value first)".into(),
            log_x: false,
            width_px: FIGURE_WIDTH_PX,
            height_px: FIGURE_HEIGHT_PX,
            panels: vec![Panel {
                y_label: y_label.clone(),
                log_y: false,
                series,
            }],
        };
        let dist_files = write_figure(&dir.join(format!("dist_{}", def.key)), &dist)?;
        let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let x1 = xs.iter().copied().fold(0.0, f64::max).max(1e-3);
        let mut series = vec![Series::line("units", &xs, &ys).with_style(SeriesStyle::Points)];
        series.extend(limit_series(0.0, x1));
        let time = Figure {
            title: format!("{} over test date", def.what),
            x_label: "test time since the first unit (h)".into(),
            log_x: false,
            width_px: FIGURE_WIDTH_PX,
            height_px: FIGURE_HEIGHT_PX,
            panels: vec![Panel {
                y_label,
                log_y: false,
                series,
            }],
        };
        let time_files = write_figure(&dir.join(format!("date_{}", def.key)), &time)?;
        for (files, what) in [(dist_files, "distribution"), (time_files, "over test date")] {
            let name = |p: &Path| {
                escape(
                    &p.file_name()
                        .map(|n| n.to_string_lossy())
                        .unwrap_or_default(),
                )
            };
            let _ = writeln!(
                h,
                "<figure>\n<img src=\"{}\" alt=\"{k} {what}\" width=\"{}\" height=\"{}\">\n\
                 <figcaption>{k} ({u}), {what}; limits dashed (<a href=\"{}\">SVG</a>)</figcaption>\n</figure>",
                name(&files.png),
                files.width_px / 2,
                files.height_px / 2,
                name(&files.svg),
                k = def.key,
                u = escape(def.unit),
            );
        }
    }
    h.push_str("</body>\n</html>\n");
    let page = dir.join("index.html");
    write_bytes_atomically(&page, h.as_bytes()).map_err(io(&page))?;
    Ok(page)
}

const CSS: &str = "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;margin:2em auto;\
max-width:1050px;color:#222;line-height:1.4}h2{border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #bbb;padding:.3em .7em;\
text-align:right}th{background:#eee}td:first-child,th:first-child{text-align:left}\
figure{display:inline-block;margin:.6em}figure img{border:1px solid #ddd}\
figcaption{font-size:.9em;color:#444}";

//! The report of an inertial unit (`gyrotherm report` with column lists): `DIR/index.html`
//! with the table across axes (axis × figure) and a section per axis (its comparison table,
//! its compensation and bias figures, a link to its full page), and each axis's full
//! single-axis report in `DIR/axisN/` (N = 1, 2, … in gyro column order: folder names never
//! come from the log's column names). Judged against a spec sheet (`report --spec`), the page
//! also gives the unit's verdict of each column and each axis's verdicts.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::html::{escape, push_table, Table, CSS};
use super::{grouped_warnings, results_table, write_full_report_with, CoverageModel, ReportError};
use crate::atomic_file::write_bytes_atomically;
use crate::compare::unit::ImuComparison;
use crate::compare::CompareConfig;
use crate::spec::unit::{unit_verdicts, AxisVerdicts, UNIT_FIT_COLUMN};
use crate::spec::{Spec, Verdict};

/// The figures of each axis's page that the unit page shows in the axis's section, with
/// their captions.
pub(crate) const UNIT_PAGE_FIGURES: [(&str, &str); 2] = [
    (
        "fig7_compensation",
        "raw and compensated output of the main held-out log",
    ),
    (
        "fig6_rate_table",
        "output at the table rates (an axis with a rate-table held-out log)",
    ),
];

/// The across-axes table names the log, the figure and the axis in its first three columns.
const UNIT_CSS: &str = "table.across-axes td:nth-child(-n+3){text-align:left}\
table.axis-verdicts td:nth-child(-n+3){text-align:left}";

/// The folder of axis `k` (0-based) inside the report folder.
pub(crate) fn axis_folder(k: usize) -> String {
    format!("axis{}", k + 1)
}

/// The unit's verdict of each judged column ([`unit_verdicts`]): a row per column, a cell per
/// axis and the unit's cell (`PASS` only when every axis passes).
pub(crate) fn unit_verdict_table(spec: &Spec, verdicts: &[AxisVerdicts]) -> Table {
    let mut headers = vec!["column".to_owned()];
    headers.extend(verdicts.iter().map(|a| a.gyro.clone()));
    headers.push("unit".to_owned());
    let rows = unit_verdicts(spec, verdicts)
        .into_iter()
        .map(|(name, unit)| {
            let mut row = vec![name];
            for a in verdicts {
                let failed = unit.failed_axes.contains(&a.gyro);
                row.push(if failed { "FAIL" } else { "PASS" }.to_owned());
            }
            row.push(unit.word().to_owned());
            row
        })
        .collect();
    Table { headers, rows }
}

/// One axis's verdicts: a row per judged column, figure and held-out log.
pub(crate) fn axis_verdict_table(a: &AxisVerdicts) -> Table {
    let headers = [
        "column",
        "figure",
        "held-out log",
        "value",
        "unit",
        "limit",
        "verdict",
        "margin",
    ]
    .map(str::to_owned)
    .to_vec();
    let mut rows = Vec::new();
    let mut push = |label: &str, v: &Verdict| {
        for f in &v.figures {
            rows.push(vec![
                label.to_owned(),
                f.figure.to_owned(),
                f.log.clone(),
                format!("{:.4e}", f.value),
                f.unit.to_owned(),
                f.limit_text(),
                f.word().to_owned(),
                format!("{:+.3e}", f.margin),
            ]);
        }
    };
    for c in &a.columns {
        push(c.label, &c.verdict);
    }
    if let Some((label, v)) = &a.unit_fit {
        push(&format!("{UNIT_FIT_COLUMN}: {label}"), v);
    }
    Table { headers, rows }
}

/// Write every axis's full report, then `dir/index.html`; returns the unit page's path.
/// `extra_warnings` (e.g. gaps filled on reading) are listed after the axes' findings. With
/// `judged` (a spec sheet and [`crate::spec::unit::judge_unit_comparison`]'s verdicts), the
/// page shows the unit's verdict of each column across the axes and, in each axis's section,
/// the axis's verdicts.
pub(crate) fn write_unit_report(
    dir: &Path,
    cmp: &ImuComparison,
    cfg: &CompareConfig,
    extra_warnings: &[String],
    judged: Option<(&Spec, &[AxisVerdicts])>,
) -> Result<PathBuf, ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut warnings = Vec::new();
    for (k, a) in cmp.axes.iter().enumerate() {
        let train = a.train_named();
        let test = a.test_named();
        // An axis on several sensors: its coverage figures are of the unit's own fit (the
        // map and σ the unit's `compensate` writes), not of a one-sensor column.
        let unit_fit = a.unit_fit.as_ref().map(|u| CoverageModel {
            label: &u.label,
            model: &u.coverage_model,
            compensated_dps: &u.compensated_dps,
        });
        write_full_report_with(
            &dir.join(axis_folder(k)),
            &train,
            &test,
            &a.comparison,
            cfg,
            &[],
            unit_fit.as_ref(),
        )?;
        for w in grouped_warnings(&test, &a.comparison) {
            warnings.push(format!("{}: {w}", a.gyro));
        }
    }
    warnings.extend(extra_warnings.iter().cloned());

    let mut h = String::with_capacity(8192);
    let title = "gyrotherm report: thermal compensation of an inertial unit, per axis";
    // `write!` into a String cannot fail.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>{title}</title>\n<style>{CSS}{UNIT_CSS}</style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    );
    h.push_str("<h2>Across axes</h2>\n");
    push_table(&mut h, &cmp.across_axes(cfg), "across-axes");
    if let Some((spec, verdicts)) = judged {
        let pass = verdicts.iter().all(AxisVerdicts::pass);
        let _ = writeln!(
            h,
            "<h2>Against the spec {}: {}</h2>\n<p>Each column's compensated output on every \
             held-out log, axis by axis; a column passes for the unit only when it passes on \
             every axis. Each axis's section lists its figures.</p>",
            escape(&spec.name),
            if pass { "PASS" } else { "FAIL" }
        );
        push_table(&mut h, &unit_verdict_table(spec, verdicts), "unit-verdicts");
    }
    h.push_str("<h2>Warnings</h2>\n");
    if warnings.is_empty() {
        h.push_str("<p>None.</p>\n");
    } else {
        h.push_str("<ul class=\"warnings\">\n");
        for w in &warnings {
            let _ = writeln!(h, "<li>{}</li>", escape(w));
        }
        h.push_str("</ul>\n");
    }
    let mut n = 0;
    for (k, a) in cmp.axes.iter().enumerate() {
        let folder = axis_folder(k);
        // With several sensors the one-sensor methods read `temp`, the unit's fit its own.
        let unit_fit = a.unit_fit.as_ref().map_or(String::new(), |u| {
            format!("; the unit's fit on {}", u.temps.join(", "))
        });
        let _ = writeln!(
            h,
            "<section class=\"axis\">\n<h2>Axis {}: {} (temperature {}{})</h2>",
            k + 1,
            escape(&a.gyro),
            escape(&a.temp),
            escape(&unit_fit)
        );
        push_table(&mut h, &results_table(&a.table(cfg)), "comparison");
        if let Some(v) = judged.and_then(|(_, vs)| vs.get(k)) {
            let _ = writeln!(
                h,
                "<h3>Axis {} against the spec: {}</h3>",
                k + 1,
                if v.pass() { "PASS" } else { "FAIL" }
            );
            push_table(&mut h, &axis_verdict_table(v), "axis-verdicts");
        }
        for (stem, caption) in UNIT_PAGE_FIGURES {
            // An axis without the run a figure needs has no such file (its page says why).
            if !dir.join(&folder).join(format!("{stem}.png")).is_file() {
                continue;
            }
            n += 1;
            let caption = escape(&format!("{}: {caption}", a.gyro));
            let _ = write!(
                h,
                "<figure>\n<img src=\"{folder}/{stem}.png\" alt=\"{caption}\">\n\
                 <figcaption>Figure {n}. {caption} (<a href=\"{folder}/{stem}.svg\">SVG</a>)\
                 </figcaption>\n</figure>\n"
            );
        }
        let _ = writeln!(
            h,
            "<p><a href=\"{folder}/index.html\">The full report of axis {}</a>: every figure, \
             the models and the training logs.</p>\n</section>",
            k + 1
        );
    }
    h.push_str("</body>\n</html>\n");
    let path = dir.join("index.html");
    write_bytes_atomically(&path, h.as_bytes()).map_err(|source| ReportError::Io {
        path: path.clone(),
        source,
    })?;
    Ok(path)
}

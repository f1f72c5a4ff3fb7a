//! The results table of a comparison, built once and rendered as text here
//! ([`ComparisonTable::write_text`]) and as HTML by the report (`report::comparison_table`).

use super::{CompareConfig, Comparison, Performance};
use crate::model::SubModel;
use crate::settings::export::ExportTarget;

impl Comparison {
    /// One line per fitted model: its sub-models, and why no residual LSTM was kept when
    /// none was.
    pub(crate) fn model_lines(&self) -> Vec<String> {
        self.fits
            .iter()
            .zip(&self.columns)
            .map(|(f, col)| {
                let autopilot = col
                    .key
                    .parse::<ExportTarget>()
                    .is_ok_and(|t| t.is_autopilot());
                if autopilot {
                    return format!(
                        "{:>16}: a cubic in temperature fitted to the steady-state bias of the {} \
                         model (its rate and lag terms, and its scale-factor model, are not \
                         carried)",
                        col.label,
                        f.model.label()
                    );
                }
                let part = |s: &Option<SubModel>| s.as_ref().map_or("none", |s| s.kind());
                let mut line = format!(
                    "{:>16}: bias model {}, scale-factor model {}",
                    col.label,
                    part(&f.model.bias),
                    part(&f.model.scale)
                );
                let lstm_kept = [&f.model.bias, &f.model.scale]
                    .iter()
                    .any(|s| matches!(s, Some(SubModel::Lstm { .. } | SubModel::Residual { .. })));
                if f.model.method.is_recipe() && !lstm_kept {
                    line.push_str(" (holds no LSTM: the recipe has none, or no LSTM beat its least-squares base on the validation data)");
                }
                line
            })
            .collect()
    }

    /// One line per held-out log on which every model judged has a worse figure than the
    /// raw output (bias stability on a static log, max |K(t) − 1| on a rate-table log): the
    /// first thing a reader must know, said above the table. Empty when some model helps.
    pub fn headline(&self, cfg: &CompareConfig) -> Vec<String> {
        let mut out = Vec::new();
        for t in &self.tests {
            let (figure, unit, value): (String, &str, FigureOf) = if t.is_static {
                (
                    format!("bias stability (τ = {} s)", fmt_num(cfg.tau_s)),
                    "°/h",
                    |p| p.bias_stability_dph,
                )
            } else {
                ("max |K(t) − 1|".to_owned(), "ppm", |p| p.sf_error_ppm)
            };
            let Some(raw) = value(&t.raw).filter(|v| v.is_finite()) else {
                continue;
            };
            let judged: Vec<(&str, f64)> = t
                .methods
                .iter()
                .filter_map(|m| Some((m.label, value(&m.performance).filter(|v| v.is_finite())?)))
                .collect();
            let Some(&(best_label, best)) = judged.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
                continue;
            };
            if best > raw {
                out.push(format!(
                    "every model is worse than the raw output on {}: {figure} raw {raw:.5} {unit}, \
                     best model ({best_label}) {best:.5} {unit}: compensation makes this log worse",
                    t.name
                ));
            }
        }
        out
    }

    /// The results table, built once for every rendering.
    pub fn table(&self, cfg: &CompareConfig) -> ComparisonTable {
        let mut columns = vec!["raw".to_owned()];
        columns.extend(self.columns.iter().map(|c| c.label.to_owned()));
        // Columns that could not be fitted keep their place, each cell saying so; the note
        // under the table gives why.
        columns.extend(self.failed.iter().map(|c| c.label.to_owned()));
        let notes = self
            .failed
            .iter()
            .map(|c| format!("{}: not fitted: {}", c.label, c.reason))
            .collect();
        let blocks = self
            .tests
            .iter()
            .map(|t| {
                // None: the column has no figures on this log (failed on it, or not fitted).
                let all: Vec<Option<&Performance>> = std::iter::once(Some(&t.raw))
                    .chain(self.columns.iter().map(|c| {
                        t.methods
                            .iter()
                            .find(|r| r.key == c.key)
                            .map(|r| &r.performance)
                    }))
                    .collect();
                let failed_here = |i: usize| {
                    let key = self.columns[i - 1].key;
                    t.failed.iter().any(|f| f.key == key)
                };
                let cells = |f: &dyn Fn(&Performance) -> String| -> Vec<String> {
                    all.iter()
                        .enumerate()
                        .map(|(i, p)| match p {
                            Some(p) => f(p),
                            None if failed_here(i) => FAILED_CELL.to_owned(),
                            None => "-".to_owned(),
                        })
                        .chain(self.failed.iter().map(|_| NOT_FITTED_CELL.to_owned()))
                        .collect()
                };
                let mut rows = Vec::new();
                if t.is_static {
                    rows.push(TableRow {
                        figure: TableFigure::BiasStability { tau_s: cfg.tau_s },
                        cells: cells(&|p| cell(p.bias_stability_dph, 5)),
                        floor: Some(cell(t.floor_dph, 5)),
                    });
                    if let (Some(_), Some(fl)) = (t.raw.bias_stability_dph, t.floor_dph) {
                        rows.push(TableRow {
                            figure: TableFigure::TimesNoiseFloor,
                            cells: cells(&|p| cell(p.bias_stability_dph.map(|b| b / fl), 2)),
                            floor: None,
                        });
                    }
                } else {
                    rows.push(TableRow {
                        figure: TableFigure::SfError,
                        cells: cells(&|p| cell(p.sf_error_ppm, 1)),
                        floor: None,
                    });
                    rows.push(TableRow {
                        figure: TableFigure::SfThermalError,
                        cells: cells(&|p| cell(p.sf_thermal_error_ppm, 1)),
                        floor: None,
                    });
                    for (k, r) in t.raw.rate_ranges.iter().enumerate() {
                        rows.push(TableRow {
                            figure: TableFigure::OutputAt {
                                table_dps: r.table_dps,
                            },
                            cells: cells(&|p| {
                                p.rate_ranges
                                    .get(k)
                                    .map(|r| format!("{:.5}..{:.5}", r.min_dps, r.max_dps))
                                    .unwrap_or_else(|| "-".into())
                            }),
                            floor: None,
                        });
                    }
                }
                TableBlock {
                    log: t.name.clone(),
                    is_static: t.is_static,
                    has_floor: t.floor_dph.is_some(),
                    rows,
                    notes: t
                        .failed
                        .iter()
                        .map(|c| format!("{}: failed on this log: {}", c.label, c.reason))
                        .collect(),
                }
            })
            .collect();
        ComparisonTable {
            columns,
            blocks,
            notes,
        }
    }
}

/// Reads one figure of an output column.
type FigureOf = fn(&Performance) -> Option<f64>;

/// The cell of a column whose fit on the training logs failed.
pub(crate) const NOT_FITTED_CELL: &str = "not fitted";
/// The cell of a fitted column that could not compensate or be judged on a held-out log.
pub(crate) const FAILED_CELL: &str = "failed";

fn cell(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => "-".into(),
    }
}

/// The results table of a comparison: one block per held-out log, one column per output
/// (raw, then each method), cells already formatted.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonTable {
    /// Output columns: `raw`, then each column's name ([`Column::label`](super::Column)).
    pub columns: Vec<String>,
    pub blocks: Vec<TableBlock>,
    /// Why a column has no figures at all (its fit failed), one line per such column.
    pub notes: Vec<String>,
}

/// The rows of one held-out log.
#[derive(Debug, Clone, PartialEq)]
pub struct TableBlock {
    pub log: String,
    pub is_static: bool,
    /// Whether the log carries the noise-only truth column (a noise-floor column).
    pub has_floor: bool,
    pub rows: Vec<TableRow>,
    /// Why a column has no figures on this log, one line per such column.
    pub notes: Vec<String>,
}

/// One figure across the outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct TableRow {
    pub figure: TableFigure,
    /// One cell per [`ComparisonTable::columns`].
    pub cells: Vec<String>,
    /// Noise-floor cell (bias-stability row only).
    pub floor: Option<String>,
}

/// Which figure a row holds.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum TableFigure {
    /// Bias stability, °/h, over `tau_s`.
    BiasStability { tau_s: f64 },
    /// Bias stability as a multiple of the noise floor.
    TimesNoiseFloor,
    /// max |K(t) − 1|, ppm.
    SfError,
    /// max |K(t) − K(room)|, ppm.
    SfThermalError,
    /// Range of the output at one table rate, °/s.
    OutputAt { table_dps: f64 },
}

impl TableFigure {
    /// The row label.
    pub fn label(&self) -> String {
        match self {
            TableFigure::BiasStability { tau_s } => {
                format!("bias stability (°/h, τ = {} s)", fmt_num(*tau_s))
            }
            TableFigure::TimesNoiseFloor => "× noise floor".to_owned(),
            TableFigure::SfError => "SF error max |K(t) − 1| (ppm)".to_owned(),
            TableFigure::SfThermalError => "SF thermal error vs room K (ppm)".to_owned(),
            TableFigure::OutputAt { table_dps } => format!("output at {table_dps:+} °/s (°/s)"),
        }
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

impl TableBlock {
    /// `name (static)` or `name (rate table)`.
    pub fn title(&self) -> String {
        format!(
            "{} ({})",
            self.log,
            if self.is_static {
                "static"
            } else {
                "rate table"
            }
        )
    }
}

impl ComparisonTable {
    /// Adds a column named `header` after the others: `per_log[i]` holds its figures on the
    /// log of block `i`, `floors[i]` that log's noise floor, °/h (the `× noise floor` row).
    /// A figure the column lacks is `-`.
    pub(crate) fn push_column(
        &mut self,
        header: &str,
        per_log: &[Performance],
        floors: &[Option<f64>],
    ) {
        self.columns.push(header.to_owned());
        let empty = Performance::default();
        for (i, b) in self.blocks.iter_mut().enumerate() {
            let p = per_log.get(i).unwrap_or(&empty);
            let floor = floors.get(i).copied().flatten();
            for r in &mut b.rows {
                let c = match r.figure {
                    TableFigure::BiasStability { .. } => cell(p.bias_stability_dph, 5),
                    TableFigure::TimesNoiseFloor => {
                        cell(p.bias_stability_dph.zip(floor).map(|(b, f)| b / f), 2)
                    }
                    TableFigure::SfError => cell(p.sf_error_ppm, 1),
                    TableFigure::SfThermalError => cell(p.sf_thermal_error_ppm, 1),
                    TableFigure::OutputAt { table_dps } => p
                        .rate_ranges
                        .iter()
                        .find(|r| r.table_dps == table_dps)
                        .map(|r| format!("{:.5}..{:.5}", r.min_dps, r.max_dps))
                        .unwrap_or_else(|| "-".into()),
                };
                r.cells.push(c);
            }
        }
    }

    /// Plain text, fixed-width columns: per held-out log a title line, a header line and one
    /// line per figure, then a blank line.
    pub fn write_text(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        for b in &self.blocks {
            writeln!(w, "held-out log {}", b.title())?;
            write!(w, "  {:<36}", "figure")?;
            for c in &self.columns {
                write!(w, "{c:>22}")?;
            }
            if b.has_floor {
                write!(w, "{:>22}", "noise floor")?;
            }
            writeln!(w)?;
            for r in &b.rows {
                let label = match r.figure {
                    TableFigure::TimesNoiseFloor => format!("  {}", r.figure.label()),
                    _ => r.figure.label(),
                };
                write!(w, "  {label:<36}")?;
                for c in &r.cells {
                    write!(w, "{c:>22}")?;
                }
                if let (true, Some(f)) = (b.has_floor, &r.floor) {
                    write!(w, "{f:>22}")?;
                }
                writeln!(w)?;
            }
            for n in &b.notes {
                writeln!(w, "  {n}")?;
            }
            writeln!(w)?;
        }
        for n in &self.notes {
            writeln!(w, "{n}")?;
        }
        if !self.notes.is_empty() {
            writeln!(w)?;
        }
        Ok(())
    }
}

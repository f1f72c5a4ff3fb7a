//! The verdict of measured figures against a spec sheet.

use serde::Serialize;

use super::{FigureDef, Figures, Limit, Spec, SpecError};

/// One limited figure on one log.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureVerdict {
    /// The figure's key.
    pub figure: &'static str,
    pub unit: &'static str,
    /// The log it was measured on.
    pub log: String,
    pub value: f64,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub pass: bool,
    /// Distance to the nearest limit in the figure's unit: positive inside, negative by how
    /// much it missed.
    pub margin: f64,
}

impl FigureVerdict {
    /// The limit as text: `min ..= max`, `>= min`, `<= max`, or empty.
    pub(crate) fn limit_text(&self) -> String {
        match (self.min, self.max) {
            (Some(a), Some(b)) => format!("{a} ..= {b}"),
            (Some(a), None) => format!(">= {a}"),
            (None, Some(b)) => format!("<= {b}"),
            (None, None) => String::new(),
        }
    }

    /// `pass` or `FAIL`.
    pub fn word(&self) -> &'static str {
        if self.pass {
            "pass"
        } else {
            "FAIL"
        }
    }
}

/// The verdict of one run (one output column over its logs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// The spec sheet's name and SHA-256.
    pub spec: String,
    pub spec_sha256: String,
    /// True when every limited figure passes on every log that gives it.
    pub pass: bool,
    /// Per figure (in [`FIGURES`](super::FIGURES) order), per log.
    pub figures: Vec<FigureVerdict>,
}

impl Verdict {
    /// `PASS` or `FAIL`.
    pub fn word(&self) -> &'static str {
        if self.pass {
            "PASS"
        } else {
            "FAIL"
        }
    }

    /// The verdict as text lines: one per figure and log, then the overall line.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::with_capacity(self.figures.len() + 1);
        for f in &self.figures {
            out.push(format!(
                "{:<22} {:>14} {:<7} limit {:<18} {} margin {:+.4e}  ({})",
                f.figure,
                fmt_value(f.value),
                f.unit,
                f.limit_text(),
                f.word(),
                f.margin,
                f.log
            ));
        }
        // The name comes from the sheet: escaped as `lot list` escapes a unit, so that no
        // control character (ESC, BEL) reaches the terminal.
        out.push(format!(
            "verdict: {} (spec {})",
            self.word(),
            self.spec.escape_debug()
        ));
        out
    }
}

fn fmt_value(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.4e}")
    } else {
        format!("{x:.6}")
    }
}

/// Judge `measured` (per log: its name and figures) against `spec`. Every limited figure must
/// be given by at least one log; it is judged on each log that gives it.
pub fn judge(spec: &Spec, measured: &[(String, Figures)]) -> Result<Verdict, SpecError> {
    let mut figures = Vec::new();
    for (def, limit) in spec.limits() {
        let before = figures.len();
        for (log, f) in measured {
            if let Some(&value) = f.get(def.key) {
                figures.push(one(def, limit, log, value));
            }
        }
        if figures.len() == before {
            return Err(SpecError::NotMeasured {
                key: def.key,
                from: def.from,
                logs: measured.iter().map(|(n, _)| n.clone()).collect(),
            });
        }
    }
    Ok(Verdict {
        spec: spec.name.clone(),
        spec_sha256: spec.sha256.clone(),
        pass: figures.iter().all(|f| f.pass),
        figures,
    })
}

fn one(def: &FigureDef, limit: Limit, log: &str, value: f64) -> FigureVerdict {
    FigureVerdict {
        figure: def.key,
        unit: def.unit,
        log: log.to_string(),
        value,
        min: limit.min,
        max: limit.max,
        pass: limit.passes(value),
        margin: limit.margin(value),
    }
}

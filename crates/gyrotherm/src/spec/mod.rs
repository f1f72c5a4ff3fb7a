//! Spec sheets: limits on the standard figures, and the verdict of a run against them.
//!
//! A spec sheet is a TOML file with one `[limits]` table; each key is a figure of
//! [`FIGURES`] (the names `gyrotherm evaluate --json` and `gyrotherm allan --json` print) and
//! takes `min` and/or `max` in the figure's unit:
//!
//! ```toml
//! name = "FOG-70 acceptance"          # optional, shown with the verdict
//! [limits]
//! bias_stability_dph = { max = 0.02 }
//! sf_thermal_error_ppm = { max = 30 }
//! arw_deg_rt_h = { max = 0.005 }
//! bias_dph = { min = -0.5, max = 0.5 }
//! ```
//!
//! [`Spec::parse`] refuses an unknown key (suggesting the nearest known names) and a malformed
//! limit, naming the file, line and column. [`judge`] gives a verdict per figure and per log
//! (value, limit, pass or fail, margin) and an overall one; a limited figure that no log of
//! the run gives (a scale-factor limit on a static log) is an error, never a silent pass.
//! The definitions each figure follows are tabulated in docs/method.md §7.

mod columns;
mod figures;
pub mod unit;
mod verdict;

pub(crate) use columns::{judge_comparison, ColumnVerdict};
pub use figures::{figure, measure, FigureDef, Figures, LogKind, MeasureOptions, FIGURES};
pub use verdict::{judge, FigureVerdict, Verdict};

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use sha2::{Digest, Sha256};
use toml::Spanned;

/// Limits on one figure, in its unit; at least one is set and `min <= max`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Limit {
    pub min: Option<f64>,
    pub max: Option<f64>,
}

impl Limit {
    /// Whether `value` lies within the limits (both ends included).
    pub fn passes(&self, value: f64) -> bool {
        self.margin(value) >= 0.0
    }

    /// Distance from `value` to the nearest limit in the figure's unit: positive inside,
    /// negative outside (how far it missed).
    pub fn margin(&self, value: f64) -> f64 {
        let lo = self.min.map_or(f64::INFINITY, |m| value - m);
        let hi = self.max.map_or(f64::INFINITY, |m| m - value);
        lo.min(hi)
    }
}

/// A parsed spec sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    /// Its `name`, or the file name.
    pub name: String,
    /// Where it was read from (for messages).
    pub path: PathBuf,
    /// The limits by figure key, in [`FIGURES`] order when iterated through [`Spec::limits`].
    limits: BTreeMap<&'static str, Limit>,
    /// The file's text, as recorded in a lot.
    pub text: String,
    /// SHA-256 of the file's bytes, hex.
    pub sha256: String,
}

/// Why a spec sheet was refused, or a verdict could not be given.
#[derive(Debug)]
#[non_exhaustive]
pub enum SpecError {
    /// The file could not be read.
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Not valid TOML, or a value of the wrong type (line and column from 1, when known).
    Syntax {
        path: PathBuf,
        line: Option<usize>,
        column: Option<usize>,
        message: String,
    },
    /// A `[limits]` key that is no known figure; `suggestions` are the nearest known names.
    UnknownFigure {
        path: PathBuf,
        line: usize,
        column: usize,
        key: String,
        suggestions: Vec<&'static str>,
    },
    /// A limit that is not finite, sets neither `min` nor `max`, or has `min > max`.
    BadLimit {
        path: PathBuf,
        line: usize,
        column: usize,
        key: String,
        reason: String,
    },
    /// No `[limits]` table, or an empty one.
    NoLimits { path: PathBuf },
    /// The figures of held-out log `log` could not be computed.
    Measure {
        log: String,
        source: crate::metrics::EvaluationError,
    },
    /// A limited figure that no log of the run gives.
    NotMeasured {
        key: &'static str,
        from: LogKind,
        logs: Vec<String>,
    },
}

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // The cause follows through `source()`.
            SpecError::Read { path, .. } => {
                write!(f, "{}: cannot read the spec sheet", path.display())
            }
            SpecError::Syntax {
                path,
                line,
                column,
                message,
            } => {
                write!(f, "{}", path.display())?;
                if let (Some(l), Some(c)) = (line, column) {
                    write!(f, ":{l}:{c}")?;
                }
                write!(
                    f,
                    ": {}; a spec sheet is a [limits] table of `figure = {{ min = …, max = … }}`",
                    message.trim_end()
                )
            }
            SpecError::UnknownFigure {
                path,
                line,
                column,
                key,
                suggestions,
            } => {
                write!(
                    f,
                    "{}:{line}:{column}: unknown figure `{key}` in [limits]",
                    path.display()
                )?;
                if suggestions.is_empty() {
                    let all: Vec<&str> = FIGURES.iter().map(|d| d.key).collect();
                    write!(f, "; known figures: {}", all.join(", "))
                } else {
                    write!(f, "; did you mean {}?", quoted_list(suggestions))
                }
            }
            SpecError::BadLimit {
                path,
                line,
                column,
                key,
                reason,
            } => write!(
                f,
                "{}:{line}:{column}: limit on `{key}`: {reason}",
                path.display()
            ),
            SpecError::NoLimits { path } => write!(
                f,
                "{}: no limits; add a [limits] table, e.g. `bias_stability_dph = {{ max = 0.02 }}`",
                path.display()
            ),
            SpecError::Measure { log, source } => {
                write!(f, "{log}: {source}")?;
                if let Some(inner) = std::error::Error::source(source) {
                    write!(f, ": {inner}")?;
                }
                Ok(())
            }
            SpecError::NotMeasured { key, from, logs } => {
                let logs = if logs.is_empty() {
                    "none".to_string()
                } else {
                    logs.join(", ")
                };
                match from {
                    // A static log was maybe given: its Allan curve is where the term is read,
                    // and a curve can lack the term's part, so "needs a static log" would name
                    // the wrong cause.
                    LogKind::Static => write!(
                        f,
                        "the spec limits `{key}` but no held-out log gives it (logs: {logs}): \
                         it is read from the Allan curve of a static log ({}), and no log's \
                         curve showed it; a rate-table log has no such curve, and a static \
                         log's curve lacks the part when its output does not vary (a constant \
                         log) or it is too short; add a static log that shows it or remove the \
                         limit",
                        figure(key).map_or("", |d| d.what)
                    ),
                    LogKind::RateTable | LogKind::Any => write!(
                        f,
                        "the spec limits `{key}` but no held-out log gives it (it needs {}; \
                         logs: {logs}); add such a log or remove the limit",
                        if *from == LogKind::RateTable {
                            "a rate-table log"
                        } else {
                            "a log long enough for it"
                        }
                    ),
                }
            }
        }
    }
}

impl std::error::Error for SpecError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SpecError::Read { source, .. } => Some(source),
            _ => None,
        }
    }
}

fn quoted_list(names: &[&str]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match q.len() {
        0 => String::new(),
        1 => q[0].clone(),
        n => format!("{} or {}", q[..n - 1].join(", "), q[n - 1]),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpec {
    name: Option<String>,
    limits: Option<BTreeMap<Spanned<String>, Spanned<RawLimit>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLimit {
    min: Option<f64>,
    max: Option<f64>,
}

/// Line and column (from 1, columns in characters) of byte offset `at` in `text`.
pub(crate) fn line_column(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Levenshtein distance in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The known figure names nearest `key` (at most three, within a third of its length, or
/// containing it / contained in it).
pub(crate) fn nearest_figures(key: &str) -> Vec<&'static str> {
    let budget = (key.chars().count() / 3).max(2);
    let mut scored: Vec<(usize, &'static str)> = FIGURES
        .iter()
        .map(|d| (edit_distance(key, d.key), d.key))
        .filter(|(d, k)| *d <= budget || (key.len() >= 4 && (k.contains(key) || key.contains(k))))
        .collect();
    scored.sort();
    scored.into_iter().take(3).map(|(_, k)| k).collect()
}

impl Spec {
    /// Read and check the spec sheet at `path`.
    pub fn load(path: &Path) -> Result<Spec, SpecError> {
        let bytes = crate::input_file::read_capped(path, crate::input_file::InputKind::Spec)
            .map_err(|source| SpecError::Read {
                path: path.to_path_buf(),
                source,
            })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let (line, column) = {
                let ok = &e.as_bytes()[..e.utf8_error().valid_up_to()];
                line_column(std::str::from_utf8(ok).unwrap_or(""), ok.len())
            };
            SpecError::Syntax {
                path: path.to_path_buf(),
                line: Some(line),
                column: Some(column),
                message: "not UTF-8 text".into(),
            }
        })?;
        Spec::parse(&text, path)
    }

    /// Check the text of a spec sheet; `path` names it in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Spec, SpecError> {
        let raw: RawSpec = toml::from_str(text).map_err(|e| {
            let (line, column) = match e.span() {
                Some(s) => {
                    let (l, c) = line_column(text, s.start);
                    (Some(l), Some(c))
                }
                None => (None, None),
            };
            SpecError::Syntax {
                path: path.to_path_buf(),
                line,
                column,
                message: e.message().to_string(),
            }
        })?;
        let Some(raw_limits) = raw.limits.filter(|l| !l.is_empty()) else {
            return Err(SpecError::NoLimits {
                path: path.to_path_buf(),
            });
        };
        let mut limits = BTreeMap::new();
        for (key, lim) in raw_limits {
            let (line, column) = line_column(text, key.span().start);
            let Some(def) = figure(key.get_ref()) else {
                return Err(SpecError::UnknownFigure {
                    path: path.to_path_buf(),
                    line,
                    column,
                    key: key.get_ref().clone(),
                    suggestions: nearest_figures(key.get_ref()),
                });
            };
            let (vl, vc) = line_column(text, lim.span().start);
            let bad = |reason: String| SpecError::BadLimit {
                path: path.to_path_buf(),
                line: vl,
                column: vc,
                key: def.key.to_string(),
                reason,
            };
            let l = lim.get_ref();
            for (name, v) in [("min", l.min), ("max", l.max)] {
                if let Some(v) = v.filter(|v| !v.is_finite()) {
                    return Err(bad(format!("{name} = {v} is not a finite number")));
                }
            }
            match (l.min, l.max) {
                (None, None) => {
                    return Err(bad(format!(
                        "give `min` and/or `max` ({}), e.g. `{} = {{ max = 1.0 }}`",
                        def.unit, def.key
                    )))
                }
                (Some(a), Some(b)) if a > b => {
                    return Err(bad(format!("min = {a} is above max = {b}; swap them")))
                }
                _ => {}
            }
            limits.insert(
                def.key,
                Limit {
                    min: l.min,
                    max: l.max,
                },
            );
        }
        let name = raw.name.unwrap_or_else(|| {
            path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into(),
            )
        });
        Ok(Spec {
            name,
            path: path.to_path_buf(),
            limits,
            text: text.to_string(),
            sha256: format!("{:x}", Sha256::digest(text.as_bytes())),
        })
    }

    /// The limits, in [`FIGURES`] order.
    pub fn limits(&self) -> impl Iterator<Item = (&'static FigureDef, Limit)> + '_ {
        FIGURES
            .iter()
            .filter_map(|d| self.limits.get(d.key).map(|l| (d, *l)))
    }

    /// The limit on `key`, if any.
    pub fn limit(&self, key: &str) -> Option<Limit> {
        self.limits.get(key).copied()
    }

    /// Whether any limit is on an Allan noise term (which costs an Allan curve per log).
    pub(crate) fn needs_noise_terms(&self) -> bool {
        self.limits().any(|(d, _)| d.from == LogKind::Static)
    }
}

#[cfg(test)]
mod tests;

//! What training covered, and how well: the coverage map a model file carries.
//!
//! `train` (through [`crate::fit::fit_model`]) maps the steps of the static training logs on a
//! grid over (T, dT) (the first two features) and cross-validates the bias model over
//! contiguous time blocks: the least-squares terms of the fitted bias model are fitted again
//! on all blocks but one and predict the block left out (the thermal lags stay as identified;
//! of a base with a residual LSTM, only the base is cross-validated). Per cell the file keeps
//! the count of held-out steps and the RMS of their residual (prediction − the 100 s smoothed
//! output, °/h), and σ: the RMS shrunk towards the pooled RMS by
//! [`SHRINK_STEPS`](crate::settings::coverage::SHRINK_STEPS) steps, times
//! [`SIGMA_SCALE`](crate::settings::coverage::SIGMA_SCALE), where the cell holds at least
//! [`MIN_CELL_STEPS`](crate::settings::coverage::MIN_CELL_STEPS) steps (0, not covered,
//! otherwise). The flight crate's [`CoverageMap`] turns it into a per-sample verdict.
//!
//! In the file (`"coverage"`, absent in files written before it, and for LSTM bias models,
//! which cannot be re-fitted per fold in reasonable time):
//! ```json
//! "coverage": {"temp_min_c": -45.0, "temp_cell_c": 6.5, "n_temp": 16,
//!              "rate_min_c_per_s": -0.06, "rate_cell_c_per_s": 0.01, "n_rate": 12,
//!              "folds": 5, "count": [...], "rms_dph": [...], "sigma_dph": [...],
//!              "growth_per_cell": 0.5}
//! ```
//! with one value per cell, row-major by temperature.

use std::fmt;

use gyrotherm_core::coverage::{CoverageError, CoverageMap, Grid, Verdict};
use serde::{Deserialize, Serialize};

use crate::baseline::{self, LsqError};
use crate::model::SubModel;
pub use crate::settings::coverage::CoverageSettings;
use crate::targets::TargetSet;

/// The coverage map in the model file (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoverageDef {
    /// Lower edge of the first temperature cell, °C.
    pub temp_min_c: f64,
    /// Temperature cell width, °C.
    pub temp_cell_c: f64,
    /// Temperature cells.
    pub n_temp: usize,
    /// Lower edge of the first rate cell, °C/s.
    pub rate_min_c_per_s: f64,
    /// Rate cell width, °C/s.
    pub rate_cell_c_per_s: f64,
    /// Rate cells.
    pub n_rate: usize,
    /// Cross-validation folds.
    pub folds: usize,
    /// Held-out steps per cell.
    pub count: Vec<u64>,
    /// RMS of the held-out residual per cell, °/h (0 where the count is 0).
    pub rms_dph: Vec<f64>,
    /// σ per cell, °/h (0: not covered).
    pub sigma_dph: Vec<f64>,
    /// Growth of σ per cell of distance outside the covered cells.
    pub growth_per_cell: f64,
}

impl CoverageDef {
    /// The grid geometry.
    pub fn grid(&self) -> Grid {
        Grid {
            temp_min_c: self.temp_min_c,
            temp_cell_c: self.temp_cell_c,
            n_temp: self.n_temp,
            rate_min_c_per_s: self.rate_min_c_per_s,
            rate_cell_c_per_s: self.rate_cell_c_per_s,
            n_rate: self.n_rate,
        }
    }

    /// The flight crate's map, checked (also the count and RMS lists' lengths).
    pub fn to_core(&self) -> Result<CoverageMap, CoverageError> {
        let n = self.n_temp.saturating_mul(self.n_rate);
        if self.count.len() != n || self.rms_dph.len() != n {
            return Err(CoverageError::SigmaLength);
        }
        if self.rms_dph.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(CoverageError::Sigma);
        }
        CoverageMap::new(self.grid(), &self.sigma_dph, self.growth_per_cell)
    }

    /// Covered cells.
    pub fn covered_cells(&self) -> usize {
        self.sigma_dph.iter().filter(|s| **s > 0.0).count()
    }

    /// Pooled RMS of the held-out residual over all cells, °/h.
    pub fn pooled_rms_dph(&self) -> f64 {
        let (ss, n) = self
            .count
            .iter()
            .zip(&self.rms_dph)
            .fold((0.0, 0u64), |(ss, n), (&c, &r)| {
                (ss + c as f64 * r * r, n + c)
            });
        (ss / n.max(1) as f64).sqrt()
    }

    /// The same map with other σ scale and growth (for calibration): σ of every cell times
    /// `scale`.
    pub fn rescaled(&self, scale: f64, growth_per_cell: f64) -> CoverageDef {
        CoverageDef {
            sigma_dph: self.sigma_dph.iter().map(|s| s * scale).collect(),
            growth_per_cell,
            ..self.clone()
        }
    }
}

/// Why no coverage map was made.
#[derive(Debug)]
#[non_exhaustive]
pub enum CoverageFitError {
    /// The bias model has no least-squares part to fit again per fold.
    NotLeastSquares,
    /// No labelled step of a static log.
    NoBiasSteps,
    /// No cell holds enough held-out steps.
    NoCoveredCell { most_steps: u64, needed: u64 },
    /// A fold could not be fitted.
    Fold { fold: usize, source: LsqError },
    /// The map the core refuses.
    Core(CoverageError),
}

impl fmt::Display for CoverageFitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoverageFitError::NotLeastSquares => f.write_str(
                "the bias model is an LSTM alone: its cross-validated error per region is not \
                 computed (a refit per fold would cost the whole training again)",
            ),
            CoverageFitError::NoBiasSteps => {
                f.write_str("no static log with labelled bias steps: nothing to map")
            }
            CoverageFitError::NoCoveredCell { most_steps, needed } => write!(
                f,
                "no (T, dT) cell holds {needed} held-out steps (the most: {most_steps}); the \
                 training logs are too short to map"
            ),
            CoverageFitError::Fold { fold, .. } => {
                write!(f, "cross-validation fold {}", fold + 1)
            }
            CoverageFitError::Core(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for CoverageFitError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CoverageFitError::Fold { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Cell widths and lower edge for values spanning `lo..=hi` in `n` cells of at least `min`:
/// the grid is centred on the span.
fn axis(lo: f64, hi: f64, n: usize, min: f64) -> (f64, f64) {
    let w = ((hi - lo) / n as f64).max(min);
    let centre = 0.5 * (lo + hi);
    (centre - 0.5 * w * n as f64, w)
}

/// Cell index of `x` on an axis (clamped: the grid spans every training value).
fn cell(x: f64, lo: f64, w: f64, n: usize) -> usize {
    let k = ((x - lo) / w).floor();
    if k <= 0.0 {
        0
    } else {
        (k as usize).min(n - 1)
    }
}

/// The coverage map of a bias model fitted on `sets` (static logs' bias targets on the
/// model's features): see the module doc.
pub fn cross_validated(
    bias: &SubModel,
    sets: &[TargetSet],
    s: &CoverageSettings,
) -> Result<CoverageDef, CoverageFitError> {
    let terms = match bias {
        SubModel::Baseline { terms, .. } | SubModel::Residual { terms, .. } => terms,
        SubModel::Lstm { .. } => return Err(CoverageFitError::NotLeastSquares),
    };
    let folds = s.folds.max(2);
    // All sets' rows in one design; fold of each labelled row: its contiguous block within
    // its own log, so every fold holds a part of every log.
    let nf = terms.n_features;
    let mut rows = Vec::new();
    let mut target = Vec::new();
    let mut fold = Vec::new();
    let mut names = Vec::new();
    let mut units = Vec::new();
    for set in sets.iter().filter(|t| t.table.n_features == nf) {
        if names.is_empty() {
            names = set.table.names.clone();
            units = set.table.units.clone();
        }
        let n_lab = set.labelled();
        let mut k = 0usize;
        for (r, (&m, &y)) in set.mask.iter().zip(&set.target).enumerate() {
            if !m || !y.is_finite() {
                continue;
            }
            rows.extend_from_slice(set.table.row(r));
            target.push(y);
            fold.push(k * folds / n_lab.max(1));
            k += 1;
        }
    }
    let n = target.len();
    if n == 0 || nf < 2 {
        return Err(CoverageFitError::NoBiasSteps);
    }
    let mut resid_dph = vec![f64::NAN; n];
    for f in 0..folds {
        let mask: Vec<bool> = fold.iter().map(|&k| k != f).collect();
        let fit = baseline::fit_rows(&rows, nf, &names, &units, &target, Some(&mask), terms)
            .map_err(|source| CoverageFitError::Fold { fold: f, source })?;
        for (r, _) in fold.iter().enumerate().filter(|(_, &k)| k == f) {
            let x = &rows[r * nf..(r + 1) * nf];
            resid_dph[r] = (fit.predict_row(x) - target[r]) * 3600.0;
        }
    }
    let col = |c: usize| rows.iter().skip(c).step_by(nf).copied();
    let range = |c: usize| {
        col(c).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        })
    };
    let (tlo, thi) = range(0);
    let (rlo, rhi) = range(1);
    let (nt, nr) = (s.temp_cells, s.rate_cells);
    let (t0, tw) = axis(tlo, thi, nt, crate::settings::coverage::MIN_TEMP_CELL_C);
    let (r0, rw) = axis(
        rlo,
        rhi,
        nr,
        crate::settings::coverage::MIN_RATE_CELL_C_PER_S,
    );
    let mut count = vec![0u64; nt * nr];
    let mut ss = vec![0.0f64; nt * nr];
    for ((t, r), e) in col(0).zip(col(1)).zip(&resid_dph) {
        let c = cell(t, t0, tw, nt) * nr + cell(r, r0, rw, nr);
        count[c] += 1;
        ss[c] += e * e;
    }
    let pooled_ss = ss.iter().sum::<f64>() / n as f64;
    let rms_dph: Vec<f64> = count
        .iter()
        .zip(&ss)
        .map(|(&c, &q)| if c == 0 { 0.0 } else { (q / c as f64).sqrt() })
        .collect();
    let sigma_dph: Vec<f64> = count
        .iter()
        .zip(&ss)
        .map(|(&c, &q)| {
            if c < s.min_cell_steps {
                0.0
            } else {
                s.sigma_scale
                    * ((q + s.shrink_steps * pooled_ss) / (c as f64 + s.shrink_steps)).sqrt()
            }
        })
        .collect();
    if sigma_dph.iter().all(|v| *v <= 0.0) {
        return Err(CoverageFitError::NoCoveredCell {
            most_steps: count.iter().copied().max().unwrap_or(0),
            needed: s.min_cell_steps,
        });
    }
    let def = CoverageDef {
        temp_min_c: t0,
        temp_cell_c: tw,
        n_temp: nt,
        rate_min_c_per_s: r0,
        rate_cell_c_per_s: rw,
        n_rate: nr,
        folds,
        count,
        rms_dph,
        sigma_dph,
        growth_per_cell: s.growth_per_cell,
    };
    def.to_core().map_err(CoverageFitError::Core)?;
    Ok(def)
}

/// The `coverage` and `sigma_dph` fields of an output row (both empty without a verdict).
pub fn push_verdict<W: std::io::Write>(
    writer: &mut crate::csvlog::LogWriter<W>,
    verdict: Option<Verdict>,
) {
    match verdict {
        Some(v) => {
            writer.push_raw(v.coverage.as_str().as_bytes());
            writer.push_f64(v.sigma_dph);
        }
        None => {
            writer.push_raw(b"");
            writer.push_raw(b"");
        }
    }
}

/// What to tell the user when a model file carries no coverage map: nothing when it does.
/// The reason is the one training gave (kept in the file); a file without it was written
/// before gyrotherm stored maps or their reasons.
pub fn missing_note(model: &crate::model::ModelFile) -> Option<String> {
    if model.coverage.is_some() {
        return None;
    }
    Some(match &model.coverage_note {
        Some(why) => {
            // The file may have been edited: no control character reaches the terminal.
            let why: String = why
                .chars()
                .take(400)
                .map(|c| if c.is_control() { '?' } else { c })
                .collect();
            format!(
                "the model file has no coverage map ({why}): the coverage and sigma_dph \
                 columns stay empty"
            )
        }
        None => "the model file has no coverage map (written before gyrotherm stored one, or \
                 its bias model is an LSTM alone): the coverage and sigma_dph columns stay \
                 empty; re-train to get them"
            .to_owned(),
    })
}

/// Shares of the samples of `log` whose verdict is inside, edge and outside (in that order,
/// of the samples with a verdict) under `model`'s map, stepped by the flight compensator as
/// `compensate` steps it; None when the model has no map or no sample got a verdict.
pub fn shares(
    model: &crate::model::ModelFile,
    log: &crate::csvlog::TestLog,
) -> Result<Option<[f64; 3]>, crate::compensate::CompensateError> {
    let Some(map) = model.coverage.as_ref().and_then(|c| c.to_core().ok()) else {
        return Ok(None);
    };
    let mut comp = crate::compensate::compensator(model)?;
    let mut n = [0u64; 3];
    for i in 0..log.len() {
        comp.step(log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        if let Some(v) = map.verdict_of(comp.features()) {
            n[v.coverage as usize] += 1;
        }
    }
    let total: u64 = n.iter().sum();
    Ok((total > 0).then(|| n.map(|k| k as f64 / total as f64)))
}

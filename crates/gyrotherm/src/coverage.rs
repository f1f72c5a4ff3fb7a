//! What training covered, and how well: the coverage map a model file carries.
//!
//! `train` (through [`crate::fit::fit_model`]) maps the steps of the static training logs on a
//! grid over (T, dT) (the first two features) and cross-validates the bias model over
//! contiguous time blocks: the least-squares terms of the fitted bias model are fitted again
//! on all blocks but one and predict the block left out (the thermal lags stay as identified;
//! of a base with a residual LSTM, only the base is cross-validated). Per cell the file keeps
//! the count of held-out steps and the RMS of their residual (prediction − the 100 s smoothed
//! output, °/h), and σ: the RMS shrunk towards the pooled RMS by
//! `SHRINK_STEPS` steps, times
//! [`SIGMA_SCALE`](crate::settings::coverage::SIGMA_SCALE), where the cell holds at least
//! `MIN_CELL_STEPS` steps (0, not covered,
//! otherwise). The flight crate's [`CoverageMap`](gyrotherm_core::coverage::CoverageMap)
//! turns it into a per-sample verdict. The file's form of the map, [`CoverageDef`], is
//! defined with the model file it sits in.

use std::fmt;

use gyrotherm_core::coverage::CoverageError;

use crate::baseline::{self, LsqError};
pub use crate::model::{missing_coverage_note as missing_note, CoverageDef};
use crate::model::{ModelFile, SubModel};
pub use crate::settings::coverage::CoverageSettings;
use crate::targets::TargetSet;

/// Why no coverage map was made.
#[derive(Debug)]
#[non_exhaustive]
pub(crate) enum CoverageFitError {
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
pub(crate) fn cross_validated(
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

/// Shares of the samples of `log` whose verdict is inside, edge and outside (in that order,
/// of the samples with a verdict) under `model`'s map, stepped by the flight compensator as
/// `compensate` steps it; None when the model has no map or no sample got a verdict.
pub fn shares(
    model: &ModelFile,
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

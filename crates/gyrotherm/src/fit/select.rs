//! Choosing a least-squares term set from the training data: a small family of polynomial
//! term sets over the thermal-state features, ranked by blocked cross-validation in time.
//!
//! Why: a term set chosen from the simulator's own bias equation fits that simulator and no
//! other unit (`docs/experiments/term-selection.md`). So the candidates are a generic ladder
//! ([`super::terms::ladder`]) and the data choose: each run is cut into [`FOLDS`]
//! contiguous segments of its time axis; for each segment index every candidate is fitted on all runs with that segment (and a
//! [`GAP_STEPS`] margin either side, against leakage through the smoothed target) left out,
//! and predicts the left-out steps, each run keeping its own offset fitted on the rest of the
//! run. The score is the RMS of these out-of-fold residuals with each run's mean removed
//! (bias stability ignores a constant): a held-out part of the temperature cycle, predicted
//! from the others, as the held-out run will be. Blocked cross-validation for dependent data:
//! Roberts et al. 2017, "Cross-validation strategies for data with temporal, spatial,
//! hierarchical, or phylogenetic structure", Ecography 40(8), DOI 10.1111/ecog.02881.

use super::error::FitError;
use super::terms::Candidate;
use crate::baseline::{fit_fixed_effects, FixedEffectsFit};
use crate::targets::TargetSet;

/// Contiguous segments per run (folds of the blocked cross-validation); chosen on the
/// held-out sweep, and the choice is sensitive (`docs/experiments/term-selection.md`).
pub const FOLDS: usize = 5;

/// Steps left out of training either side of a validation segment: the bias target is a
/// centred 100 s moving average, so neighbouring steps share noise with the segment's edges.
pub const GAP_STEPS: usize = 200;

/// Relative margin within which a smaller term set is preferred to the best-scoring one: the
/// spread of one set's cross-validated score over training seeds of one unit (±10 %;
/// measured in `docs/experiments/term-selection.md`).
pub(crate) const PARSIMONY_TOL: f64 = 0.10;

/// How a term set was chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct TermSelection {
    /// Candidate names, in the order tried.
    pub names: Vec<String>,
    /// Cross-validated RMS residual of each candidate, target units (infinite where a fold
    /// could not be fitted: too few steps or dependent terms).
    pub cv_rms: Vec<f64>,
    /// Index of the chosen candidate (least cross-validated RMS).
    pub chosen: usize,
    /// Folds used.
    pub folds: usize,
}

impl TermSelection {
    /// The chosen candidate's name.
    pub fn chosen_name(&self) -> &str {
        &self.names[self.chosen]
    }

    /// One line: every candidate's score, the chosen one marked.
    pub fn describe(&self) -> String {
        self.names
            .iter()
            .zip(&self.cv_rms)
            .enumerate()
            .map(|(i, (n, s))| format!("{}{n} {s:.3e}", if i == self.chosen { "*" } else { "" }))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Copies of `train` whose masks keep (`keep = true`) or drop the steps of segment `fold` of
/// `folds` of each run (dropping also `gap` steps either side).
fn fold_sets(train: &[TargetSet], fold: usize, folds: usize, gap: usize) -> Vec<TargetSet> {
    train
        .iter()
        .map(|s| {
            let nr = s.table.n_rows();
            let (a, b) = segment(nr, fold, folds);
            let (a, b) = (a.saturating_sub(gap), (b + gap).min(nr));
            let mask = (0..nr).map(|r| s.mask[r] && !(a..b).contains(&r)).collect();
            TargetSet {
                table: s.table.clone(),
                target: s.target.clone(),
                mask,
            }
        })
        .collect()
}

/// Rows `[a, b)` of segment `fold` of `folds` equal contiguous segments of `nr` rows.
fn segment(nr: usize, fold: usize, folds: usize) -> (usize, usize) {
    (nr * fold / folds, nr * (fold + 1) / folds)
}

/// Blocked cross-validated RMS residual of each candidate (see the module doc); infinite for
/// a candidate that could not be fitted on some fold.
pub(crate) fn cross_validate(
    train: &[TargetSet],
    cands: &[Candidate],
    folds: usize,
    gap: usize,
) -> Vec<f64> {
    // Out-of-fold residuals per candidate, per run.
    let mut resid: Vec<Vec<Vec<f64>>> = cands
        .iter()
        .map(|_| {
            train
                .iter()
                .map(|s| vec![f64::NAN; s.table.n_rows()])
                .collect()
        })
        .collect();
    let mut failed = vec![false; cands.len()];
    for fold in 0..folds {
        let sets = fold_sets(train, fold, folds, gap);
        for (ci, c) in cands.iter().enumerate() {
            if failed[ci] {
                continue;
            }
            let fit: FixedEffectsFit = match fit_fixed_effects(&sets, &c.terms) {
                Ok(f) => f,
                Err(_) => {
                    failed[ci] = true;
                    continue;
                }
            };
            for (run, s) in train.iter().enumerate() {
                let (a, b) = segment(s.table.n_rows(), fold, folds);
                let out = &mut resid[ci][run][a..b];
                for (k, o) in out.iter_mut().enumerate() {
                    let r = a + k;
                    if s.mask[r] {
                        *o = s.target[r] - fit.predict_row(s.table.row(r)) - fit.run_offset[run];
                    }
                }
            }
        }
    }
    resid
        .iter()
        .zip(&failed)
        .map(|(runs, &f)| {
            if f {
                return f64::INFINITY;
            }
            pooled_within_run_rms(runs)
        })
        .collect()
}

/// Score of held-out residuals, one vector a run: their RMS about each run's own mean (a
/// run's constant offset is not scored), pooled over the runs. Non-finite entries (steps not
/// held out) are skipped; ∞ when nothing was held out.
pub(crate) fn pooled_within_run_rms(runs: &[Vec<f64>]) -> f64 {
    let (mut ss, mut n) = (0.0, 0usize);
    for r in runs {
        let v: Vec<f64> = r.iter().copied().filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            continue;
        }
        let m = v.iter().sum::<f64>() / v.len() as f64;
        ss += v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
        n += v.len();
    }
    if n == 0 {
        f64::INFINITY
    } else {
        (ss / n as f64).sqrt()
    }
}

/// Choose among `cands` by blocked cross-validation: the candidate with the fewest terms whose
/// cross-validated RMS residual is within `PARSIMONY_TOL` of the least (the
/// one-standard-error rule's idea, Hastie, Tibshirani & Friedman, *The Elements of Statistical
/// Learning*, 2nd ed., §7.10: prefer the simpler model when the difference is within the
/// score's own noise). An error when no candidate can be fitted on every fold.
pub fn select_terms(
    train: &[TargetSet],
    cands: &[Candidate],
    folds: usize,
    gap: usize,
) -> Result<TermSelection, FitError> {
    if cands.is_empty() {
        return Err(FitError::NoCandidates);
    }
    let cv_rms = cross_validate(train, cands, folds.max(2), gap);
    let best = cv_rms
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    // The fewest terms within PARSIMONY_TOL of the least score; then the lower score.
    let chosen = cv_rms
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite() && **v <= best * (1.0 + PARSIMONY_TOL))
        .min_by(|a, b| {
            cands[a.0]
                .terms
                .len()
                .cmp(&cands[b.0].terms.len())
                .then(a.1.total_cmp(b.1))
        })
        .map(|(i, _)| i)
        .ok_or(FitError::NoCandidateFits {
            folds: folds.max(2),
        })?;
    Ok(TermSelection {
        names: cands.iter().map(|c| c.name.clone()).collect(),
        cv_rms,
        chosen,
        folds: folds.max(2),
    })
}

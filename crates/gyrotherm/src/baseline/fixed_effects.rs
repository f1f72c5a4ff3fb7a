//! Least squares with one offset per training run (fixed effects): several runs of one unit
//! share the thermal terms but each has its own turn-on bias (or scale-factor offset).

use super::{LsqError, Terms, RANK_TOL};
use crate::targets::TargetSet;
use nalgebra::{DMatrix, DVector};

/// A least-squares baseline with one offset per training run.
pub(crate) struct FixedEffectsFit {
    pub(crate) terms: Terms,
    /// Coefficients; the constant term holds the mean offset over the runs (by labelled steps).
    pub(crate) coefficients: Vec<f64>,
    /// Offset of each run relative to the constant term, target units.
    pub(crate) run_offset: Vec<f64>,
    /// RMS residual over the labelled steps, target units.
    pub(crate) rms: f64,
}

impl FixedEffectsFit {
    pub(crate) fn predict_row(&self, x: &[f64]) -> f64 {
        super::evaluate(&self.terms, &self.coefficients, x)
    }
}

/// Least squares `y = a_run + Σ_j c_j·m_j(x)` over the labelled steps of all runs (`terms`
/// must start with the constant term, which becomes the per-run offsets `a_run`): the
/// "within" estimator — monomials and targets centred per run, solved by SVD on RMS-scaled
/// columns, refused below [`RANK_TOL`]. With one run this is ordinary least
/// squares.
pub(crate) fn fit_fixed_effects(
    train: &[TargetSet],
    terms: &Terms,
) -> Result<FixedEffectsFit, LsqError> {
    debug_assert!(terms.powers[0].iter().all(|p| *p == 0));
    let nt = terms.len();
    let mut design: Vec<f64> = Vec::new();
    let mut y: Vec<f64> = Vec::new();
    let mut run_means: Vec<(Vec<f64>, f64, usize)> = Vec::new();
    for s in train {
        let (start_row, start_y) = (design.len(), y.len());
        for r in 0..s.table.n_rows() {
            if s.mask[r] {
                design.extend_from_slice(&terms.design_row(s.table.row(r))[1..]);
                y.push(s.target[r]);
            }
        }
        let n = y.len() - start_y;
        let mut mean = vec![0.0; nt - 1];
        let mut ymean = 0.0;
        if n > 0 {
            ymean = y[start_y..].iter().sum::<f64>() / n as f64;
            y[start_y..].iter_mut().for_each(|v| *v -= ymean);
            if nt > 1 {
                for row in design[start_row..].chunks_exact(nt - 1) {
                    for (m, v) in mean.iter_mut().zip(row) {
                        *m += v;
                    }
                }
                mean.iter_mut().for_each(|m| *m /= n as f64);
                for row in design[start_row..].chunks_exact_mut(nt - 1) {
                    for (v, m) in row.iter_mut().zip(&mean) {
                        *v -= m;
                    }
                }
            }
        }
        run_means.push((mean, ymean, n));
    }
    let n = y.len();
    if n < nt + train.len() {
        return Err(LsqError::TooFewSamples {
            used: n,
            terms: nt - 1 + train.len(),
        });
    }
    if nt == 1 {
        // A constant only: the run means.
        let total: usize = run_means.iter().map(|r| r.2).sum();
        let c0 = run_means.iter().map(|r| r.1 * r.2 as f64).sum::<f64>() / total as f64;
        let rms = (y.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        return Ok(FixedEffectsFit {
            terms: terms.clone(),
            coefficients: vec![c0],
            run_offset: run_means
                .iter()
                .map(|r| if r.2 > 0 { r.1 - c0 } else { 0.0 })
                .collect(),
            rms,
        });
    }
    let mut scale = vec![0.0; nt - 1];
    for row in design.chunks_exact(nt - 1) {
        for (s, v) in scale.iter_mut().zip(row) {
            *s += v * v;
        }
    }
    for (j, s) in scale.iter_mut().enumerate() {
        *s = (*s / n as f64).sqrt();
        if *s <= 0.0 || !s.is_finite() {
            return Err(LsqError::ConstantTerm { term: j + 1 });
        }
    }
    let x = DMatrix::from_fn(n, nt - 1, |r, c| design[r * (nt - 1) + c] / scale[c]);
    let svd = x.clone().svd(true, true);
    let (smax, smin) = svd
        .singular_values
        .iter()
        .fold((0.0f64, f64::INFINITY), |(a, b), &v| (a.max(v), b.min(v)));
    let ratio = smin / smax;
    if ratio.is_nan() || ratio < RANK_TOL {
        return Err(LsqError::RankDeficient {
            ratio,
            terms: (0..nt).map(|j| terms.name(j, &[])).collect(),
        });
    }
    let yv = DVector::from_vec(y);
    let c = svd
        .solve(&yv, 0.0)
        .map_err(|e| LsqError::Shape(format!("SVD solve failed: {e}")))?;
    let resid = &yv - &x * &c;
    let rms = (resid.norm_squared() / n as f64).sqrt();
    let slopes: Vec<f64> = c.iter().zip(&scale).map(|(v, s)| v / s).collect();
    let offsets: Vec<f64> = run_means
        .iter()
        .map(|(m, ym, _)| ym - m.iter().zip(&slopes).map(|(a, b)| a * b).sum::<f64>())
        .collect();
    let total: usize = run_means.iter().map(|r| r.2).sum();
    let c0 = offsets
        .iter()
        .zip(&run_means)
        .map(|(o, r)| o * r.2 as f64)
        .sum::<f64>()
        / total as f64;
    let mut coefficients = vec![c0];
    coefficients.extend_from_slice(&slopes);
    Ok(FixedEffectsFit {
        terms: terms.clone(),
        coefficients,
        run_offset: offsets
            .iter()
            .zip(&run_means)
            .map(|(o, r)| if r.2 > 0 { o - c0 } else { 0.0 })
            .collect(),
        rms,
    })
}

//! Baseline fits: least squares over a list of monomials of the features.
//!
//! - Linear, the published comparison (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004):
//!   `bias = c0 + c1·T + c2·dT` ([`Terms::linear`] over the published features).
//! - Polynomial, the industry standard: `1, T, …, T^n, dT, …, dT^m`, optionally `T·dT`
//!   ([`Terms::poly`]); any further features (thermal-state lags) enter linearly.
//!
//! The fit solves `min ‖X c - y‖` by SVD (nalgebra) on the column-scaled design matrix
//! (each column divided by its RMS), with a rank check: a fit whose smallest/largest singular
//! value ratio is below `RANK_TOL` is refused with the terms that are dependent, and a term
//! over a feature that does not vary in the training data is refused first with the feature's
//! value (e.g. a run at constant temperature). The coefficients are for the raw (unscaled)
//! monomials, so `gyrotherm_core::baseline::BaselineModel` evaluates them directly.
//!
//! The same least squares with one offset per training run (the "within" estimator, for
//! fits over several runs whose turn-on bias differs) is in `fixed_effects`, used by the LSTM
//! recipes' bases and by term selection.

mod fixed_effects;

pub(crate) use fixed_effects::{fit_fixed_effects, FixedEffectsFit};

use crate::features::FeatureTable;
use gyrotherm_core::baseline::{BaselineError, BaselineModel, MAX_POWER, MAX_TERMS};
use gyrotherm_core::features::MAX_FEATURES;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Smallest accepted ratio of smallest to largest singular value of the scaled design matrix.
pub(crate) const RANK_TOL: f64 = 1e-10;

/// The monomials of a baseline model: `powers[j][i]` is the power of feature `i` in term `j`.
/// JSON: `{"n_features": 2, "powers": [[0,0],[1,0],[0,1]]}`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Terms {
    /// Features the terms are over.
    pub n_features: usize,
    /// One power list (length `n_features`) per term.
    pub powers: Vec<Vec<u8>>,
}

/// Degrees of a polynomial baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PolyDegrees {
    /// Highest power of T (feature 0).
    pub temp: u8,
    /// Highest power of dT (feature 1).
    pub rate: u8,
    /// Include the cross term T·dT.
    pub cross: bool,
}

impl Default for PolyDegrees {
    /// Cubic in T, linear in dT, with the cross term.
    fn default() -> Self {
        PolyDegrees {
            temp: 3,
            rate: 1,
            cross: true,
        }
    }
}

/// Monomial powers over `n` features from (feature, power) pairs, e.g. `monomial(5, &[(0, 1),
/// (2, 1)])` is `T·D300` over the thermal-state features.
pub(crate) fn monomial(n: usize, parts: &[(usize, u8)]) -> Vec<u8> {
    let mut p = vec![0u8; n];
    for &(i, q) in parts {
        p[i] = q;
    }
    p
}

/// Ground evaluation of `Σ c_j·m_j(x)`: the design row of `terms` at `x` times `coefficients`.
pub(crate) fn evaluate(terms: &Terms, coefficients: &[f64], x: &[f64]) -> f64 {
    terms
        .design_row(x)
        .iter()
        .zip(coefficients)
        .map(|(a, c)| a * c)
        .sum()
}

impl Terms {
    /// `1` plus every feature linearly: over the published features (T, dT) this is
    /// `c0 + c1·T + c2·dT`.
    pub fn linear(n_features: usize) -> Terms {
        let mut powers = vec![vec![0u8; n_features]];
        for i in 0..n_features {
            let mut p = vec![0u8; n_features];
            p[i] = 1;
            powers.push(p);
        }
        Terms { n_features, powers }
    }

    /// `1, T, …, T^temp, dT, …, dT^rate` (+ `T·dT`), and features 2.. linearly.
    /// Needs `n_features ≥ 2` (T is feature 0, dT feature 1); checked by [`Terms::validate`].
    pub fn poly(n_features: usize, deg: PolyDegrees) -> Terms {
        let unit = |i: usize, p: u8| {
            let mut v = vec![0u8; n_features];
            if i < n_features {
                v[i] = p;
            }
            v
        };
        let mut powers = vec![vec![0u8; n_features]];
        for p in 1..=deg.temp {
            powers.push(unit(0, p));
        }
        for p in 1..=deg.rate {
            powers.push(unit(1, p));
        }
        if deg.cross && n_features >= 2 {
            let mut v = unit(0, 1);
            v[1] = 1;
            powers.push(v);
        }
        for i in 2..n_features {
            powers.push(unit(i, 1));
        }
        Terms { n_features, powers }
    }

    /// Number of terms.
    pub fn len(&self) -> usize {
        self.powers.len()
    }

    /// True with no terms.
    pub fn is_empty(&self) -> bool {
        self.powers.is_empty()
    }

    /// Shapes and limits the flight crate can evaluate: 1..=MAX_TERMS distinct terms, each with
    /// `n_features` powers ≤ MAX_POWER, `n_features ≤ MAX_FEATURES`.
    pub fn validate(&self) -> Result<(), TermsError> {
        if self.n_features > MAX_FEATURES {
            return Err(TermsError::TooManyFeatures {
                n_features: self.n_features,
            });
        }
        if self.powers.is_empty() || self.powers.len() > MAX_TERMS {
            return Err(TermsError::TermCount {
                terms: self.powers.len(),
            });
        }
        for (j, p) in self.powers.iter().enumerate() {
            if p.len() != self.n_features {
                return Err(TermsError::PowerCount {
                    term: j,
                    powers: p.len(),
                    n_features: self.n_features,
                });
            }
            if let Some(&q) = p.iter().find(|&&q| q > MAX_POWER) {
                return Err(TermsError::PowerTooHigh { term: j, power: q });
            }
            if self.powers[..j].contains(p) {
                return Err(TermsError::Repeated { term: j });
            }
        }
        Ok(())
    }

    /// Readable name of term `j`, e.g. `1`, `T`, `T^2·dT`.
    pub fn name(&self, j: usize, feature_names: &[String]) -> String {
        let parts: Vec<String> = self.powers[j]
            .iter()
            .enumerate()
            .filter(|(_, &p)| p > 0)
            .map(|(i, &p)| {
                let n = feature_names
                    .get(i)
                    .cloned()
                    .unwrap_or_else(|| format!("x{i}"));
                if p == 1 {
                    n
                } else {
                    format!("{n}^{p}")
                }
            })
            .collect();
        if parts.is_empty() {
            "1".to_owned()
        } else {
            parts.join("·")
        }
    }

    /// [`Terms::design_row`] from term `from` on, appended to `out` (the same values to the
    /// bit: a power 0 contributes the exact factor 1 and a power 1 the value itself, so
    /// both are taken without `powi`).
    pub fn extend_design_row(&self, x: &[f64], from: usize, out: &mut Vec<f64>) {
        out.extend(self.powers[from..].iter().map(|p| {
            let mut acc = 1.0;
            for (&q, &v) in p.iter().zip(x) {
                match q {
                    0 => {}
                    1 => acc *= v,
                    _ => acc *= v.powi(i32::from(q)),
                }
            }
            acc
        }));
    }

    /// The terms as each one's non-zero powers, for building many design rows
    /// ([`SparseTerms::extend_design_row`]).
    pub fn sparse(&self) -> SparseTerms {
        let mut sparse = SparseTerms {
            ends: Vec::with_capacity(self.powers.len()),
            factors: Vec::new(),
        };
        for p in &self.powers {
            sparse.factors.extend(
                p.iter()
                    .enumerate()
                    .filter(|(_, &q)| q != 0)
                    .map(|(f, &q)| (f, q)),
            );
            sparse.ends.push(sparse.factors.len());
        }
        sparse
    }

    /// The monomial values of term `j..` at feature vector `x` (ground evaluation, `powi`).
    pub fn design_row(&self, x: &[f64]) -> Vec<f64> {
        self.powers
            .iter()
            .map(|p| {
                p.iter()
                    .zip(x)
                    .map(|(&q, &v)| v.powi(i32::from(q)))
                    .product()
            })
            .collect()
    }
}

/// [`Terms`] kept as each term's non-zero powers in feature order ([`Terms::sparse`]): a
/// design row is then a few products per term instead of a pass over every feature.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SparseTerms {
    /// End of each term's factors in `factors`.
    ends: Vec<usize>,
    /// (feature, power) of every non-zero power, term after term.
    factors: Vec<(usize, u8)>,
}

impl SparseTerms {
    /// [`Terms::extend_design_row`], to the bit: the same factors multiplied in the same
    /// order (a power 0 is the exact factor 1, left out of both).
    pub fn extend_design_row(&self, x: &[f64], from: usize, out: &mut Vec<f64>) {
        let mut start = if from == 0 { 0 } else { self.ends[from - 1] };
        out.extend(self.ends[from..].iter().map(|&end| {
            let mut acc = 1.0;
            // A feature past the row's end is skipped, as `zip` does there.
            for &(f, q) in &self.factors[start..end] {
                if let Some(&v) = x.get(f) {
                    // Low powers as `powi` computes them (squaring, then a product), without
                    // the call.
                    acc *= match q {
                        1 => v,
                        2 => v * v,
                        3 => v * (v * v),
                        4 => (v * v) * (v * v),
                        _ => v.powi(i32::from(q)),
                    };
                }
            }
            start = end;
            acc
        }));
    }
}

/// A term list the flight crate cannot evaluate.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum TermsError {
    /// More features than the flight crate's `MAX_FEATURES`.
    TooManyFeatures { n_features: usize },
    /// No terms, or more than the flight crate's `MAX_TERMS`.
    TermCount { terms: usize },
    /// Term `term` has `powers` powers for `n_features` features.
    PowerCount {
        term: usize,
        powers: usize,
        n_features: usize,
    },
    /// Term `term` has a power above the flight crate's `MAX_POWER`.
    PowerTooHigh { term: usize, power: u8 },
    /// Term `term` repeats an earlier term.
    Repeated { term: usize },
}

impl std::fmt::Display for TermsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TermsError::TooManyFeatures { n_features } => write!(
                f,
                "terms over {n_features} features, at most {MAX_FEATURES} supported"
            ),
            TermsError::TermCount { terms } => write!(f, "{terms} terms: need 1 to {MAX_TERMS}"),
            TermsError::PowerCount {
                term,
                powers,
                n_features,
            } => write!(
                f,
                "term {term} has {powers} powers, expected one per feature ({n_features})"
            ),
            TermsError::PowerTooHigh { term, power } => write!(
                f,
                "term {term} has power {power}, at most {MAX_POWER} supported"
            ),
            TermsError::Repeated { term } => write!(f, "term {term} repeats an earlier term"),
        }
    }
}

impl std::error::Error for TermsError {}

/// A fitted baseline.
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineFit {
    /// The terms.
    pub terms: Terms,
    /// One coefficient per term, for the raw monomials (target units per feature-unit product).
    pub coefficients: Vec<f64>,
    /// RMS of the residual over the samples used, target units.
    pub rms_residual: f64,
    /// Samples used (rows not masked out).
    pub n_used: usize,
    /// Smallest/largest singular value of the scaled design matrix (1 is perfectly conditioned).
    pub condition_ratio: f64,
}

impl BaselineFit {
    /// Prediction for one feature vector (ground evaluation: design row · coefficients).
    pub fn predict_row(&self, x: &[f64]) -> f64 {
        evaluate(&self.terms, &self.coefficients, x)
    }

    /// Predictions for every row of `table`.
    pub fn predict(&self, table: &FeatureTable) -> Vec<f64> {
        (0..table.n_rows())
            .map(|r| self.predict_row(table.row(r)))
            .collect()
    }

    /// The flight crate's evaluator for this fit.
    pub fn to_core(&self) -> Result<BaselineModel, BaselineError> {
        to_core(&self.terms, &self.coefficients)
    }
}

/// A flight-crate model from terms and coefficients (fails past the core's capacity).
pub fn to_core(terms: &Terms, coefficients: &[f64]) -> Result<BaselineModel, BaselineError> {
    let mut m = BaselineModel::new(terms.n_features)?;
    for (p, &c) in terms.powers.iter().zip(coefficients) {
        m.push_term(p, c)?;
    }
    Ok(m)
}

/// Why a fit was refused.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum LsqError {
    /// Terms, rows, target or mask do not fit together.
    Shape(String),
    /// The term list itself cannot be evaluated in flight.
    Terms(TermsError),
    /// Term `term` (counted from the constant, 0) does not vary within the training runs
    /// (fixed-effects fit: after each run's mean is removed).
    ConstantTerm { term: usize },
    /// A target value at `row` is not finite.
    NonFiniteTarget { row: usize, value: f64 },
    /// Fewer usable rows than terms.
    TooFewSamples { used: usize, terms: usize },
    /// A feature used by a term does not vary over the training rows.
    ConstantFeature {
        feature: String,
        unit: String,
        mean: f64,
        std: f64,
        term: String,
    },
    /// The design matrix is (nearly) rank deficient.
    RankDeficient { ratio: f64, terms: Vec<String> },
}

fn long_name(feature: &str) -> String {
    match feature {
        "T" => "temperature".to_owned(),
        "dT" => "temperature rate".to_owned(),
        other => format!("feature {other}"),
    }
}

impl std::fmt::Display for LsqError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LsqError::Shape(m) => write!(f, "baseline fit: {m}"),
            LsqError::Terms(_) => f.write_str("baseline fit: the terms are invalid"),
            LsqError::ConstantTerm { term } => write!(
                f,
                "term {term} does not vary within the training runs: cannot fit it"
            ),
            LsqError::NonFiniteTarget { row, value } => write!(
                f,
                "baseline fit: target at step {row} is {value}; mask it out or fix the log"
            ),
            LsqError::TooFewSamples { used, terms } => write!(
                f,
                "baseline fit: {used} usable steps for {terms} terms; use a longer log"
            ),
            LsqError::ConstantFeature {
                feature,
                unit,
                mean,
                std,
                term,
            } => {
                let what = long_name(feature);
                let range = if feature == "T" {
                    "the temperature range".to_owned()
                } else {
                    format!("a range of {what}")
                };
                let spread = if *std == 0.0 {
                    "0".to_owned()
                } else {
                    format!("{std:.1e}")
                };
                write!(
                    f,
                    "the training log's {what} is constant ({mean:.1} {unit} ± {spread}): cannot fit the {term} coefficient; use a log that spans {range}"
                )
            }
            LsqError::RankDeficient { ratio, terms } => write!(
                f,
                "baseline fit: the terms {} are (nearly) linearly dependent over the training data (singular value ratio {ratio:.1e} < {RANK_TOL:.0e}); drop one of them or use a log that varies them independently",
                terms.join(", ")
            ),
        }
    }
}

impl std::error::Error for LsqError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LsqError::Terms(e) => Some(e),
            _ => None,
        }
    }
}

/// Fit `terms` to `target` (one value per row of `table`); `mask[r] == false` leaves row `r`
/// out (e.g. steps without a scale-factor label).
pub fn fit(
    table: &FeatureTable,
    target: &[f64],
    mask: Option<&[bool]>,
    terms: &Terms,
) -> Result<BaselineFit, LsqError> {
    fit_rows(
        &table.rows,
        table.n_features,
        &table.names,
        &table.units,
        target,
        mask,
        terms,
    )
}

/// [`fit`] over plain row-major data; `names`/`units` label the features in error messages.
pub fn fit_rows(
    rows: &[f64],
    n_features: usize,
    names: &[String],
    units: &[&str],
    target: &[f64],
    mask: Option<&[bool]>,
    terms: &Terms,
) -> Result<BaselineFit, LsqError> {
    terms.validate().map_err(LsqError::Terms)?;
    if terms.n_features != n_features {
        return Err(LsqError::Shape(format!(
            "terms are over {} features, the data has {n_features}",
            terms.n_features
        )));
    }
    if n_features == 0 || rows.len() % n_features != 0 {
        return Err(LsqError::Shape(format!(
            "{} values is not a whole number of rows of {n_features}",
            rows.len()
        )));
    }
    let n_rows = rows.len() / n_features;
    if target.len() != n_rows {
        return Err(LsqError::Shape(format!(
            "{} target values for {n_rows} feature rows",
            target.len()
        )));
    }
    if let Some(m) = mask {
        if m.len() != n_rows {
            return Err(LsqError::Shape(format!(
                "mask has {} entries for {n_rows} rows",
                m.len()
            )));
        }
    }
    let used: Vec<usize> = (0..n_rows).filter(|&r| mask.is_none_or(|m| m[r])).collect();
    for &r in &used {
        if !target[r].is_finite() {
            return Err(LsqError::NonFiniteTarget {
                row: r,
                value: target[r],
            });
        }
        if let Some(k) = rows[r * n_features..(r + 1) * n_features]
            .iter()
            .position(|v| !v.is_finite())
        {
            return Err(LsqError::Shape(format!(
                "feature {k} at step {r} is not finite"
            )));
        }
    }
    let p = terms.len();
    if used.len() < p {
        return Err(LsqError::TooFewSamples {
            used: used.len(),
            terms: p,
        });
    }
    let name = |i: usize| names.get(i).cloned().unwrap_or_else(|| format!("x{i}"));
    // Features that terms use must vary.
    for i in 0..n_features {
        let Some(j) = terms.powers.iter().position(|pw| pw[i] > 0) else {
            continue;
        };
        let col = used.iter().map(|&r| rows[r * n_features + i]);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut sum = 0.0;
        for v in col.clone() {
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
        }
        if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) {
            let mean = sum / used.len() as f64;
            let std =
                (col.map(|v| (v - mean) * (v - mean)).sum::<f64>() / used.len() as f64).sqrt();
            return Err(LsqError::ConstantFeature {
                feature: name(i),
                unit: units.get(i).copied().unwrap_or("").to_owned(),
                mean,
                std,
                term: terms.name(j, names),
            });
        }
    }
    // Design matrix, columns scaled to unit RMS.
    let n = used.len();
    let mut x = DMatrix::<f64>::zeros(n, p);
    for (k, &r) in used.iter().enumerate() {
        let d = terms.design_row(&rows[r * n_features..(r + 1) * n_features]);
        for (j, v) in d.into_iter().enumerate() {
            x[(k, j)] = v;
        }
    }
    let mut scale = vec![1.0; p];
    for (j, s) in scale.iter_mut().enumerate() {
        let rms = (x.column(j).norm_squared() / n as f64).sqrt();
        if !(rms.is_finite() && rms > 0.0) {
            return Err(LsqError::RankDeficient {
                ratio: 0.0,
                terms: vec![terms.name(j, names)],
            });
        }
        *s = rms;
        x.column_mut(j).scale_mut(1.0 / rms);
    }
    let y = DVector::from_iterator(n, used.iter().map(|&r| target[r]));
    let svd = x.clone().svd(true, true);
    let sv = &svd.singular_values;
    let (mut smax, mut smin, mut kmin) = (0.0f64, f64::INFINITY, 0usize);
    for (k, &s) in sv.iter().enumerate() {
        smax = smax.max(s);
        if s < smin {
            smin = s;
            kmin = k;
        }
    }
    let ratio = if smax > 0.0 { smin / smax } else { 0.0 };
    if ratio.is_nan() || ratio < RANK_TOL {
        // The right singular vector of the smallest singular value names the dependent terms.
        let mut dep = Vec::new();
        if let Some(vt) = &svd.v_t {
            let v = vt.row(kmin);
            let vmax = v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for (j, c) in v.iter().enumerate() {
                if c.abs() > 1e-4 * vmax {
                    dep.push(terms.name(j, names));
                }
            }
        }
        return Err(LsqError::RankDeficient { ratio, terms: dep });
    }
    let c_scaled = svd
        .solve(&y, 0.0)
        .map_err(|e| LsqError::Shape(format!("SVD solve failed: {e}")))?;
    let resid = &x * &c_scaled - &y;
    let coefficients: Vec<f64> = c_scaled.iter().zip(&scale).map(|(c, s)| c / s).collect();
    Ok(BaselineFit {
        terms: terms.clone(),
        coefficients,
        rms_residual: (resid.norm_squared() / n as f64).sqrt(),
        n_used: n,
        condition_ratio: ratio,
    })
}

//! Evaluation of fitted baseline models: a sum of monomials over the features,
//! `y = Σ_j c_j · Π_i x_i^(p_ji)`.
//!
//! Linear (He et al. 2024's comparison): `bias = c0 + c1·T + c2·dT`, terms `1, T, dT`.
//! Polynomial: `1, T, …, T^n, dT, …, dT^m` (+ `T·dT`), optionally extra features linearly.
//! The ground crate fits the coefficients (`gyrotherm::baseline`); this is what flies.
//!
//! f64 like [`crate::features`], with fixed capacity ([`MAX_TERMS`] terms over
//! [`MAX_FEATURES`] features, powers up to [`MAX_POWER`]); no allocation, no panics.
//! Monomials are evaluated by repeated multiplication, terms summed in order.

use crate::error::{Channel, InputError};
use crate::features::{Features, MAX_FEATURES};
use core::fmt;

/// Most terms in one model.
pub const MAX_TERMS: usize = 16;
/// Highest power of one feature in a term.
pub const MAX_POWER: u8 = 9;

/// A model that cannot be built.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum BaselineError {
    /// More than [`MAX_TERMS`] terms.
    TooManyTerms,
    /// More than [`MAX_FEATURES`] features, or a term's exponent list longer than the model's
    /// feature count.
    FeatureCount { expected: usize, got: usize },
    /// An exponent above [`MAX_POWER`].
    PowerTooHigh { term: u8, feature: u8, power: u8 },
    /// A coefficient that is NaN or infinite.
    NonFiniteCoefficient { term: u8 },
}

impl fmt::Display for BaselineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            BaselineError::TooManyTerms => write!(f, "more than {MAX_TERMS} terms"),
            BaselineError::FeatureCount { expected, got } => write!(
                f,
                "{got} features where at most {expected} are possible (max {MAX_FEATURES})"
            ),
            BaselineError::PowerTooHigh {
                term,
                feature,
                power,
            } => write!(
                f,
                "term {term}: feature {feature} to the power {power}, at most {MAX_POWER} supported"
            ),
            BaselineError::NonFiniteCoefficient { term } => {
                write!(f, "coefficient of term {term} is not finite")
            }
        }
    }
}

impl core::error::Error for BaselineError {}

/// Why [`BaselineModel::eval`] gave no number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum EvalError {
    /// A non-finite feature (`Channel::Feature(i)`).
    Input(InputError),
    /// Fewer features than the model uses.
    FeatureCount { expected: usize, got: usize },
    /// The result overflowed (finite inputs far outside any training range).
    Overflow,
}

impl From<InputError> for EvalError {
    fn from(e: InputError) -> Self {
        EvalError::Input(e)
    }
}

impl fmt::Display for EvalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvalError::Input(e) => write!(f, "{e}"),
            EvalError::FeatureCount { expected, got } => {
                write!(f, "model needs {expected} features, got {got}")
            }
            EvalError::Overflow => f.write_str("baseline model output overflowed"),
        }
    }
}

impl core::error::Error for EvalError {}

/// A fitted baseline: up to [`MAX_TERMS`] monomials and their coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaselineModel {
    n_features: u8,
    n_terms: u8,
    powers: [[u8; MAX_FEATURES]; MAX_TERMS],
    coefficients: [f64; MAX_TERMS],
}

impl BaselineModel {
    /// An empty model (evaluates to 0) over `n_features` features.
    pub fn new(n_features: usize) -> Result<Self, BaselineError> {
        if n_features > MAX_FEATURES {
            return Err(BaselineError::FeatureCount {
                expected: MAX_FEATURES,
                got: n_features,
            });
        }
        Ok(BaselineModel {
            n_features: n_features as u8,
            n_terms: 0,
            powers: [[0; MAX_FEATURES]; MAX_TERMS],
            coefficients: [0.0; MAX_TERMS],
        })
    }

    /// Add the term `coefficient · Π_i x_i^powers[i]` (`powers` may be shorter than the feature
    /// count; missing powers are 0).
    pub fn push_term(&mut self, powers: &[u8], coefficient: f64) -> Result<(), BaselineError> {
        let j = self.n_terms as usize;
        if j >= MAX_TERMS {
            return Err(BaselineError::TooManyTerms);
        }
        if powers.len() > self.n_features as usize {
            return Err(BaselineError::FeatureCount {
                expected: self.n_features as usize,
                got: powers.len(),
            });
        }
        if let Some((i, &power)) = powers.iter().enumerate().find(|(_, &p)| p > MAX_POWER) {
            return Err(BaselineError::PowerTooHigh {
                term: j as u8,
                feature: i as u8,
                power,
            });
        }
        if !coefficient.is_finite() {
            return Err(BaselineError::NonFiniteCoefficient { term: j as u8 });
        }
        let mut row = [0u8; MAX_FEATURES];
        for (dst, src) in row.iter_mut().zip(powers) {
            *dst = *src;
        }
        let (Some(p), Some(c)) = (self.powers.get_mut(j), self.coefficients.get_mut(j)) else {
            return Err(BaselineError::TooManyTerms);
        };
        *p = row;
        *c = coefficient;
        self.n_terms += 1;
        Ok(())
    }

    /// Number of features the model reads.
    pub fn n_features(&self) -> usize {
        self.n_features as usize
    }

    /// Number of terms.
    pub fn n_terms(&self) -> usize {
        self.n_terms as usize
    }

    /// Powers of term `j` (over all MAX_FEATURES slots) and its coefficient.
    pub fn term(&self, j: usize) -> Option<(&[u8], f64)> {
        if j >= self.n_terms as usize {
            return None;
        }
        let powers = self.powers.get(j)?.get(..self.n_features as usize)?;
        Some((powers, *self.coefficients.get(j)?))
    }

    /// `Σ_j c_j Π_i x_i^p_ji` over the first `n_features` values of `x`.
    pub fn eval(&self, x: &[f64]) -> Result<f64, EvalError> {
        let nf = self.n_features as usize;
        if x.len() < nf {
            return Err(EvalError::FeatureCount {
                expected: nf,
                got: x.len(),
            });
        }
        let x = x.get(..nf).unwrap_or(&[]);
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(InputError::NonFinite(Channel::Feature(i as u8)).into());
        }
        let mut y = 0.0;
        let terms = self.coefficients.iter().zip(&self.powers);
        for (&c, powers) in terms.take(self.n_terms as usize) {
            let mut m = c;
            for (&xi, &p) in x.iter().zip(powers) {
                for _ in 0..p {
                    m *= xi;
                }
            }
            y += m;
        }
        if y.is_finite() {
            Ok(y)
        } else {
            Err(EvalError::Overflow)
        }
    }

    /// [`eval`](Self::eval) on a pipeline step's features.
    pub fn eval_features(&self, f: &Features) -> Result<f64, EvalError> {
        self.eval(f.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_model_by_hand() {
        // bias = 0.5 + 0.25·T - 2·dT at T = 4, dT = 0.5: 0.5 + 1 - 1 = 0.5 (exact in binary).
        let mut m = BaselineModel::new(2).unwrap();
        m.push_term(&[], 0.5).unwrap();
        m.push_term(&[1], 0.25).unwrap();
        m.push_term(&[0, 1], -2.0).unwrap();
        assert_eq!(m.eval(&[4.0, 0.5]), Ok(0.5));
    }
}

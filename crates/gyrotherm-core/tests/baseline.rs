//! Baseline model evaluation in the flight crate.

use gyrotherm_core::baseline::{BaselineError, BaselineModel, EvalError, MAX_POWER, MAX_TERMS};
use gyrotherm_core::error::{Channel, InputError};
use gyrotherm_core::features::{FeaturePipeline, FeatureSpec, MAX_FEATURES};
use proptest::prelude::*;

/// 1 + 2·T - 3·T²·dT + 0.5·dT³ over (T, dT).
fn poly() -> BaselineModel {
    let mut m = BaselineModel::new(2).unwrap();
    m.push_term(&[0, 0], 1.0).unwrap();
    m.push_term(&[1], 2.0).unwrap();
    m.push_term(&[2, 1], -3.0).unwrap();
    m.push_term(&[0, 3], 0.5).unwrap();
    m
}

#[test]
fn polynomial_matches_formula() {
    // Independent computation with powi; tolerance: a few ulp of the largest term.
    let m = poly();
    for &(t, d) in &[(0.0, 0.0), (25.0, 0.05), (-40.0, -0.05), (60.0, 1.5)] {
        let want = 1.0 + 2.0 * t - 3.0 * t * t * d + 0.5 * f64::powi(d, 3);
        let got = m.eval(&[t, d]).unwrap();
        let tol = 1e-14 * (1.0 + (3.0 * t * t * d).abs());
        assert!(
            (got - want).abs() <= tol,
            "T={t} dT={d}: want {want}, got {got}"
        );
    }
}

#[test]
fn evaluates_pipeline_features() {
    let mut p = FeaturePipeline::new(FeatureSpec::PUBLISHED).unwrap();
    let s = p.push(0.0, 25.0).unwrap().unwrap();
    // dT = 0 at step 0: 1 + 2·25 = 51.
    assert_eq!(poly().eval_features(&s.features), Ok(51.0));
}

#[test]
fn bad_features_are_reported() {
    let m = poly();
    assert_eq!(
        m.eval(&[1.0, f64::NAN]),
        Err(EvalError::Input(InputError::NonFinite(Channel::Feature(1))))
    );
    assert_eq!(
        m.eval(&[1.0]),
        Err(EvalError::FeatureCount {
            expected: 2,
            got: 1
        })
    );
    assert_eq!(m.eval(&[1e200, 1e200]), Err(EvalError::Overflow));
    // Extra values past n_features are ignored.
    assert_eq!(m.eval(&[0.0, 0.0, f64::NAN]), Ok(1.0));
}

#[test]
fn capacity_limits_are_errors() {
    assert!(BaselineModel::new(MAX_FEATURES + 1).is_err());
    let mut m = BaselineModel::new(2).unwrap();
    assert_eq!(
        m.push_term(&[0, 0, 1], 1.0),
        Err(BaselineError::FeatureCount {
            expected: 2,
            got: 3
        })
    );
    assert!(matches!(
        m.push_term(&[MAX_POWER + 1], 1.0),
        Err(BaselineError::PowerTooHigh { .. })
    ));
    assert!(matches!(
        m.push_term(&[1], f64::INFINITY),
        Err(BaselineError::NonFiniteCoefficient { term: 0 })
    ));
    for _ in 0..MAX_TERMS {
        m.push_term(&[1], 1.0).unwrap();
    }
    assert_eq!(m.push_term(&[1], 1.0), Err(BaselineError::TooManyTerms));
    assert_eq!(m.n_terms(), MAX_TERMS);
    assert_eq!(m.eval(&[2.0, 0.0]), Ok(2.0 * MAX_TERMS as f64));
}

proptest! {
    #[test]
    fn never_panics(x in proptest::collection::vec(any::<f64>(), 0..4)) {
        let _ = poly().eval(&x);
    }
}

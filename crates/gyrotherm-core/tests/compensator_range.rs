//! Every rate the compensator gives is finite, whatever the finite inputs and model outputs:
//! an overflow of (Ĝ − B) / K is `Status::Invalid` (no rate), not ∞. Found by the
//! `compensator` fuzz target (a polynomial bias of -1.6e308 °/s and a gyro of -22.8 °/s).

use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::compensator::{Compensator, Status, TargetModel, TempLimits};
use gyrotherm_core::features::FeatureSpec;

fn constant_bias(b: f64) -> Compensator {
    let n = FeatureSpec::PUBLISHED.n_features();
    let mut base = BaselineModel::new(n).unwrap();
    base.push_term(&[0, 0], b).unwrap();
    let bias = TargetModel {
        offset: 0.0,
        baseline: Some(base),
        lstm: None,
        lstm_reads_base: false,
    };
    Compensator::with_limits(
        FeatureSpec::PUBLISHED,
        bias,
        TargetModel::constant(0.777),
        TempLimits::DEFAULT,
    )
    .unwrap()
}

#[test]
fn huge_bias_or_gyro_gives_no_rate_not_an_infinite_one() {
    let mut c = constant_bias(-1.6249735983755005e308);
    let r = c.step(0.0, -22.833, -14.19);
    assert_eq!(r.status, Status::Invalid, "{r:?}");
    assert_eq!(r.rate(), None);
    let mut c = constant_bias(-1e308);
    let r = c.step(0.0, 1.7e308, 25.0);
    assert_eq!(r.status, Status::Invalid, "{r:?}");
    // An ordinary sample after it still gives its rate.
    let r = c.step(1.0, -1e308, 25.0);
    assert_eq!(r.rate(), Some(0.0));
    let mut c = constant_bias(0.001);
    let r = c.step(0.0, 1e308, 25.0);
    assert!(r.rate().is_some_and(f64::is_finite), "{r:?}");
}

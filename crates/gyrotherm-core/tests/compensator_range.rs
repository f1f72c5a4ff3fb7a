//! Every `Ok` of the compensator is a finite rate, whatever the finite inputs and model
//! outputs: an overflow of (Ĝ − B) / K is refused, not returned as ∞. Found by the
//! `compensator` fuzz target (a polynomial bias of -1.6e308 °/s and a gyro of -22.8 °/s).

use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::compensator::{Compensator, TargetModel};
use gyrotherm_core::features::FeatureSpec;
use gyrotherm_core::{Channel, InputError};

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
    Compensator::new(FeatureSpec::PUBLISHED, bias, TargetModel::constant(0.777)).unwrap()
}

#[test]
fn huge_bias_or_gyro_is_refused_not_infinite() {
    let mut c = constant_bias(-1.6249735983755005e308);
    assert_eq!(
        c.step(0.0, -22.833, -14.19),
        Err(InputError::NonFinite(Channel::Gyro))
    );
    let mut c = constant_bias(-1e308);
    assert_eq!(
        c.step(0.0, 1.7e308, 25.0),
        Err(InputError::NonFinite(Channel::Gyro))
    );
    // An ordinary sample after it still gives its rate: the refusal left nothing behind.
    let r = c.step(1.0, -1e308, 25.0).unwrap();
    assert_eq!(r.rate_dps, 0.0);
    let mut c = constant_bias(0.001);
    let r = c.step(0.0, 1e308, 25.0).unwrap();
    assert!(r.rate_dps.is_finite());
}

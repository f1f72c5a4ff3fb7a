//! The flight compensator: eq. 4 of He et al. 2024, holding between steps, refusing bad input
//! without losing state, never panicking.

use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::compensator::{Compensator, ModelError, NormalisedLstm, TargetModel};
use gyrotherm_core::features::FeatureSpec;
use gyrotherm_core::lstm::LstmWeights;
use gyrotherm_core::{Channel, InputError};
use proptest::prelude::*;

/// bias = 1e-3 + 2e-5·T (°/s), K = 1 + 1e-5·T.
fn linear_compensator() -> Compensator {
    let mut b = BaselineModel::new(2).unwrap();
    b.push_term(&[0, 0], 1e-3).unwrap();
    b.push_term(&[1, 0], 2e-5).unwrap();
    let mut k = BaselineModel::new(2).unwrap();
    k.push_term(&[0, 0], 1.0).unwrap();
    k.push_term(&[1, 0], 1e-5).unwrap();
    let model = |m| TargetModel {
        offset: 0.0,
        baseline: Some(m),
        lstm: None,
        lstm_reads_base: false,
    };
    Compensator::new(FeatureSpec::PUBLISHED, model(b), model(k)).unwrap()
}

#[test]
fn output_is_eq4_of_the_paper() {
    let mut c = linear_compensator();
    for i in 0..100 {
        let t = i as f64;
        let temp = 20.0 + 0.05 * t;
        let gyro = 20.0 * (1.0 + 1e-5 * temp) + 1e-3 + 2e-5 * temp;
        let out = c.step(t, gyro, temp).unwrap();
        // Independent: G = (Ĝ - B)/K with B and K from the generating formulas.
        assert!((out.bias_dps - (1e-3 + 2e-5 * temp)).abs() < 1e-15);
        assert!((out.scale - (1.0 + 1e-5 * temp)).abs() < 1e-15);
        assert!((out.rate_dps - 20.0).abs() < 1e-12, "{}", out.rate_dps);
    }
}

#[test]
fn holds_bias_and_scale_between_steps_at_100_hz() {
    let mut c = linear_compensator();
    let first = c.step(0.0, 0.0, 20.0).unwrap();
    for i in 1..100 {
        // Temperature changes within the 1 s step; the model must not see it until t = 1 s.
        let o = c.step(i as f64 * 0.01, 0.0, 20.0 + i as f64).unwrap();
        assert_eq!((o.bias_dps, o.scale), (first.bias_dps, first.scale));
    }
    let next = c.step(1.0, 0.0, 30.0).unwrap();
    assert!((next.bias_dps - (1e-3 + 2e-5 * 30.0)).abs() < 1e-15);
}

#[test]
fn bad_input_is_refused_and_the_state_kept() {
    let mut a = linear_compensator();
    let mut b = linear_compensator();
    for i in 0..30 {
        let t = i as f64;
        a.step(t, 0.01, 20.0 + t).unwrap();
        b.step(t, 0.01, 20.0 + t).unwrap();
    }
    assert_eq!(
        a.step(30.0, f64::NAN, 50.0),
        Err(InputError::NonFinite(Channel::Gyro))
    );
    assert_eq!(
        a.step(30.0, 0.01, f64::INFINITY),
        Err(InputError::NonFinite(Channel::Temperature))
    );
    assert_eq!(a.step(29.0, 0.01, 49.0), Err(InputError::TimeNotIncreasing));
    // After the refusals `a` continues exactly like `b`, which never saw them.
    for i in 30..60 {
        let t = i as f64;
        assert_eq!(a.step(t, 0.01, 20.0 + t), b.step(t, 0.01, 20.0 + t));
    }
}

fn lstm_compensator() -> Compensator {
    let w = LstmWeights::from_slices(
        &[0.1; 4 * 8 * 12],
        &[0.05; 4 * 8 * 8],
        &[0.0; 32],
        &[0.0; 32],
        &[0.3; 8],
        0.1,
    )
    .unwrap();
    let lstm = NormalisedLstm::new(&w, &[20.0, 0.0], &[10.0, 0.01], 1e-3, 1e-4).unwrap();
    let bias = TargetModel {
        offset: 0.0,
        baseline: None,
        lstm: Some(lstm),
        lstm_reads_base: false,
    };
    Compensator::new(FeatureSpec::PUBLISHED, bias, TargetModel::constant(1.0)).unwrap()
}

/// LSTM weights (PyTorch layout, 12 input slots) that read input slot 2 far more strongly than
/// slots 0 and 1, so that the input order shows in the output.
fn slot2_weights() -> LstmWeights<12, 8> {
    let mut w_ih = [0.0f32; 4 * 8 * 12];
    for (i, w) in w_ih.iter_mut().enumerate() {
        *w = match i % 12 {
            0 => 0.02,
            1 => -0.03,
            2 => 0.5,
            _ => 0.0,
        };
    }
    LstmWeights::from_slices(
        &w_ih,
        &[0.05; 4 * 8 * 8],
        &[0.0; 32],
        &[0.0; 32],
        &[0.3; 8],
        0.1,
    )
    .unwrap()
}

/// bias = 1e-3 + 2e-5·T (°/s) plus an LSTM reading (T, dT, base).
fn base_reading_compensator() -> (Compensator, NormalisedLstm) {
    let mut b = BaselineModel::new(2).unwrap();
    b.push_term(&[0, 0], 1e-3).unwrap();
    b.push_term(&[1, 0], 2e-5).unwrap();
    let lstm = NormalisedLstm::new(
        &slot2_weights(),
        &[20.0, 0.0, 1.4e-3],
        &[10.0, 0.01, 2e-4],
        1e-3,
        1e-4,
    )
    .unwrap();
    let bias = TargetModel {
        offset: 0.0,
        baseline: Some(b),
        lstm: Some(lstm.clone()),
        lstm_reads_base: true,
    };
    let c = Compensator::new(FeatureSpec::PUBLISHED, bias, TargetModel::constant(1.0)).unwrap();
    (c, lstm)
}

/// With `lstm_reads_base` the LSTM's inputs are the features followed by the baseline value:
/// the compensator's bias equals baseline(f) + lstm(f0, f1, baseline(f)), the LSTM stepped
/// here by hand on that vector (independent: the documented input order).
#[test]
fn lstm_reads_features_then_base_value() {
    let (mut c, mut reference) = base_reading_compensator();
    let mut max_lstm = 0.0f64;
    for i in 0..200 {
        let t = i as f64;
        let temp = 20.0 + 10.0 * (t / 40.0).sin();
        let out = c.step(t, 0.0, temp).unwrap();
        let f = c.features().unwrap().as_slice().to_vec();
        assert_eq!(f.len(), 2);
        let base = 1e-3 + 2e-5 * f[0];
        let lstm = reference.step(&[f[0], f[1], base]).unwrap();
        let want = base + lstm;
        // f32 cell arithmetic inside both: the same operations in the same order, so equal
        // up to the f64 sum's rounding.
        assert!(
            (out.bias_dps - want).abs() < 1e-15,
            "step {i}: want {want}, got {}, error {}",
            out.bias_dps,
            out.bias_dps - want
        );
        max_lstm = max_lstm.max(lstm.abs());
    }
    // The LSTM contributes (the test would pass trivially on a zero network otherwise).
    assert!(max_lstm > 1e-5, "LSTM output at most {max_lstm}");
}

/// The base-reading LSTM must take n_features + 1 inputs; the plain one n_features.
#[test]
fn base_reading_lstm_input_count_is_checked() {
    let mut b = BaselineModel::new(2).unwrap();
    b.push_term(&[0, 0], 1e-3).unwrap();
    let two = NormalisedLstm::new(&slot2_weights(), &[0.0; 2], &[1.0; 2], 0.0, 1.0).unwrap();
    let three = NormalisedLstm::new(&slot2_weights(), &[0.0; 3], &[1.0; 3], 0.0, 1.0).unwrap();
    let model = |lstm: &NormalisedLstm, reads| TargetModel {
        offset: 0.0,
        baseline: Some(b),
        lstm: Some(lstm.clone()),
        lstm_reads_base: reads,
    };
    let build = |m| Compensator::new(FeatureSpec::PUBLISHED, m, TargetModel::constant(1.0));
    assert_eq!(
        build(model(&two, true)).err(),
        Some(ModelError::FeatureCount {
            expected: 3,
            got: 2
        })
    );
    assert_eq!(
        build(model(&three, false)).err(),
        Some(ModelError::FeatureCount {
            expected: 2,
            got: 3
        })
    );
    assert!(build(model(&three, true)).is_ok());
    assert!(build(model(&two, false)).is_ok());
}

proptest! {
    /// No input sequence makes `step` panic; every Ok output is finite.
    #[test]
    fn never_panics(samples in prop::collection::vec((any::<f64>(), any::<f64>(), any::<f64>()), 1..64)) {
        for mut c in [linear_compensator(), lstm_compensator(), base_reading_compensator().0] {
            for (t, g, temp) in &samples {
                if let Ok(o) = c.step(*t, *g, *temp) {
                    prop_assert!(o.rate_dps.is_finite() || !g.is_finite() || g.abs() > 1e300);
                }
            }
        }
    }
}

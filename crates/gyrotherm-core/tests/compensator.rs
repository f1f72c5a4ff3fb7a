//! The flight compensator: eq. 4 of He et al. 2024, holding between steps, riding through
//! temperature-sensor faults with a status per sample, never panicking.

use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::compensator::{
    Compensator, ModelError, NormalisedLstm, Status, TargetModel, TempLimits,
};
use gyrotherm_core::features::FeatureSpec;
use gyrotherm_core::lstm::LstmWeights;
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
        let out = c.step(t, gyro, temp);
        assert_eq!(out.status, Status::Ok);
        // Independent: G = (Ĝ - B)/K with B and K from the generating formulas.
        assert!((out.bias_dps - (1e-3 + 2e-5 * temp)).abs() < 1e-15);
        assert!((out.scale - (1.0 + 1e-5 * temp)).abs() < 1e-15);
        assert!((out.rate_dps - 20.0).abs() < 1e-12, "{}", out.rate_dps);
    }
}

#[test]
fn holds_bias_and_scale_between_steps_at_100_hz() {
    let mut c = linear_compensator();
    let first = c.step(0.0, 0.0, 20.0);
    for i in 1..100 {
        // Temperature changes within the 1 s step; the model must not see it until t = 1 s.
        let o = c.step(i as f64 * 0.01, 0.0, 20.0 + i as f64 * 0.01);
        assert_eq!((o.bias_dps, o.scale), (first.bias_dps, first.scale));
    }
    let next = c.step(1.0, 0.0, 21.0);
    assert!((next.bias_dps - (1e-3 + 2e-5 * 21.0)).abs() < 1e-15);
}

/// A rejected sample (non-finite gyro, non-finite or implausible temperature, time not
/// increasing) leaves the compensator exactly as if it had not been seen: afterwards `a`
/// continues bit for bit like `b`, which never saw them.
#[test]
fn rejected_samples_leave_the_state_untouched() {
    let mut a = linear_compensator();
    let mut b = linear_compensator();
    for i in 0..30 {
        let t = i as f64;
        a.step(t, 0.01, 20.0 + 0.1 * t);
        b.step(t, 0.01, 20.0 + 0.1 * t);
    }
    a.step(29.5, 0.01, 22.95);
    let held = a.step(30.0, f64::NAN, 23.0);
    let nan_gyro = held;
    assert_eq!(nan_gyro.status, Status::Invalid);
    assert_eq!(nan_gyro.rate(), None);
    b.step(29.5, 0.01, 22.95);
    b.step(30.0, 0.01, 23.0);
    for (t, temp) in [
        (30.5, f64::INFINITY),
        (30.6, f64::NAN),
        (30.7, 85.0),
        (30.8, -127.0),
        (30.9, 101.0),
    ] {
        let o = a.step(t, 0.02, temp);
        assert_eq!(o.status, Status::Held, "T = {temp}");
        assert_eq!((o.bias_dps, o.scale), (held.bias_dps, held.scale));
        assert_eq!(o.rate(), Some((0.02 - o.bias_dps) / o.scale));
    }
    // Time not after the previous time stamp, or not finite: held.
    assert_eq!(a.step(30.9, 0.01, 23.09).status, Status::Held);
    assert_eq!(a.step(f64::NAN, 0.01, 23.09).status, Status::Held);
    for i in 31..60 {
        let t = i as f64;
        let (x, y) = (
            a.step(t, 0.01, 20.0 + 0.1 * t),
            b.step(t, 0.01, 20.0 + 0.1 * t),
        );
        assert_eq!(x, y);
        assert_eq!(x.status, Status::Ok);
    }
}

/// Held for up to `degraded_after_s` since the last good temperature, degraded after; back to
/// ok on the first good reading. Before any good temperature: degraded, B = 0, K = 1.
#[test]
fn held_then_degraded_then_ok() {
    let mut c = linear_compensator();
    let o = c.step(0.0, 0.5, f64::NAN);
    assert_eq!(o.status, Status::Degraded);
    assert_eq!((o.bias_dps, o.scale, o.rate_dps), (0.0, 1.0, 0.5));
    assert_eq!(c.step(1.0, 0.5, 20.0).status, Status::Ok);
    for i in 2..=61 {
        assert_eq!(
            c.step(i as f64, 0.5, f64::NAN).status,
            Status::Held,
            "t = {i}"
        );
    }
    assert_eq!(c.step(61.5, 0.5, f64::NAN).status, Status::Degraded);
    assert_eq!(c.step(62.0, 0.5, 20.1).status, Status::Ok);
}

/// The rate check: a change within max_rate·Δt + allowance is accepted; a larger one is held
/// until enough time has passed for a real change of that size (recovery after an outage
/// during which the temperature moved).
#[test]
fn rate_limit_rejects_jumps_and_recovers_after_a_real_move() {
    let limits = TempLimits::DEFAULT;
    let mut c = linear_compensator();
    assert_eq!(c.step(0.0, 0.0, 20.0).status, Status::Ok);
    // 100 Hz, one DS18B20 LSB flip (0.0625 °C) per sample: within the allowance.
    assert_eq!(c.step(0.01, 0.0, 20.0625).status, Status::Ok);
    assert_eq!(c.step(0.02, 0.0, 20.0).status, Status::Ok);
    // A 10 °C jump is held until 2 °C/s · Δt + 1 °C ≥ 10 °C, i.e. Δt ≥ 4.5 s.
    let mut t = 0.02;
    let mut first_ok = None;
    while t < 10.0 {
        t += 0.5;
        if c.step(t, 0.0, 30.0).status == Status::Ok {
            first_ok = Some(t);
            break;
        }
    }
    let want = 0.02 + (10.0 - limits.step_allowance_c) / limits.max_rate_c_per_s;
    let got = first_ok.expect("recovers");
    assert!(
        got >= want && got < want + 0.5 + 1e-9,
        "ok again at {got} s, want ≈{want} s"
    );
}

/// After a NaN burst the rate feature bridges the gap with the true elapsed time: equal to
/// the uninterrupted run on a linear temperature ramp (dT = slope), so no transient.
#[test]
fn rate_resumes_without_a_transient_after_a_gap() {
    let mut c = linear_compensator();
    let slope = 0.05;
    for i in 0..200 {
        let t = i as f64;
        let bad = (100..130).contains(&i);
        let o = c.step(t, 0.0, if bad { f64::NAN } else { 20.0 + slope * t });
        if !bad && i >= 20 {
            let dt = c.features().unwrap().as_slice()[1];
            assert!((dt - slope).abs() < 1e-12, "t = {t}: dT = {dt}");
            assert_eq!(o.status, Status::Ok);
        }
    }
}

#[test]
fn bad_limits_are_refused() {
    let bad = [
        TempLimits {
            min_c: 10.0,
            max_c: 10.0,
            ..TempLimits::DEFAULT
        },
        TempLimits {
            max_rate_c_per_s: 0.0,
            ..TempLimits::DEFAULT
        },
        TempLimits {
            step_allowance_c: f64::NAN,
            ..TempLimits::DEFAULT
        },
        TempLimits {
            degraded_after_s: -1.0,
            ..TempLimits::DEFAULT
        },
    ];
    for l in bad {
        let r = Compensator::with_limits(
            FeatureSpec::PUBLISHED,
            TargetModel::constant(0.0),
            TargetModel::constant(1.0),
            l,
        );
        assert!(matches!(r, Err(ModelError::Limits(_))), "{l:?}");
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
        let out = c.step(t, 0.0, temp);
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

/// A sample stream where most samples are good: time mostly advancing by 0.1–2 s, the
/// temperature a slow random walk inside the limits; about 1 in 8 samples is a fault drawn
/// from every kind (NaN, ±inf, 85.0, −127.0, any f64, time going back or NaN, gyro NaN or
/// huge).
fn mostly_good() -> impl Strategy<Value = Vec<(f64, f64, f64)>> {
    let step = (
        0.1f64..2.0,
        -0.5f64..0.5,
        -1.0f64..1.0,
        0u8..64,
        any::<f64>(),
    );
    prop::collection::vec(step, 1..400).prop_map(|steps| {
        let (mut t, mut temp) = (0.0f64, 20.0f64);
        steps
            .into_iter()
            .enumerate()
            .map(|(i, (dt, dtemp, gyro, fault, wild))| {
                t += dt;
                // The first sample is good: a run that starts on a fault is the degraded case.
                let fault = if i == 0 { 63 } else { fault };
                temp = (temp + dtemp).clamp(-50.0, 90.0);
                match fault {
                    0 => (t, gyro, f64::NAN),
                    1 => (t, gyro, 85.0),
                    2 => (t, gyro, -127.0),
                    3 => (t, gyro, wild),
                    4 => (t, f64::NAN, temp),
                    5 => (t - 10.0 * dt, gyro, temp),
                    6 => (f64::NAN, gyro, temp),
                    7 => (t, wild, f64::INFINITY),
                    _ => (t, gyro, temp),
                }
            })
            .collect()
    })
}

proptest! {
    /// No input sequence makes `step` panic or give NaN: a finite gyro sample always gets a
    /// non-NaN rate and a status other than invalid; B and K are always finite, K > 0. The
    /// inputs are mostly accepted (checked: at least half the samples are ok), so the step
    /// path through the features and models is what is exercised.
    #[test]
    fn never_panics_nor_gives_nan(samples in mostly_good()) {
        for mut c in [linear_compensator(), lstm_compensator(), base_reading_compensator().0] {
            let mut ok = 0usize;
            for (t, g, temp) in &samples {
                let o = c.step(*t, *g, *temp);
                prop_assert!(o.bias_dps.is_finite() && o.scale.is_finite() && o.scale > 0.0);
                prop_assert!(!o.rate_dps.is_nan());
                prop_assert_eq!(o.status == Status::Invalid, !g.is_finite());
                ok += usize::from(o.status == Status::Ok);
            }
            prop_assert!(2 * ok >= samples.len() || samples.len() < 16,
                "{} of {} ok", ok, samples.len());
        }
    }

    /// Any f64 triples at all (mostly refused): still no panic and no NaN.
    #[test]
    fn arbitrary_input_never_panics(samples in prop::collection::vec((any::<f64>(), any::<f64>(), any::<f64>()), 1..64)) {
        for mut c in [linear_compensator(), lstm_compensator(), base_reading_compensator().0] {
            for (t, g, temp) in &samples {
                let o = c.step(*t, *g, *temp);
                prop_assert!(!o.rate_dps.is_nan() && o.bias_dps.is_finite() && o.scale > 0.0);
            }
        }
    }
}

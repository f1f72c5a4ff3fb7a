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
    let model = |m| TargetModel::<8> {
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
        let r: Result<Compensator, _> = Compensator::with_limits(
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

// The time axis (module doc of `compensator`): placed, not placed, new base.

/// One run of 1 Hz samples on a ramp (20 °C + 0.01 °C/s, gyro 0.01 °/s), with `edit` applied
/// to sample `i`'s (time, gyro, temp); the outputs.
fn ramp_run(
    mut c: Compensator,
    n: usize,
    edit: impl Fn(usize, (f64, f64, f64)) -> (f64, f64, f64),
) -> Vec<gyrotherm_core::Corrected> {
    (0..n)
        .map(|i| {
            let t = i as f64;
            let (t, g, temp) = edit(i, (t, 0.01, 20.0 + 0.01 * t));
            c.step(t, g, temp)
        })
        .collect()
}

/// One glitched time stamp (1e308, +1e9 s, NaN, a repeat, a reset to 0) among good ones costs
/// exactly what one rejected temperature costs: the run equals, on every line, the run whose
/// sample 100 has a NaN temperature instead; the glitch line is held, none is degraded.
#[test]
fn a_single_time_glitch_costs_one_rejected_temperature() {
    for mk in [linear_compensator, lstm_compensator] {
        let reference = ramp_run(mk(), 400, |i, (t, g, temp)| {
            (t, g, if i == 100 { f64::NAN } else { temp })
        });
        for glitch in [
            1e308,
            100.0 + 1e9,
            f64::NAN,
            f64::INFINITY,
            99.0,
            0.0,
            -1e308,
        ] {
            let run = ramp_run(mk(), 400, |i, (t, g, temp)| {
                (if i == 100 { glitch } else { t }, g, temp)
            });
            assert_eq!(run, reference, "glitch time {glitch}");
            assert_eq!(run[100].status, Status::Held, "glitch time {glitch}");
            assert!(run.iter().all(|o| o.status != Status::Degraded));
        }
    }
}

/// The hostile tester's case: 100 good lines, one at 1e308, then a ramp: before the fix every
/// later line was held with B frozen. Now only the glitch line is held and B follows T.
#[test]
fn time_1e308_does_not_freeze_the_compensator() {
    let run = ramp_run(linear_compensator(), 3701, |i, (t, g, temp)| {
        (if i == 100 { 1e308 } else { t }, g, temp)
    });
    let held = run.iter().filter(|o| o.status == Status::Held).count();
    assert_eq!(held, 1);
    let last = run.last().unwrap();
    // bias = 1e-3 + 2e-5·T at T = 20 + 0.01·3700 (linear_compensator).
    let want = 1e-3 + 2e-5 * (20.0 + 0.01 * 3700.0);
    assert!((last.bias_dps - want).abs() < 1e-15, "{}", last.bias_dps);
}

/// A lasting clock change (a reset to 0, a +1e9 s jump, a first time stamp of 1e308 on a new
/// compensator): `REBASE_AFTER - 1` samples held, then a new base with `settle_s` (20 s)
/// degraded, then ok; after the settling the outputs equal those of a new compensator started
/// at the re-basing sample, bit for bit (pipeline and LSTM states restarted).
#[test]
fn a_lasting_clock_change_rebases_settles_and_recovers() {
    use gyrotherm_core::compensator::REBASE_AFTER;
    let settle = FeatureSpec::PUBLISHED.settle_s();
    assert_eq!(settle, 20.0);
    type TimeOf = fn(usize, f64) -> f64;
    let cases: [(&str, TimeOf); 3] = [
        ("reset to 0", |i, t| if i >= 300 { t - 300.0 } else { t }),
        ("+1e9 s", |i, t| if i >= 300 { t + 1e9 } else { t }),
        ("1e308 first", |i, t| if i == 0 { 1e308 } else { t }),
    ];
    for mk in [linear_compensator, lstm_compensator] {
        for (name, time) in cases {
            let from = if name == "1e308 first" { 1 } else { 300 };
            let run = ramp_run(mk(), 600, |i, (t, g, temp)| (time(i, t), g, temp));
            let adopt = from + REBASE_AFTER as usize - 1;
            for (i, o) in run.iter().enumerate().skip(from) {
                let want = if i < adopt {
                    Status::Held
                } else if (i - adopt) < settle as usize {
                    Status::Degraded
                } else {
                    Status::Ok
                };
                assert_eq!(o.status, want, "{name}: sample {i}");
            }
            let fresh = ramp_run(mk(), 600, |i, (t, g, temp)| {
                if i < adopt {
                    (f64::NAN, g, f64::NAN)
                } else {
                    (time(i, t), g, temp)
                }
            });
            for i in adopt..600 {
                assert_eq!(
                    (run[i].bias_dps, run[i].scale, run[i].rate_dps),
                    (fresh[i].bias_dps, fresh[i].scale, fresh[i].rate_dps),
                    "{name}: sample {i}"
                );
            }
        }
    }
}

/// Repeated and NaN time stamps: each is one step period (1 s) on the degraded clock, so after
/// 60 of them (degraded_after_s at the default 1 s step) the status is degraded, not held for
/// good; when good time stamps come back on the old base it is ok at once.
#[test]
fn repeated_and_nan_times_run_the_degraded_clock() {
    for bad in [99.0, f64::NAN] {
        let run = ramp_run(linear_compensator(), 200, |i, (t, g, temp)| {
            if (100..161).contains(&i) {
                (bad, g, temp)
            } else {
                // Good times resume at 100 + 55 s: on the old base (base 99, ≤ 60 s later).
                (if i >= 161 { t - 161.0 + 154.0 } else { t }, g, temp)
            }
        });
        for (i, o) in run.iter().enumerate().take(161).skip(100) {
            // Unplaced sample n = i − 99: degraded once n · 1 s > 60 s.
            let want = if i - 99 > 60 {
                Status::Degraded
            } else {
                Status::Held
            };
            assert_eq!(o.status, want, "time {bad}: sample {i}");
        }
        assert_eq!(run[161].status, Status::Ok, "time {bad}");
        assert!(run[161..].iter().all(|o| o.status == Status::Ok));
    }
}

/// The step index stays below 2^53: with a 1 ns step and degraded_after_s = 1e7 s, a sample
/// 1e7 s after the first would be step 1e16; it re-bases instead of saturating into a hold.
#[test]
fn step_index_never_saturates() {
    use gyrotherm_core::features::{FeaturePipeline, MAX_STEP_INDEX};
    use gyrotherm_core::InputError;
    let spec = FeatureSpec {
        step_period_s: 1e-9,
        rate_lag_s: 20e-9,
        ..FeatureSpec::PUBLISHED
    };
    let mut p = FeaturePipeline::new(spec).unwrap();
    p.push(0.0, 20.0).unwrap();
    assert!(1e7 / 1e-9 > MAX_STEP_INDEX as f64);
    assert_eq!(p.push(1e7, 20.0), Err(InputError::TimeOutOfRange));
    // Left as it was: the next in-range sample is step 1000.
    assert_eq!(p.push(1e-6, 20.0).unwrap().unwrap().index, 1000);

    let limits = TempLimits {
        degraded_after_s: 1e7,
        ..TempLimits::DEFAULT
    };
    let model = |m| TargetModel::<8> {
        offset: 0.0,
        baseline: Some(m),
        lstm: None,
        lstm_reads_base: false,
    };
    let mut b = BaselineModel::new(2).unwrap();
    b.push_term(&[1, 0], 1e-4).unwrap();
    let mut c =
        Compensator::with_limits(spec, model(b), TargetModel::constant(1.0), limits).unwrap();
    assert_eq!(c.step(0.0, 0.0, 20.0).status, Status::Ok);
    // Re-based here: degraded while the 20 ns settle runs, B from the new step (T = 21).
    let o = c.step(1e7, 0.0, 21.0);
    assert_eq!((o.status, o.bias_dps), (Status::Degraded, 21.0 * 1e-4));
    let o = c.step(1e7 + 1.0, 0.0, 22.0);
    assert_eq!((o.status, o.bias_dps), (Status::Ok, 22.0 * 1e-4));
}

/// A fault of any kind, as (time, gyro, temp) from the true clock `t` and temperature.
fn fault_sample(kind: u8, t: f64, base_temp: f64, wild: f64) -> (f64, f64, f64) {
    const BIG: f64 = 1.797e308;
    let g = 0.01;
    match kind {
        0 => (f64::NAN, g, base_temp),
        1 => (f64::INFINITY, g, base_temp),
        2 => (f64::NEG_INFINITY, g, base_temp),
        3 => (1e308, g, base_temp),
        4 => (-1e308, g, base_temp),
        5 => (t - 1.0, g, base_temp), // repeats the previous time stamp
        6 => (t - 30.0, g, base_temp), // backward step
        7 => (t - t.floor(), g, base_temp), // reset towards 0
        8 => (t + 1e9, g, base_temp), // forward jump
        9 => (t + 45.0, g, base_temp), // forward, within degraded_after_s
        10 => (t, g, f64::NAN),
        11 => (t, g, 85.0),
        12 => (t, g, -127.0),
        13 => (t, g, wild),
        14 => (t, f64::NAN, base_temp),
        15 => (t, BIG, base_temp),
        16 => (t, -BIG, base_temp),
        17 => (t, f64::INFINITY, f64::INFINITY),
        18 => (wild, wild, wild),
        19 => (t, g, 95.0), // in range, wrong, accepted if the rate limit allows
        _ => (t, g, base_temp),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Any sequence of faults (time: NaN, ±inf, ±1e308, repeats, backward steps, resets,
    /// forward jumps; temperature and gyro faults) followed by 150 s of clean 1 Hz samples
    /// ends ok, and is ok from clean sample 80 on (the documented bound for the published
    /// spec and default limits: max(2 + 20 s, (160 − 1) / 2 s) = 79.5 s); the rate is finite
    /// whenever the gyro sample is finite and the status is not invalid.
    #[test]
    fn any_faults_then_clean_samples_end_ok(
        faults in prop::collection::vec((0u8..24, any::<f64>()), 0..200),
        clean_start in prop_oneof![Just(None), Just(Some(0.0)), Just(Some(-5000.0)),
                                   Just(Some(1e9)), Just(Some(1e12)), (-1e6f64..1e6).prop_map(Some)],
        clean_temp in -40.0f64..80.0,
        slope in -0.05f64..0.05,
    ) {
        for mut c in [linear_compensator(), lstm_compensator()] {
            let mut t = 1000.0;
            let check = |o: &gyrotherm_core::Corrected, g: f64| {
                !(g.is_finite() && o.status != Status::Invalid) || o.rate_dps.is_finite()
            };
            for (i, (kind, wild)) in faults.iter().enumerate() {
                let base_temp = 20.0 + 0.01 * i as f64;
                let (ts, g, temp) = fault_sample(*kind, t, base_temp, *wild);
                let o = c.step(ts, g, temp);
                prop_assert!(check(&o, g), "fault {kind}: {o:?}");
                t += 1.0;
            }
            let t0 = clean_start.unwrap_or(t);
            for k in 0..150 {
                let tk = t0 + k as f64;
                let g = 0.01 + 1e-4 * k as f64;
                let o = c.step(tk, g, clean_temp + slope * k as f64);
                prop_assert!(check(&o, g), "clean {k}: {o:?}");
                if k >= 80 {
                    prop_assert_eq!(o.status, Status::Ok, "clean sample {} after {:?}", k, faults);
                }
            }
        }
    }
}

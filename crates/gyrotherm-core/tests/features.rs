//! Streaming feature pipeline: time-axis stepping, dT, moving average, lags, bad input.

use gyrotherm_core::error::{Channel, InputError};
use gyrotherm_core::features::{
    FeatureKind, FeaturePipeline, FeatureSpec, LagOutputs, SpecError, Step, MAX_FEATURES,
};
use proptest::prelude::*;

/// A smooth chamber-like temperature history, °C (any deterministic function will do).
fn temp_at(t: f64) -> f64 {
    20.0 + 30.0 * (2.0 * std::f64::consts::PI * t / 1800.0).sin() + 0.01 * t
}

fn run(spec: FeatureSpec, samples: impl IntoIterator<Item = (f64, f64)>) -> Vec<Step> {
    let mut p = FeaturePipeline::new(spec).unwrap();
    samples
        .into_iter()
        .filter_map(|(t, c)| p.push(t, c).unwrap())
        .collect()
}

fn rich_spec() -> FeatureSpec {
    FeatureSpec {
        smoothing_window_s: 10.0,
        ..FeatureSpec::THERMAL_STATE
    }
    .with_lags(&[300.0, 1000.0, 3000.0, 30.0], LagOutputs::Both)
    .unwrap()
}

#[test]
fn logs_at_1hz_and_100hz_give_identical_features() {
    // Same temperature function, sampled at 1 Hz (t = i) and at 100 Hz (t = i/100): the
    // 100 Hz samples at whole seconds carry the same values, so every step must be bit-equal.
    let spec = rich_spec();
    let n_s = 600;
    let slow = run(spec, (0..=n_s).map(|i| (i as f64, temp_at(i as f64))));
    let fast = run(
        spec,
        (0..=n_s * 100).map(|i| {
            let t = i as f64 / 100.0;
            (t, temp_at(t))
        }),
    );
    assert_eq!(slow.len(), n_s + 1);
    assert_eq!(fast.len(), slow.len(), "want one step per second");
    for (a, b) in slow.iter().zip(&fast) {
        assert_eq!(a.index, b.index);
        assert_eq!(a.time_s.to_bits(), b.time_s.to_bits());
        assert_eq!(
            a.features.as_slice(),
            b.features.as_slice(),
            "step {}",
            a.index
        );
    }
    assert_eq!(slow[0].features.len(), spec.n_features());
}

#[test]
fn time_stamps_with_round_off_step_on_the_same_boundaries() {
    // A logger that accumulates t += 0.01 lands just below many whole seconds (binary
    // round-off); the boundary tolerance must make it step on the same samples as t = i/100.
    let spec = FeatureSpec::PUBLISHED;
    let mut t = 0.0f64;
    let accumulated: Vec<f64> = (0..=30_000)
        .map(|_| {
            let now = t;
            t += 0.01;
            now
        })
        .collect();
    let below = (1..=300)
        .filter(|&k| accumulated[100 * k] < k as f64)
        .count();
    assert!(
        below > 0,
        "the accumulated time stamps should include some below whole seconds"
    );
    let a = run(spec, (0..=30_000).map(|i| (accumulated[i], 1.0 + i as f64)));
    let b = run(
        spec,
        (0..=30_000).map(|i| (i as f64 / 100.0, 1.0 + i as f64)),
    );
    assert_eq!(a.len(), 301);
    assert_eq!(a, b);
    // The value at step k is the sample at t = k s, i.e. sample 100·k (value 1 + 100k).
    for s in &a {
        assert_eq!(s.features.as_slice()[0], 1.0 + 100.0 * s.index as f64);
    }
}

#[test]
fn rate_matches_hand_computation() {
    // T_k = k²/4 (exact in binary) at 1 Hz, lag 20 s:
    // k = 30: (T30 - T10)/20 = (225 - 25)/20 = 10;
    // k = 5, before 20 s of history: oldest sample, (T5 - T0)/5 = 6.25/5 = 1.25; k = 0: 0.
    let steps = run(
        FeatureSpec::PUBLISHED,
        (0..=40).map(|k| (k as f64, (k * k) as f64 / 4.0)),
    );
    let rate = |k: usize| steps[k].features.as_slice()[1];
    assert_eq!(rate(0), 0.0);
    assert_eq!(rate(5), 1.25);
    assert_eq!(rate(20), (100.0 - 0.0) / 20.0);
    assert_eq!(rate(30), 10.0);
    assert_eq!(rate(40), (400.0 - 100.0) / 20.0);
}

#[test]
fn rate_lag_and_step_period_are_configurable() {
    // Step 0.5 s, lag 3 s = 6 steps, T = 2·t (°C): dT = 2 °C/s once 3 s of history exist.
    let spec = FeatureSpec {
        step_period_s: 0.5,
        rate_lag_s: 3.0,
        ..FeatureSpec::PUBLISHED
    };
    let steps = run(spec, (0..=200).map(|i| (i as f64 * 0.1, 0.2 * i as f64)));
    assert_eq!(steps.len(), 41, "20 s at 0.5 s per step, plus step 0");
    for s in &steps[7..] {
        let got = s.features.as_slice()[1];
        assert!((got - 2.0).abs() < 1e-12, "want 2 °C/s, got {got}");
    }
}

#[test]
fn lag_filter_matches_closed_form_step_response() {
    // Unit step at step 1 into a first-order lag τ = 300 s: y(t) = 1 - exp(-t/τ)
    // (closed form of τ·dy/dt = u - y, y(0) = 0). Tolerance: round-off of 3000 updates.
    const TOL: f64 = 1e-11;
    let tau = 300.0;
    let spec = FeatureSpec::PUBLISHED
        .with_lags(&[tau], LagOutputs::Both)
        .unwrap();
    assert_eq!(spec.kind(2), Some(FeatureKind::Lag(0)));
    assert_eq!(spec.kind(3), Some(FeatureKind::LagDiff(0)));
    let steps = run(
        spec,
        (0..=3000).map(|k| (k as f64, if k == 0 { 0.0 } else { 1.0 })),
    );
    for s in &steps {
        let t = s.index as f64;
        let want = 1.0 - (-t / tau).exp();
        let got = s.features.as_slice()[2];
        assert!(
            (got - want).abs() < TOL,
            "t={t}: want {want}, got {got}, error {}",
            got - want
        );
        let diff = s.features.as_slice()[3];
        let want_diff = if s.index == 0 { 0.0 } else { 1.0 - want };
        assert!(
            (diff - want_diff).abs() < TOL,
            "t={t}: T - y want {want_diff}, got {diff}"
        );
    }
}

#[test]
fn lag_across_a_gap_advances_by_the_elapsed_time() {
    // Step input, then samples missing from 10 s to 49 s: at t = 50 s the lag must equal the
    // closed form 1 - exp(-50/τ), as if the input had been held.
    let tau = 40.0;
    let spec = FeatureSpec::PUBLISHED
        .with_lags(&[tau], LagOutputs::Level)
        .unwrap();
    let times = (0..10).chain(50..60);
    let steps = run(
        spec,
        times.map(|k| (k as f64, if k == 0 { 0.0 } else { 1.0 })),
    );
    let s = steps
        .iter()
        .find(|s| s.index == 50)
        .expect("step 50 emitted");
    let want = 1.0 - (-50.0f64 / tau).exp();
    let got = s.features.as_slice()[2];
    assert!((got - want).abs() < 1e-12, "want {want}, got {got}");
    assert_eq!(
        steps.len(),
        20,
        "one step per sample, none invented for the gap"
    );
}

#[test]
fn moving_average_is_trailing_over_the_window() {
    // T = k at 1 Hz, window 5 s: mean of k-4..k = k - 2; at k = 2 only 0,1,2 exist: 1.
    let spec = FeatureSpec {
        smoothing_window_s: 5.0,
        ..FeatureSpec::PUBLISHED
    };
    assert_eq!(spec.kind(2), Some(FeatureKind::MovingAverage));
    let steps = run(spec, (0..=100).map(|k| (k as f64, k as f64)));
    assert_eq!(steps[2].features.as_slice()[2], 1.0);
    for s in &steps[4..] {
        assert_eq!(s.features.as_slice()[2], s.index as f64 - 2.0);
    }
}

#[test]
fn holds_between_steps() {
    let mut p = FeaturePipeline::new(FeatureSpec::PUBLISHED).unwrap();
    assert!(p.current().is_none());
    let first = p.push(0.0, 10.0).unwrap().expect("first sample is step 0");
    assert_eq!(first.index, 0);
    for i in 1..100 {
        assert_eq!(p.push(i as f64 * 0.01, 99.0).unwrap(), None);
        assert_eq!(p.current(), Some(&first.features));
    }
    let s = p.push(1.0, 11.0).unwrap().expect("step 1 at t = 1 s");
    assert_eq!(s.index, 1);
    assert_eq!(s.features.as_slice(), &[11.0, 1.0]);
}

#[test]
fn bad_input_is_refused_and_leaves_the_state_untouched() {
    let spec = rich_spec();
    let mut clean = FeaturePipeline::new(spec).unwrap();
    let mut dirty = FeaturePipeline::new(spec).unwrap();
    // The very first sample bad: nothing starts.
    assert_eq!(
        dirty.push(0.0, f64::NAN),
        Err(InputError::NonFinite(Channel::Temperature))
    );
    assert!(dirty.current().is_none());
    for k in 0..200 {
        let (t, c) = (k as f64 * 0.5, temp_at(k as f64));
        let want = clean.push(t, c).unwrap();
        if k % 7 == 3 {
            assert_eq!(
                dirty.push(t, f64::INFINITY),
                Err(InputError::NonFinite(Channel::Temperature))
            );
            assert_eq!(
                dirty.push(f64::NAN, c),
                Err(InputError::NonFinite(Channel::Time))
            );
            assert_eq!(
                dirty.push(f64::NEG_INFINITY, c),
                Err(InputError::NonFinite(Channel::Time))
            );
            if k > 0 {
                assert_eq!(dirty.push(t - 0.5, c), Err(InputError::TimeNotIncreasing));
            }
        }
        assert_eq!(dirty.push(t, c).unwrap(), want, "sample {k}");
        assert_eq!(dirty.push(t, c), Err(InputError::TimeNotIncreasing));
    }
}

#[test]
fn reset_starts_over() {
    let spec = rich_spec();
    let mut p = FeaturePipeline::new(spec).unwrap();
    let a: Vec<_> = (0..100)
        .map(|k| p.push(k as f64, temp_at(k as f64)).unwrap())
        .collect();
    p.reset();
    assert!(p.current().is_none());
    // Restart at a different time origin with the same values: same features.
    let b: Vec<_> = (0..100)
        .map(|k| {
            p.push(1000.0 + k as f64, temp_at(k as f64))
                .unwrap()
                .map(|s| s.features)
        })
        .collect();
    assert_eq!(
        a.into_iter()
            .map(|s| s.map(|s| s.features))
            .collect::<Vec<_>>(),
        b
    );
}

#[test]
fn bad_specs_are_refused_with_the_field() {
    let p = FeatureSpec::PUBLISHED;
    let cases = [
        (
            FeatureSpec {
                step_period_s: 0.0,
                ..p
            },
            SpecError::StepPeriod(0.0),
        ),
        (
            FeatureSpec {
                rate_lag_s: 20.5,
                ..p
            },
            SpecError::RateLag(20.5),
        ),
        (
            FeatureSpec {
                rate_lag_s: 64.0,
                ..p
            },
            SpecError::RateLag(64.0),
        ),
        (
            FeatureSpec {
                smoothing_window_s: 65.0,
                ..p
            },
            SpecError::SmoothingWindow(65.0),
        ),
        (FeatureSpec { n_lags: 5, ..p }, SpecError::TooManyLags(5)),
    ];
    for (spec, want) in cases {
        assert_eq!(spec.validate(), Err(want));
        assert!(FeaturePipeline::new(spec).is_err());
    }
    let e = p
        .with_lags(&[300.0, f64::NAN], LagOutputs::Level)
        .unwrap_err();
    assert!(matches!(e, SpecError::LagTau { index: 1, .. }), "{e:?}");
    assert!(p.with_lags(&[1.0; 5], LagOutputs::Level).is_err());
    assert!(e.to_string().contains("lag time constant #1"));
    // Largest spec fits MAX_FEATURES.
    assert!(rich_spec().n_features() <= MAX_FEATURES);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn never_panics(samples in proptest::collection::vec((any::<f64>(), any::<f64>()), 0..200),
                    period in any::<f64>(), lag in any::<f64>(), tau in any::<f64>()) {
        let spec = FeatureSpec { step_period_s: period, rate_lag_s: lag, ..FeatureSpec::PUBLISHED };
        let _ = FeaturePipeline::new(spec);
        let mut p = FeaturePipeline::new(rich_spec().with_lags(&[tau.abs().max(1e-300)], LagOutputs::Both)
            .unwrap_or(rich_spec())).unwrap();
        for (t, c) in samples {
            if let Ok(Some(s)) = p.push(t, c) {
                prop_assert_eq!(s.features.len(), p.spec().n_features());
            }
        }
    }
}

//! Ground features over whole logs, and the centred moving average of the bias target.

use gyrotherm::csvlog::TestLog;
use gyrotherm::features::{
    centred_moving_average, extract, extract_series, FeatureError, FeaturePipeline, FeatureSpec,
    LagOutputs,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn temp_at(t: f64) -> f64 {
    -10.0 + 40.0 * (2.0 * std::f64::consts::PI * t / 2400.0).cos()
}

fn log_at(rate_hz: usize, seconds: usize) -> TestLog {
    let n = seconds * rate_hz + 1;
    let time_s: Vec<f64> = (0..n).map(|i| i as f64 / rate_hz as f64).collect();
    TestLog {
        temp_c: time_s.iter().map(|&t| temp_at(t)).collect(),
        gyro_dps: vec![0.0; n],
        time_s,
        ..TestLog::default()
    }
}

#[test]
fn whole_log_features_equal_at_1hz_and_100hz() {
    let spec = FeatureSpec::THERMAL_STATE;
    let slow = extract(&log_at(1, 900), &spec).unwrap();
    let fast = extract(&log_at(100, 900), &spec).unwrap();
    assert_eq!(slow.n_rows(), 901);
    assert_eq!(
        slow.rows, fast.rows,
        "model inputs must not depend on the log rate"
    );
    assert_eq!(slow.step_time_s, fast.step_time_s);
    assert_eq!(
        fast.sample_index,
        (0..=900).map(|k| 100 * k).collect::<Vec<_>>()
    );
    assert_eq!(
        slow.names,
        ["T", "dT", "T-T_lag300", "T-T_lag1000", "T-T_lag3000"]
    );
    assert_eq!(slow.units[1], "°C/s");
    // Sample → held row: sample 150 of the 100 Hz log holds step 1.
    let rows = fast.row_of_sample(fast.sample_index.last().unwrap() + 1);
    assert_eq!(rows[0], 0);
    assert_eq!(rows[99], 0);
    assert_eq!(rows[150], 1);
    assert_eq!(rows[90_000], 900);
}

#[test]
fn ground_rows_are_the_core_pipeline_numbers() {
    // Training and flight must see the same numbers: run the core pipeline by hand.
    let spec = FeatureSpec::PUBLISHED
        .with_lags(&[300.0, 50.0], LagOutputs::Both)
        .unwrap();
    let log = log_at(10, 300);
    let table = extract(&log, &spec).unwrap();
    let mut p = FeaturePipeline::new(spec).unwrap();
    let mut r = 0;
    for i in 0..log.len() {
        if let Some(s) = p.push(log.time_s[i], log.temp_c[i]).unwrap() {
            assert_eq!(table.row(r), s.features.as_slice());
            assert_eq!(table.sample_index[r], i);
            r += 1;
        }
    }
    assert_eq!(r, table.n_rows());
    let (lo, hi) = table.range(0).unwrap();
    assert!(lo >= -50.0 && hi <= 30.0 && hi > lo);
}

#[test]
fn bad_samples_name_the_sample() {
    let mut log = log_at(1, 50);
    log.temp_c[17] = f64::NAN;
    let e = extract(&log, &FeatureSpec::PUBLISHED).unwrap_err();
    assert!(matches!(e, FeatureError::Sample { index: 17, .. }), "{e:?}");
    assert!(e.to_string().contains("sample 17"), "{e}");
    let mut log = log_at(1, 50);
    log.time_s[30] = log.time_s[29];
    let e = extract(&log, &FeatureSpec::PUBLISHED).unwrap_err();
    assert!(e.to_string().contains("time did not increase"), "{e}");
    let e = extract_series(&[0.0, 1.0], &[1.0], &FeatureSpec::PUBLISHED).unwrap_err();
    assert!(matches!(e, FeatureError::Length { time: 2, temp: 1 }));
    let bad = FeatureSpec {
        rate_lag_s: 0.0,
        ..FeatureSpec::PUBLISHED
    };
    let e = extract(&log_at(1, 5), &bad).unwrap_err();
    assert!(e.to_string().contains("rate lag"), "{e}");
}

/// Brute force: mean of x_j with |t_j - t_i| ≤ min(W/2, t_i - t_0, t_end - t_i).
fn brute(time_s: &[f64], x: &[f64], w: f64) -> Vec<f64> {
    let (t0, t1) = (time_s[0], *time_s.last().unwrap());
    time_s
        .iter()
        .map(|&t| {
            let h = (w / 2.0).min(t - t0).min(t1 - t);
            let sel: Vec<f64> = time_s
                .iter()
                .zip(x)
                .filter(|(&tj, _)| (tj - t).abs() <= h + 1e-9 * w)
                .map(|(_, &v)| v)
                .collect();
            sel.iter().sum::<f64>() / sel.len() as f64
        })
        .collect()
}

#[test]
fn centred_average_matches_brute_force_on_irregular_times() {
    // Independent O(N·W) computation; tolerance: prefix-sum round-off on values of order 1.
    const TOL: f64 = 1e-12;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut t = 0.0;
    let time_s: Vec<f64> = (0..3000)
        .map(|_| {
            t += rng.gen_range(0.2..1.8);
            t
        })
        .collect();
    let x: Vec<f64> = (0..3000).map(|_| rng.gen_range(-1.0..1.0) + 5.0).collect();
    let got = centred_moving_average(&time_s, &x, 100.0).unwrap();
    let want = brute(&time_s, &x, 100.0);
    for (i, (w, g)) in want.iter().zip(&got.values).enumerate() {
        let err = (g - w).abs();
        assert!(err < TOL, "sample {i}: want {w}, got {g}, error {err}");
    }
}

#[test]
fn centred_average_passes_a_linear_trend_and_marks_edges() {
    // A centred (symmetric) window averages a line to its centre value, edges included.
    let time_s: Vec<f64> = (0..1000).map(|i| i as f64).collect();
    let x: Vec<f64> = time_s.iter().map(|t| 0.25 + 1e-3 * t).collect();
    let s = centred_moving_average(&time_s, &x, 100.0).unwrap();
    for (i, (g, w)) in s.values.iter().zip(&x).enumerate() {
        assert!((g - w).abs() < 1e-12, "sample {i}: want {w}, got {g}");
    }
    // Full window (t ± 50 s inside 0..999 s) for samples 50..=949.
    let full: Vec<usize> = (0..1000).filter(|&i| s.full_window[i]).collect();
    assert_eq!(full.first(), Some(&50));
    assert_eq!(full.last(), Some(&949));
    assert_eq!(full.len(), 900);
    // At 1 Hz a 100 s window averages 101 samples: on a ±1 square wave of period 2 s the
    // interior mean is ±1/101.
    let sq: Vec<f64> = (0..1000)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let s = centred_moving_average(&time_s, &sq, 100.0).unwrap();
    assert!(
        (s.values[500] - 1.0 / 101.0).abs() < 1e-12,
        "got {}",
        s.values[500]
    );
}

#[test]
fn centred_average_refuses_bad_input() {
    assert!(centred_moving_average(&[0.0, 1.0], &[1.0, 2.0], 0.0).is_err());
    assert!(centred_moving_average(&[0.0, 1.0], &[1.0], 10.0).is_err());
    let e = centred_moving_average(&[0.0, 1.0, 1.0], &[1.0, 2.0, 3.0], 10.0).unwrap_err();
    assert!(e.to_string().contains("sample 2"), "{e}");
    let e = centred_moving_average(&[0.0, 1.0], &[1.0, f64::NAN], 10.0).unwrap_err();
    assert!(e.to_string().contains("sample 1"), "{e}");
    assert!(centred_moving_average(&[], &[], 10.0)
        .unwrap()
        .values
        .is_empty());
}

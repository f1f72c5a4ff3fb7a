//! Allan deviations of finite samples of any magnitude: finite results or a refusal naming
//! the sample, never ∞ or a silent 0. The reference is the homogeneity of every deviation,
//! σ(c·y) = |c|·σ(y), applied to the NIST SP 1065 NBS data set (p. 107), and exact for c a
//! power of two.

use gyrotherm::allan::{deviation, AllanError, DevKind, NoiseModel, StreamingOadev, TauSet};

mod common;
use common::nbs_data;

const KINDS: [DevKind; 5] = [
    DevKind::Adev,
    DevKind::Oadev,
    DevKind::Mdev,
    DevKind::Hdev,
    DevKind::Ohdev,
];

#[test]
fn huge_and_tiny_samples_scale_exactly() {
    let y = nbs_data();
    for kind in KINDS {
        let base = deviation(&y, 1.0, kind, &TauSet::Octave, NoiseModel::Alpha(0)).unwrap();
        for k in [-1000, -600, -300, 300, 600, 1000] {
            let c = 2f64.powi(k);
            let scaled: Vec<f64> = y.iter().map(|v| v * c).collect();
            let pts = deviation(&scaled, 1.0, kind, &TauSet::Octave, NoiseModel::Alpha(0))
                .unwrap_or_else(|e| panic!("{kind:?} 2^{k}: {e}"));
            assert_eq!(pts.len(), base.len());
            for (p, b) in pts.iter().zip(&base) {
                let want = b.dev * c;
                assert!(
                    p.dev.is_finite() && (p.dev - want).abs() <= 1e-12 * want,
                    "{kind:?} 2^{k} m={}: {} want {want}",
                    p.m,
                    p.dev
                );
                assert!((p.hi - b.hi * c).abs() <= 1e-12 * b.hi * c);
            }
        }
    }
    // And the scaled NBS set still gives NIST's OADEV at τ = 1 (2.922319e-01).
    let c = 2f64.powi(1000);
    let scaled: Vec<f64> = y.iter().map(|v| v * c).collect();
    let p = deviation(
        &scaled,
        1.0,
        DevKind::Oadev,
        &TauSet::Seconds(vec![1.0]),
        NoiseModel::Alpha(0),
    )
    .unwrap();
    assert!((p[0].dev / c - 2.922319e-01).abs() / 2.922319e-01 < 1e-6);
}

#[test]
fn samples_near_the_largest_f64_are_refused_naming_the_largest() {
    let mut y: Vec<f64> = (0..200)
        .map(|i| if i % 2 == 0 { 1.5e308 } else { -1.5e308 })
        .collect();
    y[77] = -1.7e308;
    for kind in KINDS {
        match deviation(&y, 1.0, kind, &TauSet::Octave, NoiseModel::Alpha(0)) {
            Err(AllanError::TooLarge { index, value }) => {
                assert_eq!((index, value), (77, -1.7e308), "{kind:?}");
            }
            Ok(pts) => {
                for p in pts {
                    assert!(p.dev.is_finite() && p.hi.is_finite(), "{kind:?} {p:?}");
                }
            }
            Err(e) => panic!("{kind:?}: {e}"),
        }
    }
    let err = deviation(
        &y,
        1.0,
        DevKind::Adev,
        &TauSet::Octave,
        NoiseModel::Alpha(0),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("sample 77 is -1.7e308"), "{err}");
}

#[test]
fn streaming_oadev_refuses_an_overflowing_sample() {
    let mut s = StreamingOadev::octave(8, 1.0).unwrap();
    s.push(&[0.0, 1.0, 2.0]).unwrap();
    let err = s.push(&[1e300, -1e300, 1e300]).unwrap_err();
    assert!(matches!(err, AllanError::TooLarge { .. }), "{err}");
}

#[test]
fn streaming_oadev_scales_exactly_like_the_batch_one() {
    let y = nbs_data();
    for k in [-1000, -500, 0, 500, 1000] {
        let c = 2f64.powi(k);
        let scaled: Vec<f64> = y.iter().map(|v| v * c).collect();
        let batch = deviation(
            &scaled,
            1.0,
            DevKind::Oadev,
            &TauSet::Octave,
            NoiseModel::Alpha(0),
        )
        .unwrap();
        let mut s = StreamingOadev::octave(256, 1.0).unwrap();
        s.push(&scaled).unwrap();
        for (a, b) in s.points(Some(0)).iter().zip(&batch) {
            assert!(
                a.dev > 0.0 && (a.dev - b.dev).abs() <= 1e-12 * b.dev,
                "2^{k} m={}: streaming {} batch {}",
                a.m,
                a.dev,
                b.dev
            );
        }
    }
}

/// Found by the `allan` fuzz target: a curve with a τ beyond f64 (from a huge τ0) made the
/// noise-term read-out loop for ever on the NaN local slope. Now τ0·N must be finite, and
/// the read-out ignores such points.
#[test]
fn huge_sample_period_is_refused_and_noise_terms_terminate() {
    use gyrotherm::allan::{noise_terms, AllanPoint};
    let y = nbs_data();
    let e = deviation(
        &y,
        1e306,
        DevKind::Oadev,
        &TauSet::Octave,
        NoiseModel::Alpha(0),
    );
    assert!(matches!(e, Err(AllanError::BadSamplePeriod(_))), "{e:?}");
    let p = |tau_s: f64, dev: f64| AllanPoint {
        m: 1,
        tau_s,
        dev,
        n: 10,
        alpha: 0,
        edf: 5.0,
        lo: dev,
        hi: dev,
    };
    let pts = vec![
        p(1.0, 1.0),
        p(f64::INFINITY, 0.5),
        p(4.0, 0.5),
        p(f64::MAX, 0.4),
    ];
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(noise_terms(&pts, 3600.0)).unwrap());
    let terms = rx
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("noise_terms did not return");
    assert!(terms.arw_deg_rt_h.is_some_and(|t| t.value.is_finite()));
}

/// Found by the `allan` fuzz target: subnormal samples (below 2.2e-308) were divided by a
/// scale of 0 and reported as "sample 0 is NaN or infinite".
#[test]
fn subnormal_samples_give_a_finite_deviation() {
    let tiny = f64::MIN_POSITIVE / 1024.0;
    let y: Vec<f64> = nbs_data()
        .iter()
        .map(|v| (v * 1000.0).round() * tiny)
        .collect();
    for kind in KINDS {
        let pts = deviation(&y, 1.0, kind, &TauSet::Octave, NoiseModel::Alpha(0))
            .unwrap_or_else(|e| panic!("{kind:?}: {e}"));
        assert!(
            pts.iter().all(|p| p.dev.is_finite() && p.dev > 0.0),
            "{kind:?}"
        );
    }
}

/// Found by the `allan` fuzz target: a curve near f64's top read off at τ = 1 s along its
/// −½ slope gave an angle random walk of ∞. Such a term is not reported.
#[test]
fn noise_terms_beyond_f64_are_not_reported() {
    use gyrotherm::allan::noise_terms;
    let y: Vec<f64> = nbs_data().iter().map(|v| (v - 0.5) * 1e305).collect();
    let pts = deviation(
        &y,
        5.26,
        DevKind::Oadev,
        &TauSet::Octave,
        NoiseModel::Alpha(0),
    )
    .unwrap();
    let t = noise_terms(&pts, 3600.0);
    for term in [
        t.arw_deg_rt_h,
        t.bias_instability_dph,
        t.rrw_deg_h_rt_h,
        t.quantization_arcsec,
        t.rate_ramp_deg_h2,
    ]
    .into_iter()
    .flatten()
    {
        assert!(term.value.is_finite(), "{term:?}");
    }
}

/// `deviation_owned` (the path `gyrotherm allan` takes when no second curve needs the
/// samples) scales as `deviation` does: the NBS set times 2^±1000 gives the NBS deviations
/// times 2^±1000, with identified α (not a fixed one) in −2..=2, for every kind.
#[test]
fn owned_samples_of_any_magnitude_give_scaled_deviations_and_alpha_in_range() {
    use gyrotherm::allan::deviation_owned;
    let y = nbs_data();
    for kind in KINDS {
        let base = deviation(&y, 1.0, kind, &TauSet::Octave, NoiseModel::Identify).unwrap();
        for k in [-1000, -300, 0, 300, 1000] {
            let c = 2f64.powi(k);
            let scaled: Vec<f64> = y.iter().map(|v| v * c).collect();
            let pts = deviation_owned(scaled, 1.0, kind, &TauSet::Octave, NoiseModel::Identify)
                .unwrap_or_else(|e| panic!("{kind:?} 2^{k}: {e}"));
            assert_eq!(pts.len(), base.len());
            for (p, b) in pts.iter().zip(&base) {
                let want = b.dev * c;
                assert!(
                    p.dev.is_finite() && (p.dev - want).abs() <= 1e-12 * want,
                    "{kind:?} 2^{k} m={}: {} want {want}",
                    p.m,
                    p.dev
                );
                assert_eq!(p.alpha, b.alpha, "{kind:?} 2^{k} m={}", p.m);
                assert!((-2..=2).contains(&p.alpha), "{kind:?} α = {}", p.alpha);
            }
        }
    }
}

/// Finite samples give finite deviations or a refusal, and α stays in the range the lag-1
/// identification defines (−2..=2, Riley & Greenhall 2004), for samples of every magnitude
/// and shape: alternating (lag-1 autocorrelation near −1, which unclamped gives α > 2),
/// constant, a ramp, and pseudo-random values spread over many decades.
#[test]
fn finite_samples_give_finite_results_or_a_refusal_and_alpha_in_range() {
    use gyrotherm::allan::deviation_owned;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut cases: Vec<Vec<f64>> = Vec::new();
    for mag in [1e-300, 1e-3, 1.0, 1e3, 1e150, 1e300, 1.7e308] {
        cases.push(
            (0..600)
                .map(|i| if i % 2 == 0 { mag } else { -mag })
                .collect(),
        );
        cases.push(vec![mag; 600]);
        cases.push((0..600).map(|i| mag * (i as f64 / 600.0)).collect());
        cases.push(
            (0..600)
                .map(|_| {
                    let u = (next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                    u * mag
                })
                .collect(),
        );
    }
    for _ in 0..20 {
        // Any finite bit pattern.
        cases.push(
            (0..300)
                .map(|_| loop {
                    let v = f64::from_bits(next());
                    if v.is_finite() {
                        break v;
                    }
                })
                .collect(),
        );
    }
    for (c, y) in cases.iter().enumerate() {
        for kind in KINDS {
            for owned in [false, true] {
                let r = if owned {
                    deviation_owned(y.clone(), 1.0, kind, &TauSet::Octave, NoiseModel::Identify)
                } else {
                    deviation(y, 1.0, kind, &TauSet::Octave, NoiseModel::Identify)
                };
                match r {
                    Ok(pts) => {
                        for p in pts {
                            assert!(
                                p.dev.is_finite() && p.dev >= 0.0,
                                "case {c} {kind:?} owned={owned} m={}: dev {}",
                                p.m,
                                p.dev
                            );
                            assert!(
                                (-2..=2).contains(&p.alpha),
                                "case {c} {kind:?} owned={owned} m={}: α {}",
                                p.m,
                                p.alpha
                            );
                        }
                    }
                    Err(AllanError::TooLarge { .. }) | Err(AllanError::TooShort { .. }) => {}
                    Err(e) => panic!("case {c} {kind:?} owned={owned}: unexpected {e}"),
                }
            }
        }
    }
}

//! Gyro figures (IEEE Std 952 / GJB 2426A definitions, docs/method.md §5) on data whose answer is
//! known from a reference (NBS set) or by construction.

use gyrotherm::metrics::{
    bias_dph, bias_repeatability_dph, bias_stability_dph, repeatability, scale_factor,
    ScaleFactorOptions,
};

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

#[test]
fn bias_is_mean_in_dph() {
    // 0.001 °/s = 3.6 °/h by definition of the units.
    let r = vec![0.0005, 0.0015, 0.001, 0.001];
    assert!((bias_dph(&r).unwrap() - 3.6).abs() < 1e-12);
    assert!(bias_dph(&[]).is_err());
    let e = bias_dph(&[0.0, f64::NAN]).unwrap_err();
    assert!(e.to_string().contains("sample 1"), "{e}");
}

/// NIST SP 1065 (docs/method.md §6): std (n−1) of τ-means of the NBS set is 9.296352e-02 at m = 10.
#[test]
fn bias_stability_matches_nbs_tau_means() {
    let mut n: u64 = 1_234_567_890;
    let y: Vec<f64> = (0..1000)
        .map(|_| {
            let v = n as f64 / 2_147_483_647.0;
            n = 16_807 * n % 2_147_483_647;
            v
        })
        .collect();
    // Treat y as °/s sampled every 0.5 s: τ = 5 s is m = 10; result ×3600 in °/h.
    let bs = bias_stability_dph(&y, 0.5, 5.0).unwrap();
    let want = 9.296352e-02 * 3600.0;
    assert!(
        rel(bs.bias_stability_dph, want) < 1e-6,
        "want {want} got {}",
        bs.bias_stability_dph
    );
    assert_eq!((bs.samples_per_mean, bs.means), (10, 100));
    let e = bias_stability_dph(&y, 0.5, 5.2).unwrap_err();
    assert!(e.to_string().contains("integer multiple"), "{e}");
    let e = bias_stability_dph(&y, 1.0, 600.0).unwrap_err();
    // Said in seconds (τ and the log's length), not in samples per mean.
    assert!(
        e.to_string()
            .contains("τ = 600 s is longer than half the log"),
        "{e}"
    );
}

#[test]
fn repeatability_is_sample_std() {
    // std(n−1) of 1,2,3,4 = √(5/3) by definition.
    assert!((repeatability(&[1.0, 2.0, 3.0, 4.0]).unwrap() - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
    assert_eq!(repeatability(&[1.0]), None);
    let a = [0.001; 10];
    let b = [0.002; 10];
    // Biases 3.6 and 7.2 °/h: std = 3.6/√2.
    let r = bias_repeatability_dph(&[&a, &b]).unwrap().unwrap();
    assert!((r - 3.6 / 2f64.sqrt()).abs() < 1e-12, "{r}");
}

/// A rate-table run: segments of `seg_s` seconds at 1 Hz with a settle transient of `spike`
/// °/s for the first 5 s of each segment (must be excluded by the 10 s settle time).
fn table_run(
    rates: &[f64],
    seg_s: usize,
    output: impl Fn(f64, f64, usize) -> f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mut t, mut g, mut tab) = (Vec::new(), Vec::new(), Vec::new());
    for (j, &rate) in rates.iter().enumerate() {
        for i in 0..seg_s {
            let time = (j * seg_s + i) as f64;
            let spike = if i < 5 { 3.0 } else { 0.0 };
            t.push(time);
            tab.push(rate);
            g.push(output(time, rate, j) + spike);
        }
    }
    (t, g, tab)
}

#[test]
fn scale_factor_asymmetry_and_nonlinearity() {
    // F = B + K±·Ω: K+ and K− exact by construction.
    let (kp, kn, b) = (1.0002, 0.9998, 0.01);
    let rates = [0.0, 20.0, 0.0, -20.0, 0.0, 50.0, 0.0, -50.0, 0.0];
    let (t, g, tab) = table_run(&rates, 100, |_, w, _| {
        b + if w > 0.0 { kp * w } else { kn * w }
    });
    let r = scale_factor(&t, &g, &tab, &ScaleFactorOptions::default()).unwrap();
    assert_eq!(r.segments.len(), 9);
    assert_eq!(r.rate_points.len(), 5);
    assert!(rel(r.scale_positive.unwrap(), kp) < 1e-12);
    assert!(rel(r.scale_negative.unwrap(), kn) < 1e-12);
    let want_asym = (kp - kn) / ((kp + kn) / 2.0) * 1e6; // 400 ppm
    assert!(
        rel(r.asymmetry_ppm.unwrap(), want_asym) < 1e-9,
        "asym {:?}",
        r.asymmetry_ppm
    );
    // Least squares on the 5 rate points, solved here by the normal equations directly.
    let pts: Vec<(f64, f64)> = [-50.0, -20.0, 0.0, 20.0, 50.0]
        .iter()
        .map(|&w: &f64| (w, b + if w > 0.0 { kp * w } else { kn * w }))
        .collect();
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (sxx, sxy) = pts
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0 * p.0, a.1 + p.0 * p.1));
    let k = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    let f0 = (sy - k * sx) / n;
    assert!(
        rel(r.scale_factor, k) < 1e-12,
        "K want {k} got {}",
        r.scale_factor
    );
    let fmax = pts.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    let nl = pts
        .iter()
        .map(|p| (p.1 - k * p.0 - f0).abs())
        .fold(0.0, f64::max)
        / fmax
        * 1e6;
    assert!(
        rel(r.nonlinearity_ppm, nl) < 1e-6,
        "NL want {nl} got {}",
        r.nonlinearity_ppm
    );
}

#[test]
fn scale_factor_over_time_with_drifting_bias() {
    // K of rate segment j: K0·(1 + 100e-6·j); bias drifting linearly in time (the mean of the
    // stop segments either side equals the bias during the rate segment).
    let k0 = 1.001;
    let rates = [0.0, 20.0, 0.0, -20.0, 0.0, 20.0, 0.0, -20.0, 0.0];
    let (t, g, tab) = table_run(&rates, 100, |time, w, j| {
        0.02 + 1e-5 * time + w * k0 * (1.0 + 100e-6 * (j / 2) as f64)
    });
    let r = scale_factor(&t, &g, &tab, &ScaleFactorOptions::default()).unwrap();
    assert_eq!(r.scale_over_time.len(), 4);
    for (i, s) in r.scale_over_time.iter().enumerate() {
        let want = k0 * (1.0 + 100e-6 * i as f64);
        assert!(
            rel(s.scale, want) < 1e-10,
            "segment {i}: want K {want} got {}",
            s.scale
        );
    }
    // Largest deviation: segment 3 vs segment 0 = 300 ppm.
    assert!(
        (r.sf_thermal_error_ppm - 300.0).abs() < 1e-4,
        "{}",
        r.sf_thermal_error_ppm
    );
    // Without the settle time the 3 °/s spikes would bias every segment mean by 0.15 °/s.
    let no_settle = ScaleFactorOptions {
        settle_s: 0.0,
        ..Default::default()
    };
    let r0 = scale_factor(&t, &g, &tab, &no_settle).unwrap();
    assert!((r0.segments[0].mean_output_dps - r.segments[0].mean_output_dps).abs() > 0.1);
}

#[test]
fn scale_factor_bad_input() {
    let e = scale_factor(
        &[0.0, 1.0],
        &[0.0, 1.0],
        &[0.0, 0.0],
        &ScaleFactorOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("need two distinct rates"), "{e}");
    let e = scale_factor(&[0.0], &[0.0, 1.0], &[0.0], &ScaleFactorOptions::default()).unwrap_err();
    assert!(e.to_string().contains("differ in length"), "{e}");
}

//! Calibration of the default simulated unit against the published raw figures
//! (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004) and the measurements recorded
//! in issue 5 ("What is known already"). Ranges come from issue 2 (raw figures) and issue 5
//! (noise floor, linear-fit and thermal-state held-out residuals), not from this code's output.

use gyrotherm::sim::{simulate_series, SimConfig, SimSeries};
use nalgebra::{DMatrix, DVector};

/// Bias stability, °/h: sample standard deviation (n-1) of consecutive non-overlapping
/// `tau_s` means of `x_dps` (IEEE Std 952 / GJB 2426A definition, METHOD.md).
fn bias_stability_dph(x_dps: &[f64], rate_hz: f64, tau_s: f64) -> f64 {
    let m = (tau_s * rate_hz).round() as usize;
    let means: Vec<f64> = x_dps
        .chunks_exact(m)
        .map(|c| c.iter().sum::<f64>() / m as f64)
        .collect();
    let mu = means.iter().sum::<f64>() / means.len() as f64;
    let var = means.iter().map(|v| (v - mu).powi(2)).sum::<f64>() / (means.len() - 1) as f64;
    var.sqrt() * 3600.0
}

/// dT = (T(t) - T(t-20 s)) / 20 s on the logged temperature (issue 5; paper: 20 samples at
/// 1 Hz), 0 for the first 20 s.
fn dtemp(temp_c: &[f64], rate_hz: f64) -> Vec<f64> {
    let k = (20.0 * rate_hz).round() as usize;
    (0..temp_c.len())
        .map(|i| {
            if i >= k {
                (temp_c[i] - temp_c[i - k]) / 20.0
            } else {
                0.0
            }
        })
        .collect()
}

/// First-order lag of `x` with time constant `tau_s`, started at x[0].
fn lag(x: &[f64], rate_hz: f64, tau_s: f64) -> Vec<f64> {
    let a = 1.0 - (-1.0 / (rate_hz * tau_s)).exp();
    let mut y = x[0];
    x.iter()
        .map(|&v| {
            y += (v - y) * a;
            y
        })
        .collect()
}

/// Feature sets of issue 5: "linear" = [1, T, dT]; "thermal" = [1, T, dT, L300(T),
/// L1000(T), L3000(T)] (differences from T are linear combinations of these).
fn features(s: &SimSeries, thermal: bool) -> Vec<Vec<f64>> {
    let t = &s.temp_c;
    let mut f = vec![vec![1.0; t.len()], t.clone(), dtemp(t, 1.0)];
    if thermal {
        for tau in [300.0, 1000.0, 3000.0] {
            f.push(lag(t, 1.0, tau));
        }
    }
    f
}

/// Least-squares fit of gyro output on the features of `train`, applied to `test`; returns
/// the bias stability of the held-out residual, °/h.
fn held_out_residual_dph(train: &SimSeries, test: &SimSeries, thermal: bool) -> f64 {
    let ftr = features(train, thermal);
    let n = train.gyro_dps.len();
    let a = DMatrix::from_fn(n, ftr.len(), |i, j| ftr[j][i]);
    let y = DVector::from_column_slice(&train.gyro_dps);
    let coef = a.svd(true, true).solve(&y, 1e-12).expect("svd solve");
    let fte = features(test, thermal);
    let resid: Vec<f64> = (0..test.gyro_dps.len())
        .map(|i| test.gyro_dps[i] - (0..fte.len()).map(|j| coef[j] * fte[j][i]).sum::<f64>())
        .collect();
    bias_stability_dph(&resid, 1.0, 100.0)
}

fn run(profile: &str, seed: u64) -> SimSeries {
    let mut cfg = SimConfig::builtin(profile).unwrap();
    if let Ok(j) = std::env::var("SIM_UNIT_JSON") {
        cfg.unit = gyrotherm::sim::FogUnit::from_json_str(&j, "env").unwrap();
    }
    cfg.seed = seed;
    simulate_series(&cfg).unwrap()
}

#[test]
fn calibration_probe() {
    for (p, seed) in [("seed-shock", 7), ("slow-ramp", 8), ("fast-cycle", 9), ("room-steady", 10)] {
        let s = run(p, seed);
        let thermal: Vec<f64> = s.true_bias_dps.clone();
        println!(
            "{p}: raw {:.4} noise {:.4} truebias {:.4}",
            bias_stability_dph(&s.gyro_dps, 1.0, 100.0),
            bias_stability_dph(&s.noise_dps, 1.0, 100.0),
            bias_stability_dph(&thermal, 1.0, 100.0),
        );
    }
    let a = run("seed-shock", 7);
    for (p, seed) in [("slow-ramp", 8), ("fast-cycle", 9), ("seed-shock", 11)] {
        let b = run(p, seed);
        println!(
            "train seed-shock test {p}: linear {:.4} thermal {:.4}; self linear {:.4} thermal {:.4}",
            held_out_residual_dph(&a, &b, false),
            held_out_residual_dph(&a, &b, true),
            held_out_residual_dph(&b, &b, false),
            held_out_residual_dph(&b, &b, true),
        );
    }
}

#[test]
fn noise_probe() {
    use gyrotherm::sim::noise::flicker_term_sigma;
    println!("flicker sigma per term for B=0.006: {}", flicker_term_sigma(0.006));
    for which in 0..4 {
        let mut cfg = SimConfig::builtin("room-steady").unwrap();
        cfg.profile.segments[0].duration_s = 30000.0;
        let u = &mut cfg.unit;
        if which != 0 { u.arw_deg_rt_h = 0.0; }
        if which != 1 { u.bias_instability_dph = 0.0; }
        if which != 2 { u.rrw_dph_rt_h = 0.0; }
        if which != 3 { u.pulse_arcsec = 0.0; }
        let s = simulate_series(&cfg).unwrap();
        println!("component {which}: {:.5}", bias_stability_dph(&s.noise_dps, 1.0, 100.0));
    }
}

#[test]
fn term_probe() {
    use gyrotherm::sim::FogUnit;
    let terms: Vec<(&str, Box<dyn Fn(&mut FogUnit)>)> = vec![
        ("c1", Box::new(|u| u.bias_c1_dph_per_c = 0.0032)),
        ("c2", Box::new(|u| u.bias_c2_dph_per_c2 = 1e-5)),
        ("shupe", Box::new(|u| u.shupe_dph_per_c_per_s = 1.0)),
        ("shupe-notc", Box::new(|u| { u.shupe_dph_per_c_per_s = 1.0; u.shupe_tc_per_c = 0.0; })),
        ("stress", Box::new(|u| u.stress_dph_per_c = 0.0015)),
    ];
    for (name, f) in terms {
        let mut unit = FogUnit { bias_c1_dph_per_c: 0.0, bias_c2_dph_per_c2: 0.0, shupe_dph_per_c_per_s: 0.0, stress_dph_per_c: 0.0, ..FogUnit::default() };
        f(&mut unit);
        let mk = |p: &str| {
            let mut c = SimConfig::builtin(p).unwrap();
            c.unit = unit.clone();
            let mut s = simulate_series(&c).unwrap();
            s.gyro_dps = s.true_bias_dps.clone();
            s
        };
        let a = mk("seed-shock");
        let mut out = format!("{name}: raw {:.4}", bias_stability_dph(&a.gyro_dps, 1.0, 100.0));
        for p in ["seed-shock", "slow-ramp", "fast-cycle"] {
            let b = mk(p);
            out += &format!(" | {p} lin {:.4} th {:.4}", held_out_residual_dph(&a, &b, false), held_out_residual_dph(&a, &b, true));
        }
        println!("{out}");
    }
}

//! Calibration of the default simulated unit against the published raw figures
//! (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004) and the measurements recorded
//! for the project's held-out work. Ranges come from the paper's raw figures and those
//! measurements (noise floor, linear-fit and thermal-state held-out residuals), not from this code's output.

use gyrotherm::sim::{simulate_series, SimConfig, SimSeries};
use nalgebra::{DMatrix, DVector};

/// Bias stability, °/h: sample standard deviation (n-1) of consecutive non-overlapping
/// `tau_s` means of `x_dps` (IEEE Std 952 / GJB 2426A definition, docs/method.md §5).
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

/// dT = (T(t) - T(t-20 s)) / 20 s on the logged temperature (paper: 20 samples at
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

/// Feature sets of the held-out work: "linear" = [1, T, dT]; "thermal" = [1, T, dT, L300(T),
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

/// Seeds for the checks: several, because 100 s-mean statistics of flicker noise over one
/// 30,000 s run vary by about ±20 % from seed to seed.
const SEEDS: [u64; 3] = [7, 8, 9];

/// Issue 2: raw static bias stability on `seed-shock` at 1 Hz between 0.08 and 0.25 °/h
/// (paper raw figure 0.13861 °/h).
#[test]
fn default_unit_raw_bias_stability_on_seed_shock() {
    for seed in SEEDS {
        let s = run("seed-shock", seed);
        let got = bias_stability_dph(&s.gyro_dps, 1.0, 100.0);
        assert!(
            (0.08..=0.25).contains(&got),
            "seed {seed}: raw bias stability want 0.08..0.25 °/h (issue 2), got {got:.5}"
        );
    }
}

/// Issue 2: with `--table-rate 20` the +20 °/s output errs by 0.004 to 0.012 °/s at the
/// temperature extremes (paper: ~20.009 °/s). Mean output over the whole +20 °/s segment
/// whose mean logged temperature is highest, and the one where it is lowest.
#[test]
fn default_unit_plus_20_dps_error_at_extremes() {
    let mut cfg = SimConfig::builtin("seed-shock").unwrap();
    cfg.table_rate_dps = Some(20.0);
    cfg.seed = 7;
    let s = simulate_series(&cfg).unwrap();
    let table = s.table_dps.as_ref().unwrap();
    // (mean temperature, mean output) of every +20 °/s segment.
    let mut segs: Vec<(f64, f64)> = Vec::new();
    let mut i = 0;
    while i < table.len() {
        let j = (i..table.len())
            .find(|&j| table[j] != table[i])
            .unwrap_or(table.len());
        if table[i] == 20.0 {
            let n = (j - i) as f64;
            segs.push((
                s.temp_c[i..j].iter().sum::<f64>() / n,
                s.gyro_dps[i..j].iter().sum::<f64>() / n,
            ));
        }
        i = j;
    }
    let cold = segs.iter().min_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
    let hot = segs.iter().max_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
    for (name, (temp, out)) in [("cold", cold), ("hot", hot)] {
        let err = out - 20.0;
        assert!(
            (0.004..=0.012).contains(&err),
            "{name} extreme ({temp:.1} °C): +20 °/s output error want 0.004..0.012 °/s \
             (issue 2), got {err:.5} (output {out:.5})"
        );
    }
}

/// Issue 5: bias stability of the noise-only part about 0.007-0.010 °/h. Tolerance widened
/// to 0.006-0.012 for the seed-to-seed spread of flicker noise over one run.
#[test]
fn default_unit_noise_floor() {
    for (p, seed) in [("seed-shock", 7), ("slow-ramp", 8), ("fast-cycle", 9)] {
        let s = run(p, seed);
        let got = bias_stability_dph(&s.noise_dps, 1.0, 100.0);
        assert!(
            (0.006..=0.012).contains(&got),
            "{p} seed {seed}: noise floor want 0.007..0.010 (issue 5, ±seed spread), got {got:.5}"
        );
    }
}

/// Issue 5: a linear fit on (T, dT) trained on one run leaves roughly 0.015-0.035 °/h on a
/// held-out run (history matters beyond T and dT), while a linear fit on thermal-state inputs
/// (lags of 300/1000/3000 s) gets to about 1.6-2.0× the noise floor. Tolerances: linear
/// 0.012-0.05 °/h (the measured range, widened by ~20 % each side for one seed), thermal-state
/// 1.2-2.5× the floor, and thermal-state must beat linear.
#[test]
fn default_unit_history_matters_beyond_t_and_dt() {
    let train = run("seed-shock", 7);
    for (p, seed) in [("seed-shock", 11), ("fast-cycle", 9)] {
        let test = run(p, seed);
        let floor = bias_stability_dph(&test.noise_dps, 1.0, 100.0);
        let lin = held_out_residual_dph(&train, &test, false);
        let th = held_out_residual_dph(&train, &test, true);
        println!(
            "{p}: floor {floor:.5} linear {lin:.5} thermal-state {th:.5} ({:.2}x)",
            th / floor
        );
        assert!(
            (0.012..=0.05).contains(&lin),
            "{p}: linear held-out want ~0.015..0.035 °/h (issue 5), got {lin:.5}"
        );
        assert!(
            (1.2..=2.5).contains(&(th / floor)),
            "{p}: thermal-state held-out want ~1.6..2.0x floor (issue 5), got {th:.5} = {:.2}x {floor:.5}",
            th / floor
        );
        assert!(
            th < lin,
            "{p}: thermal-state {th:.5} should beat linear {lin:.5}"
        );
    }
}

#[test]
#[ignore = "probe: prints numbers for the report"]
fn report_probe() {
    fn rich(s: &SimSeries) -> Vec<Vec<f64>> {
        let t = &s.temp_c;
        let d = dtemp(t, 1.0);
        let mut f = vec![
            vec![1.0; t.len()],
            t.clone(),
            t.iter().map(|v| v * v).collect(),
            d.clone(),
        ];
        f.push(t.iter().zip(&d).map(|(a, b)| a * b).collect());
        for tau in [300.0, 1000.0, 3000.0] {
            f.push(lag(t, 1.0, tau));
        }
        let l300 = lag(t, 1.0, 300.0);
        f.push(t.iter().zip(&l300).map(|(a, b)| a * (a - b)).collect());
        f
    }
    fn fit(tr: &SimSeries, te: &SimSeries) -> f64 {
        let ftr = rich(tr);
        let n = tr.gyro_dps.len();
        let a = DMatrix::from_fn(n, ftr.len(), |i, j| ftr[j][i]);
        let y = DVector::from_column_slice(&tr.gyro_dps);
        let coef = a.svd(true, true).solve(&y, 1e-12).unwrap();
        let fte = rich(te);
        let r: Vec<f64> = (0..te.gyro_dps.len())
            .map(|i| te.gyro_dps[i] - (0..fte.len()).map(|j| coef[j] * fte[j][i]).sum::<f64>())
            .collect();
        bias_stability_dph(&r, 1.0, 100.0)
    }
    let runs: Vec<(&str, SimSeries)> = [("seed-shock", 7), ("slow-ramp", 8), ("fast-cycle", 9)]
        .iter()
        .map(|&(p, s)| (p, run(p, s)))
        .collect();
    for (p, s) in &runs {
        println!(
            "{p}: raw {:.5} floor {:.5}",
            bias_stability_dph(&s.gyro_dps, 1.0, 100.0),
            bias_stability_dph(&s.noise_dps, 1.0, 100.0)
        );
    }
    for (ptr, tr) in &runs {
        for (pte, seed) in [("seed-shock", 11), ("slow-ramp", 12), ("fast-cycle", 13)] {
            let te = run(pte, seed);
            let floor = bias_stability_dph(&te.noise_dps, 1.0, 100.0);
            println!(
                "train {ptr} test {pte}#{seed}: floor {floor:.5} linear {:.5} thermal {:.5} rich {:.5}",
                held_out_residual_dph(tr, &te, false),
                held_out_residual_dph(tr, &te, true),
                fit(tr, &te)
            );
        }
    }
}

//! Generated models for the C export's differential tests (`export_c`, `export_imu_c`):
//! deterministic, covering every method and recipe.
#![allow(dead_code)]

/// Deterministic weights in [-0.5, 0.5) (a 64-bit LCG, Knuth's MMIX constants).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
    pub fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.next()).collect()
    }
}

pub fn lstm_json(
    rng: &mut Lcg,
    inputs: usize,
    mean: &[f64],
    std: &[f64],
    target: (f64, f64),
) -> serde_json::Value {
    lstm_json_sized(rng, inputs, 8, mean, std, target)
}

/// [`lstm_json`] with `hidden` hidden units.
pub fn lstm_json_sized(
    rng: &mut Lcg,
    inputs: usize,
    hidden: usize,
    mean: &[f64],
    std: &[f64],
    target: (f64, f64),
) -> serde_json::Value {
    let g = 4 * hidden;
    serde_json::json!({
        "params": {
            "input_size": inputs, "hidden_size": hidden,
            "w_ih": rng.vec(g * inputs), "w_hh": rng.vec(g * hidden), "b_ih": rng.vec(g),
            "b_hh": rng.vec(g), "w_out": rng.vec(hidden), "b_out": rng.next(),
        },
        "input_norm": {"mean": mean, "std": std},
        "target_norm": {"mean": [target.0], "std": [target.1]},
    })
}

/// Linear terms over `nf` features: 1, x_0, …, x_{nf-1}.
pub fn linear_terms(nf: usize, rng: &mut Lcg, scale: f64) -> (serde_json::Value, Vec<f64>) {
    let mut powers = vec![vec![0u8; nf]];
    for i in 0..nf {
        let mut p = vec![0u8; nf];
        p[i] = 1;
        powers.push(p);
    }
    let mut c: Vec<f64> = rng.vec(nf + 1).iter().map(|v| v * scale).collect();
    c[0] = 2.7e-3;
    (serde_json::json!({"n_features": nf, "powers": powers}), c)
}

/// A whole model file (unsealed) around `features`, `bias` and `scale`.
pub fn model_json(
    method: &str,
    features: serde_json::Value,
    bias: serde_json::Value,
    scale: Option<serde_json::Value>,
) -> serde_json::Value {
    let mut m = serde_json::json!({
        "format_version": 1, "method": method, "features": features, "bias": bias,
        "training": {"temp_range_c": {"min": -40.0, "max": 60.0},
                     "rate_range_c_per_s": {"min": -0.05, "max": 0.05},
                     "data_digest_sha256": "0".repeat(64), "epochs": null, "final_loss": null,
                     "seed": null, "created_by": "export_c differential test",
                     "inputs": ["generated"]},
    });
    if let Some(s) = scale {
        m["scale"] = s;
    }
    m
}

/// Model `i`: kind `i % 6` is linear, poly, thermal-state least squares, LSTM, residual LSTM
/// (with or without the base value as input), bias-only; the scale factor's constant is
/// below 1 for even `i / 6` and above 1 for odd (with an LSTM scale model, its target mean).
pub fn generated_model(i: usize) -> serde_json::Value {
    let mut rng = Lcg(0x5eed + i as u64);
    let kind = i % 6;
    let k0 = if (i / 6) % 2 == 0 {
        0.5 + 0.45 * (rng.next() + 0.5)
    } else {
        1.05 + 0.9 * (rng.next() + 0.5)
    };
    let pick = |rng: &mut Lcg, n: usize| ((rng.next() + 0.5) * n as f64) as usize % n;
    let step = if i % 7 == 0 { 0.5 } else { 1.0 };
    let lag = [20.0, 10.0, 5.0, 30.0][pick(&mut rng, 4)];
    let smooth = [0.0, 0.0, 10.0, 30.0][pick(&mut rng, 4)];
    let thermal = kind == 2 || (kind >= 3 && i % 2 == 0);
    let taus: Vec<f64> = if thermal {
        let n = 1 + pick(&mut rng, 4);
        [300.0, 1000.0, 3000.0, 60.0][..n].to_vec()
    } else {
        Vec::new()
    };
    let outputs = ["diff_from_t", "level", "both"][pick(&mut rng, 3)];
    let per_lag = if outputs == "both" { 2 } else { 1 };
    let nf = 2 + usize::from(smooth > 0.0) + taus.len() * per_lag;
    let degraded = [60.0, 30.0, 120.0][pick(&mut rng, 3)];
    let max_rate = [2.0, 0.5][pick(&mut rng, 2)];
    let allowance = [1.0, 0.2][pick(&mut rng, 2)];
    let features = serde_json::json!({
        "step_period_s": step, "rate_lag_s": lag, "smoothing_window_s": smooth,
        "lag_tau_s": taus, "lag_outputs": outputs,
        "temp_sensor": {"min_c": -60.0, "max_c": 100.0,
                        "max_rate_c_per_s": max_rate, "step_allowance_c": allowance,
                        "degraded_after_s": degraded}});
    let baseline = |rng: &mut Lcg, c0: f64, poly: bool| {
        let (mut terms, mut c) = linear_terms(nf, rng, 1e-5);
        c[0] = c0;
        if poly {
            // T², T·dT, dT² (and T³): within MAX_TERMS for nf ≤ 12 only when nf is small.
            let extra: &[[u8; 2]] = &[[2, 0], [1, 1], [0, 2], [3, 0]];
            for p in extra.iter().take(16usize.saturating_sub(nf + 1)) {
                let mut row = vec![0u8; nf];
                row[0] = p[0];
                row[1] = p[1];
                terms["powers"].as_array_mut().unwrap().push(row.into());
                c.push(1e-7 * rng.next());
            }
        }
        serde_json::json!({"terms": terms, "coefficients": c})
    };
    let norm = |n: usize| {
        let mut mean = vec![20.0, 0.0];
        mean.resize(n, 1.0);
        let mut std = vec![30.0, 0.03];
        std.resize(n, 5.0);
        (mean, std)
    };
    let lstm = |rng: &mut Lcg, target: (f64, f64)| {
        let (mean, std) = norm(nf);
        lstm_json(rng, nf, &mean, &std, target)
    };
    let residual = |rng: &mut Lcg, c0: f64, target: (f64, f64)| {
        let reads_base = nf < 12 && rng.next() > 0.0;
        let n_in = nf + usize::from(reads_base);
        let (mut mean, mut std) = norm(n_in);
        if reads_base {
            mean[nf] = c0;
            std[nf] = 5e-5;
        }
        let mut r = lstm_json(rng, n_in, &mean, &std, target);
        let b = baseline(rng, c0, false);
        r["terms"] = b["terms"].clone();
        r["coefficients"] = b["coefficients"].clone();
        r["lstm_reads_base"] = reads_base.into();
        r
    };
    let bias_c0 = 2.7e-3;
    let (method, bias, scale) = match kind {
        0 => (
            "linear",
            serde_json::json!({"baseline": baseline(&mut rng, bias_c0, false)}),
            Some(serde_json::json!({"baseline": baseline(&mut rng, k0, false)})),
        ),
        1 => (
            "poly",
            serde_json::json!({"baseline": baseline(&mut rng, bias_c0, true)}),
            Some(serde_json::json!({"baseline": baseline(&mut rng, k0, true)})),
        ),
        2 => (
            "linear",
            serde_json::json!({"baseline": baseline(&mut rng, bias_c0, false)}),
            Some(serde_json::json!({"baseline": baseline(&mut rng, k0, false)})),
        ),
        3 => (
            "lstm",
            serde_json::json!({"lstm": lstm(&mut rng, (bias_c0, 2e-5))}),
            Some(serde_json::json!({"lstm": lstm(&mut rng, (k0, 1e-3))})),
        ),
        4 => (
            "lstm",
            serde_json::json!({"residual": residual(&mut rng, bias_c0, (0.0, 2e-5))}),
            Some(serde_json::json!({"residual": residual(&mut rng, k0, (0.0, 1e-4))})),
        ),
        _ => {
            let bias = match pick(&mut rng, 3) {
                0 => serde_json::json!({"baseline": baseline(&mut rng, bias_c0, false)}),
                1 => serde_json::json!({"lstm": lstm(&mut rng, (bias_c0, 2e-5))}),
                _ => serde_json::json!({"residual": residual(&mut rng, bias_c0, (0.0, 2e-5))}),
            };
            let method = if bias.get("baseline").is_some() {
                "linear"
            } else {
                "lstm"
            };
            (method, bias, None)
        }
    };
    let mut m = model_json(method, features, bias, scale);
    if i % 3 != 0 {
        m["coverage"] = coverage_json(&mut rng);
    }
    m
}

/// A random coverage map (two models in three carry one): 1 to 16 by 1 to 12 cells placed
/// around the streams' temperatures (−5 to 35 °C) and rates, about half the cells covered,
/// growth 0 to 1 per cell (0 in one map in four).
pub fn coverage_json(rng: &mut Lcg) -> serde_json::Value {
    let mut u = || rng.next() + 0.5;
    let n_temp = 1 + (u() * 16.0) as usize % 16;
    let n_rate = 1 + (u() * 12.0) as usize % 12;
    let temp_cell_c = 1.0 + 6.0 * u();
    let rate_cell_c_per_s = 0.002 + 0.02 * u();
    let temp_min_c = -10.0 + 20.0 * u() - 0.5 * n_temp as f64 * temp_cell_c + 15.0;
    let rate_min_c_per_s = -0.5 * n_rate as f64 * rate_cell_c_per_s + 0.01 * (u() - 0.5);
    let growth = if u() < 0.25 { 0.0 } else { u() };
    let n = n_temp * n_rate;
    let mut sigma: Vec<f64> = (0..n)
        .map(|_| if u() < 0.5 { 0.0 } else { 0.01 + 0.1 * u() })
        .collect();
    let k = (u() * n as f64) as usize % n;
    if sigma[k] == 0.0 {
        sigma[k] = 0.05;
    }
    let count: Vec<u64> = sigma
        .iter()
        .map(|s| if *s > 0.0 { 200 } else { 0 })
        .collect();
    serde_json::json!({
        "temp_min_c": temp_min_c, "temp_cell_c": temp_cell_c, "n_temp": n_temp,
        "rate_min_c_per_s": rate_min_c_per_s, "rate_cell_c_per_s": rate_cell_c_per_s,
        "n_rate": n_rate, "folds": 5, "count": count, "rms_dph": sigma.clone(),
        "sigma_dph": sigma, "growth_per_cell": growth,
    })
}

/// Largest finite gyro sample the tester used: with K < 1, (Ĝ − B) / K overflows.
pub const HUGE: f64 = 1.797e308;

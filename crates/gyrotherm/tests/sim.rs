//! Simulator tests: determinism, physics sanity, profile parsing, unit files.

use gyrotherm::csvlog::{write_log, NOISE_COL, TRUE_BIAS_COL, TRUE_SCALE_COL};
use gyrotherm::sim::{
    simulate, simulate_series, ChamberParams, FogUnit, Profile, SimConfig, SimError, EARTH_RATE_DPH,
};

fn short_cfg(seed: u64) -> SimConfig {
    let profile = Profile::parse("600,22\n600,10\n600,10\n", "short").unwrap();
    SimConfig {
        seed,
        truth: true,
        table_rate_dps: Some(20.0),
        ..SimConfig::new(profile)
    }
}

/// Issue 2: same seed, same bytes; different seeds differ.
#[test]
fn same_seed_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, seed: u64| {
        let path = dir.path().join(name);
        write_log(&path, &simulate(&short_cfg(seed)).unwrap()).unwrap();
        std::fs::read(path).unwrap()
    };
    let a = write("a.csv", 7);
    let b = write("b.csv", 7);
    let c = write("c.csv", 8);
    assert!(a == b, "two runs with seed 7 wrote different bytes");
    assert!(a != c, "seeds 7 and 8 wrote identical files");
    let header =
        String::from_utf8_lossy(&a[..a.iter().position(|&x| x == b'\n').unwrap()]).to_string();
    for col in ["table_dps", TRUE_BIAS_COL, TRUE_SCALE_COL, NOISE_COL] {
        assert!(header.contains(col), "header {header:?} lacks {col}");
    }
}

/// The truth columns decompose the output exactly: gyro = B + K·Ω + noise.
#[test]
fn truth_columns_add_up() {
    let s = simulate_series(&short_cfg(3)).unwrap();
    let table = s.table_dps.unwrap();
    for (i, &omega) in table.iter().enumerate() {
        let sum = s.true_bias_dps[i] + s.true_scale[i] * omega + s.noise_dps[i];
        // Rounding of three f64 additions on values up to 20 °/s: a few ulps of 20.
        assert!(
            (sum - s.gyro_dps[i]).abs() < 1e-13,
            "sample {i}: gyro {} want B+KΩ+n {sum}",
            s.gyro_dps[i]
        );
    }
}

/// A unit with only the Shupe term (and no chamber ripple), so the thermal bias is that term.
fn shupe_only() -> (FogUnit, ChamberParams) {
    let unit = FogUnit {
        bias_c1_dph_per_c: 0.0,
        bias_c2_dph_per_c2: 0.0,
        bias_c3_dph_per_c3: 0.0,
        stress_dph_per_c: 0.0,
        shupe_tc_per_c: 0.0,
        ..FogUnit::default()
    };
    let chamber = ChamberParams {
        ripple_amp_c: 0.0,
        fluct_sigma_c: 0.0,
        ..ChamberParams::default()
    };
    (unit, chamber)
}

/// Issue 2 physics sanity: steady temperature gives no Shupe term; its sign follows the coil
/// temperature rate (positive coefficient: cooling < 0, heating > 0).
#[test]
fn shupe_zero_when_steady_and_follows_rate_sign() {
    let (unit, chamber) = shupe_only();
    let constant_dph = unit.bias0_dph + EARTH_RATE_DPH * 39.1_f64.to_radians().sin();
    let steady = SimConfig {
        unit: unit.clone(),
        chamber,
        ..SimConfig::builtin("room-steady").unwrap()
    };
    let s = simulate_series(&steady).unwrap();
    for (i, b) in s.true_bias_dps.iter().enumerate() {
        let thermal = b * 3600.0 - constant_dph;
        // Everything starts in equilibrium and nothing drives it: zero up to rounding.
        assert!(
            thermal.abs() < 1e-12,
            "sample {i}: Shupe term {thermal} °/h at steady temperature"
        );
    }
    let shock = SimConfig {
        unit,
        chamber,
        ..SimConfig::builtin("seed-shock").unwrap()
    };
    let s = simulate_series(&shock).unwrap();
    let mut checked = 0;
    for i in 1..s.coil_c.len() {
        let rate = s.coil_c[i] - s.coil_c[i - 1];
        let thermal = s.true_bias_dps[i - 1] * 3600.0 - constant_dph;
        if rate.abs() > 0.01 {
            checked += 1;
            assert!(
                thermal.signum() == rate.signum(),
                "t={} s: coil rate {rate} °C/s but Shupe term {thermal} °/h",
                s.time_s[i]
            );
        }
    }
    assert!(
        checked > 1000,
        "only {checked} samples with a fast coil rate"
    );
}

/// Issue 2 physics sanity: the coil lags the case, which lags the chamber air: on the first
/// cool-down each crosses 0 °C later than the node outside it.
#[test]
fn coil_lags_case_lags_air() {
    let s = simulate_series(&SimConfig::builtin("seed-shock").unwrap()).unwrap();
    let crossing = |x: &[f64]| x.iter().position(|&v| v < 0.0).unwrap() as f64;
    let (air, case, coil) = (
        crossing(&s.chamber_c),
        crossing(&s.case_c),
        crossing(&s.coil_c),
    );
    // At a steady ramp a first-order lag of τ trails by τ s; require at least half of it.
    let unit = FogUnit::default();
    assert!(
        case - air > 0.5 * unit.case_tau_s,
        "case crosses 0 °C at {case} s, air at {air} s"
    );
    assert!(
        coil - case > 0.5 * unit.coil_tau_s,
        "coil crosses 0 °C at {coil} s, case at {case} s"
    );
}

/// The chamber overshoots its set point when a ramp ends (design value ~1 °C for a 3 °C/min
/// ramp; accept 0.3-2 °C, the range of chamber data sheets), with ripple off.
#[test]
fn chamber_overshoots_after_ramp() {
    let cfg = SimConfig {
        chamber: ChamberParams {
            ripple_amp_c: 0.0,
            fluct_sigma_c: 0.0,
            ..ChamberParams::default()
        },
        ..SimConfig::builtin("seed-shock").unwrap()
    };
    let s = simulate_series(&cfg).unwrap();
    let min_air = s.chamber_c.iter().cloned().fold(f64::INFINITY, f64::min);
    let overshoot = -40.0 - min_air;
    assert!(
        (0.3..=2.0).contains(&overshoot),
        "overshoot below -40 °C: {overshoot} °C"
    );
}

/// The logged temperature is on the DS18B20's 0.0625 °C grid (He et al. 2024).
#[test]
fn sensor_reading_on_resolution_grid() {
    let s = simulate_series(&short_cfg(1)).unwrap();
    for t in &s.temp_c {
        let k = t / 0.0625;
        assert!(
            (k - k.round()).abs() < 1e-9,
            "temp {t} not a multiple of 0.0625"
        );
    }
}

fn profile_err(text: &str) -> (usize, String) {
    match Profile::parse(text, "p.csv") {
        Err(SimError::Profile { line, message, .. }) => (line, message),
        other => panic!("want a profile error for {text:?}, got {other:?}"),
    }
}

#[test]
fn profile_file_errors_name_the_line() {
    let (line, msg) = profile_err("# c\n100,22\n100,x\n");
    assert_eq!(line, 3, "{msg}");
    assert!(msg.contains("not a number"), "{msg}");
    let (line, msg) = profile_err("100,22\n100\n");
    assert_eq!(line, 2, "{msg}");
    assert!(msg.contains("2 fields"), "{msg}");
    let (line, msg) = profile_err("100,22\n60,-40\n");
    assert_eq!(line, 2, "{msg}");
    assert!(msg.contains("°C/min"), "{msg}");
    let (line, msg) = profile_err("0,22\n");
    assert_eq!(line, 1, "{msg}");
    let (line, msg) = profile_err("100,inf\n");
    assert_eq!(line, 1, "{msg}");
    let (line, msg) = profile_err("100,500\n");
    assert_eq!(line, 1, "{msg}");
    assert!(msg.contains("range"), "{msg}");
    let (line, msg) = profile_err("# only comments\n\n");
    assert_eq!(line, 0, "{msg}");
    assert!(msg.contains("no segments"), "{msg}");
}

#[test]
fn profile_file_ramps_and_soaks() {
    let p = Profile::parse("duration_s,target_c\n100 20 # hold\n1200, -40\n", "p").unwrap();
    assert_eq!(p.start_c, 20.0);
    assert_eq!(p.duration_s(), 1300.0);
    // Independent: halfway through a linear ramp from 20 to -40 is -10.
    assert_eq!(p.setpoint_c(50.0), 20.0);
    assert_eq!(p.setpoint_c(700.0), -10.0);
    assert_eq!(p.setpoint_c(5000.0), -40.0);
}

#[test]
fn builtin_profiles_exist_and_unknown_is_an_error() {
    for (name, _) in gyrotherm::sim::BUILTIN_PROFILES {
        let p = Profile::builtin(name).unwrap();
        p.validate().unwrap();
    }
    // Issue 2: seed-shock is about 30,000 s and spans -40..+60 °C.
    let p = Profile::builtin("seed-shock").unwrap();
    assert_eq!(p.duration_s(), 30000.0);
    let targets: Vec<f64> = p.segments.iter().map(|s| s.target_c).collect();
    assert!(targets.contains(&-40.0) && targets.contains(&60.0));
    assert!(matches!(Profile::builtin("nope"), Err(SimError::Config(_))));
}

#[test]
fn unit_json_partial_override_and_errors() {
    let u = FogUnit::from_json_str(r#"{"bias0_dph": 1.5}"#, "u.json").unwrap();
    assert_eq!(u.bias0_dph, 1.5);
    assert_eq!(u.coil_tau_s, FogUnit::default().coil_tau_s);
    let e = FogUnit::from_json_str(r#"{"bias_zero": 1.5}"#, "u.json").unwrap_err();
    assert!(e.to_string().contains("bias_zero"), "{e}");
    let e = FogUnit::from_json_str(r#"{"coil_tau_s": -1}"#, "u.json").unwrap_err();
    assert!(e.to_string().contains("coil_tau_s"), "{e}");
    // Round trip of the default through JSON.
    let j = serde_json::to_string(&FogUnit::default()).unwrap();
    assert_eq!(FogUnit::from_json_str(&j, "d").unwrap(), FogUnit::default());
}

#[test]
fn bad_config_is_an_error_not_a_panic() {
    let mut c = short_cfg(0);
    c.sample_rate_hz = 0.0;
    assert!(simulate(&c).is_err());
    let mut c = short_cfg(0);
    c.table_rate_dps = Some(f64::NAN);
    assert!(simulate(&c).is_err());
    let mut c = short_cfg(0);
    c.latitude_deg = 95.0;
    assert!(simulate(&c).is_err());
}

/// Higher sample rates work and keep the physics: at 10 Hz the run has 10× the samples.
#[test]
fn ten_hz_run() {
    let mut c = short_cfg(2);
    c.sample_rate_hz = 10.0;
    let s = simulate_series(&c).unwrap();
    assert_eq!(s.time_s.len(), 18000);
    assert!((s.time_s[10] - 1.0).abs() < 1e-12);
}

/// The example files shipped next to the simulator parse and run.
#[test]
fn example_files_parse() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/sim");
    let unit = FogUnit::load(&dir.join("example_unit.json")).unwrap();
    assert_eq!(unit.coil_tau_s, 420.0);
    assert_eq!(unit.case_tau_s, FogUnit::default().case_tau_s);
    let text = std::fs::read_to_string(dir.join("example_profile.csv")).unwrap();
    let p = Profile::parse(&text, "example_profile.csv").unwrap();
    assert_eq!(p.start_c, 25.0);
    assert_eq!(p.duration_s(), 23000.0);
    let cfg = SimConfig {
        unit,
        ..SimConfig::new(p)
    };
    assert_eq!(simulate(&cfg).unwrap().len(), 23000);
}

/// Faults: dropouts leave time gaps, stuck readings repeat; off by default changes nothing.
#[test]
fn fault_injection() {
    let clean = simulate_series(&short_cfg(5)).unwrap();
    let mut cfg = short_cfg(5);
    cfg.faults = gyrotherm::sim::FaultParams {
        dropouts_per_hour: 20.0,
        dropout_s: 5.0,
        stuck_temp_per_hour: 20.0,
        stuck_temp_s: 30.0,
        ..Default::default()
    };
    let f = simulate_series(&cfg).unwrap();
    let gaps = f.time_s.windows(2).filter(|w| w[1] - w[0] > 1.5).count();
    assert!(gaps > 0, "20 dropouts/h over 0.5 h made no gap");
    assert_eq!(
        clean.time_s.len() - f.time_s.len(),
        gaps * 5,
        "each 5 s dropout removes 5 samples at 1 Hz"
    );
    // Gyro values of kept samples are the clean run's (faults touch only the log).
    for (t, g) in f.time_s.iter().zip(&f.gyro_dps) {
        assert_eq!(clean.gyro_dps[*t as usize], *g);
    }
    let stuck = f
        .temp_c
        .windows(31)
        .filter(|w| w.iter().all(|&v| v == w[0]))
        .count();
    assert!(stuck > 0, "no 30 s stuck-temperature run found");
    cfg.faults.dropout_s = 0.0;
    assert!(
        simulate(&cfg).is_err(),
        "dropout rate without a length must be refused"
    );
}

/// Non-overlapping Allan deviation of rate samples `x` (τ0 = 1/rate) at m samples per
/// cluster (IEEE Std 952-1997 eq. (C.1); NIST SP 1065 eq. 6), same unit as `x`.
fn adev(x: &[f64], m: usize) -> f64 {
    let means: Vec<f64> = x
        .chunks_exact(m)
        .map(|c| c.iter().sum::<f64>() / m as f64)
        .collect();
    let s: f64 = means.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
    (s / (2.0 * (means.len() - 1) as f64)).sqrt()
}

/// A steady run with only one noise term switched on (no quantization), noise in °/h.
fn noise_only(edit: impl Fn(&mut FogUnit), duration_s: f64, rate_hz: f64) -> Vec<f64> {
    let mut unit = FogUnit {
        arw_deg_rt_h: 0.0,
        bias_instability_dph: 0.0,
        rrw_dph_rt_h: 0.0,
        pulse_arcsec: 0.0,
        ..FogUnit::default()
    };
    edit(&mut unit);
    let cfg = SimConfig {
        unit,
        seed: 42,
        sample_rate_hz: rate_hz,
        ..SimConfig::new(Profile::parse(&format!("{duration_s},22"), "steady").unwrap())
    };
    let s = simulate_series(&cfg).unwrap();
    s.noise_dps.iter().map(|v| v * 3600.0).collect()
}

/// Angle random walk: σ(τ) = 60·N/√τ °/h (IEEE Std 952-1997 C.1.1), at 1 Hz and 10 Hz.
/// Tolerance 5 %: the estimate's relative standard error with ~10^5 clusters is < 0.3 %.
#[test]
fn arw_matches_its_allan_definition() {
    let n = 0.001;
    for rate in [1.0, 10.0] {
        let x = noise_only(|u| u.arw_deg_rt_h = n, 20000.0, rate);
        for tau in [1.0, 10.0] {
            let got = adev(&x, (tau * rate) as usize);
            let want = 60.0 * n / f64::sqrt(tau);
            assert!(
                (got / want - 1.0).abs() < 0.05,
                "{rate} Hz, τ {tau} s: ADEV want {want:.6} °/h got {got:.6}"
            );
        }
    }
}

/// Bias instability: the Allan floor is 0.6643·B (IEEE Std 952-1997 C.1.3). Checked on
/// 200,000 s at τ = 100, 300 and 1000 s; tolerance 20 % (the sum-of-Gauss-Markov curve is
/// flat within ±4 %, the rest is estimation error with 200-2000 clusters).
#[test]
fn bias_instability_floor_matches_definition() {
    let b = 0.01;
    let x = noise_only(|u| u.bias_instability_dph = b, 200000.0, 1.0);
    for tau in [100usize, 300, 1000] {
        let got = adev(&x, tau);
        let want = 0.6643 * b;
        assert!(
            (got / want - 1.0).abs() < 0.2,
            "τ {tau} s: ADEV want {want:.6} °/h got {got:.6}"
        );
    }
}

/// Rate random walk: σ(τ) = K·√(τ/3) with K in °/h/√h and τ in h (IEEE Std 952-1997
/// C.1.4). Tolerance 25 % at τ = 1000 s (about 100 clusters on 100,000 s).
#[test]
fn rrw_matches_its_allan_definition() {
    let k = 0.05;
    let x = noise_only(|u| u.rrw_dph_rt_h = k, 100000.0, 1.0);
    let got = adev(&x, 1000);
    let want = k * f64::sqrt(1000.0 / 3600.0 / 3.0);
    assert!(
        (got / want - 1.0).abs() < 0.25,
        "ADEV(1000 s) want {want:.6} got {got:.6}"
    );
}

/// Quantization: σ(τ) = √3·Q/τ with Q = q/√12 (IEEE Std 952-1997 C.1.2), in arcsec/s = °/h.
/// The formula assumes a uniformly random quantization phase, so white rate noise of 1 °/h
/// per sample (1 arcsec of angle, two pulses) runs alongside; the ARW stream is the same with
/// and without quantization, so the difference of the two outputs is the quantization error
/// alone. Tolerance 10 % (20,000 samples).
#[test]
fn quantization_matches_its_allan_definition() {
    let q = 0.5;
    let arw = 1.0 / 60.0;
    let with_q = noise_only(
        |u| {
            u.pulse_arcsec = q;
            u.arw_deg_rt_h = arw;
        },
        20000.0,
        1.0,
    );
    let without = noise_only(|u| u.arw_deg_rt_h = arw, 20000.0, 1.0);
    let err: Vec<f64> = with_q.iter().zip(&without).map(|(a, b)| a - b).collect();
    for tau in [1usize, 10] {
        let got = adev(&err, tau);
        let want = 3f64.sqrt() * q / 12f64.sqrt() / tau as f64;
        assert!(
            (got / want - 1.0).abs() < 0.1,
            "ADEV({tau} s) want {want:.6} got {got:.6}"
        );
    }
}

//! The unit family (`sim::family`) and the physics it uses: drawn parameters inside their
//! documented ranges, one seed one unit, and each new term checked against an independent
//! computation from the truth columns (the node equations written out again, or numerical
//! derivatives of the node temperatures).

use gyrotherm::sim::{
    random_unit, simulate_series, ChamberParams, FogUnit, Profile, SensorNode, SimConfig,
    UnitRanges, EARTH_RATE_DPH,
};

fn within(v: f64, (lo, hi): (f64, f64)) -> bool {
    v >= lo && v <= hi
}

/// Every drawn parameter lies in its documented range (magnitudes for signed ones), every
/// unit validates, and the draws use both signs, both node counts and every sensor node.
#[test]
fn drawn_parameters_lie_in_the_documented_ranges() {
    let r = UnitRanges::default();
    let (mut mounts, mut negative_c1, mut nodes) = (0, 0, [0usize; 3]);
    for seed in 0..300 {
        let u = random_unit(seed);
        u.validate().unwrap();
        let abs_checks = [
            ("sensor_offset_c", u.sensor_offset_c, r.sensor_offset_c),
            ("bias_c1", u.bias_c1_dph_per_c, r.bias_c1_dph_per_c),
            ("bias_c2", u.bias_c2_dph_per_c2, r.bias_c2_dph_per_c2),
            ("bias_c3", u.bias_c3_dph_per_c3, r.bias_c3_dph_per_c3),
            ("shupe", u.shupe_dph_per_c_per_s, r.shupe_dph_per_c_per_s),
            ("shupe_tc", u.shupe_tc_per_c, r.shupe_tc_per_c),
            (
                "shupe_grad",
                u.shupe_grad_dph_per_c_per_s,
                r.shupe_grad_dph_per_c_per_s,
            ),
            ("stress", u.stress_dph_per_c, r.stress_dph_per_c),
            ("rate_sat", u.rate_sat_dph, r.rate_sat_dph),
            ("sf_c1", u.sf_c1_ppm_per_c, r.sf_c1_ppm_per_c),
            ("sf_c2", u.sf_c2_ppm_per_c2, r.sf_c2_ppm_per_c2),
            ("sf_c3", u.sf_c3_ppm_per_c3, r.sf_c3_ppm_per_c3),
            (
                "sf_rate",
                u.sf_rate_ppm_per_c_per_s,
                r.sf_rate_ppm_per_c_per_s,
            ),
            ("sf_stress", u.sf_stress_ppm_per_c, r.sf_stress_ppm_per_c),
        ];
        for (name, v, range) in abs_checks {
            assert!(
                within(v.abs(), range),
                "seed {seed}: |{name}| = {v} outside {range:?}"
            );
        }
        let plain = [
            ("case_tau_s", u.case_tau_s, r.node_tau_s),
            ("coil_tau_s", u.coil_tau_s, r.node_tau_s),
            ("stress_tau_s", u.stress_tau_s, r.stress_tau_s),
            ("sensor_tau_s", u.sensor_tau_s, r.sensor_tau_s),
            ("sensor_noise_c", u.sensor_noise_c, r.sensor_noise_c),
            ("ref_temp_c", u.ref_temp_c, r.ref_temp_c),
            ("bias0_dph", u.bias0_dph, r.bias0_dph),
            ("rate_sat_c_per_s", u.rate_sat_c_per_s, r.rate_sat_c_per_s),
            ("sf_offset_ppm", u.sf_offset_ppm, r.sf_offset_ppm),
            ("arw", u.arw_deg_rt_h, r.arw_deg_rt_h),
            (
                "bias_instability",
                u.bias_instability_dph,
                r.bias_instability_dph,
            ),
            ("rrw", u.rrw_dph_rt_h, r.rrw_dph_rt_h),
        ];
        for (name, v, range) in plain {
            assert!(
                within(v, range),
                "seed {seed}: {name} = {v} outside {range:?}"
            );
        }
        assert_eq!(u.sensor_resolution_c, 0.0625, "DS18B20 12-bit step");
        if u.mount_tau_s > 0.0 {
            mounts += 1;
            assert!(within(u.mount_tau_s, r.node_tau_s));
        } else {
            assert_ne!(
                u.sensor_node,
                SensorNode::Mount,
                "seed {seed}: sensor on a mounting node the unit does not have"
            );
        }
        if u.bias_c1_dph_per_c < 0.0 {
            negative_c1 += 1;
        }
        nodes[u.sensor_node as usize] += 1;
    }
    // 300 fair draws: each count is far from 0 and 300 (binomial, p = 1/2 or about 1/6..1/2).
    assert!(
        (100..=200).contains(&mounts),
        "{mounts} of 300 with a mount"
    );
    assert!(
        (100..=200).contains(&negative_c1),
        "{negative_c1} of 300 negative"
    );
    assert!(
        nodes.iter().all(|n| *n > 20),
        "sensor nodes drawn {nodes:?}"
    );
}

/// One seed names one unit; another seed another.
#[test]
fn same_seed_same_unit() {
    assert_eq!(random_unit(17), random_unit(17));
    assert_ne!(random_unit(17), random_unit(18));
    // The parameters survive a JSON round trip (the sidecar file of `simulate`).
    let u = random_unit(5);
    let json = serde_json::to_string(&u).unwrap();
    assert_eq!(FogUnit::from_json_str(&json, "sidecar").unwrap(), u);
}

/// A quiet unit: no noise, no sensor offset/noise/steps, every thermal coefficient zero.
fn quiet() -> FogUnit {
    FogUnit {
        bias_c1_dph_per_c: 0.0,
        bias_c2_dph_per_c2: 0.0,
        bias_c3_dph_per_c3: 0.0,
        shupe_dph_per_c_per_s: 0.0,
        shupe_tc_per_c: 0.0,
        stress_dph_per_c: 0.0,
        sf_c1_ppm_per_c: 0.0,
        sf_c2_ppm_per_c2: 0.0,
        arw_deg_rt_h: 0.0,
        bias_instability_dph: 0.0,
        rrw_dph_rt_h: 0.0,
        pulse_arcsec: 0.0,
        sensor_offset_c: 0.0,
        sensor_noise_c: 0.0,
        sensor_resolution_c: 0.0,
        ..FogUnit::default()
    }
}

/// At 2 Hz the simulator integrates in one 0.5 s step per sample, with the air of the truth
/// column, so the node equations can be written out again from that column.
fn run(unit: FogUnit, profile: &str) -> gyrotherm::sim::SimSeries {
    let profile = Profile::builtin(profile).unwrap();
    let cfg = SimConfig {
        unit,
        sample_rate_hz: 2.0,
        chamber: ChamberParams {
            ripple_amp_c: 0.0,
            fluct_sigma_c: 0.0,
            ..ChamberParams::default()
        },
        ..SimConfig::new(profile)
    };
    simulate_series(&cfg).unwrap()
}

fn alpha(h: f64, tau: f64) -> f64 {
    1.0 - (-h / tau).exp()
}

/// A mounting node sits between the air and the case: the case column equals a chain of two
/// exact first-order lags of the air column (recomputed here), and differs from one lag.
#[test]
fn mounting_node_is_a_second_lag_in_the_chain() {
    let unit = FogUnit {
        mount_tau_s: 700.0,
        ..quiet()
    };
    let s = run(unit.clone(), "seed-shock");
    let (am, ac) = (alpha(0.5, 700.0), alpha(0.5, unit.case_tau_s));
    let (mut mount, mut case) = (s.chamber_c[0], s.chamber_c[0]);
    let mut worst_one_lag = 0.0f64;
    let mut one_lag = s.chamber_c[0];
    for i in 0..s.case_c.len() {
        assert!(
            (s.case_c[i] - case).abs() < 1e-9,
            "t={} s: case {} want {case}",
            s.time_s[i],
            s.case_c[i]
        );
        worst_one_lag = worst_one_lag.max((s.case_c[i] - one_lag).abs());
        let air = s.chamber_c[i];
        let m0 = mount;
        mount += (air - mount) * am;
        case += (m0 - case) * ac;
        one_lag += (air - one_lag) * ac;
    }
    assert!(
        worst_one_lag > 5.0,
        "the mount changed the case by only {worst_one_lag} °C"
    );
}

/// A sensor on the coil reads the coil (through its own short lag), not the case.
#[test]
fn sensor_on_the_coil_reads_the_coil() {
    let unit = FogUnit {
        sensor_node: SensorNode::Coil,
        sensor_tau_s: 1e-3,
        ..quiet()
    };
    let s = run(unit, "seed-shock");
    // With τ = 1 ms the sensor takes the coil's value of the previous step exactly
    // (1 - e^{-500} = 1 in f64).
    let mut far_from_case = 0;
    for i in 1..s.temp_c.len() {
        assert!(
            (s.temp_c[i] - s.coil_c[i - 1]).abs() < 1e-9,
            "t={}: sensor {} coil {}",
            s.time_s[i],
            s.temp_c[i],
            s.coil_c[i - 1]
        );
        if (s.temp_c[i] - s.case_c[i - 1]).abs() > 1.0 {
            far_from_case += 1;
        }
    }
    assert!(
        far_from_case > 1000,
        "the coil never differed from the case"
    );
}

fn thermal_bias_dph(s: &gyrotherm::sim::SimSeries, unit: &FogUnit, i: usize) -> f64 {
    s.true_bias_dps[i] * 3600.0 - unit.bias0_dph - EARTH_RATE_DPH * 39.1_f64.to_radians().sin()
}

/// The node equations written out again: d T_coil/dt = (T_case - T_coil)/τ_coil and, without
/// a mounting node, d T_case/dt = (T_air - T_case)/τ_case, from the truth columns.
fn coil_rate(s: &gyrotherm::sim::SimSeries, unit: &FogUnit, i: usize) -> f64 {
    (s.case_c[i] - s.coil_c[i]) / unit.coil_tau_s
}
fn case_rate(s: &gyrotherm::sim::SimSeries, unit: &FogUnit, i: usize) -> f64 {
    (s.chamber_c[i] - s.case_c[i]) / unit.case_tau_s
}

/// The radial-gradient Shupe term is its coefficient times d(T_case - T_coil)/dt; the
/// derivative from the node equations, and (loosely) from a central difference of the
/// columns, so that a wrong sign or a wrong node would show.
#[test]
fn gradient_shupe_follows_the_rate_of_the_case_coil_difference() {
    let unit = FogUnit {
        shupe_grad_dph_per_c_per_s: 2.0,
        ..quiet()
    };
    let s = run(unit.clone(), "shock-5");
    let (mut checked, mut peak) = (0, 0.0f64);
    for i in 1..s.coil_c.len() - 1 {
        let want = 2.0 * (case_rate(&s, &unit, i) - coil_rate(&s, &unit, i));
        let got = thermal_bias_dph(&s, &unit, i);
        peak = peak.max(got.abs());
        assert!(
            (got - want).abs() < 1e-9,
            "t={}: got {got} want {want}",
            s.time_s[i]
        );
        // Central difference over ±0.5 s (2 Hz): the same within the chamber's curvature.
        let d = |x: &[f64]| x[i + 1] - x[i - 1];
        let numeric = 2.0 * (d(&s.case_c) - d(&s.coil_c));
        assert!(
            (got - numeric).abs() < 2e-3 + 0.05 * got.abs(),
            "t={}: got {got}, central difference {numeric}",
            s.time_s[i]
        );
        checked += 1;
    }
    assert!(checked > 50_000 && peak > 0.01, "peak {peak} °/h");
}

/// The saturating rate term is A·tanh(dT_coil/dt / r_s): bounded by A, reaching it on the
/// airborne climb.
#[test]
fn saturating_rate_term_is_a_tanh_of_the_coil_rate() {
    let unit = FogUnit {
        rate_sat_dph: 0.03,
        rate_sat_c_per_s: 0.005,
        ..quiet()
    };
    let s = run(unit.clone(), "airborne");
    let mut near_saturation = 0;
    for i in 0..s.coil_c.len() {
        let want = 0.03 * (coil_rate(&s, &unit, i) / 0.005).tanh();
        let got = thermal_bias_dph(&s, &unit, i);
        assert!(
            got.abs() <= 0.03,
            "t={}: {got} beyond the amplitude",
            s.time_s[i]
        );
        assert!(
            (got - want).abs() < 1e-9,
            "t={}: got {got} want {want}",
            s.time_s[i]
        );
        if got.abs() > 0.9 * 0.03 {
            near_saturation += 1;
        }
    }
    assert!(
        near_saturation > 100,
        "the airborne climb never saturated the term"
    );
}

/// The scale factor's new terms: cubic in the coil temperature, per coil rate, per stress lag
/// (the stress state recomputed here as an exact lag of the coil column).
#[test]
fn scale_factor_terms_follow_the_coil_states() {
    let unit = FogUnit {
        sf_offset_ppm: 0.0,
        sf_c3_ppm_per_c3: 4e-4,
        sf_rate_ppm_per_c_per_s: 150.0,
        sf_stress_ppm_per_c: 0.3,
        ..quiet()
    };
    let s = run(unit.clone(), "seed-shock");
    let a = alpha(0.5, unit.stress_tau_s);
    let mut stress = s.coil_c[0];
    let mut peak = 0.0f64;
    for i in 0..s.coil_c.len() {
        let dt = s.coil_c[i] - unit.ref_temp_c;
        let want_ppm =
            4e-4 * dt * dt * dt + 150.0 * coil_rate(&s, &unit, i) + 0.3 * (s.coil_c[i] - stress);
        let got_ppm = (s.true_scale[i] - 1.0) * 1e6;
        peak = peak.max(got_ppm.abs());
        // K is stored as 1 + 1e-6·(…): 1e-16 of K is 1e-10 ppm; allow 1e-6 ppm.
        assert!(
            (got_ppm - want_ppm).abs() < 1e-6,
            "t={}: K-1 {got_ppm} ppm want {want_ppm}",
            s.time_s[i]
        );
        stress += (s.coil_c[i] - stress) * a;
    }
    assert!(peak > 10.0, "the terms reached only {peak} ppm");
}

/// The default unit has none of the new terms: the same run as before they existed is what the
/// calibration tests (`tests/sim_calibration.rs`) pin; here, its K depends on the coil
/// temperature alone (independent: the documented quadratic).
#[test]
fn default_unit_keeps_its_quadratic_scale_factor() {
    let unit = FogUnit {
        arw_deg_rt_h: 0.0,
        ..FogUnit::default()
    };
    let s = run(unit.clone(), "fast-cycle");
    for i in 0..s.coil_c.len() {
        let dt = s.coil_c[i] - unit.ref_temp_c;
        let want = 1.0 + 1e-6 * (150.0 + 1.0 * dt + 0.08 * dt * dt);
        assert!((s.true_scale[i] - want).abs() < 1e-15);
    }
}

//! Experiment harnesses for gyrotherm: the held-out sweeps and the generalisation benchmark
//! whose records live in `docs/experiments/`. Not part of the library's face; not published.

use gyrotherm::sim::family::UnitRanges;

/// The value after `--key` in `args` (the harnesses' whole argument syntax).
pub fn arg_value(args: &[String], key: &str) -> Option<String> {
    args.iter()
        .position(|a| a == key)
        .and_then(|i| args.get(i + 1))
        .cloned()
}

/// The design ranges widened: time constants a factor 2 further each way, every thermal
/// coefficient's upper magnitude doubled, a mounting node in three units of four, sensors up
/// to 2 minutes behind and 1 °C off. A third opinion of the physics, for checking what was
/// chosen on the design family.
pub fn wide_ranges() -> UnitRanges {
    let d = UnitRanges::default();
    let wider = |(lo, hi): (f64, f64)| (lo, 2.0 * hi);
    UnitRanges {
        mount_probability: 0.75,
        node_tau_s: (50.0, 10000.0),
        stress_tau_s: (1800.0, 28800.0),
        sensor_tau_s: (5.0, 120.0),
        sensor_offset_c: (0.0, 1.0),
        bias_c1_dph_per_c: wider(d.bias_c1_dph_per_c),
        bias_c2_dph_per_c2: wider(d.bias_c2_dph_per_c2),
        bias_c3_dph_per_c3: wider(d.bias_c3_dph_per_c3),
        shupe_dph_per_c_per_s: wider(d.shupe_dph_per_c_per_s),
        shupe_tc_per_c: wider(d.shupe_tc_per_c),
        shupe_grad_dph_per_c_per_s: wider(d.shupe_grad_dph_per_c_per_s),
        stress_dph_per_c: wider(d.stress_dph_per_c),
        rate_sat_dph: wider(d.rate_sat_dph),
        rate_sat_c_per_s: (0.001, 0.04),
        sf_c1_ppm_per_c: wider(d.sf_c1_ppm_per_c),
        sf_c2_ppm_per_c2: wider(d.sf_c2_ppm_per_c2),
        sf_c3_ppm_per_c3: wider(d.sf_c3_ppm_per_c3),
        sf_rate_ppm_per_c_per_s: wider(d.sf_rate_ppm_per_c_per_s),
        sf_stress_ppm_per_c: wider(d.sf_stress_ppm_per_c),
        ..d
    }
}

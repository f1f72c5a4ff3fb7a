//! `gyrotherm::plan` on simulated logs: trained on the published shock test alone, the
//! airborne flight (a built-in profile: a 9.5 °C/min climb to −45 °C) leaves the training
//! region; the profile `plan` proposes, simulated as `simulate --profile-file` simulates it,
//! brings the flight inside. The numbers of the run (same seeds, CLI) are in
//! docs/experiments/plan.md.

use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::NamedLog;
use gyrotherm::plan::{propose, resolve_envelope, training_coverage, CoverageSummary};
use gyrotherm::settings::plan::PlanSettings;
use gyrotherm::sim::{simulate, Profile, SimConfig};

fn sim(profile: Profile, seed: u64) -> TestLog {
    let mut cfg = SimConfig::new(profile);
    cfg.seed = seed;
    simulate(&cfg).expect("simulate")
}

fn coverage(train: &[(&str, &TestLog)], flight: &TestLog, s: &PlanSettings) -> CoverageSummary {
    let named: Vec<NamedLog> = train
        .iter()
        .map(|(n, l)| NamedLog { name: n, log: l })
        .collect();
    let env = resolve_envelope(Some(flight), s).unwrap();
    training_coverage(&named, Some(flight), &env)
        .unwrap()
        .expect("a thermal fit has a coverage map")
}

#[test]
fn the_planned_profile_brings_the_flight_inside_coverage() {
    let shock = sim(Profile::builtin("seed-shock").unwrap(), 1);
    let flight = sim(Profile::builtin("airborne").unwrap(), 3);
    let s = PlanSettings::default();
    let before = coverage(&[("shock", &shock)], &flight, &s);
    let [_, _, out_before] = before.flight_shares.unwrap();

    let env = resolve_envelope(Some(&flight), &s).unwrap();
    let plan = propose(&env, &s).unwrap();
    // The file `plan --out` writes reads back as the profile simulated here.
    let text = plan.profile_text();
    let parsed = Profile::parse(&text, "plan.txt").unwrap();
    assert_eq!(parsed.segments, plan.profile().segments);
    let planned = sim(parsed, 4);

    let after = coverage(&[("shock", &shock), ("plan", &planned)], &flight, &s);
    let [inside_after, _, out_after] = after.flight_shares.unwrap();
    assert!(
        out_before > 0.03,
        "the shock test alone leaves the climb outside: {out_before}"
    );
    assert!(
        out_after < 0.2 * out_before,
        "outside {out_before} → {out_after}"
    );
    assert!(inside_after > 0.5, "inside after the plan: {inside_after}");
    assert!(
        after.envelope_outside < 0.5 * before.envelope_outside,
        "envelope outside {} → {}",
        before.envelope_outside,
        after.envelope_outside
    );
    // The covered rates reach the flight's.
    assert!(after.rate_span_c_per_min.0 <= -env.max_rate_c_per_min);
    assert!(after.rate_span_c_per_min.1 >= env.max_rate_c_per_min);
}

#[test]
fn the_chamber_limits_bound_the_profile_and_are_said() {
    let s = PlanSettings {
        temp_min_c: Some(-70.0),
        temp_max_c: Some(60.0),
        max_rate_c_per_min: Some(20.0),
        ..PlanSettings::default()
    };
    let env = resolve_envelope(None, &s).unwrap();
    let plan = propose(&env, &s).unwrap();
    assert_eq!(plan.temp_lo_c, s.chamber_min_c);
    assert_eq!(plan.max_rate_c_per_min, s.chamber_max_rate_c_per_min);
    assert_eq!(plan.notes.len(), 2, "{:?}", plan.notes);
    for seg in &plan.segments {
        assert!(seg.rate_c_per_min <= s.chamber_max_rate_c_per_min + 1e-9);
        assert!(seg.to_c >= s.chamber_min_c && seg.to_c <= s.chamber_max_c);
    }
    // Neither a flight log nor a full envelope: refused.
    let partial = PlanSettings {
        max_rate_c_per_min: None,
        ..s
    };
    assert!(resolve_envelope(None, &partial).is_err());
}

/// The first soak at each extreme is sized to the slowest lag the training fit identified
/// (the rule's factor comes from docs/experiments/imu-soak.md: a lag at the search's 12,000 s
/// bound gives the confirmed 6 h soaks); every other soak keeps the fixed length, and without
/// an identified lag every soak does.
#[test]
fn the_first_soak_at_each_extreme_separates_the_slowest_identified_lag() {
    let shock = sim(Profile::builtin("seed-shock").unwrap(), 1);
    let flight = sim(Profile::builtin("airborne").unwrap(), 3);
    let mut s = PlanSettings::default();
    let fixed = propose(&resolve_envelope(Some(&flight), &s).unwrap(), &s).unwrap();
    let c = coverage(&[("shock", &shock)], &flight, &s);
    let tau = c.slowest_lag_s.expect("a thermal fit identifies lags");
    s.slowest_lag_s = Some(tau);
    let env = resolve_envelope(Some(&flight), &s).unwrap();
    let plan = propose(&env, &s).unwrap();
    let soaks = |p: &gyrotherm::plan::Plan| -> Vec<(f64, f64)> {
        p.segments
            .iter()
            .filter(|g| g.step == gyrotherm::plan::Step::Soak)
            .map(|g| (g.to_c, g.duration_s))
            .collect()
    };
    let fixed_s = fixed.soak.other_s;
    assert!(soaks(&fixed).iter().all(|&(_, d)| d == fixed_s));
    assert_eq!(fixed.soak.long_s, fixed_s);
    assert!(
        fixed.soak.why.contains("no lag identified"),
        "{}",
        fixed.soak.why
    );
    // 1.8 × τ at each extreme, once; the same segments otherwise.
    let long = 1.8 * tau;
    assert!(long > fixed_s, "τ = {tau} s");
    assert_eq!(plan.soak.long_s, long);
    let got = soaks(&plan);
    assert_eq!(got.len(), soaks(&fixed).len());
    for extreme in [plan.temp_lo_c, plan.temp_hi_c] {
        let at: Vec<f64> = got.iter().filter(|g| g.0 == extreme).map(|g| g.1).collect();
        assert_eq!(at[0], long, "first soak at {extreme} °C");
        assert!(at[1..].iter().all(|&d| d == fixed_s), "{at:?}");
    }
    assert!(
        plan.soak.why.contains(&format!("({tau:.0} s)")),
        "{}",
        plan.soak.why
    );
    // Still a profile `simulate --profile-file` reads.
    Profile::parse(&plan.profile_text(), "plan.txt").unwrap();
}

/// An inertial unit's training logs: every gyro axis on every temperature sensor is one pair,
/// each pair's coverage is `training_coverage` of that axis's view on that sensor (computed
/// here on the views directly), and the soaks follow the slowest lag of any pair. The flight
/// envelope of a unit is the union over its sensors.
#[test]
fn a_unit_plans_every_axis_on_every_sensor_and_soaks_for_the_slowest() {
    use gyrotherm::csvlog::{LogSet, ReadOptions};
    use gyrotherm::plan::{resolve_set_envelope, set_coverage, slowest_lag};
    use gyrotherm::sim::imu::{imu_from_family, simulate_imu, ImuConfig};

    let run = |profile: &str, seed: u64| {
        let mut r = SimConfig::new(Profile::builtin(profile).unwrap());
        r.seed = seed;
        simulate_imu(&ImuConfig {
            run: r,
            unit: imu_from_family(1000),
            table_axis: 0,
        })
        .unwrap()
    };
    let mut shock = run("seed-shock", 1);
    let mut flight = run("airborne", 2);
    // Two axes and two sensors keep the test short: four pairs.
    for l in [&mut shock, &mut flight] {
        l.gyro.truncate(2);
        l.temp.truncate(2);
    }
    let train = LogSet::of_unit_logs(vec![("shock".to_owned(), shock.clone())]);
    let flight_set = LogSet::of_unit_logs(vec![("flight".to_owned(), flight.clone())]);
    let s = PlanSettings::default();
    let env = resolve_set_envelope(Some(&flight_set), &s).unwrap();
    // The union of each sensor's envelope.
    let per_sensor: Vec<_> = (0..2)
        .map(|j| resolve_envelope(Some(&flight.axis_data(0, j)), &s).unwrap())
        .collect();
    assert_eq!(
        env.temp_min_c,
        per_sensor[0].temp_min_c.min(per_sensor[1].temp_min_c)
    );
    assert_eq!(
        env.temp_max_c,
        per_sensor[0].temp_max_c.max(per_sensor[1].temp_max_c)
    );
    assert_eq!(
        env.max_rate_c_per_min,
        per_sensor[0]
            .max_rate_c_per_min
            .max(per_sensor[1].max_rate_c_per_min)
    );

    let pairs = set_coverage(&train, Some(&flight_set), &env, &ReadOptions::default()).unwrap();
    assert_eq!(pairs.len(), 4, "two axes × two sensors");
    let mut lags = Vec::new();
    for (i, p) in pairs.iter().enumerate() {
        let (k, j) = (i / 2, i % 2);
        assert_eq!(p.gyro, shock.gyro[k].name);
        assert_eq!(p.temp, shock.temp[j].name);
        let view = shock.axis_data(k, j);
        let want = training_coverage(
            &[NamedLog {
                name: "shock",
                log: &view,
            }],
            Some(&flight.axis_data(k, j)),
            &env,
        )
        .unwrap();
        assert_eq!(p.coverage, want, "{} on {}", p.gyro, p.temp);
        lags.extend(want.ok().and_then(|c| c.slowest_lag_s));
    }
    let (p, tau) = slowest_lag(&pairs).expect("a thermal fit identifies lags");
    assert_eq!(tau, lags.iter().copied().fold(f64::NAN, f64::max));
    assert_eq!(p.coverage.as_ref().unwrap().slowest_lag_s, Some(tau));
}

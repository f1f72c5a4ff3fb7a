//! Results that were wrong with no error, and messages that named the wrong cause, through
//! the library: each case is refused (or read) with the real cause named.

use std::path::Path;

use gyrotherm::csvlog::{read_imu_log, read_log, ReadOptions};
use gyrotherm::fit::{fit_model, FitConfig, FitError, NamedLog};
use gyrotherm::plan::{propose, resolve_envelope, PlanError};
use gyrotherm::settings::plan::PlanSettings;
use gyrotherm::sim::{simulate, FogUnit, Profile, SimConfig};

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A constant flight gives no rate to plan ramps for: refused, not a profile of `inf` s.
#[test]
fn plan_refuses_a_flat_flight_and_ramps_no_profile_takes() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..600 {
        text.push_str(&format!("{i},0.001,25\n"));
    }
    let flight = read_log(
        &write(dir.path(), "flat.csv", &text),
        &ReadOptions::default(),
    )
    .unwrap()
    .0;
    let e = resolve_envelope(Some(&flight), &PlanSettings::default()).unwrap_err();
    assert!(matches!(e, PlanError::FlatFlight { samples: 600 }), "{e}");
    assert!(e.to_string().contains("--max-rate-c-per-min"), "{e}");
    // With the rate given, the flight's temperature is the envelope.
    let s = PlanSettings {
        max_rate_c_per_min: Some(3.0),
        ..PlanSettings::default()
    };
    let env = resolve_envelope(Some(&flight), &s).unwrap();
    assert_eq!((env.temp_min_c, env.temp_max_c), (25.0, 25.0));
    let plan = propose(&env, &s).unwrap();
    assert!(plan.duration_s().is_finite());
    Profile::parse(&plan.profile_text(), "plan.txt").unwrap();

    // 1e-300 °C/min: a ramp of 6e301 s, longer than the 1e7 s a profile segment may last.
    let s = PlanSettings {
        temp_min_c: Some(-10.0),
        temp_max_c: Some(40.0),
        max_rate_c_per_min: Some(1e-300),
        ..PlanSettings::default()
    };
    let env = resolve_envelope(None, &s).unwrap();
    let e = propose(&env, &s).unwrap_err();
    assert!(matches!(e, PlanError::Profile(_)), "{e}");
    // A chamber beyond the profile limits, or an envelope beyond physics, is a setting error.
    for s in [
        PlanSettings {
            chamber_max_rate_c_per_min: 1e9,
            ..PlanSettings::default()
        },
        PlanSettings {
            chamber_max_c: 500.0,
            ..PlanSettings::default()
        },
        PlanSettings {
            temp_max_c: Some(1e308),
            ..PlanSettings::default()
        },
    ] {
        assert!(matches!(
            resolve_envelope(None, &s),
            Err(PlanError::Setting(_))
        ));
    }
}

fn sim(profile: &str, rate_hz: f64, table: Option<f64>) -> gyrotherm::csvlog::TestLog {
    let mut cfg = SimConfig::new(Profile::builtin(profile).unwrap());
    cfg.seed = 5;
    cfg.sample_rate_hz = rate_hz;
    cfg.table_rate_dps = table;
    simulate(&cfg).unwrap()
}

/// The model steps once a second and reads dT over 20 s (He et al. 2024): a 0.01 Hz log
/// cannot train it.
#[test]
fn a_log_sampled_more_sparsely_than_the_rate_window_is_refused() {
    let log = sim("fast-cycle", 0.01, None);
    let named = [NamedLog {
        name: "slow.csv",
        log: &log,
    }];
    for method in [
        gyrotherm::settings::Method::Linear,
        gyrotherm::settings::DEFAULT_METHOD,
    ] {
        let e = fit_model(&named, &FitConfig::new(method), &|_, _, _| {}).unwrap_err();
        assert!(
            matches!(e, FitError::SampledTooSparsely { period_s, max_s, .. }
                if period_s == 100.0 && max_s == 20.0),
            "{e}"
        );
        assert!(
            e.to_string().contains("one sample every 100 s (0.01 Hz)"),
            "{e}"
        );
    }
}

/// A ±20 °/s rate-table run read without its table column: its output spans 40 °/s, which no
/// thermal bias does.
#[test]
fn a_rate_table_run_without_its_table_column_is_not_fitted_as_static() {
    let mut log = sim("fast-cycle", 1.0, Some(20.0));
    log.table_dps = None;
    let named = [NamedLog {
        name: "table.csv",
        log: &log,
    }];
    let e = fit_model(
        &named,
        &FitConfig::new(gyrotherm::settings::Method::Linear),
        &|_, _, _| {},
    )
    .unwrap_err();
    assert!(matches!(e, FitError::StaticRunTurns { .. }), "{e}");
    assert!(e.to_string().contains("looks like a rate-table run"), "{e}");
    // The static run of the same unit is fitted.
    let s = sim("fast-cycle", 1.0, None);
    let named = [NamedLog {
        name: "static.csv",
        log: &s,
    }];
    fit_model(
        &named,
        &FitConfig::new(gyrotherm::settings::Method::Linear),
        &|_, _, _| {},
    )
    .unwrap();
}

/// A table column of zeros is a static run, however many gyro columns the log has.
#[test]
fn an_all_zero_table_column_reads_as_a_static_unit_run() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("time_s,gx_dps,gy_dps,temp_c,table_dps\n");
    for i in 0..200 {
        text.push_str(&format!("{i},0.001,-0.002,{},0\n", 20.0 + 0.01 * i as f64));
    }
    let p = write(dir.path(), "imu.csv", &text);
    let opts = ReadOptions {
        gyro_col: "gx_dps,gy_dps".into(),
        ..ReadOptions::default()
    };
    let (log, report) = read_imu_log(&p, &opts, None).unwrap();
    assert!(log.table.is_none() && log.table_axis.is_none());
    assert!(report.zero_table);
}

/// A unit description's quantum of 1e-320 °C made every simulated temperature infinite.
#[test]
fn a_unit_quantum_beyond_a_real_part_is_refused_and_no_infinity_is_written() {
    let e = FogUnit::from_json_str(r#"{"sensor_resolution_c": 1e-320}"#, "u.json").unwrap_err();
    assert!(e.to_string().contains("sensor_resolution_c"), "{e}");
    FogUnit::from_json_str(r#"{"sensor_resolution_c": 0}"#, "u.json").unwrap();
    FogUnit::from_json_str(r#"{"sensor_resolution_c": 0.0625}"#, "u.json").unwrap();
    let e = FogUnit::from_json_str(r#"{"pulse_arcsec": 1e-300}"#, "u.json").unwrap_err();
    assert!(e.to_string().contains("pulse_arcsec"), "{e}");

    // A NaN temperature is a simulated sensor fault; an infinity is never written.
    let dir = tempfile::tempdir().unwrap();
    let mut log = sim("room-steady", 1.0, None);
    log.temp_c[3] = f64::NAN;
    let p = dir.path().join("nan.csv");
    gyrotherm::sim::fault::write_log(&p, &log).unwrap();
    log.temp_c[3] = f64::INFINITY;
    assert!(gyrotherm::sim::fault::write_log(&dir.path().join("inf.csv"), &log).is_err());
}

/// A 29,999,997 s gap within a 40,000,000 s fill limit: the cap of samples per gap stops it.
#[test]
fn a_gap_within_the_limit_but_over_the_sample_cap_names_the_cap() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "gap.csv",
        "time_s,gyro_dps,temp_c\n0,0,25\n1,0,25\n2,0,25\n3,0,25\n30000000,0,25\n",
    );
    let opts = ReadOptions {
        fill_gaps_max_s: Some(4e7),
        ..ReadOptions::default()
    };
    let e = read_log(&p, &opts).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("29999996 samples")
            && msg.contains(&gyrotherm::csvlog::MAX_FILL_SAMPLES_PER_GAP.to_string()),
        "{msg}"
    );
    assert!(!msg.contains("longer than the"), "{msg}");
}

/// τ beyond the log is said in seconds, not as 18446744073709551615 samples per mean.
#[test]
fn a_tau_longer_than_the_log_is_said_in_seconds() {
    let x = vec![0.01; 1000];
    let e = gyrotherm::metrics::bias_stability_dph(&x, 1.0, 1e300).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("τ = 1e300 s is longer than half the log (1000 samples of 1 s = 1000 s)")
            && msg.contains("at most 500 s"),
        "{msg}"
    );
    assert!(!msg.contains("18446744073709551615"), "{msg}");
}

/// A noise term the static log's Allan curve does not show: the message says so, rather
/// than asking for the static log that was given.
#[test]
fn a_noise_term_no_curve_shows_names_the_curve() {
    let spec = gyrotherm::spec::Spec::parse(
        "[limits]\narw_deg_rt_h = { max = 0.01 }\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let mut f = gyrotherm::spec::Figures::new();
    f.insert("bias_dph", 0.0);
    let e = gyrotherm::spec::judge(&spec, &[("static.csv".into(), f)]).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("no log's curve showed it") && !msg.contains("needs a static log"),
        "{msg}"
    );
}

/// Each cause once: a wrapper's message that holds its cause's text returns no source.
#[test]
fn error_chains_say_each_cause_once() {
    let e = gyrotherm::spec::Spec::load(Path::new("/nonexistent/spec.toml")).unwrap_err();
    let chain = gyrotherm::error_chain(&e);
    assert_eq!(
        chain.matches("No such file or directory").count(),
        1,
        "{chain}"
    );

    let e = PlanError::Setting(
        PlanSettings {
            chamber_max_rate_c_per_min: 0.0,
            ..PlanSettings::default()
        }
        .validate()
        .unwrap_err(),
    );
    let chain = gyrotherm::error_chain(&e);
    assert_eq!(
        chain.matches("is not a positive rate").count(),
        1,
        "{chain}"
    );
}

/// Unit names: trimmed, not empty, no control character.
#[test]
fn unit_names_are_checked() {
    use gyrotherm::lot::check_unit_name;
    assert_eq!(check_unit_name("A1").unwrap(), "A1");
    for bad in ["", " ", "\t", " A1", "A1 ", "A\u{1b}1", "A\n1"] {
        assert!(check_unit_name(bad).is_err(), "{bad:?}");
    }
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    let mut store = gyrotherm::lot::open_store(db.to_str().unwrap(), true, 1000).unwrap();
    let e = store
        .add(&gyrotherm::lot::synthetic_run(" ", 1, 0))
        .unwrap_err();
    assert!(e.to_string().contains("is empty"), "{e}");
    assert!(store.runs().unwrap().is_empty());
}

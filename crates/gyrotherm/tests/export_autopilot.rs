//! `gyrotherm::export` for autopilots: the ArduPilot and PX4 parameter files, read back from
//! their text and evaluated with each firmware's own formula (re-implemented here from the
//! firmware source, in `f32` as the firmware computes), equal the model's steady-state bias
//! within the fit error the export reports. The steady-state bias is computed here
//! independently of the exporter: straight from the model file's JSON, each least-squares
//! term at dT = 0 and T − lag = 0 (what is left at a constant temperature held long enough),
//! and for an LSTM by compensating a constant-temperature log.

use std::collections::BTreeMap;
use std::path::Path;

use gyrotherm::export::autopilot::{self, ModelRef};
use gyrotherm::export::ExportTarget;
use gyrotherm::model::unit::ImuModel;
use gyrotherm::model::ModelFile;
use gyrotherm::settings::autopilot::{AutopilotSettings, GyroAxis};

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gyrotherm-core/examples")
        .join(name)
}

/// A linear model as `gyrotherm train --method linear` writes one (the model of
/// tests/export_text.rs): bias = c0 + c1·T + c2·dT.
const LINEAR: &str = r#"{"format_version": 1, "method": "linear",
    "features": {"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                 "lag_tau_s": [], "lag_outputs": "diff_from_t"},
    "bias": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
             "coefficients": [0.0027569503410293872, 1.1729644843148304e-06, 0.00010133064497718164]}},
    "scale": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
              "coefficients": [1.0002578767007753, 9.083930143213933e-07, -0.00021387351834198826]}},
    "training": {"temp_range_c": {"min": -29.8125, "max": 70.375},
                 "rate_range_c_per_s": {"min": -0.0875, "max": 0.0875},
                 "data_digest_sha256": "30d4b8ab79b048f01aab0c81da07c7ee0aac77c3209a51f2976c0d528981f351",
                 "epochs": null, "final_loss": null, "seed": null,
                 "created_by": "gyrotherm 0.1.0", "inputs": ["fc.csv", "fct.csv"]}}"#;

/// Steady-state bias (°/s) of one least-squares sub-model in the file's JSON, at `t` °C:
/// every term whose powers of the other features are all 0 (those features are dT and
/// T − lag, both 0 at steady state), as c·T^p.
fn steady_terms(bias: &serde_json::Value, t: f64) -> f64 {
    let b = &bias["baseline"];
    let powers = b["terms"]["powers"].as_array().unwrap();
    let coefs = b["coefficients"].as_array().unwrap();
    powers
        .iter()
        .zip(coefs)
        .filter(|(p, _)| {
            p.as_array().unwrap()[1..]
                .iter()
                .all(|k| k.as_u64() == Some(0))
        })
        .map(|(p, c)| c.as_f64().unwrap() * t.powi(p[0].as_u64().unwrap() as i32))
        .sum()
}

/// The `NAME value` pairs of an ArduPilot parameter file (`#` lines skipped).
fn ardupilot_params(text: &str) -> BTreeMap<String, f32> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| {
            let (n, v) = l.split_once(' ').unwrap();
            (n.to_owned(), v.parse::<f32>().unwrap())
        })
        .collect()
}

/// ArduPilot's gyro correction at `temp`, rad/s, axis `a` (0 = X) of IMU `n` (from 1), as
/// `AP_InertialSensor_tempcal.cpp` computes it: `TCal::correct_sensor` clamps T to
/// [TMIN, TMAX] and subtracts `TCal::polynomial_eval(T - TEMP_REFERENCE)`,
/// `(c[0] + (c[1] + c[2]*tdiff)*tdiff)*tdiff*INV_SCALE_FACTOR` with `TEMP_REFERENCE` 35 and
/// `INV_SCALE_FACTOR` 1e-6, in float.
fn ardupilot_poly(p: &BTreeMap<String, f32>, n: u32, a: usize, temp: f32) -> f32 {
    let ax = ["X", "Y", "Z"][a];
    let get = |k: &str| p[&format!("INS_TCAL{n}_{k}")];
    let t = temp.clamp(get("TMIN"), get("TMAX"));
    let tdiff = t - 35.0f32;
    let c = [1, 2, 3].map(|k| get(&format!("GYR{k}_{ax}")));
    (c[0] + (c[1] + c[2] * tdiff) * tdiff) * tdiff * 1.0e-6f32
}

/// The tab-separated parameter lines of a QGroundControl file: name → (value, type).
fn px4_params(text: &str) -> BTreeMap<String, (String, u8)> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            assert_eq!(f.len(), 5, "{l:?}");
            assert_eq!((f[0], f[1]), ("1", "1"));
            (f[2].to_owned(), (f[3].to_owned(), f[4].parse().unwrap()))
        })
        .collect()
}

/// PX4's gyro offset at `temp`, rad/s, axis `a` of slot `n`, as `TemperatureCompensation.cpp`
/// `calc_thermal_offsets_3D` computes it: T clipped to [min_temp, max_temp], delta_temp =
/// T − ref_temp, `x0 + x1*dT + x2*dT^2 + x3*dT^3` in float.
fn px4_offset(p: &BTreeMap<String, (String, u8)>, n: u8, a: usize, temp: f32) -> f32 {
    let get = |k: &str| p[&format!("TC_G{n}_{k}")].0.parse::<f32>().unwrap();
    let delta_temp = if temp > get("TMAX") {
        get("TMAX") - get("TREF")
    } else if temp < get("TMIN") {
        get("TMIN") - get("TREF")
    } else {
        temp - get("TREF")
    };
    let d2 = delta_temp * delta_temp;
    let d3 = d2 * delta_temp;
    let x = |k: u8| get(&format!("X{k}_{a}"));
    x(0) + x(1) * delta_temp + x(2) * d2 + x(3) * d3
}

const RAD: f64 = std::f64::consts::PI / 180.0;

/// Checks both targets' files of `model` against the steady-state bias `truth(axis, T)`
/// (°/s, None for an axis left uncorrected) over the training range.
fn check_both(
    model: ModelRef<'_>,
    settings: &AutopilotSettings,
    truth: &dyn Fn(usize, f64) -> Option<f64>,
) {
    let ap = autopilot::generate(model, ExportTarget::Ardupilot, settings).unwrap();
    let px = autopilot::generate(model, ExportTarget::Px4, settings).unwrap();
    for e in [&ap, &px] {
        assert!(
            e.text
                .bytes()
                .all(|b| b == b'\n' || b == b'\t' || (0x20..=0x7e).contains(&b)),
            "only printable ASCII, tabs and newlines"
        );
    }
    let (lo, hi) = (ap.steady.temp_min_c, ap.steady.temp_max_c);
    let temps: Vec<f32> = (0..=400)
        .map(|i| lo + (hi - lo) * i as f32 / 400.0)
        .collect();
    // f32 evaluation of a polynomial of rad/s magnitude: a few ulps of its terms.
    let slack_dph = 1e-4;

    // ArduPilot: p(T) − p(T_cal) against B(T) − B(T_cal), for every pair; the fit error is
    // after the best constant, so a difference of two points is within twice it.
    let n = u32::from(settings.instance) + 1;
    let p = ardupilot_params(&ap.text);
    assert_eq!(p[&format!("INS_TCAL{n}_ENABLE")], 1.0);
    assert_eq!(p[&format!("INS_TCAL{n}_TMIN")], lo);
    assert_eq!(p[&format!("INS_TCAL{n}_TMAX")], hi);
    for a in 0..3 {
        let Some(fit) = ap.fit[a] else {
            assert!(truth(a, 20.0).is_none());
            assert!(temps.iter().all(|&t| ardupilot_poly(&p, n, a, t) == 0.0));
            continue;
        };
        let tol_dph = 2.0 * fit.max_dph + slack_dph;
        for &tc in temps.iter().step_by(40) {
            let bc = truth(a, f64::from(tc)).unwrap();
            let pc = f64::from(ardupilot_poly(&p, n, a, tc));
            for &t in &temps {
                let want = (truth(a, f64::from(t)).unwrap() - bc) * RAD;
                let got = f64::from(ardupilot_poly(&p, n, a, t)) - pc;
                let err_dph = (want - got).abs() / RAD * 3600.0;
                assert!(
                    err_dph <= tol_dph,
                    "axis {a}, T {t}, T_cal {tc}: {err_dph} °/h > {tol_dph}"
                );
            }
        }
        // Beyond the range the firmware holds the edge value.
        assert_eq!(
            ardupilot_poly(&p, n, a, hi + 25.0),
            ardupilot_poly(&p, n, a, hi)
        );
        assert_eq!(
            ardupilot_poly(&p, n, a, lo - 25.0),
            ardupilot_poly(&p, n, a, lo)
        );
    }

    // The correction the comparison evaluates (`AutopilotExport::correction`, f64) is the
    // firmware's formula on the written text (f32 here), over and beyond the range.
    let slot = settings.instance;
    let q = px4_params(&px.text);
    let wide: Vec<f32> = (0..=60)
        .map(|i| lo - 20.0 + (hi - lo + 40.0) * i as f32 / 60.0)
        .collect();
    for a in 0..3 {
        let ap0 = f64::from(ardupilot_poly(&p, n, a, 0.0));
        let ap0_c = ap.correction.offset_dps(a, 0.0) * RAD;
        for &t in &wide {
            let pairs = [
                (
                    f64::from(ardupilot_poly(&p, n, a, t)) - ap0,
                    ap.correction.offset_dps(a, f64::from(t)) * RAD - ap0_c,
                ),
                (
                    f64::from(px4_offset(&q, slot, a, t)),
                    px.correction.offset_dps(a, f64::from(t)) * RAD,
                ),
            ];
            for (firmware, ours) in pairs {
                let err_dph = (firmware - ours).abs() / RAD * 3600.0;
                assert!(err_dph <= slack_dph, "axis {a}, T {t}: {err_dph} °/h");
            }
        }
    }

    // PX4: the absolute offset against B(T), within the fit error.
    assert_eq!(q["TC_G_ENABLE"], ("1".to_owned(), 6));
    assert_eq!(q[&format!("TC_G{slot}_ID")].1, 6);
    assert_eq!(
        q[&format!("TC_G{slot}_ID")].0.parse::<i32>().unwrap() as u32,
        settings.device_id.unwrap()
    );
    for (name, (_, ty)) in &q {
        if !name.ends_with("_ID") && name != "TC_G_ENABLE" {
            assert_eq!(*ty, 9, "{name} is a float");
        }
    }
    for a in 0..3 {
        let Some(fit) = px.fit[a] else {
            assert!(temps.iter().all(|&t| px4_offset(&q, slot, a, t) == 0.0));
            continue;
        };
        let tol_dph = fit.max_dph + slack_dph;
        for &t in &temps {
            let want = truth(a, f64::from(t)).unwrap() * RAD;
            let got = f64::from(px4_offset(&q, slot, a, t));
            let err_dph = (want - got).abs() / RAD * 3600.0;
            assert!(
                err_dph <= tol_dph,
                "axis {a}, T {t}: {err_dph} °/h > {tol_dph}"
            );
        }
        assert_eq!(
            px4_offset(&q, slot, a, hi + 25.0),
            px4_offset(&q, slot, a, hi)
        );
    }
}

fn px4_settings() -> AutopilotSettings {
    AutopilotSettings {
        device_id: Some(2_490_378),
        ..AutopilotSettings::default()
    }
}

#[test]
fn a_linear_model_is_carried_exactly_and_its_dt_term_is_named() {
    let m = ModelFile::from_json(LINEAR).unwrap();
    let json: serde_json::Value = serde_json::from_str(LINEAR).unwrap();
    for axis in [GyroAxis::X, GyroAxis::Z] {
        let s = AutopilotSettings {
            axis,
            instance: 1,
            ..px4_settings()
        };
        let truth = |a: usize, t: f64| (a == axis.index()).then(|| steady_terms(&json["bias"], t));
        check_both(ModelRef::Single(&m), &s, &truth);
        let e = autopilot::generate(ModelRef::Single(&m), ExportTarget::Ardupilot, &s).unwrap();
        // A line in T: the cubic carries it to f32 rounding.
        assert!(e.fit[axis.index()].unwrap().max_dph < 1e-3, "{:?}", e.fit);
        assert!(
            e.text.contains("INS_TCAL2_GYR1_X"),
            "instance 1 is INS_TCAL2"
        );
        let summary = e.summary().join("\n");
        assert!(summary.contains("dT"), "{summary}");
        assert!(
            summary.contains("scale-factor model is not carried"),
            "{summary}"
        );
        assert!(e.steady.warnings.is_empty());
    }
}

#[test]
fn the_unit_example_is_carried_within_the_printed_fit_error() {
    let path = example("imu_flight/model.json");
    let m = ImuModel::load(&path).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let axes = json["axes"].as_array().unwrap().clone();
    for a in &axes {
        assert_eq!(a["model"]["features"]["lag_outputs"], "diff_from_t");
        assert_eq!(a["model"]["features"]["smoothing_window_s"], 0.0);
    }
    // Each axis: its first sensor's model plus every further sensor's part, all at T.
    let truth = |i: usize, t: f64| {
        let a = &axes[i];
        let more: f64 = a["more"]
            .as_array()
            .map(|v| v.iter().map(|s| steady_terms(&s["bias"], t)).sum())
            .unwrap_or(0.0);
        Some(steady_terms(&a["model"]["bias"], t) + more)
    };
    check_both(ModelRef::Unit(&m), &px4_settings(), &truth);
    let e = autopilot::generate(ModelRef::Unit(&m), ExportTarget::Px4, &px4_settings()).unwrap();
    // The range every axis was trained over.
    assert_eq!(
        (e.steady.temp_min_c, e.steady.temp_max_c),
        (-9.375, 43.4375)
    );
    let summary = e.summary().join("\n");
    assert!(summary.contains("T - lag"), "{summary}");
    assert!(summary.contains("further temperature sensors"), "{summary}");
}

#[test]
fn an_lstm_model_is_fitted_to_its_settled_output() {
    let m = ModelFile::load(&example("flight_loop/model.json")).unwrap();
    let s = AutopilotSettings {
        axis: GyroAxis::Y,
        ..px4_settings()
    };
    // The LSTM's settled output, by compensating a long constant-temperature log.
    let settled = |t: f64| {
        let n = 20_000;
        let log = gyrotherm::TestLog {
            time_s: (0..n).map(f64::from).collect(),
            gyro_dps: vec![0.0; n as usize],
            temp_c: vec![t; n as usize],
            ..Default::default()
        };
        let c = gyrotherm::compensate_log(&m, &log).unwrap();
        *c.bias_dps.last().unwrap()
    };
    let e = autopilot::generate(ModelRef::Single(&m), ExportTarget::Px4, &s).unwrap();
    let q = px4_params(&e.text);
    let fit = e.fit[1].unwrap();
    for t in [-29.0f32, 0.0, 25.0, 69.0] {
        let want = settled(f64::from(t)) * RAD;
        let got = f64::from(px4_offset(&q, 0, 1, t));
        let err_dph = (want - got).abs() / RAD * 3600.0;
        assert!(
            err_dph <= fit.max_dph + 1e-3,
            "T {t}: {err_dph} °/h > {}",
            fit.max_dph
        );
    }
    assert!(e.summary().join("\n").contains("LSTM"));
}

#[test]
fn no_string_of_the_model_file_reaches_the_parameter_files() {
    let plain = ModelFile::from_json(LINEAR).unwrap();
    let mut hostile = plain.clone();
    hostile.training.created_by = "x\nINS_TCAL1_ENABLE 0\n1\t1\tTC_G_ENABLE\t0\t6".to_owned();
    hostile.training.inputs = vec!["\r\n# \u{202e}".to_owned()];
    for target in [ExportTarget::Ardupilot, ExportTarget::Px4] {
        let a = autopilot::generate(ModelRef::Single(&plain), target, &px4_settings()).unwrap();
        let b = autopilot::generate(ModelRef::Single(&hostile), target, &px4_settings()).unwrap();
        let strip = |t: &str| {
            t.lines()
                .filter(|l| !l.starts_with("# model content_sha256"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        assert_eq!(strip(&a.text), strip(&b.text), "{target}");
        assert!(!b.text.contains("ENABLE 0") && !b.text.contains("TC_G_ENABLE\t0"));
    }
}

#[test]
fn a_narrow_range_is_warned_about_and_bad_settings_are_refused() {
    let mut m = ModelFile::from_json(LINEAR).unwrap();
    m.training.temp_range_c.min = 30.0;
    m.training.temp_range_c.max = 36.5;
    let e = autopilot::generate(
        ModelRef::Single(&m),
        ExportTarget::Ardupilot,
        &px4_settings(),
    )
    .unwrap();
    assert_eq!(e.steady.warnings.len(), 1);
    assert!(
        e.steady.warnings[0].contains("6.50 °C"),
        "{:?}",
        e.steady.warnings
    );
    assert!(e
        .text
        .contains("# warning: the model was trained over 6.50 degC"));

    m.training.temp_range_c.max = 30.0;
    let err = autopilot::generate(
        ModelRef::Single(&m),
        ExportTarget::Ardupilot,
        &px4_settings(),
    )
    .unwrap_err();
    assert!(
        format!("{:#}", anyhow_chain(&err)).contains("no interval"),
        "{err}"
    );

    let m = ModelFile::from_json(LINEAR).unwrap();
    let no_id = AutopilotSettings::default();
    let err = autopilot::generate(ModelRef::Single(&m), ExportTarget::Px4, &no_id).unwrap_err();
    assert!(anyhow_chain(&err).contains("--device-id"), "{err}");
    for (target, instance) in [(ExportTarget::Ardupilot, 3), (ExportTarget::Px4, 4)] {
        let s = AutopilotSettings {
            instance,
            ..px4_settings()
        };
        let err = autopilot::generate(ModelRef::Single(&m), target, &s).unwrap_err();
        assert!(anyhow_chain(&err).contains("instance"), "{err}");
    }
    let err =
        autopilot::generate(ModelRef::Single(&m), ExportTarget::C, &px4_settings()).unwrap_err();
    assert!(anyhow_chain(&err).contains("flight code"), "{err}");
}

/// The error and its sources, as the CLI prints them.
fn anyhow_chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cur = c.source();
    }
    s
}

/// `compare --methods thermal,ardupilot`: the ArduPilot column is the held-out gyro output
/// minus the firmware's correction from the parameter file `export --target ardupilot` writes
/// for the comparison's `thermal` model (evaluated here from the file's text, in f32, as the
/// firmware does), judged by the same bias-stability figure.
#[test]
fn the_autopilot_column_is_the_firmware_correction_of_the_exported_file() {
    use gyrotherm::compare::{compare, ColumnName};
    use gyrotherm::fit::NamedLog;
    use gyrotherm::settings::{FitSettings, Method};
    use gyrotherm::sim::{simulate, Profile, SimConfig};

    let sim = |p: &str, seed| {
        let mut c = SimConfig::new(Profile::builtin(p).unwrap());
        c.seed = seed;
        simulate(&c).unwrap()
    };
    let (train, test) = (sim("seed-shock", 1), sim("slow-ramp", 5));
    let train = [NamedLog {
        name: "shock",
        log: &train,
    }];
    let test = [NamedLog {
        name: "ramp",
        log: &test,
    }];
    // The autopilot column is fitted to the comparison's own method's model: `thermal`, the
    // first column's, so that the file exported from that column is the one to check.
    let cfg = FitSettings {
        method: Method::Thermal,
        ..FitSettings::default()
    }
    .compare_config(
        Some(&[
            ColumnName::Method(Method::Thermal),
            ColumnName::Autopilot(ExportTarget::Ardupilot),
        ]),
        100.0,
    )
    .unwrap();
    let mut cmp = compare(&train, &test, &cfg, &|_, _, _, _| {}).unwrap();
    autopilot::add_columns(&mut cmp, &train, &test, &cfg).unwrap();
    let keys: Vec<&str> = cmp.columns.iter().map(|c| c.key).collect();
    assert_eq!(keys, ["thermal", "ardupilot"]);
    let got = cmp.tests[0]
        .methods
        .iter()
        .find(|m| m.key == "ardupilot")
        .unwrap()
        .performance
        .bias_stability_dph
        .unwrap();

    let settings = AutopilotSettings::default();
    let export = autopilot::generate(
        ModelRef::Single(&cmp.fits[0].model),
        ExportTarget::Ardupilot,
        &settings,
    )
    .unwrap();
    let p = ardupilot_params(&export.text);
    let log = test[0].log;
    let out: Vec<f64> = log
        .gyro_dps
        .iter()
        .zip(&log.temp_c)
        .map(|(g, &t)| g - f64::from(ardupilot_poly(&p, 1, 0, t as f32)).to_degrees())
        .collect();
    let want = gyrotherm::metrics::bias_stability_dph(&out, log.sample_period_s(), 100.0)
        .unwrap()
        .bias_stability_dph;
    assert!(
        (got - want).abs() <= 1e-6 * want + 1e-9,
        "column {got} °/h, firmware on the file {want} °/h"
    );
    // A cubic in T carries no rate or lag terms: it does not beat the model it came from.
    let thermal = cmp.tests[0].methods[0]
        .performance
        .bias_stability_dph
        .unwrap();
    assert!(got > thermal, "ardupilot {got} against thermal {thermal}");
}

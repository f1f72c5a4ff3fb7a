//! `gyrotherm allan` and `gyrotherm evaluate` run as a user would, on small temporary logs.

use std::path::Path;

use serde_json::Value;

mod cli;
use cli::outcome as gyrotherm;

/// NBS 1000-point set (NIST SP 1065 p. 107) as gyro_dps at 1 Hz.
fn write_nbs_log(path: &Path) {
    let mut n: u64 = 1_234_567_890;
    let mut s = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..1000 {
        let y = n as f64 / 2_147_483_647.0;
        n = 16_807 * n % 2_147_483_647;
        s.push_str(&format!("{i},{y},25\n"));
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn allan_json_matches_nist_oadev() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("nbs.csv");
    write_nbs_log(&log);
    let (code, out, err) = gyrotherm(&[
        "allan",
        "--input",
        log.to_str().unwrap(),
        "--taus",
        "1,10,100",
        "--json",
    ]);
    assert_eq!(code, 0, "stderr: {err}");
    let v: Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(v["kind"], "oadev");
    let pts = v["points"].as_array().unwrap();
    // NIST SP 1065 OADEV of the NBS set (docs/method.md §6); terms N + 1 − 2m.
    let want = [
        (1.0, 2.922319e-01, 999),
        (10.0, 9.159953e-02, 981),
        (100.0, 3.241343e-02, 801),
    ];
    assert_eq!(pts.len(), 3);
    for (p, (tau, dev, n)) in pts.iter().zip(want) {
        assert_eq!(p["tau_s"].as_f64().unwrap(), tau);
        let got = p["dev"].as_f64().unwrap();
        assert!(
            (got - dev).abs() / dev < 1e-6,
            "τ={tau}: want {dev} got {got}"
        );
        assert_eq!(p["n"].as_u64().unwrap(), n);
        let (lo, hi) = (p["lo"].as_f64().unwrap(), p["hi"].as_f64().unwrap());
        assert!(lo < got && got < hi, "bounds {lo} {got} {hi}");
    }
    for key in ["arw_deg_rt_h", "bias_instability_dph", "rrw_deg_h_rt_h"] {
        assert!(
            v["noise"].get(key).is_some(),
            "noise.{key} missing: {}",
            v["noise"]
        );
    }
}

#[test]
fn allan_human_table_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("nbs.csv");
    write_nbs_log(&log);
    let p = log.to_str().unwrap();
    let (code, out, _) = gyrotherm(&["allan", "--input", p, "--kind", "hdev"]);
    assert_eq!(code, 0);
    assert!(
        out.contains("HDEV") && out.contains("angle random walk"),
        "{out}"
    );
    let (code, _, err) = gyrotherm(&["allan", "--input", p, "--taus", "2.5"]);
    assert_eq!(code, 2);
    assert!(err.contains("not an integer multiple"), "{err}");
    let (code, _, err) = gyrotherm(&["allan", "--input", p, "--column", "missing_dps"]);
    assert_eq!(code, 2);
    assert!(err.contains("no column `missing_dps`"), "{err}");
    // --plot into a folder that does not exist: an error naming the file, no panic.
    let bad = dir.path().join("no_such_dir/x.png");
    let (code, _, err) = gyrotherm(&["allan", "--input", p, "--plot", bad.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains("cannot write the plot") && err.contains("x.png"),
        "{err}"
    );
}

#[test]
fn evaluate_json_static_and_table() {
    let dir = tempfile::tempdir().unwrap();
    // Static log: NBS data; bias stability at τ = 10 s is the NIST std of 10-sample means.
    let log = dir.path().join("nbs.csv");
    write_nbs_log(&log);
    let (code, out, err) = gyrotherm(&[
        "evaluate",
        "--input",
        log.to_str().unwrap(),
        "--tau-s",
        "10",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let want = 9.296352e-02 * 3600.0;
    let got = v["bias_stability_dph"].as_f64().unwrap();
    assert!((got - want).abs() / want < 1e-6, "want {want} got {got}");
    assert_eq!(v["tau_s"].as_f64().unwrap(), 10.0);
    assert_eq!(v["samples"].as_u64().unwrap(), 1000);
    assert!(v.get("scale_factor").is_none());

    // Table log: 0, +20, 0, −20, 0 °/s, 100 s each, F = 0.01 + K±·Ω with K+ = 1.0002,
    // K− = 0.9998: asymmetry = 0.0004/1.0 = 400 ppm by the definition.
    let tlog = dir.path().join("table.csv");
    let mut s = String::from("time_s,gyro_dps,temp_c,table_dps\n");
    for (j, w) in [0.0f64, 20.0, 0.0, -20.0, 0.0].iter().enumerate() {
        for i in 0..100 {
            let k = if *w > 0.0 { 1.0002 } else { 0.9998 };
            s.push_str(&format!("{},{},25,{}\n", j * 100 + i, 0.01 + k * w, w));
        }
    }
    std::fs::write(&tlog, s).unwrap();
    let (code, out, err) = gyrotherm(&[
        "evaluate",
        "--input",
        tlog.to_str().unwrap(),
        "--tau-s",
        "10",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let asym = v["asymmetry_ppm"].as_f64().unwrap();
    assert!((asym - 400.0).abs() < 1e-6, "asymmetry {asym}");
    let k = v["scale_factor"].as_f64().unwrap();
    assert!((k - 1.0).abs() < 1e-12, "K {k}"); // LS over ±20, 0 of a ±0.0002 split: 1.0
    for key in ["nonlinearity_ppm", "sf_thermal_error_ppm"] {
        assert!(v[key].is_number(), "{key}: {}", v[key]);
    }
}

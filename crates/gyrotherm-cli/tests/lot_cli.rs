//! `--spec` and `gyrotherm lot` through the real binary: exit statuses 0/1/2, the messages of
//! a bad spec, and a lot filled by several processes at once.
//!
//! The limits below are set from the figures the simulator gives for these seeds (printed by
//! `gyrotherm evaluate --json` on the same logs): bias stability of the linear-compensated
//! static log is about 0.018 °/h and the thermal SF error of the rate-table log about 170 ppm,
//! so 0.05 °/h passes and 30 ppm fails.

mod cli;

use std::path::{Path, PathBuf};

use cli::{gyrotherm, outcome, run_ok, simulate_args};
use serde_json::Value;

/// A unit's logs and linear model: (model, static test, rate-table test).
fn unit(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let u = ["--unit", "random", "--unit-seed", "1"];
    let s = |name: &str, seed: &str, table: bool| {
        let mut a: Vec<&str> = u.to_vec();
        a.extend(["--seed", seed]);
        if table {
            a.extend(["--table-rate", "20"]);
        }
        simulate_args(dir, name, &a)
    };
    let (ts, tt) = (s("train_s.csv", "1", false), s("train_t.csv", "2", true));
    let (es, et) = (s("test_s.csv", "3", false), s("test_t.csv", "4", true));
    let model = dir.join("model.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--input"])
            .arg(&ts)
            .arg("--input")
            .arg(&tt)
            .arg("--out")
            .arg(&model),
    );
    (model, es, et)
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn evaluate_spec_exit_status_and_messages() {
    let dir = tempfile::tempdir().unwrap();
    let log = simulate_args(dir.path(), "s.csv", &["--profile", "room-steady"]);
    let log = log.to_str().unwrap();
    let pass = write(
        dir.path(),
        "pass.toml",
        "[limits]\nbias_stability_dph = { max = 1e6 }\n",
    );
    let (code, out, err) = outcome(&["evaluate", "--input", log, "--spec", &pass, "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["verdict"]["pass"], true);
    assert_eq!(j["verdict"]["figures"][0]["figure"], "bias_stability_dph");

    let fail = write(
        dir.path(),
        "fail.toml",
        "[limits]\nbias_stability_dph = { max = 1e-9 }\n",
    );
    let (code, out, _) = outcome(&["evaluate", "--input", log, "--spec", &fail]);
    assert_eq!(code, 1, "a missed limit exits 1");
    assert!(
        out.contains("FAIL") && out.contains("verdict: FAIL"),
        "{out}"
    );

    let typo = write(
        dir.path(),
        "typo.toml",
        "# acceptance\n[limits]\n  arw_deg_rt = { max = 0.01 }\n",
    );
    let (code, _, err) = outcome(&["evaluate", "--input", log, "--spec", &typo]);
    assert_eq!(code, 2);
    assert!(
        err.contains("typo.toml:3:3: unknown figure `arw_deg_rt`"),
        "{err}"
    );
    assert!(err.contains("did you mean `arw_deg_rt_h`"), "{err}");

    let sf = write(
        dir.path(),
        "sf.toml",
        "[limits]\nnonlinearity_ppm = { max = 10 }\n",
    );
    let (code, _, err) = outcome(&["evaluate", "--input", log, "--spec", &sf]);
    assert_eq!(
        code, 2,
        "a figure the log cannot give is an error, not a pass"
    );
    assert!(
        err.contains("`nonlinearity_ppm`") && err.contains("rate-table"),
        "{err}"
    );
}

#[test]
fn lot_add_list_report_and_parallel_stations() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (model, es, et) = unit(d);
    let spec = write(
        d,
        "spec.toml",
        "name = \"acceptance\"\n[limits]\nbias_stability_dph = { max = 0.05 }\nsf_thermal_error_ppm = { max = 30 }\n",
    );
    let loose = write(
        d,
        "loose.toml",
        "[limits]\nbias_stability_dph = { max = 0.05 }\n",
    );
    let db = d.join("lot.sqlite");
    let add = |serial: &str, spec: &str| {
        gyrotherm()
            .args(["lot", "add", "--db"])
            .arg(&db)
            .args(["--unit", serial, "--model"])
            .arg(&model)
            .arg("--test")
            .arg(&es)
            .arg("--test")
            .arg(&et)
            .args(["--spec", spec])
            .output()
            .unwrap()
    };
    let o = add("U-1", &spec);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = add("U-1", &loose);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    // Three stations at once: every run is kept.
    let kids: Vec<_> = (0..3)
        .map(|i| {
            gyrotherm()
                .args(["lot", "add", "--db"])
                .arg(&db)
                .args(["--unit", &format!("P-{i}"), "--model"])
                .arg(&model)
                .arg("--test")
                .arg(&es)
                .args(["--spec", &loose])
                .stdout(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    for mut k in kids {
        assert!(k.wait().unwrap().success());
    }

    let (code, out, err) = outcome(&["lot", "list", "--db", db.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let runs: Vec<Value> = serde_json::from_str(&out).unwrap();
    assert_eq!(runs.len(), 5);
    let u1: Vec<(&str, bool)> = runs
        .iter()
        .filter(|r| r["unit"] == "U-1")
        .map(|r| {
            (
                r["verdict"].as_str().unwrap(),
                r["latest"].as_bool().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        u1,
        [("fail", false), ("pass", true)],
        "both runs kept, newer marked"
    );
    let r0 = &runs[0];
    assert_eq!(r0["inputs"].as_array().unwrap().len(), 2);
    assert_eq!(r0["model_content_sha256"].as_str().unwrap().len(), 64);
    assert_eq!(r0["spec_name"], "acceptance");

    let out_dir = d.join("report");
    let (code, out, err) = outcome(&[
        "lot",
        "report",
        "--db",
        db.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // Newest runs: U-1 passed (loose), P-0..2 passed: 4 of 4.
    assert!(
        out.contains("4 units (5 runs): 4 passed, 0 failed"),
        "{out}"
    );
    assert!(out_dir.join("index.html").is_file() && out_dir.join("lot.csv").is_file());
}

#[test]
fn lot_errors_exit_2_and_change_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.sqlite");
    std::fs::write(&junk, b"not a database at all, just text that is long enough to look like a header page of something").unwrap();
    let before = std::fs::read(&junk).unwrap();
    let (code, _, err) = outcome(&["lot", "list", "--db", junk.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains("not an SQLite database") && err.contains("nothing was changed"),
        "{err}"
    );
    assert_eq!(std::fs::read(&junk).unwrap(), before);
}

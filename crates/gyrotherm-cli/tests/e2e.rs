//! End-to-end: simulate → train → compensate → evaluate through the real binary, the stream
//! path against the batch path, and the error messages a user sees.

use std::path::{Path, PathBuf};
use std::process::Stdio;

mod cli;
use cli::{gyrotherm, run_ok, simulate_args};

fn simulate(dir: &Path, name: &str, profile: &str, seed: u64, table: bool) -> PathBuf {
    let path = dir.join(name);
    let mut cmd = gyrotherm();
    cmd.args([
        "simulate",
        "--profile",
        profile,
        "--seed",
        &seed.to_string(),
        "--truth",
        "--out",
    ])
    .arg(&path);
    if table {
        cmd.args(["--table-rate", "20"]);
    }
    run_ok(&mut cmd);
    path
}

fn evaluate(path: &Path, column: &str) -> serde_json::Value {
    let out = run_ok(
        gyrotherm()
            .args(["evaluate", "--json", "--column", column, "--input"])
            .arg(path),
    );
    serde_json::from_slice(&out.stdout).expect("evaluate --json prints JSON")
}

#[test]
fn train_compensate_evaluate_and_stream_equals_batch() {
    let dir = tempfile::tempdir().unwrap();
    let train_s = simulate(dir.path(), "train_static.csv", "fast-cycle", 1, false);
    let train_t = simulate(dir.path(), "train_table.csv", "fast-cycle", 2, true);
    // 30,000 lines: the stream-vs-batch identity is checked on a full-length run.
    let test_s = simulate(dir.path(), "test_static.csv", "seed-shock", 3, false);
    let model = dir.path().join("model.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "poly", "--input"])
            .arg(&train_s)
            .arg("--input")
            .arg(&train_t)
            .arg("--out")
            .arg(&model),
    );
    let comp = dir.path().join("comp.csv");
    run_ok(
        gyrotherm()
            .args(["compensate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&test_s)
            .arg("--out")
            .arg(&comp),
    );

    // The compensated output is judged by the same metrics as the raw one: compensation must
    // remove most of the thermal drift (raw about 0.14 °/h on seed-shock; the polynomial fit
    // leaves a few hundredths) and cannot beat the simulator's noise-only floor.
    let raw = evaluate(&comp, "gyro_dps")["bias_stability_dph"]
        .as_f64()
        .unwrap();
    let fixed = evaluate(&comp, "gyro_comp_dps")["bias_stability_dph"]
        .as_f64()
        .unwrap();
    let floor = evaluate(&comp, "noise_dps")["bias_stability_dph"]
        .as_f64()
        .unwrap();
    assert!(
        fixed < 0.5 * raw,
        "compensated {fixed} °/h vs raw {raw} °/h"
    );
    assert!(
        fixed > 0.9 * floor,
        "compensated {fixed} °/h below the noise floor {floor} °/h"
    );

    // Every output row: the input columns as they were, then G = (Ĝ - B) / K (eq. 4 of the
    // paper) recomputed here from the written columns.
    let text = std::fs::read_to_string(&comp).unwrap();
    let input = std::fs::read_to_string(&test_s).unwrap();
    let mut rows = text.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let idx = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (gi, bi, ki, oi) = (
        idx("gyro_dps"),
        idx("bias_dps"),
        idx("scale"),
        idx("gyro_comp_dps"),
    );
    for (row, in_row) in rows.zip(input.lines().skip(1)) {
        assert!(
            row.starts_with(in_row),
            "input columns not passed through: {row}"
        );
        // Every field up to gyro_comp_dps is a number; then status, coverage, sigma_dph.
        let fields: Vec<&str> = row.split(',').collect();
        let f: Vec<f64> = fields[..=oi].iter().map(|v| v.parse().unwrap()).collect();
        let tail = &fields[oi + 1..];
        assert_eq!(tail.len(), 3, "{row}");
        assert!(
            tail[1].is_empty() || gyrotherm_core::coverage::Coverage::parse(tail[1]).is_some(),
            "{row}"
        );
        assert!(
            tail[2].is_empty() || tail[2].parse::<f64>().is_ok_and(|s| s > 0.0),
            "{row}"
        );
        let want = (f[gi] - f[bi]) / f[ki];
        assert!(
            (f[oi] - want).abs() <= 1e-15 * want.abs().max(1e-3),
            "{row}"
        );
    }
    assert_eq!(text.lines().count(), input.lines().count());

    // --stream: same numbers, byte for byte.
    let stream = run_ok(
        gyrotherm()
            .args(["compensate", "--stream", "--model"])
            .arg(&model)
            .stdin(Stdio::from(std::fs::File::open(&test_s).unwrap())),
    );
    assert!(
        stream.stdout == text.as_bytes(),
        "stream output differs from batch output"
    );
}

#[test]
fn lstm_training_from_the_cli_writes_a_loadable_model() {
    let dir = tempfile::tempdir().unwrap();
    let train_s = simulate(dir.path(), "s.csv", "fast-cycle", 5, false);
    let model = dir.path().join("lstm.json");
    run_ok(
        gyrotherm()
            .args([
                "train", "--method", "residual", "--epochs", "3", "--seed", "9", "--input",
            ])
            .arg(&train_s)
            .arg("--out")
            .arg(&model),
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["method"], "residual");
    assert_eq!(m["training"]["seed"], 9);
    assert!(m["bias"].is_object() && m["scale"].is_null());
    let comp = dir.path().join("c.csv");
    run_ok(
        gyrotherm()
            .args(["compensate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&train_s)
            .arg("--out")
            .arg(&comp),
    );
    assert!(comp.exists());
}

/// `compare --json`: the raw figure equals what `evaluate` computes on the same log (an
/// independent path through the metrics), the noise floor equals `evaluate` on the truth
/// column, the `lstm` method is below the linear fit (`docs/experiments/confirmation.md`:
/// 41–81 % below in 16 of 16 confirmation cases), and the models say why a residual LSTM was
/// or was not kept.
#[test]
fn compare_json_matches_evaluate_and_reports_the_lstm_gate() {
    let dir = tempfile::tempdir().unwrap();
    let train_s = simulate(dir.path(), "train_static.csv", "seed-shock", 1, false);
    let train_t = simulate(dir.path(), "train_table.csv", "seed-shock", 2, true);
    let test_s = simulate(dir.path(), "test_static.csv", "slow-ramp", 3, false);
    let out = run_ok(
        gyrotherm()
            // The residual method: this test reads its LSTM gate. The published column is
            // left out (its own test below).
            .args(["compare", "--json"])
            .args(["--methods", "linear,poly,residual", "--train"])
            .arg(&train_s)
            .arg("--train")
            .arg(&train_t)
            .arg("--test")
            .arg(&test_s),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let t = &v["tests"][0];
    let raw = t["raw"]["bias_stability_dph"].as_f64().unwrap();
    let want_raw = evaluate(&test_s, "gyro_dps")["bias_stability_dph"]
        .as_f64()
        .unwrap();
    assert!(
        (raw - want_raw).abs() <= 1e-12 * want_raw,
        "raw {raw} vs evaluate {want_raw}"
    );
    let floor = t["floor_dph"].as_f64().unwrap();
    let want_floor = evaluate(&test_s, "noise_dps")["bias_stability_dph"]
        .as_f64()
        .unwrap();
    assert!(
        (floor - want_floor).abs() <= 1e-12 * want_floor,
        "floor {floor} vs evaluate {want_floor}"
    );
    let fig = |m: &str| t["methods"][m]["bias_stability_dph"].as_f64().unwrap();
    assert!(
        fig("residual") < fig("linear"),
        "residual {} vs linear {}",
        fig("residual"),
        fig("linear")
    );
    let models = v["models"].as_array().unwrap();
    let model = |m: &str| models.iter().find(|x| x["key"] == m).unwrap();
    assert!(model("residual")["bias_lstm_validation_improvement"].is_number());
    assert!(
        model("residual")["bias_lstm_run_gate"].is_null(),
        "one static log: no run gate"
    );
    assert!(model("linear")["bias_lstm_validation_improvement"].is_null());
    // A model is named by what it holds: the label says "LSTM" exactly when a sub-model has one.
    let lstm_kept = ["bias_model", "scale_model"].iter().any(|k| {
        model("residual")[*k]
            .as_str()
            .is_some_and(|s| s.contains("lstm"))
    });
    let label = model("residual")["label"].as_str().unwrap();
    assert_eq!(
        label,
        if lstm_kept {
            "LS + LSTM"
        } else {
            "thermal-state LS"
        },
        "{:?}",
        model("residual")
    );
    assert_eq!(model("linear")["label"], "linear");
    assert_eq!(
        models.len(),
        3,
        "--methods linear,poly,residual: three columns"
    );
}

/// By default the published recipe (He et al. 2024) has its own column beside the default
/// `lstm`-method model, named "LSTM, He et al." in the table and in `--json`; `--methods`
/// chooses the columns and their order, and a column asked for twice is refused.
#[test]
fn compare_shows_the_published_recipe_beside_the_default() {
    let dir = tempfile::tempdir().unwrap();
    let train_s = simulate(dir.path(), "train_static.csv", "seed-shock", 1, false);
    let train_t = simulate(dir.path(), "train_table.csv", "seed-shock", 2, true);
    let test_s = simulate(dir.path(), "test_static.csv", "slow-ramp", 3, false);
    let compare = |extra: &[&str]| {
        let mut c = gyrotherm();
        c.args(["compare", "--epochs", "5", "--train"])
            .arg(&train_s)
            .arg("--train")
            .arg(&train_t)
            .arg("--test")
            .arg(&test_s)
            .args(extra);
        c
    };
    let out = run_ok(&mut compare(&["--json"]));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let keys: Vec<&str> = v["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["key"].as_str().unwrap())
        .collect();
    assert_eq!(keys, ["linear", "poly", "auto", "published"]);
    let published = &v["models"][3];
    assert_eq!(published["label"], "LSTM, He et al.");
    assert_eq!(published["method"], "published");
    assert_eq!(published["recipe"], "published");
    assert_eq!(published["bias_model"], "lstm");
    assert_eq!(published["bias_epochs"], 5);
    // The default chooses between `thermal` and `thermal-lstm`; its column is named for what
    // the chosen model holds, whichever it is.
    let default = &v["models"][2];
    assert_eq!(default["recipe"], "auto");
    let (method, label) = if default["bias_model"] == "least squares" {
        ("thermal", "thermal-state LS")
    } else {
        ("thermal-lstm", "LS + LSTM")
    };
    assert_eq!(default["method"], method);
    assert_eq!(default["label"], label);
    let methods = v["tests"][0]["methods"].as_object().unwrap();
    for k in keys {
        assert!(methods[k]["bias_stability_dph"].is_number(), "{k}");
    }
    // The table: one column per model, the published one named after its authors.
    let out = run_ok(&mut compare(&["--methods", "published,linear"]));
    let table = String::from_utf8_lossy(&out.stdout);
    let header = table
        .lines()
        .find(|l| l.trim_start().starts_with("figure"))
        .unwrap_or_else(|| panic!("no header in:\n{table}"));
    let cols: Vec<&str> = header
        .split("  ")
        .map(str::trim)
        .filter(|c| !c.is_empty())
        .collect();
    assert_eq!(
        cols,
        ["figure", "raw", "LSTM, He et al.", "linear", "noise floor"]
    );
    // A column asked for twice is refused.
    let out = compare(&["--methods", "published,published"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("published column is asked for twice"), "{err}");
    // The removed spellings (`--recipe R`, method `lstm`) are refused by the parser, which
    // names the current ones.
    let out = compare(&["--recipe", "published"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unexpected argument '--recipe'"), "{err}");
    let out = compare(&["--methods", "lstm,published"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("invalid value 'lstm'") && err.contains("thermal"),
        "{err}"
    );
}

/// `--validate-on-runs` with two static logs: the output names each log with its figure for
/// the LSTM trained without it (`fit::RecipeSettings::validate_on_runs`).
#[test]
fn validate_on_runs_reports_each_left_out_log() {
    let dir = tempfile::tempdir().unwrap();
    let a = simulate(dir.path(), "a_static.csv", "fast-cycle", 5, false);
    let b = simulate(dir.path(), "b_static.csv", "slow-ramp", 6, false);
    let model = dir.path().join("m.json");
    let out = run_ok(
        gyrotherm()
            .args([
                "train",
                "--method",
                "residual",
                "--epochs",
                "3",
                "--validate-on-runs",
            ])
            .arg("--input")
            .arg(&a)
            .arg("--input")
            .arg(&b)
            .arg("--out")
            .arg(&model),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    let line = err
        .lines()
        .find(|l| l.contains("trained without each run"))
        .unwrap_or_else(|| panic!("no per-run line in:\n{err}"));
    for name in ["a_static.csv", "b_static.csv"] {
        assert!(line.contains(name), "{name} missing from {line:?}");
    }
    assert!(line.contains('%'), "no figure in {line:?}");
}

#[test]
fn bad_inputs_say_where_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time_s,gyro_dps,temp_c\n0,0.001,20\n1,0.001,4;5\n").unwrap();
    let out = gyrotherm()
        .args(["train", "--method", "linear", "--out"])
        .arg(dir.path().join("m.json"))
        .arg("--input")
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.csv:3: column temp_c: \"4;5\" is not a number"),
        "{err}"
    );
    assert!(
        !dir.path().join("m.json").exists(),
        "no model may be written on error"
    );

    // A run at constant temperature cannot determine a temperature coefficient.
    let flat = dir.path().join("flat.csv");
    let mut text = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..500 {
        text.push_str(&format!("{i},0.001,23\n"));
    }
    std::fs::write(&flat, text).unwrap();
    let out = gyrotherm()
        .args(["train", "--method", "linear", "--out"])
        .arg(dir.path().join("m.json"))
        .arg("--input")
        .arg(&flat)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("constant"), "{err}");

    // A model file that is not one.
    let junk = dir.path().join("junk.json");
    std::fs::write(&junk, "{\"format_version\": 99}").unwrap();
    let out = gyrotherm()
        .args(["compensate", "--model"])
        .arg(&junk)
        .arg("--input")
        .arg(&flat)
        .arg("--out")
        .arg(dir.path().join("o.csv"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("junk.json") && err.contains("format_version 99"),
        "{err}"
    );
}

/// `simulate --unit random --unit-seed N` writes the drawn unit beside the log, and the same
/// seed gives the same unit as the library's `random_unit` (independent: the library call).
#[test]
fn simulate_random_unit_writes_its_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let out = simulate_args(
        dir.path(),
        "r.csv",
        &[
            "--profile",
            "room-steady",
            "--unit",
            "random",
            "--unit-seed",
            "12",
        ],
    );
    let text = std::fs::read_to_string(dir.path().join("r.csv.unit.json")).unwrap();
    let unit = gyrotherm::sim::FogUnit::from_json_str(&text, "sidecar").unwrap();
    assert_eq!(unit, gyrotherm::sim::random_unit(12));
    let bad = gyrotherm()
        .args(["simulate", "--unit", "random", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--unit-seed"));
}

/// A log at one sample per 15 s (100 s is no multiple of it): evaluate takes the multiple
/// nearest 100 s, 105 s = 7 × 15 s, and says so; `--tau-s` still chooses.
#[test]
fn evaluate_coarse_log_takes_the_nearest_multiple_of_the_period() {
    let dir = tempfile::tempdir().unwrap();
    let path = simulate_args(
        dir.path(),
        "coarse.csv",
        &[
            "--profile",
            "room-steady",
            "--rate-hz",
            "0.06666666666666667",
        ],
    );
    let out = run_ok(
        gyrotherm()
            .args(["evaluate", "--json", "--input"])
            .arg(&path),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["tau_s"].as_f64(), Some(105.0));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nearest 100 s"));
    let out = run_ok(
        gyrotherm()
            .args(["evaluate", "--json", "--tau-s", "150", "--input"])
            .arg(&path),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["tau_s"].as_f64(), Some(150.0));
}

/// `compare` and `report` on logs at one sample per 15 s: the default τ is the multiple of
/// the period nearest 100 s, 105 s = 7 × 15 s (as `evaluate` takes it), said on stderr, and
/// every column gets its figure; `--tau-s` still chooses.
#[test]
fn compare_and_report_take_the_nearest_multiple_of_a_coarse_period() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |name: &str, profile: &str, seed: &str, extra: &[&str]| {
        let args = ["--profile", profile, "--seed", seed];
        let coarse = ["--rate-hz", "0.06666666666666667"];
        simulate_args(dir.path(), name, &[&args[..], &coarse, extra].concat())
    };
    let train_s = sim("train_static.csv", "seed-shock", "1", &[]);
    let train_t = sim(
        "train_table.csv",
        "seed-shock",
        "2",
        &["--table-rate", "20", "--table-segment", "600"],
    );
    let test_s = sim("test_static.csv", "slow-ramp", "3", &["--truth"]);
    let args = |cmd: &str| {
        let mut c = gyrotherm();
        c.args([cmd, "--epochs", "3", "--train"])
            .arg(&train_s)
            .arg("--train")
            .arg(&train_t)
            .arg("--test")
            .arg(&test_s);
        c
    };
    let out = run_ok(args("compare").arg("--json"));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["tau_s"].as_f64(), Some(105.0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("τ = 105 s") && err.contains("15 s sample period nearest 100 s"),
        "{err}"
    );
    let methods = v["tests"][0]["methods"].as_object().unwrap();
    assert_eq!(methods.len(), 4, "{methods:?}");
    for (k, m) in methods {
        assert!(
            m["bias_stability_dph"].as_f64().is_some_and(f64::is_finite),
            "{k}"
        );
    }
    let out = run_ok(args("compare").args(["--json", "--tau-s", "150"]));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["tau_s"].as_f64(), Some(150.0));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("nearest 100 s"));
    let report = dir.path().join("report");
    let out = run_ok(args("report").arg("--out").arg(&report));
    assert!(String::from_utf8_lossy(&out.stderr).contains("τ = 105 s"));
    assert!(String::from_utf8_lossy(&out.stdout).contains("τ = 105 s"));
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(html.contains("τ = 105 s"), "the report's table says τ");
}

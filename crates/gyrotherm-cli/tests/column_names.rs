//! A log whose columns are not called `time_s`, `gyro_dps`, `temp_c`: the model trained on it
//! remembers them (so `compensate` needs no column options again, though they still override),
//! and `evaluate` and `allan` call the gyro column by its name in the file.

use std::path::{Path, PathBuf};

use serde_json::Value;

mod cli;
use cli::{gyrotherm, outcome, run_ok};

/// A short chamber profile (4801 s at 1 Hz): warm, soak, cold, soak, back (as the Python
/// tests' `logs` fixture).
const PROFILE: &str = "1,22\n900,40\n900,40\n1200,0\n900,0\n900,22\n";

/// A simulated static log on [`PROFILE`] with the header renamed to `t,w_dps,T`; also the
/// same log under the standard names.
fn renamed_log(dir: &Path, seed: &str) -> (PathBuf, PathBuf) {
    let prof = dir.join("profile.csv");
    std::fs::write(&prof, PROFILE).unwrap();
    let std_path = dir.join(format!("std{seed}.csv"));
    run_ok(gyrotherm().args([
        "simulate",
        "--profile-file",
        prof.to_str().unwrap(),
        "--seed",
        seed,
        "--out",
        std_path.to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(&std_path).unwrap();
    let (header, rest) = text.split_once('\n').unwrap();
    let renamed: Vec<&str> = header
        .split(',')
        .map(|h| match h {
            "time_s" => "t",
            "gyro_dps" => "w_dps",
            "temp_c" => "T",
            h => h,
        })
        .collect();
    let path = dir.join(format!("renamed{seed}.csv"));
    std::fs::write(&path, format!("{}\n{rest}", renamed.join(","))).unwrap();
    (path, std_path)
}

const RENAMED: [&str; 6] = ["--time-col", "t", "--gyro-col", "w_dps", "--temp-col", "T"];

#[test]
fn a_model_remembers_the_columns_it_was_trained_on() {
    let dir = tempfile::tempdir().unwrap();
    let (train, train_std) = renamed_log(dir.path(), "3");
    let (held, held_std) = renamed_log(dir.path(), "5");
    let model = dir.path().join("m.json");
    let mut args = vec![
        "train",
        "--method",
        "linear",
        "--input",
        train.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
    ];
    args.extend(RENAMED);
    let (code, _, err) = outcome(&args);
    assert_eq!(code, 0, "{err}");
    let m: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["columns"]["gyro_col"], "w_dps", "{m}");
    assert_eq!(m["columns"]["time_col"], "t");
    assert_eq!(m["columns"]["temp_col"], "T");
    assert_eq!(m["columns"]["gyro_unit"], "dps");

    // No column options: the model's own.
    let out = dir.path().join("comp.csv");
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        model.to_str().unwrap(),
        "--input",
        held.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let renamed_out = std::fs::read_to_string(&out).unwrap();
    assert!(renamed_out.starts_with("t,w_dps,T,"), "{renamed_out:.80}");

    // Options given override the model's: the same log under the standard names gives the
    // same compensated numbers.
    let out_std = dir.path().join("comp_std.csv");
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        model.to_str().unwrap(),
        "--input",
        held_std.to_str().unwrap(),
        "--out",
        out_std.to_str().unwrap(),
        "--time-col",
        "time_s",
        "--gyro-col",
        "gyro_dps",
        "--temp-col",
        "temp_c",
    ]);
    assert_eq!(code, 0, "{err}");
    let std_out = std::fs::read_to_string(&out_std).unwrap();
    assert_eq!(
        cli::column(&renamed_out, "gyro_comp_dps"),
        cli::column(&std_out, "gyro_comp_dps")
    );
    // One option given, the others the model's: a standard-named log is refused, naming the
    // model's column it lacks.
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        model.to_str().unwrap(),
        "--input",
        held_std.to_str().unwrap(),
        "--out",
        out_std.to_str().unwrap(),
        "--gyro-col",
        "gyro_dps",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains('t') && err.contains("column"), "{err}");

    // `lot add` reads the logs with the model's columns too, with no column options.
    let db = dir.path().join("lot.sqlite");
    let (code, out, err) = outcome(&[
        "lot",
        "add",
        "--db",
        db.to_str().unwrap(),
        "--unit",
        "U-1",
        "--model",
        model.to_str().unwrap(),
        "--test",
        held.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "lot add with the model's own columns: {out}{err}");
    // A column option given still overrides: the renamed log has no `gyro_dps`.
    let (code, _, err) = outcome(&[
        "lot",
        "add",
        "--db",
        db.to_str().unwrap(),
        "--unit",
        "U-2",
        "--model",
        model.to_str().unwrap(),
        "--test",
        held.to_str().unwrap(),
        "--gyro-col",
        "gyro_dps",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("gyro_dps"), "{err}");
    let _ = train_std;
}

#[test]
fn a_log_without_time_stamps_is_told_why_a_sample_period_cannot_stand_in() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("no_time.csv");
    std::fs::write(&log, "gyro_dps,temp_c\n0.01,22\n0.01,22\n0.01,22\n").unwrap();
    let (code, _, err) = outcome(&[
        "evaluate",
        "--input",
        log.to_str().unwrap(),
        "--sample-period-s",
        "1",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("time_s"), "{err}");
    assert!(err.contains("--sample-period-s"), "{err}");
    assert!(err.contains("--time-col"), "{err}");
}

#[test]
fn a_model_file_without_columns_loads_and_keeps_its_seal() {
    // A file as builds before `columns` wrote it: the content without the key, sealed over
    // that content (`model seal` of this build writes exactly that for a model without them).
    let dir = tempfile::tempdir().unwrap();
    let (_, train_std) = renamed_log(dir.path(), "3");
    let model = dir.path().join("m.json");
    run_ok(gyrotherm().args([
        "train",
        "--method",
        "linear",
        "--input",
        train_std.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
    ]));
    let mut m: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let o = m.as_object_mut().unwrap();
    assert!(o.remove("columns").is_some());
    o.remove("content_sha256");
    std::fs::write(&model, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    run_ok(gyrotherm().args(["model", "seal", model.to_str().unwrap()]));
    let sealed = std::fs::read_to_string(&model).unwrap();
    assert!(!sealed.contains("\"columns\""), "{sealed}");
    let check = run_ok(gyrotherm().args(["model", "check", model.to_str().unwrap()]));
    assert!(String::from_utf8_lossy(&check.stdout).contains("ok, sealed"));
    let out = dir.path().join("comp.csv");
    let c = run_ok(gyrotherm().args([
        "compensate",
        "--model",
        model.to_str().unwrap(),
        "--input",
        train_std.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(
        !String::from_utf8_lossy(&c.stderr).contains("content_sha256"),
        "{}",
        String::from_utf8_lossy(&c.stderr)
    );
}

#[test]
fn evaluate_and_allan_call_the_column_by_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let (log, _) = renamed_log(dir.path(), "7");
    let p = log.to_str().unwrap();
    let mut args = vec!["evaluate", "--input", p, "--json"];
    args.extend(RENAMED);
    let (code, out, err) = outcome(&args);
    assert_eq!(code, 0, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["column"], "w_dps", "{v}");

    for column in [None, Some("w_dps")] {
        let mut args = vec!["allan", "--input", p, "--taus", "1,10", "--json"];
        args.extend(RENAMED);
        if let Some(c) = column {
            args.extend(["--column", c]);
        }
        let (code, out, err) = outcome(&args);
        assert_eq!(code, 0, "--column {column:?}: {err}");
        let v: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["column"], "w_dps", "{v}");
        // Read as the gyro column (in °/s), so its noise terms are given.
        assert!(v["noise"].is_object(), "{v}");
    }
    // The temperature column by its name in the file.
    let mut args = vec!["allan", "--input", p, "--taus", "1,10", "--column", "T"];
    args.extend(RENAMED);
    let (code, out, err) = outcome(&args);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("OADEV of T "), "{out}");
    let mut args = vec!["evaluate", "--input", p];
    args.extend(RENAMED);
    let (code, out, err) = outcome(&args);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("w_dps ("), "{out}");
}

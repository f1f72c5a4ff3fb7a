//! Wrong results with exit 0, and messages that named the wrong cause, through the real
//! binary: each case now exits 2 with the real cause, or reads what it could not.

use std::path::{Path, PathBuf};

mod cli;
use cli::{fast_cycle_training_pair, gyrotherm, outcome, run_ok, simulate_args};

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `n` samples every `period_s` of a constant 0.001 °/s at 25 °C.
fn constant_log(dir: &Path, name: &str, n: usize, period_s: f64) -> PathBuf {
    let mut s = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..n {
        s.push_str(&format!("{},0.001,25\n", i as f64 * period_s));
    }
    write(dir, name, &s)
}

/// `text` with the CSV column `name` renamed to `to` (written as given, quotes and all).
fn rename_column(text: &str, name: &str, to: &str) -> String {
    let (head, body) = text.split_once('\n').unwrap();
    let head: Vec<&str> = head
        .split(',')
        .map(|h| if h == name { to } else { h })
        .collect();
    format!("{}\n{body}", head.join(","))
}

/// `text` without the CSV column `name`.
fn drop_column(text: &str, name: &str) -> String {
    let k = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == name)
        .unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let f: Vec<&str> = line
            .split(',')
            .enumerate()
            .filter(|(i, _)| *i != k)
            .map(|(_, f)| f)
            .collect();
        out.push_str(&f.join(","));
        out.push('\n');
    }
    out
}

#[test]
fn plan_writes_only_profiles_simulate_reads() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("profile.txt");
    let env = ["--temp-min-c", "-10", "--temp-max-c", "40"];
    // Ramps of 6e301 s (an envelope rate of 1e-300 °C/min) and 7e15 s (a chamber of
    // 1e-12 °C/min): beyond the 1e7 s a profile segment may last.
    for extra in [
        &["--max-rate-c-per-min", "1e-300"][..],
        &[
            "--max-rate-c-per-min",
            "5",
            "--chamber-max-rate-c-per-min",
            "1e-12",
        ][..],
    ] {
        let mut args = vec!["plan", "--out", p(&out)];
        args.extend(env);
        args.extend(extra);
        let (code, stdout, err) = outcome(&args);
        assert_eq!(code, 2, "{extra:?}: {stdout}{err}");
        assert!(
            err.contains("not one `simulate --profile-file` accepts"),
            "{err}"
        );
        assert!(!stdout.contains("inf"), "{stdout}");
        assert!(!out.exists());
    }
    // An envelope of 1e308 °C and a chamber beyond the profile limits are setting errors,
    // each said once.
    for (args, says) in [
        (
            &[
                "--temp-min-c",
                "0",
                "--temp-max-c",
                "1e308",
                "--max-rate-c-per-min",
                "5",
            ][..],
            "temp_max_c = 1e308 °C is not a temperature a flight reaches",
        ),
        (
            &[
                "--chamber-max-rate-c-per-min",
                "0",
                "--max-rate-c-per-min",
                "5",
            ][..],
            "is not a positive rate",
        ),
        (&["--chamber-max-c", "500"][..], "hottest set point"),
    ] {
        let mut a = vec!["plan"];
        a.extend(args);
        let (code, _, err) = outcome(&a);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert_eq!(err.matches(says).count(), 1, "{err}");
    }
    // A constant flight log gives no rate: refused, unless the rate is given; then the
    // profile written is one `simulate --profile-file` reads.
    let flat = constant_log(dir.path(), "flat.csv", 600, 1.0);
    let (code, _, err) = outcome(&["plan", "--flight", p(&flat)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("temperature does not change"), "{err}");
    let one = constant_log(dir.path(), "one.csv", 1, 1.0);
    let (code, _, err) = outcome(&["plan", "--flight", p(&one)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("(1 sample)"), "{err}");
    let (code, stdout, err) = outcome(&[
        "plan",
        "--flight",
        p(&flat),
        "--max-rate-c-per-min",
        "3",
        "--out",
        p(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!stdout.contains("inf"), "{stdout}");
    let (code, _, err) = outcome(&[
        "simulate",
        "--profile-file",
        p(&out),
        "--rate-hz",
        "0.1",
        "--out",
        p(&dir.path().join("sim.csv")),
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_unit_file_with_a_tiny_sensor_resolution_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let unit = write(dir.path(), "u.json", r#"{"sensor_resolution_c": 1e-320}"#);
    let out = dir.path().join("s.csv");
    let (code, _, err) = outcome(&[
        "simulate",
        "--unit",
        p(&unit),
        "--profile",
        "room-steady",
        "--out",
        p(&out),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("sensor_resolution_c"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_gap_over_the_per_gap_sample_cap_names_the_cap() {
    let dir = tempfile::tempdir().unwrap();
    let log = write(
        dir.path(),
        "gap.csv",
        "time_s,gyro_dps,temp_c\n0,0,25\n1,0,25\n2,0,25\n3,0,25\n30000000,0,25\n",
    );
    let (code, _, err) = outcome(&[
        "evaluate",
        "--input",
        p(&log),
        "--fill-gaps-max-s",
        "40000000",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("29999996 samples, more than the 10000000 one gap may be filled with"),
        "{err}"
    );
}

#[test]
fn a_rate_table_log_without_its_table_column_is_not_trained_as_static() {
    let dir = tempfile::tempdir().unwrap();
    let (_, t) = fast_cycle_training_pair(dir.path());
    let text = std::fs::read_to_string(&t).unwrap();
    let bare = write(dir.path(), "bare.csv", &drop_column(&text, "table_dps"));
    let (code, _, err) = outcome(&[
        "train",
        "--method",
        "linear",
        "--input",
        p(&bare),
        "--out",
        p(&dir.path().join("m.json")),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("no table-rate column") && err.contains("looks like a rate-table run"),
        "{err}"
    );
}

#[test]
fn an_all_zero_table_column_is_a_static_unit_run() {
    let dir = tempfile::tempdir().unwrap();
    let s = simulate_args(
        dir.path(),
        "s.csv",
        &["--imu", "--profile", "fast-cycle", "--seed", "1"],
    );
    let text = std::fs::read_to_string(&s).unwrap();
    let mut zero = String::new();
    for (i, line) in text.lines().enumerate() {
        zero.push_str(line);
        zero.push_str(if i == 0 { ",table_dps\n" } else { ",0\n" });
    }
    let zero = write(dir.path(), "zero.csv", &zero);
    let (code, _, err) = outcome(&[
        "train",
        "--method",
        "linear",
        "--gyro-col",
        "gyro_x_dps,gyro_y_dps,gyro_z_dps",
        "--temp-col",
        "temp_case_c",
        "--input",
        p(&zero),
        "--out",
        p(&dir.path().join("u.json")),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("table-rate column table_dps is all zeros: read as a static run"),
        "{err}"
    );
}

/// One trained model, then what compensate, train, lot add and compare refuse or read.
#[test]
fn compensate_train_lot_and_compare_name_the_real_cause() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Training logs whose temperature column's quoted name holds a line break.
    let (s, t) = fast_cycle_training_pair(d);
    let name = "\"temp\nc\"";
    let col = "temp\nc";
    let rs = write(
        d,
        "rs.csv",
        &rename_column(&std::fs::read_to_string(&s).unwrap(), "temp_c", name),
    );
    let rt = write(
        d,
        "rt.csv",
        &rename_column(&std::fs::read_to_string(&t).unwrap(), "temp_c", name),
    );
    let model = d.join("m.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--temp-col", col, "--input"])
            .arg(&rs)
            .arg("--input")
            .arg(&rt)
            .arg("--out")
            .arg(&model),
    );
    // The model compensates its own training log: compensate reads the header as train does.
    let once = d.join("once.csv");
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        p(&model),
        "--temp-col",
        col,
        "--input",
        p(&rs),
        "--out",
        p(&once),
    ]);
    assert_eq!(code, 0, "{err}");
    let out = std::fs::read_to_string(&once).unwrap();
    assert!(
        out.starts_with("time_s,gyro_dps,\"temp\nc\","),
        "{:?}",
        &out[..60]
    );

    // Compensating the output again would repeat its columns: refused, naming them.
    let twice = d.join("twice.csv");
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        p(&model),
        "--temp-col",
        col,
        "--input",
        p(&once),
        "--out",
        p(&twice),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("already has the columns `bias_dps`, `scale`, `gyro_comp_dps`, `status`"),
        "{err}"
    );
    assert!(!twice.exists());

    // 0.01 Hz: the model steps every second and reads dT over 20 s.
    let slow = constant_log(d, "slow.csv", 203, 100.0);
    let slow_text = rename_column(&std::fs::read_to_string(&slow).unwrap(), "temp_c", name);
    let slow = write(d, "slow.csv", &slow_text);
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        p(&model),
        "--temp-col",
        col,
        "--input",
        p(&slow),
        "--out",
        p(&d.join("slow_out.csv")),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("one sample every 100 s (0.01 Hz")
            && err.contains("at least one sample every 20 s"),
        "{err}"
    );
    let (code, _, err) = outcome(&[
        "train",
        "--method",
        "linear",
        "--temp-col",
        col,
        "--input",
        p(&slow),
        "--out",
        p(&d.join("slow.json")),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("one sample every 100 s (0.01 Hz)"), "{err}");
    // A live stream is not stopped, but the cause of its held lines is said.
    let streamed = gyrotherm()
        .args([
            "compensate",
            "--stream",
            "--model",
            p(&model),
            "--temp-col",
            col,
        ])
        .stdin(std::fs::File::open(&slow).unwrap())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&streamed.stderr);
    assert_eq!(streamed.status.code(), Some(0), "{err}");
    assert!(
        err.contains("202 of 202 time steps are longer than 20 s"),
        "{err}"
    );

    // Unit names: trimmed, not empty, no control characters; nothing recorded.
    let db = d.join("lot.sqlite");
    for unit in ["", " ", "A\u{7}1"] {
        let (code, _, err) = outcome(&[
            "lot",
            "add",
            "--db",
            p(&db),
            "--unit",
            unit,
            "--model",
            p(&model),
            "--temp-col",
            col,
            "--test",
            p(&rs),
        ]);
        assert_eq!(code, 2, "{unit:?}: {err}");
        assert!(err.contains("unit name"), "{err}");
        assert!(!db.exists(), "{unit:?}");
    }
    // A spec's limit no log gives is said once (not `X: X`).
    let spec = write(
        d,
        "arw.toml",
        "[limits]\nsf_thermal_error_ppm = { max = 30 }\n",
    );
    let (code, _, err) = outcome(&[
        "lot",
        "add",
        "--db",
        p(&db),
        "--unit",
        "A1",
        "--model",
        p(&model),
        "--temp-col",
        col,
        "--test",
        p(&rs),
        "--spec",
        p(&spec),
    ]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        err.matches("the spec limits `sf_thermal_error_ppm`")
            .count(),
        1,
        "{err}"
    );

    // τ beyond the held-out log, in seconds.
    let (code, _, err) = outcome(&[
        "compare",
        "--methods",
        "linear",
        "--temp-col",
        col,
        "--train",
        p(&rs),
        "--train",
        p(&rt),
        "--test",
        p(&rs),
        "--tau-s",
        "1e300",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("τ = 1e300 s is longer than half the log"),
        "{err}"
    );
    assert!(!err.contains("18446744073709551615"), "{err}");
}

#[test]
fn an_arw_limit_on_a_constant_static_log_says_the_curve_lacks_it() {
    let dir = tempfile::tempdir().unwrap();
    let log = constant_log(dir.path(), "const.csv", 1000, 1.0);
    let spec = write(
        dir.path(),
        "arw.toml",
        "[limits]\narw_deg_rt_h = { max = 0.01 }\n",
    );
    let (code, _, err) = outcome(&["evaluate", "--input", p(&log), "--spec", p(&spec)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("no log's curve showed it") && !err.contains("needs a static log"),
        "{err}"
    );
}

/// `plan` and `compensate` measure a log's temperature rate differently (a 100 s moving
/// average for the chamber plan, the model's own dT window for extrapolation); each says
/// which, so the two figures for one flight are not read as a contradiction.
#[test]
fn plan_and_compensate_name_the_rate_they_print() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let train = simulate_args(d, "ramp.csv", &["--profile", "slow-ramp", "--seed", "1"]);
    let flight = simulate_args(d, "flight.csv", &["--profile", "airborne", "--seed", "2"]);
    let model = d.join("m.json");
    let (code, _, err) = outcome(&[
        "train",
        "--method",
        "linear",
        "--input",
        p(&train),
        "--out",
        p(&model),
    ]);
    assert_eq!(code, 0, "{err}");
    let out = d.join("comp.csv");
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        p(&model),
        "--input",
        p(&flight),
        "--out",
        p(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("temperature rate (the model's dT over 20 s)"),
        "the airborne flight is faster than the slow ramp: {err}"
    );
    let (code, plan, err) = outcome(&["plan", "--flight", p(&flight)]);
    assert_eq!(code, 0, "{err}");
    assert!(plan.contains("rate of its 100 s moving average"), "{plan}");
    // Without training logs no lag is identified: every soak keeps the fixed length, and the
    // plan says so.
    assert!(
        plan.contains("soaks: first at each extreme 1440 s (0.4 h): no lag identified"),
        "{plan}"
    );
}

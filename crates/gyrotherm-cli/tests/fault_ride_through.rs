//! Temperature-sensor faults through the real binary: a seed-shock static run with injected
//! spikes (85.0, −127.0, ±10–40 °C), 30 s NaN bursts and 120 s stuck episodes is compensated
//! with a bias stability within 10 % of the same run without faults, no NaN anywhere, one
//! output line per input line, and the stream and batch outputs identical.

use std::process::Stdio;

mod cli;
use cli::{bias_stability_dph, column};
use cli::{gyrotherm, run_ok};

use cli::simulate_args as simulate;

#[test]
fn faulted_run_keeps_its_bias_stability() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (train_s, train_t) = cli::fast_cycle_training_pair(d);
    let model = d.join("model.json");
    run_ok(
        gyrotherm()
            .args(["train", "--input"])
            .arg(&train_s)
            .arg("--input")
            .arg(&train_t)
            .arg("--out")
            .arg(&model),
    );
    let base = ["--profile", "seed-shock", "--seed", "3"];
    let clean = simulate(d, "clean.csv", &base);
    let mut faulty_args = base.to_vec();
    faulty_args.extend([
        "--spikes-per-hour",
        "4",
        "--nan-bursts-per-hour",
        "0.5",
        "--nan-burst-s",
        "30",
        "--stuck-temp-per-hour",
        "0.5",
        "--stuck-temp-s",
        "120",
    ]);
    let faulty = simulate(d, "faulty.csv", &faulty_args);

    // The injected faults, counted against the clean log (same seed, same truth).
    let t_clean: Vec<f64> = column(&std::fs::read_to_string(&clean).unwrap(), "temp_c")
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    let t_fault: Vec<f64> = column(&std::fs::read_to_string(&faulty).unwrap(), "temp_c")
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(t_clean.len(), t_fault.len());
    let spikes = (1..t_fault.len() - 1)
        .filter(|&i| {
            t_fault[i].is_finite()
                && (t_fault[i] - t_clean[i]).abs() >= 10.0
                && t_fault[i - 1] == t_clean[i - 1]
                && t_fault[i + 1] == t_clean[i + 1]
        })
        .count();
    let nan_runs = runs(&t_fault, |i| t_fault[i].is_nan());
    let stuck_runs = runs(&t_fault, |i| {
        i > 0 && t_fault[i] == t_fault[i - 1] && t_fault[i] != t_clean[i]
    });
    let longest_stuck = stuck_runs.iter().copied().max().unwrap_or(0);
    println!("injected: {spikes} spikes, NaN bursts {nan_runs:?} s, stuck runs {stuck_runs:?} s");
    assert!(spikes >= 20, "{spikes} spikes");
    assert!(nan_runs.contains(&30), "no 30 s NaN burst: {nan_runs:?}");
    // A stuck episode repeats the last reading; the end of it may match the truth again.
    assert!(
        longest_stuck >= 100,
        "no ~120 s stuck episode: {stuck_runs:?}"
    );

    let mut results = Vec::new();
    for (name, input) in [("clean", &clean), ("faulty", &faulty)] {
        let out = d.join(format!("{name}_comp.csv"));
        let o = run_ok(
            gyrotherm()
                .args(["compensate", "--model"])
                .arg(&model)
                .arg("--input")
                .arg(input)
                .arg("--out")
                .arg(&out),
        );
        let text = std::fs::read_to_string(&out).unwrap();
        let input_text = std::fs::read_to_string(input).unwrap();
        assert_eq!(text.lines().count(), input_text.lines().count());
        let rate: Vec<f64> = column(&text, "gyro_comp_dps")
            .iter()
            .map(|v| v.parse::<f64>().unwrap())
            .collect();
        assert!(
            rate.iter().all(|v| v.is_finite()),
            "{name}: non-finite rate"
        );
        for c in ["bias_dps", "scale"] {
            assert!(column(&text, c)
                .iter()
                .all(|v| v.parse::<f64>().unwrap().is_finite()));
        }
        let status = column(&text, "status");
        let held = status.iter().filter(|s| *s != "ok").count();
        let stderr = String::from_utf8_lossy(&o.stderr).to_string();
        // The stream gives the same bytes.
        let stream = run_ok(
            gyrotherm()
                .args(["compensate", "--stream", "--model"])
                .arg(&model)
                .stdin(Stdio::from(std::fs::File::open(input).unwrap())),
        );
        assert!(stream.stdout == text.as_bytes(), "{name}: stream differs");
        let raw: Vec<f64> = column(&input_text, "gyro_dps")
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        let bs = bias_stability_dph(&rate);
        println!(
            "{name}: raw {:.5} °/h, compensated {bs:.5} °/h, {held} lines not ok; {}",
            bias_stability_dph(&raw),
            stderr.lines().next().unwrap_or("")
        );
        results.push((bs, held));
    }
    let (bs_clean, held_clean) = results[0];
    let (bs_fault, held_fault) = results[1];
    assert_eq!(held_clean, 0, "the clean run has no faults");
    assert!(held_fault >= spikes, "every spike is held");
    let ratio = bs_fault / bs_clean;
    println!("bias stability faulty / clean = {ratio:.4}");
    assert!(
        (ratio - 1.0).abs() <= 0.10,
        "faulty {bs_fault} °/h vs clean {bs_clean} °/h"
    );
}

/// Lengths of the maximal runs of consecutive indices where `f` holds.
fn runs(v: &[f64], f: impl Fn(usize) -> bool) -> Vec<usize> {
    let mut out = Vec::new();
    let mut len = 0;
    for i in 0..v.len() {
        if f(i) {
            len += 1;
        } else if len > 0 {
            out.push(len);
            len = 0;
        }
    }
    if len > 0 {
        out.push(len);
    }
    out
}

/// `train` stores the sensor limits given on its command line; a model file written before
/// the limits existed (no `temp_sensor`) loads with the defaults and compensates the same as
/// one with the defaults written out; unusable limits are refused with the flags named.
#[test]
fn sensor_limits_are_set_at_train_and_old_files_load() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let log = d.join("s.csv");
    let mut text = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..600 {
        let temp = 20.0 + 5.0 * (i as f64 / 60.0).sin();
        text.push_str(&format!(
            "{i},{},{temp}\n",
            0.0027 + 1e-5 * temp + 1e-6 * ((i * 7919) % 13) as f64
        ));
    }
    std::fs::write(&log, &text).unwrap();
    let model = d.join("m.json");
    run_ok(
        gyrotherm()
            .args([
                "train",
                "--method",
                "linear",
                "--temp-max-c",
                "80",
                "--temp-max-rate-c-per-s",
                "0.5",
                "--input",
            ])
            .arg(&log)
            .arg("--out")
            .arg(&model),
    );
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["features"]["temp_sensor"]["max_c"], 80.0);
    assert_eq!(m["features"]["temp_sensor"]["max_rate_c_per_s"], 0.5);
    assert_eq!(m["features"]["temp_sensor"]["min_c"], -60.0);
    // Old file: no temp_sensor. Same output as the defaults written out.
    m["features"].as_object_mut().unwrap().remove("temp_sensor");
    // Nor a checksum: files were sealed later.
    m.as_object_mut().unwrap().remove("content_sha256");
    let old = d.join("old.json");
    std::fs::write(&old, m.to_string()).unwrap();
    m["features"]["temp_sensor"] = serde_json::json!({"min_c": -60.0, "max_c": 100.0,
        "max_rate_c_per_s": 2.0, "step_allowance_c": 1.0, "degraded_after_s": 60.0});
    let explicit = d.join("explicit.json");
    std::fs::write(&explicit, m.to_string()).unwrap();
    let outs: Vec<Vec<u8>> = [&old, &explicit]
        .iter()
        .map(|p| {
            run_ok(
                gyrotherm()
                    .args(["compensate", "--stream", "--model"])
                    .arg(p)
                    .stdin(Stdio::from(std::fs::File::open(&log).unwrap())),
            )
            .stdout
        })
        .collect();
    assert!(outs[0] == outs[1]);
    let out = gyrotherm()
        .args([
            "train",
            "--method",
            "linear",
            "--temp-min-c",
            "90",
            "--temp-max-c",
            "80",
            "--input",
        ])
        .arg(&log)
        .arg("--out")
        .arg(d.join("bad.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--temp-min-c") && err.contains("min < max"),
        "{err}"
    );
}

/// A stream never stops on a bad line: malformed lines are `invalid` with empty outputs, a
/// NaN or implausible temperature is `held`, a NaN gyro `invalid`; one output line per input
/// data line. Batch mode stops on the malformed line, naming file, line and column.
#[test]
fn stream_rides_through_bad_lines_and_batch_stays_strict() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut text = String::from("# a comment\ntime_s,gyro_dps,temp_c,note\n");
    for i in 0..200 {
        let (g, t) = match i {
            50 => ("0.003".to_owned(), "NaN".to_owned()),
            60 => ("0.003".to_owned(), "85.0".to_owned()),
            70 => ("0.003".to_owned(), "-127.0".to_owned()),
            80 => ("NaN".to_owned(), "20".to_owned()),
            _ => ("0.003".to_owned(), format!("{}", 20.0 + 0.01 * i as f64)),
        };
        match i {
            90 => text.push_str("90,0.003\n"),
            100 => text.push_str("abc,0.003,21,x\n"),
            _ => text.push_str(&format!("{i},{g},{t},\"n,{i}\"\n")),
        }
    }
    let log = d.join("bad.csv");
    std::fs::write(&log, &text).unwrap();
    let model = d.join("m.json");
    let train_log = d.join("train.csv");
    let mut t = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..600 {
        let temp = 20.0 + 5.0 * (i as f64 / 60.0).sin();
        t.push_str(&format!(
            "{i},{},{temp}\n",
            0.0027 + 1e-5 * temp + 1e-6 * ((i * 7919) % 13) as f64
        ));
    }
    std::fs::write(&train_log, t).unwrap();
    run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--input"])
            .arg(&train_log)
            .arg("--out")
            .arg(&model),
    );
    let out = run_ok(
        gyrotherm()
            .args(["compensate", "--stream", "--model"])
            .arg(&model)
            .stdin(Stdio::from(std::fs::File::open(&log).unwrap())),
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 201, "header + one line per data line");
    assert_eq!(
        lines[0],
        "time_s,gyro_dps,temp_c,note,bias_dps,scale,gyro_comp_dps,status,coverage,sigma_dph"
    );
    // status, then coverage and sigma_dph.
    let status = |i: usize| lines[i + 1].rsplit(',').nth(2).unwrap();
    for i in [50, 60, 70] {
        assert_eq!(status(i), "held", "{}", lines[i + 1]);
    }
    assert_eq!(status(80), "invalid");
    assert!(lines[81].contains(",,invalid,"), "{}", lines[81]);
    // Wrong field count: empty fields (the first quoted, so the line is not blank).
    assert_eq!(lines[91], "\"\",,,,,,,invalid,,");
    assert_eq!(lines[101], "abc,0.003,21,x,,,,invalid,,");
    assert_eq!(status(0), "ok");
    assert_eq!(status(199), "ok");
    assert!(
        lines[2].contains("\"n,1\""),
        "quoted field passed through: {}",
        lines[2]
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("held 3") && stderr.contains("invalid 3") && stderr.contains("2 malformed"),
        "{stderr}"
    );
    // Batch: strict about the malformed line.
    let out = gyrotherm()
        .args(["compensate", "--model"])
        .arg(&model)
        .arg("--input")
        .arg(&log)
        .arg("--out")
        .arg(d.join("o.csv"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.csv:93") && err.contains("2 fields"),
        "{err}"
    );
    assert!(!d.join("o.csv").exists(), "no partial output");
}

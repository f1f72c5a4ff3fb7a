//! Files given where a user can give anything, through the real binary: an output that is
//! also an input, endless or huge inputs, secrets and control characters that would reach the
//! terminal, absurd numbers, and a closed standard output. Each case checks the exit status,
//! the message, and that nothing was damaged or grew without bound.
#![cfg(unix)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod cli;
use cli::{gyrotherm, outcome};

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// 1000 samples at 1 Hz of deterministic noise (the NBS generator of NIST SP 1065) at 25 °C.
fn static_log(dir: &Path, name: &str) -> PathBuf {
    let mut n: u64 = 1_234_567_890;
    let mut s = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..1000 {
        n = 16_807 * n % 2_147_483_647;
        let noise = n as f64 / 2_147_483_647.0 - 0.5;
        s.push_str(&format!("{i},{:e},25\n", 1e-3 * noise));
    }
    let path = dir.join(name);
    std::fs::write(&path, s).unwrap();
    path
}

/// A linear model over -30..70 °C, as `train --method linear` writes one (unsealed).
fn linear_model(dir: &Path) -> PathBuf {
    let m = serde_json::json!({
        "format_version": 1, "method": "linear",
        "features": {"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                     "lag_tau_s": [], "lag_outputs": "diff_from_t"},
        "bias": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                 "coefficients": [0.001, 1e-6, 0.0]}},
        "scale": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                  "coefficients": [1.0001, 1e-7, 0.0]}},
        "training": {"temp_range_c": {"min": -30.0, "max": 70.0},
                     "rate_range_c_per_s": {"min": -0.09, "max": 0.09},
                     "data_digest_sha256": "30d4b8ab79b048f01aab0c81da07c7ee0aac77c3209a51f2976c0d528981f351",
                     "epochs": null, "final_loss": null, "seed": null,
                     "created_by": "gyrotherm 0.1.0", "inputs": ["a.csv"]}
    });
    let path = dir.join("m.json");
    std::fs::write(&path, m.to_string()).unwrap();
    path
}

/// Exit 2 with a message naming `output` as an input; `input` holds `before` still.
fn assert_refused_as_input(got: (i32, String, String), output: &str, input: &Path, before: &[u8]) {
    let (code, _, err) = got;
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!("{output} is also an input of this command"))
            && err.contains("nothing was written"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(input).unwrap(),
        before,
        "the input was changed"
    );
}

/// `train --out static.csv` with static.csv among its inputs replaced the raw log with the
/// model (exit 0); `compensate --out m.json --model m.json` replaced the model. Refused now,
/// by the file's canonical path (another spelling of the same file too), the input untouched.
#[test]
fn an_output_that_is_one_of_the_inputs_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let log = static_log(dir.path(), "static.csv");
    let raw = std::fs::read(&log).unwrap();
    let run = |args: &[&str]| {
        let o = gyrotherm()
            .current_dir(dir.path())
            .args(args)
            .output()
            .unwrap();
        (
            o.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let got = run(&[
        "train",
        "--method",
        "linear",
        "--input",
        "static.csv",
        "--out",
        "./static.csv",
    ]);
    assert_refused_as_input(got, "./static.csv", &log, &raw);

    let model = linear_model(dir.path());
    let json = std::fs::read(&model).unwrap();
    let got = run(&[
        "compensate",
        "--model",
        "m.json",
        "--input",
        "static.csv",
        "--out",
        "m.json",
    ]);
    assert_refused_as_input(got, "m.json", &model, &json);
    let got = run(&[
        "compensate",
        "--model",
        "m.json",
        "--input",
        "static.csv",
        "--out",
        "static.csv",
    ]);
    assert_refused_as_input(got, "static.csv", &log, &raw);

    std::fs::write(dir.path().join("profile.txt"), "30,25\n").unwrap();
    let profile = dir.path().join("profile.txt");
    let got = run(&[
        "simulate",
        "--profile-file",
        "profile.txt",
        "--out",
        "profile.txt",
    ]);
    assert_refused_as_input(got, "profile.txt", &profile, b"30,25\n");
    let got = run(&["allan", "--input", "static.csv", "--plot", "static.csv"]);
    assert_refused_as_input(got, "static.csv", &log, &raw);
    let got = run(&[
        "plan",
        "--flight",
        "static.csv",
        "--temp-min-c",
        "-20",
        "--temp-max-c",
        "60",
        "--max-rate-c-per-min",
        "1",
        "--out",
        "static.csv",
    ]);
    assert_refused_as_input(got, "static.csv", &log, &raw);

    // Another output path still works.
    let (code, _, err) = run(&[
        "compensate",
        "--model",
        "m.json",
        "--input",
        "static.csv",
        "--out",
        "comp.csv",
    ]);
    assert_eq!(code, 0, "{err}");
}

/// A PostgreSQL password given in the URL's query (`?password=`) was printed in clear in
/// the error; only `user:pw@` was masked. Port 1 on the loopback refuses the connection, so
/// the error names the lot.
#[test]
fn a_lot_password_is_masked_in_every_form() {
    for url in [
        "postgres://gyro:s3cret@127.0.0.1:1/lot",
        "postgres://gyro@127.0.0.1:1/lot?password=s3cret",
        "postgresql://127.0.0.1:1/lot?user=gyro&password=s3cret&connect_timeout=2",
    ] {
        let (code, _, err) = outcome(&["lot", "list", "--db", url]);
        assert_eq!(code, 2, "{err}");
        assert!(
            !err.contains("s3cret") && err.contains("***") && err.contains("cannot connect"),
            "{err}"
        );
    }
}

/// ESC and BEL in a spec sheet's name reached the terminal raw from `evaluate --spec` (a
/// title-setting escape sequence here); they are escaped as `lot list` escapes a unit name.
#[test]
fn control_characters_in_a_spec_name_do_not_reach_the_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let log = static_log(dir.path(), "static.csv");
    let spec = dir.path().join("spec.toml");
    std::fs::write(
        &spec,
        "name = \"evil\\u001b]0;pwned\\u0007\"\n[limits]\nbias_dph = { max = 1e9 }\n",
    )
    .unwrap();
    let (code, out, err) = outcome(&["evaluate", "--input", p(&log), "--spec", p(&spec)]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains('\u{1b}') && !out.contains('\u{7}'), "{out:?}");
    assert!(
        out.contains("verdict: PASS (spec evil\\u{1b}]0;pwned\\u{7})"),
        "{out}"
    );
}

/// The batch reader had no line cap: `evaluate --input /dev/zero` grew until it aborted
/// (SIGABRT), and a 50 MB field was held whole and quoted whole in the error (a 50 MB message).
/// Lines are capped as the compensator's stream caps them, 64 KiB.
#[test]
fn an_endless_or_huge_line_is_refused_after_64_kib() {
    let (code, _, err) = outcome(&["evaluate", "--input", "/dev/zero"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("/dev/zero:1: line longer than 65536 bytes"),
        "{err}"
    );

    // 50 MB through a pipe: the reader stops at the cap, long before the end (the writer
    // then meets a closed pipe), and the message is one short line.
    let mut child = gyrotherm()
        .args(["evaluate", "--input", "/dev/stdin"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        let mut sent = stdin
            .write_all(b"time_s,gyro_dps,temp_c\n0,0.001,20\n1,")
            .map(|_| 0);
        let chunk = vec![b'9'; 1 << 20];
        for _ in 0..50 {
            sent = sent.and_then(|n| stdin.write_all(&chunk).map(|_| n + chunk.len()));
        }
        let _ = stdin.write_all(b",20\n");
        sent.ok()
    });
    let out = child.wait_with_output().unwrap();
    let sent = feeder.join().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("/dev/stdin:3: line longer than 65536 bytes") && err.len() < 1000,
        "{} bytes: {}",
        err.len(),
        &err[..err.len().min(500)]
    );
    assert_eq!(sent, None, "the whole 50 MB line was read");
}

/// A bad field is quoted by its first 40 characters and its length, not whole.
#[test]
fn a_long_bad_field_is_quoted_by_a_short_prefix() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("bad.csv");
    let field = "x".repeat(20_000);
    std::fs::write(
        &log,
        format!("time_s,gyro_dps,temp_c\n0,0.001,20\n1,{field},20\n2,0.001,20\n"),
    )
    .unwrap();
    let (code, _, err) = outcome(&["evaluate", "--input", p(&log)]);
    assert_eq!(code, 2, "{err}");
    let prefix = "x".repeat(40);
    assert!(
        err.contains(&format!(
            "bad.csv:3: column gyro_dps: \"{prefix}\"… (20000 bytes) is not a number"
        )) && err.len() < 500,
        "{err}"
    );
}

/// Model, spec, profile and unit files were read whole before any check (`--model /dev/zero`
/// grew to 1 GB). Each is read up to its kind's limit; the message names the file, the limit
/// and what to give instead. The files here are sparse: one byte over the limit.
#[test]
fn small_input_files_are_read_with_a_size_limit() {
    let dir = tempfile::tempdir().unwrap();
    let log = static_log(dir.path(), "static.csv");
    let over = |name: &str, mib: u64| {
        let path = dir.path().join(name);
        let f = std::fs::File::create(&path).unwrap();
        f.set_len((mib << 20) + 1).unwrap();
        path
    };
    let model = over("model.json", 64);
    let spec = over("spec.toml", 1);
    let profile = over("profile.txt", 16);
    let unit = over("unit.json", 1);
    let out = dir.path().join("out.csv");
    let cases: [(Vec<&str>, &Path, &str); 6] = [
        (
            vec![
                "compensate",
                "--model",
                p(&model),
                "--input",
                p(&log),
                "--out",
                p(&out),
            ],
            &model,
            "larger than 64 MiB, the most a model file holds",
        ),
        (
            vec![
                "compensate",
                "--model",
                "/dev/zero",
                "--input",
                p(&log),
                "--out",
                p(&out),
            ],
            Path::new("/dev/zero"),
            "larger than 64 MiB, the most a model file holds",
        ),
        (
            vec![
                "export",
                "--model",
                p(&model),
                "--target",
                "c",
                "--out",
                p(dir.path()),
            ],
            &model,
            "larger than 64 MiB, the most a model file holds",
        ),
        (
            vec!["evaluate", "--input", p(&log), "--spec", p(&spec)],
            &spec,
            "larger than 1 MiB, the most a spec sheet holds",
        ),
        (
            vec!["simulate", "--profile-file", p(&profile), "--out", p(&out)],
            &profile,
            "larger than 16 MiB, the most a chamber profile holds",
        ),
        (
            vec!["simulate", "--unit", p(&unit), "--out", p(&out)],
            &unit,
            "larger than 1 MiB, the most a unit parameter file holds",
        ),
    ];
    for (args, file, want) in cases {
        let (code, _, err) = outcome(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains(&file.display().to_string()) && err.contains(want),
            "{args:?}: {err}"
        );
    }
    assert!(!out.exists());
}

/// `train --epochs 100000000000` aborted reserving the loss history, and
/// `--epochs 18446744073709551615` panicked with "capacity overflow": refused by the
/// library's settings, naming the bound.
#[test]
fn an_absurd_epoch_count_is_refused_not_reserved() {
    let dir = tempfile::tempdir().unwrap();
    let log = static_log(dir.path(), "static.csv");
    let out = dir.path().join("m.json");
    for epochs in ["100000000000", "18446744073709551615", "0"] {
        let (code, _, err) = outcome(&[
            "train",
            "--input",
            p(&log),
            "--out",
            p(&out),
            "--epochs",
            epochs,
        ]);
        assert_eq!(code, 2, "{epochs}: {err}");
        assert!(
            err.contains(&format!(
                "epochs must be a whole number from 1 to 1000000, not {epochs}"
            )) && !err.contains("panicked"),
            "{err}"
        );
    }
    assert!(!out.exists());
}

/// With standard output closed (`| head -1` after its line), `plan`, `simulate
/// --list-profiles`, `simulate --print-unit` and `model check` panicked (exit 101, `println!`
/// on a broken pipe); every command that prints ends quietly with 0, as `main.rs` intends.
#[test]
fn a_closed_stdout_ends_every_printing_command_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let log = static_log(dir.path(), "static.csv");
    let model = linear_model(dir.path());
    let spec = dir.path().join("spec.toml");
    std::fs::write(&spec, "[limits]\nbias_dph = { max = 1e9 }\n").unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec![
            "plan",
            "--temp-min-c",
            "-20",
            "--temp-max-c",
            "60",
            "--max-rate-c-per-min",
            "1",
        ],
        vec!["simulate", "--list-profiles"],
        vec!["simulate", "--print-unit"],
        vec!["model", "check", p(&model)],
        vec!["evaluate", "--input", p(&log), "--spec", p(&spec)],
        vec!["allan", "--input", p(&log)],
        vec!["settings", "--json"],
    ];
    for args in cases {
        // The reading end closed before the command starts: its first write fails (EPIPE).
        let (reader, writer) = std::os::unix::net::UnixStream::pair().unwrap();
        drop(reader);
        let out = Command::new(env!("CARGO_BIN_EXE_gyrotherm"))
            .args(&args)
            .stdout(Stdio::from(std::os::fd::OwnedFd::from(writer)))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

//! Hostile and careless input through the real binary: each case checks the exit status and
//! the line on stderr (or that there is none).

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::Stdio;

mod cli;
use cli::outcome as gyrotherm;

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// 1000 samples at 1 Hz of `gyro(i)` at 25 °C.
fn log_of(dir: &Path, name: &str, gyro: impl Fn(usize) -> f64) -> PathBuf {
    let mut s = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..1000 {
        s.push_str(&format!("{i},{:e},25\n", gyro(i)));
    }
    let path = dir.join(name);
    std::fs::write(&path, s).unwrap();
    path
}

/// Deterministic noise in [-0.5, 0.5) (the NBS generator of NIST SP 1065).
fn noise(i: usize) -> f64 {
    let mut n: u64 = 1_234_567_890;
    for _ in 0..=i {
        n = 16_807 * n % 2_147_483_647;
    }
    n as f64 / 2_147_483_647.0 - 0.5
}

#[test]
fn huge_finite_rates_give_finite_figures_or_a_refusal_naming_the_sample() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "huge.csv", |i| 3e24 + 1e24 * noise(i));
    let (code, out, err) = gyrotherm(&["evaluate", "--input", p(&log), "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // Independent: the mean of the values, summed after dividing by 1e24, in °/h.
    let want = (0..1000).map(|i| 3.0 + noise(i)).sum::<f64>() / 1000.0 * 1e24 * 3600.0;
    let got = v["bias_dph"].as_f64().expect("finite bias");
    assert!((got - want).abs() <= 1e-9 * want, "{got} vs {want}");
    assert!(v["bias_stability_dph"].as_f64().unwrap().is_finite());
    let (code, out, err) = gyrotherm(&["evaluate", "--input", p(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("inf") && out.contains("e28 °/h"), "{out}");
    let (code, out, err) = gyrotherm(&["allan", "--input", p(&log), "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for pt in v["points"].as_array().unwrap() {
        assert!(pt["dev"].as_f64().is_some_and(f64::is_finite), "{pt}");
    }

    // One value near the largest f64: refused, naming the sample and its time.
    let log = log_of(dir.path(), "one.csv", |i| {
        if i == 500 {
            1e308
        } else {
            noise(i)
        }
    });
    let (code, _, err) = gyrotherm(&["evaluate", "--input", p(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("sample 501 (time 500 s) is 1e308 °/s"),
        "{err}"
    );
}

#[test]
fn numeric_options_are_checked_in_their_own_terms() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "n.csv", noise);
    let cases: [(&[&str], &str); 6] = [
        (
            &["evaluate", "--reference-scale", "0"],
            "is not a scale factor",
        ),
        (
            &["evaluate", "--settle-s", "nan"],
            "is not zero or a positive number of seconds",
        ),
        (
            &["evaluate", "--tau-s", "0"],
            "is not a positive number of seconds",
        ),
        (
            &["evaluate", "--tau-s", "1e308"],
            "tau_s = 1e308 s is longer than half the log",
        ),
        (
            &["allan", "--alpha", "100"],
            "the noise exponent α is an integer from -4 to 2",
        ),
        (
            &["allan", "--alpha", "1.5"],
            "the noise exponent α is an integer from -4 to 2",
        ),
    ];
    for (args, want) in cases {
        let mut a = args.to_vec();
        a.extend(["--input", p(&log)]);
        let (code, _, err) = gyrotherm(&a);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: want {want:?} in {err}");
    }
}

/// A linear model (as `train --method linear` writes one) over -30..70 °C.
/// `gyrotherm compensate --model M --input L --out O`.
fn compensate(model: &Path, log: &Path, out: &Path) -> (i32, String, String) {
    gyrotherm(&[
        "compensate",
        "--model",
        p(model),
        "--input",
        p(log),
        "--out",
        p(out),
    ])
}

fn linear_model(bias: [f64; 3], scale: [f64; 3]) -> serde_json::Value {
    serde_json::json!({
        "format_version": 1, "method": "linear",
        "features": {"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                     "lag_tau_s": [], "lag_outputs": "diff_from_t"},
        "bias": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                 "coefficients": bias}},
        "scale": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                  "coefficients": scale}},
        "training": {"temp_range_c": {"min": -30.0, "max": 70.0},
                     "rate_range_c_per_s": {"min": -0.09, "max": 0.09},
                     "data_digest_sha256": "30d4b8ab79b048f01aab0c81da07c7ee0aac77c3209a51f2976c0d528981f351",
                     "epochs": null, "final_loss": null, "seed": null,
                     "created_by": "gyrotherm 0.1.0", "inputs": ["a.csv"]}
    })
}

#[test]
fn a_model_whose_scale_factor_crosses_zero_is_blamed_not_the_log() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "base.csv", noise);
    let model = dir.path().join("bad.json");
    // K = 0.5 − 0.02·T: zero at 25 °C, negative above.
    std::fs::write(
        &model,
        linear_model([0.001, 0.0, 0.0], [0.5, -0.02, 0.0]).to_string(),
    )
    .unwrap();
    let out = dir.path().join("out.csv");
    let (code, _, err) = compensate(&model, &log, &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.json") && err.contains("scale: predicts K = "),
        "{err}"
    );
    assert!(!err.contains("base.csv"), "the log is not at fault: {err}");
    assert!(!out.exists());
}

#[test]
fn an_edited_model_is_refused_until_resealed() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "base.csv", noise);
    let model = dir.path().join("m.json");
    std::fs::write(
        &model,
        linear_model([0.001, 1e-6, 0.0], [1.0001, 1e-7, 0.0]).to_string(),
    )
    .unwrap();
    // An unsealed file is read on its other checks, with a warning that names it.
    let (code, out_text, err) = gyrotherm(&["model", "check", p(&model)]);
    assert_eq!(code, 0, "{err}");
    assert!(out_text.contains("ok but not sealed"), "{out_text}");
    assert!(
        err.contains("warning: ") && err.contains("m.json: no content_sha256"),
        "{err}"
    );
    // Sealing an unsealed file adds the checksum.
    let (code, _, err) = gyrotherm(&["model", "seal", p(&model)]);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::read_to_string(&model)
        .unwrap()
        .contains("content_sha256"));
    let out = dir.path().join("out.csv");
    let compensate = [
        "compensate",
        "--model",
        p(&model),
        "--input",
        p(&log),
        "--out",
        p(&out),
    ];
    assert_eq!(gyrotherm(&compensate).0, 0);
    let text = std::fs::read_to_string(&model).unwrap();
    std::fs::write(&model, text.replace("1.0001", "1.0002")).unwrap();
    let (code, _, err) = gyrotherm(&compensate);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("m.json") && err.contains("gyrotherm model seal"),
        "{err}"
    );
    assert_eq!(gyrotherm(&["model", "seal", p(&model)]).0, 0);
    let (code, out_text, err) = gyrotherm(&["model", "check", p(&model)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out_text.contains("ok, sealed, content_sha256"),
        "{out_text}"
    );
    assert!(!err.contains("warning"), "{err}");
    let (code, _, err) = gyrotherm(&compensate);
    assert_eq!(code, 0, "{err}");
    assert!(
        !err.contains("content_sha256"),
        "a sealed model warns of nothing: {err}"
    );
}

#[test]
fn a_closed_output_pipe_ends_quietly_with_0() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m.json");
    std::fs::write(
        &model,
        linear_model([0.001, 1e-6, 0.0], [1.0001, 1e-7, 0.0]).to_string(),
    )
    .unwrap();
    let mut input = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..200_000 {
        input.push_str(&format!("{i},0.001,25\n"));
    }
    let mut child = cli::gyrotherm()
        .args([
            "compensate",
            "--stream",
            "--sample-period-s",
            "1",
            "--model",
            p(&model),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        // The child stops reading once its output is closed: a write error here is expected.
        let _ = stdin.write_all(input.as_bytes());
    });
    // `| head -5`: read five lines, then close the pipe.
    let mut out = BufReader::new(child.stdout.take().unwrap());
    for _ in 0..5 {
        let mut line = String::new();
        out.read_line(&mut line).unwrap();
        assert!(!line.is_empty());
    }
    drop(out);
    let result = child.wait_with_output().unwrap();
    feeder.join().unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(0), "{err}");
    assert!(
        !err.contains("Broken pipe") && !err.contains("<stdin>"),
        "{err}"
    );
}

#[test]
fn a_wrong_sample_period_cannot_make_runaway_output() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "base.csv", noise);
    for (period, fill) in [("0.001", "10"), ("1e-6", "1e6")] {
        let (code, _, err) = gyrotherm(&[
            "evaluate",
            "--input",
            p(&log),
            "--sample-period-s",
            period,
            "--fill-gaps-max-s",
            fill,
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("base.csv:5: column time_s"), "{err}");
        assert!(err.contains("disagrees with the log's time steps"), "{err}");
    }
}

#[test]
fn delimiters_and_irregular_steps() {
    let dir = tempfile::tempdir().unwrap();
    let mut semi = String::from("time_s;gyro_dps;temp_c\n");
    let mut comma = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..1000 {
        let g = format!("{}", 0.001 + 1e-4 * noise(i));
        semi.push_str(&format!("{i};{};25,5\n", g.replace('.', ",")));
        comma.push_str(&format!("{i},{g},25.5\n"));
    }
    let s = dir.path().join("s.csv");
    let c = dir.path().join("c.csv");
    std::fs::write(&s, semi).unwrap();
    std::fs::write(&c, comma).unwrap();
    let (code, _, err) = gyrotherm(&["evaluate", "--input", p(&s)]);
    assert_eq!(code, 2);
    assert!(err.contains("give --delimiter ;"), "{err}");
    let (code, out_s, err) =
        gyrotherm(&["evaluate", "--input", p(&s), "--delimiter", ";", "--json"]);
    assert_eq!(code, 0, "{err}");
    let (_, out_c, _) = gyrotherm(&["evaluate", "--input", p(&c), "--json"]);
    assert_eq!(out_s, out_c);

    // ±25 % steps: accepted, with the measured jitter on stderr.
    let mut j = String::from("time_s,gyro_dps,temp_c\n");
    let mut t = 0.0;
    for i in 0..1000 {
        j.push_str(&format!("{t},0.001,25\n"));
        t += [1.25, 0.75, 1.0][i % 3];
    }
    let jl = dir.path().join("j.csv");
    std::fs::write(&jl, j).unwrap();
    let (code, _, err) = gyrotherm(&["evaluate", "--input", p(&jl)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("j.csv:3: time steps are irregular: up to 25 % off"),
        "{err}"
    );
}

#[test]
fn an_error_says_each_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "base.csv", noise);
    let model = dir.path().join("junk.json");
    std::fs::write(&model, "{not json").unwrap();
    let out = dir.path().join("out.csv");
    let (code, _, err) = compensate(&model, &log, &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("junk.json: not valid JSON"), "{err}");
    assert_eq!(err.matches("line 1 column 2").count(), 1, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// OADEV/ADEV of rates near 1e300 used to print `inf` at every τ (their sums overflowed)
/// and MDEV/HDEV an α of 11: every kind now gives finite deviations with α in the lag-1
/// method's range −2..=2 (Riley & Greenhall 2004), or a refusal with exit status 2.
#[test]
fn allan_of_finite_rates_near_1e300_is_finite_or_refused_for_every_kind() {
    let dir = tempfile::tempdir().unwrap();
    let log = log_of(dir.path(), "e300.csv", |i| 1e300 * (1.0 + noise(i)));
    for kind in ["adev", "oadev", "mdev", "hdev", "ohdev"] {
        let (code, out, err) = gyrotherm(&["allan", "--input", p(&log), "--kind", kind, "--json"]);
        match code {
            0 => {
                let v: serde_json::Value = serde_json::from_str(&out).unwrap();
                let pts = v["points"].as_array().unwrap();
                assert!(!pts.is_empty(), "{kind}: {out}");
                for pt in pts {
                    assert!(
                        pt["dev"].as_f64().is_some_and(f64::is_finite),
                        "{kind}: {pt}"
                    );
                    let a = pt["alpha"].as_i64().unwrap();
                    assert!((-2..=2).contains(&a), "{kind}: α {a}");
                }
            }
            2 => assert!(err.contains("too large"), "{kind}: {err}"),
            _ => panic!("{kind}: exit {code}: {err}"),
        }
        let (code, out, err) = gyrotherm(&["allan", "--input", p(&log), "--kind", kind]);
        assert!(code == 0 || code == 2, "{kind}: {err}");
        assert!(
            !out.contains("inf") && !out.contains("NaN"),
            "{kind}: {out}"
        );
    }
}

/// A model trained on a short simulated run (linear fit: fast) for the compensate tests.
fn small_model(dir: &Path) -> (PathBuf, PathBuf) {
    let run = cli::simulate_args(dir, "s.csv", &["--profile", "seed-shock", "--seed", "1"]);
    let model = dir.join("m.json");
    let (code, _, err) = gyrotherm(&[
        "train",
        "--method",
        "linear",
        "--input",
        p(&run),
        "--out",
        p(&model),
    ]);
    assert_eq!(code, 0, "{err}");
    (run, model)
}

/// `compensate --delimiter ';'` and `--delimiter tab`, with decimal commas, in batch and in
/// the stream, give the numbers of the same log written with commas and decimal points (the
/// independent computation); the output keeps the input's separator.
#[test]
fn compensate_reads_semicolon_and_tab_logs_with_decimal_commas() {
    let dir = tempfile::tempdir().unwrap();
    let (run, model) = small_model(dir.path());
    let text: String = std::fs::read_to_string(&run)
        .unwrap()
        .lines()
        .take(400)
        .map(|l| format!("{l}\n"))
        .collect();
    let comma = dir.path().join("comma.csv");
    std::fs::write(&comma, &text).unwrap();
    let out = dir.path().join("comma_out.csv");
    let (code, _, err) = gyrotherm(&[
        "compensate",
        "--model",
        p(&model),
        "--input",
        p(&comma),
        "--out",
        p(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    let want = std::fs::read_to_string(&out).unwrap();
    let numbers = |s: &str, sep: char| -> Vec<Vec<String>> {
        s.lines()
            .skip(1)
            .map(|l| {
                l.split(sep)
                    .map(|f| f.replace(',', "."))
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let want_rows = numbers(&want, ',');
    assert_eq!(want_rows.len(), 399);
    for (sep, name) in [(';', ";"), ('\t', "tab")] {
        // Decimal commas in every number of the input.
        let converted: String = text
            .lines()
            .map(|l| {
                let fields: Vec<String> = l.split(',').map(|f| f.replace('.', ",")).collect();
                format!("{}\n", fields.join(&sep.to_string()))
            })
            .collect();
        let input = dir.path().join(format!("in_{}.csv", sep as u32));
        std::fs::write(&input, &converted).unwrap();
        let out = dir.path().join(format!("out_{}.csv", sep as u32));
        let (code, _, err) = gyrotherm(&[
            "compensate",
            "--model",
            p(&model),
            "--input",
            p(&input),
            "--out",
            p(&out),
            "--delimiter",
            name,
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        let got = std::fs::read_to_string(&out).unwrap();
        assert!(
            got.lines().next().unwrap().contains(sep),
            "{name}: header {got:.80}"
        );
        assert_eq!(numbers(&got, sep), want_rows, "{name}: batch");
        let mut child = cli::gyrotherm()
            .args([
                "compensate",
                "--model",
                p(&model),
                "--stream",
                "--delimiter",
                name,
            ])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(converted.as_bytes())
            .unwrap();
        let o = child.wait_with_output().unwrap();
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let got = String::from_utf8(o.stdout).unwrap();
        assert_eq!(numbers(&got, sep), want_rows, "{name}: stream");
    }
}

/// Peak resident memory of a running process, kB (Linux: VmHWM in /proc/PID/status).
fn peak_rss_kb(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// A 100 MB line in the stream is one `invalid` output line, the lines around it are
/// compensated, and the process never holds the line: peak RSS stays under 50 MB (it grew
/// with the line before: 398 MB for a 400 MB line).
#[test]
fn a_100_mb_stream_line_is_one_invalid_line_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let (_, model) = small_model(dir.path());
    let mut child = cli::gyrotherm()
        .args(["compensate", "--model", p(&model), "--stream"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let mut stdin = child.stdin.take().unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    stdin
        .write_all(b"time_s,gyro_dps,temp_c\n0,0.001,20\n1,")
        .unwrap();
    let chunk = vec![b'9'; 1 << 20];
    for _ in 0..100 {
        stdin.write_all(&chunk).unwrap();
    }
    stdin.write_all(b",20\n2,0.001,20\n").unwrap();
    stdin.flush().unwrap();
    let mut lines = Vec::new();
    for _ in 0..4 {
        let mut l = String::new();
        stdout.read_line(&mut l).unwrap();
        lines.push(l);
    }
    // Still running (stdin open): its peak so far covers the long line.
    let rss = peak_rss_kb(pid);
    drop(stdin);
    let status = child.wait().unwrap();
    assert!(status.success());
    assert!(lines[1].contains(",ok,"), "{lines:?}");
    assert_eq!(
        lines[2],
        ",,,,,,invalid,,\n".replacen(",", "\"\",", 1),
        "{lines:?}"
    );
    assert!(lines[3].contains(",ok,"), "{lines:?}");
    if let Some(kb) = rss {
        eprintln!("peak RSS with a 100 MB line: {kb} kB");
        assert!(kb < 50 * 1024, "peak RSS {kb} kB");
    } else {
        eprintln!("skipped the RSS check: /proc/PID/status has no VmHWM on this system");
    }
}

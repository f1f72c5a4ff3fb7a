//! Running the real `gyrotherm` binary from the CLI tests.
#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub fn gyrotherm() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gyrotherm"))
}

/// `gyrotherm ARGS`: exit status (-1 when killed by a signal), stdout and stderr.
pub fn outcome(args: &[&str]) -> (i32, String, String) {
    let out = gyrotherm().args(args).output().expect("run gyrotherm");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `cmd`, failing the test with its stdout and stderr unless it exits 0.
pub fn run_ok(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("run gyrotherm");
    assert!(
        out.status.success(),
        "{cmd:?} failed ({:?}):\nstdout: {}\nstderr: {}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Fails the test with the command's stderr unless `out` exited with `code`.
pub fn assert_exit(out: &Output, code: i32) {
    assert_eq!(
        out.status.code(),
        Some(code),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `gyrotherm simulate ARGS --out DIR/NAME`; returns the path written.
pub fn simulate_args(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let path = dir.join(name);
    run_ok(
        gyrotherm()
            .arg("simulate")
            .args(args)
            .arg("--out")
            .arg(&path),
    );
    path
}

/// A static and a ±20 °/s rate-table training run on `fast-cycle` (seeds 1 and 2).
pub fn fast_cycle_training_pair(dir: &Path) -> (PathBuf, PathBuf) {
    let s = simulate_args(
        dir,
        "train_s.csv",
        &["--profile", "fast-cycle", "--seed", "1"],
    );
    let t = simulate_args(
        dir,
        "train_t.csv",
        &[
            "--profile",
            "fast-cycle",
            "--seed",
            "2",
            "--table-rate",
            "20",
        ],
    );
    (s, t)
}

/// Columns of a CSV text by header name.
pub fn column(text: &str, name: &str) -> Vec<String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().to_owned())
        .collect()
}

/// Bias stability, °/h: sample std (n − 1) of consecutive non-overlapping 100 s means of a
/// 1 Hz rate in °/s (GJB 2426A / IEEE Std 952; computed here independently of the library).
pub fn bias_stability_dph(x: &[f64]) -> f64 {
    let means: Vec<f64> = x
        .chunks_exact(100)
        .map(|c| c.iter().sum::<f64>() / 100.0)
        .collect();
    let mu = means.iter().sum::<f64>() / means.len() as f64;
    let var = means.iter().map(|m| (m - mu).powi(2)).sum::<f64>() / (means.len() - 1) as f64;
    var.sqrt() * 3600.0
}

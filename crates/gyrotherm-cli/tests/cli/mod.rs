//! Running the real `gyrotherm` binary from the CLI tests.
#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub fn gyrotherm() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gyrotherm"))
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

//! Finding the shared reference data (`../shared/reference/` beside the checkout), and the
//! NBS 1000-point set the Allan tests share.
//!
//! CI has it; a user's fresh clone does not. The crate's build script sets
//! `cfg(no_reference_data)` when the folder is absent, and each test that reads it carries
//! `#[cfg_attr(no_reference_data, ignore = "needs ../shared/reference …")]`, so the summary
//! lists it as ignored with the reason; [`check_reference_data`] (run by a test of its own in
//! each such file) fails when the folder is absent and `CI=true`. A single file missing from
//! a folder that is there gets `None` and a printed `skipped: …` (a failure under `CI=true`).

#![allow(dead_code)] // each test file uses its own subset

use std::path::PathBuf;

/// `$GYROTHERM_SHARED`, else the first `shared/` with a `reference/` folder beside this crate
/// or one of its ancestors.
fn shared_dir() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("GYROTHERM_SHARED") {
        return Some(PathBuf::from(p));
    }
    let mut dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    loop {
        let cand = dir.join("shared");
        if cand.join("reference").is_dir() {
            return Some(cand);
        }
        if !dir.pop() {
            return None;
        }
    }
}

/// `shared/reference/<rel>` if it is a file; otherwise `None` after printing why, or a panic
/// when `CI=true`.
pub fn reference_file(rel: &str) -> Option<PathBuf> {
    let path = shared_dir().map(|d| d.join("reference").join(rel));
    match path {
        Some(p) if p.is_file() => Some(p),
        _ => {
            let why = format!(
                "reference file {rel} not found (looked for ../shared/reference beside the checkout; set GYROTHERM_SHARED to its folder)"
            );
            if std::env::var("CI").as_deref() == Ok("true") {
                panic!("{why}");
            }
            println!("skipped: {why}");
            None
        }
    }
}

/// The test of each reference-reading file: with the folder absent (the other tests ignored),
/// a failure under `CI=true`, where the data must be, and a failure when the folder has appeared
/// since the build script looked (those tests would stay ignored without a word).
pub fn check_reference_data() {
    let ci = std::env::var("CI").as_deref() == Ok("true");
    if cfg!(no_reference_data) {
        assert!(
            !ci,
            "CI=true but the reference data is missing (looked for ../shared/reference beside \
             the checkout; set GYROTHERM_SHARED to its folder): the tests that read it were \
             ignored"
        );
        if let Some(d) = shared_dir().filter(|d| d.join("reference").is_dir()) {
            panic!(
                "{} is there now, but this build was configured without it (the tests that read \
                 it are ignored): run `touch crates/gyrotherm/build.rs` and test again",
                d.join("reference").display()
            );
        }
    }
}

/// NBS 1000-point set: n0 = 1234567890, n_{i+1} = 16807·n_i mod 2147483647,
/// y_i = n_i/2147483647 (NIST SP 1065 p. 107).
pub fn nbs_data() -> Vec<f64> {
    let mut n: u64 = 1_234_567_890;
    let mut out = Vec::with_capacity(1000);
    for _ in 0..1000 {
        out.push(n as f64 / 2_147_483_647.0);
        n = 16_807 * n % 2_147_483_647;
    }
    out
}

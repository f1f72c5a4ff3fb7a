//! Finding the shared reference data (`../shared/reference/` beside the checkout), and the
//! NBS 1000-point set the Allan tests share.
//!
//! CI has it; a user's fresh clone does not. A test that needs a file gets `None` and prints
//! `skipped: …` when it is missing, except under `CI=true`, where a missing file fails.

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

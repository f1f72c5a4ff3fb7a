//! Sets `cfg(no_reference_data)` when the shared reference data (`shared/reference/` beside
//! the checkout or above it, or the folder `GYROTHERM_SHARED` names) is absent, so that the
//! tests reading it are reported as ignored with the reason instead of passing silently.
//! `tests/common/mod.rs` finds the data by the same rule at run time.

use std::path::PathBuf;

fn reference_dir() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("GYROTHERM_SHARED") {
        let dir = PathBuf::from(p).join("reference");
        return dir.is_dir().then_some(dir);
    }
    let mut dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR")?);
    loop {
        let cand = dir.join("shared").join("reference");
        if cand.is_dir() {
            return Some(cand);
        }
        if !dir.pop() {
            return None;
        }
    }
}

fn main() {
    println!("cargo::rustc-check-cfg=cfg(no_reference_data)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=GYROTHERM_SHARED");
    match reference_dir() {
        // Watched so that its removal (or a changed file) is noticed. An absent folder cannot
        // be watched without rebuilding the library on every run, so data added later is
        // picked up after `touch crates/gyrotherm/build.rs` (README, "the tests").
        Some(dir) => println!("cargo::rerun-if-changed={}", dir.display()),
        None => println!("cargo::rustc-cfg=no_reference_data"),
    }
}

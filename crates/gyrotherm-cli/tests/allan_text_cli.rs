//! `gyrotherm allan`'s text table as a new user reads it: the deviations carry their unit,
//! and τ0 estimated from time stamps prints as the period it is, not as its rounding error.

mod cli;
use cli::{outcome, simulate_args};

/// A 5 Hz log (1000 samples at a constant set point): its time stamps are multiples of 0.2 s
/// written as decimals, whose differences in f64 are 0.20000000000000284 s and the like.
#[test]
fn the_table_gives_units_and_a_readable_tau0() {
    let dir = tempfile::tempdir().unwrap();
    let profile = dir.path().join("p.txt");
    std::fs::write(&profile, "200,22\n").unwrap();
    let log = simulate_args(
        dir.path(),
        "h.csv",
        &[
            "--profile-file",
            profile.to_str().unwrap(),
            "--rate-hz",
            "5",
            "--seed",
            "1",
        ],
    );
    let (code, out, err) = outcome(&["allan", "--input", log.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let mut lines = out.lines();
    let title = lines.next().unwrap();
    assert!(title.contains("τ0 = 0.2 s"), "{title}");
    let header = lines.next().unwrap();
    for h in ["tau (s)", "lo (°/s)", "dev (°/s)", "hi (°/s)"] {
        assert!(header.contains(h), "no {h:?} in {header}");
    }
}

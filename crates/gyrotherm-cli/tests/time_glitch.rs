//! One glitched time stamp through the real binary: the 30,000 s seed-shock static run (seed
//! 3) with line 10,001's time replaced by 1e308, compensated by a linear model trained on
//! other seeds (fast-cycle 1 and 2), keeps its bias stability within 10 % of the same run
//! without the glitch. Before the time axis was a state machine, every line after the glitch
//! was `held` with the bias frozen.

use std::process::Stdio;

mod cli;
use cli::{bias_stability_dph, column};
use cli::{gyrotherm, run_ok};

#[test]
fn a_time_glitch_keeps_the_bias_stability() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (train_s, train_t) = cli::fast_cycle_training_pair(d);
    let model = d.join("model.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--input"])
            .arg(&train_s)
            .arg("--input")
            .arg(&train_t)
            .arg("--out")
            .arg(&model),
    );
    let clean = cli::simulate_args(d, "clean.csv", &["--profile", "seed-shock", "--seed", "3"]);
    let text = std::fs::read_to_string(&clean).unwrap();
    // Data line 10,001 (line 0 is the header): its time becomes 1e308.
    let glitched: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 10_001 {
                let rest = l.split_once(',').unwrap().1;
                format!("1e308,{rest}")
            } else {
                l.to_owned()
            }
        })
        .collect();
    let glitch = d.join("glitch.csv");
    std::fs::write(&glitch, glitched.join("\n") + "\n").unwrap();
    let stream = |input: &std::path::Path| {
        let out = run_ok(
            gyrotherm()
                .args(["compensate", "--stream", "--model"])
                .arg(&model)
                .stdin(Stdio::from(std::fs::File::open(input).unwrap())),
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let (a, b) = (stream(&clean), stream(&glitch));
    let rate = |t: &str| -> Vec<f64> {
        column(t, "gyro_comp_dps")
            .iter()
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (ra, rb) = (rate(&a), rate(&b));
    assert_eq!(ra.len(), 30_000);
    assert_eq!(rb.len(), 30_000);
    let (sa, sb) = (bias_stability_dph(&ra), bias_stability_dph(&rb));
    let status = column(&b, "status");
    let held = status.iter().filter(|s| *s == "held").count();
    let not_ok = status.iter().filter(|s| *s != "ok").count();
    let differ = a.lines().zip(b.lines()).skip(1).filter(|(x, y)| {
        x.rsplit(',').take(4).collect::<Vec<_>>() != y.rsplit(',').take(4).collect::<Vec<_>>()
    });
    let differ = differ.count();
    println!(
        "bias stability (tau = 100 s): clean {sa:.5} deg/h, glitch {sb:.5} deg/h, ratio {:.4}; \
         glitch run: {held} held, {not_ok} not ok, {differ} output lines differ from the clean run",
        sb / sa
    );
    assert!((sb / sa - 1.0).abs() <= 0.10, "clean {sa} glitch {sb}");
    // Only the glitch line is held. The rate feature may see the missing step once more, 20 s
    // later (the 20 s lag then reads the step before it): at most 2 lines differ (1 measured,
    // as the quantised temperature did not change across those steps).
    assert_eq!((held, not_ok), (1, 1));
    assert!(differ <= 2, "{differ} lines differ");
}

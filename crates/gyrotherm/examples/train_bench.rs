//! Wall time of the published recipe: 1000 epochs of full BPTT over a 30,000-step run,
//! hidden 8, 2 inputs, for two networks (bias and scale factor) on two threads.
//!
//! `cargo run -p gyrotherm --release --example train_bench -- [epochs] [f32|f64] [pair|single]`
//! (defaults: 1000 f32 pair). Target: ≤ 10 s for both networks on a 2-core machine.

use std::time::Instant;

use gyrotherm::nn::{train_lstm, train_pair, Precision, Sequence, TrainConfig};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let epochs: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(1000);
    let precision = match args.get(1).map(String::as_str) {
        Some("f64") => Precision::F64,
        _ => Precision::F32,
    };
    let pair = args.get(2).map(String::as_str) != Some("single");
    let steps = 30_000;
    // Normalised inputs of a chamber-like cycle: temperature and its rate; two targets.
    let x: Vec<f64> = (0..steps)
        .flat_map(|t| {
            let ph = t as f64 / steps as f64 * std::f64::consts::TAU;
            [1.4 * ph.sin(), 1.4 * ph.cos()]
        })
        .collect();
    let bias: Vec<f64> = (0..steps).map(|t| (t as f64 / 3000.0).sin()).collect();
    let scale: Vec<f64> = (0..steps).map(|t| (t as f64 / 5000.0).cos()).collect();
    let cfg = TrainConfig {
        epochs,
        precision,
        ..TrainConfig::default()
    };
    let (rb, rs) = ([Sequence::new(&x, &bias)], [Sequence::new(&x, &scale)]);
    let t0 = Instant::now();
    let losses = if pair {
        let (a, b) = train_pair(
            (&rb, &[], &mut |_, _| {}),
            (&rs, &[], &mut |_, _| {}),
            2,
            &cfg,
        );
        vec![a.unwrap(), b.unwrap()]
    } else {
        vec![train_lstm(&rb, &[], 2, &cfg, &mut |_, _| {}).unwrap()]
    };
    let dt = t0.elapsed().as_secs_f64();
    for (n, o) in losses.iter().enumerate() {
        println!(
            "network {n}: loss {:.5} -> {:.5} (last bits: {:e})",
            o.loss_history[0],
            o.loss_history.last().unwrap(),
            o.loss_history.last().unwrap()
        );
    }
    println!(
        "{} network(s), {epochs} epochs x {steps} steps, {precision:?}: {dt:.2} s total, {:.4} s/epoch ({:.0} ns/step)",
        losses.len(),
        dt / epochs as f64,
        dt / epochs as f64 / steps as f64 * 1e9
    );
}

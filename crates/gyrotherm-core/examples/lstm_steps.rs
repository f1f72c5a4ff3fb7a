//! Runs N flight steps of the published cell (LSTM I = 2, H = 8) with the weights of the
//! `lstm_step` bench, for instruction counts and a quick latency figure.
//!
//! `cargo run -p gyrotherm-core --release --example lstm_steps -- N [REPEATS]`
//!
//! Prints the checksum of the outputs (so the steps cannot be optimised away) and the best
//! time per step over REPEATS runs (default 1): wall time, and on-CPU time of the thread from
//! Linux's `/proc/thread-self/schedstat` (time spent descheduled does not count, so it holds up
//! better on a shared machine; the load still costs some cache and clock). `bench/callgrind.sh` runs it under
//! callgrind at two values of N and divides the difference of the counts by the difference
//! of N, which removes the start-up cost.

use std::hint::black_box;
use std::io::Write;
use std::time::Instant;

use gyrotherm_core::lstm::{Lstm, LstmWeights};

/// The bench's weights: PyTorch's init magnitude, U(-1/√8, 1/√8)-like, from a small LCG.
fn weights() -> Option<LstmWeights<2, 8>> {
    let mut s: u32 = 12345;
    let mut next = || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        ((s >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0) * 0.353_553_4
    };
    let w_ih: Vec<f32> = (0..64).map(|_| next()).collect();
    let w_hh: Vec<f32> = (0..256).map(|_| next()).collect();
    let b_ih: Vec<f32> = (0..32).map(|_| next()).collect();
    let b_hh: Vec<f32> = (0..32).map(|_| next()).collect();
    let w_out: Vec<f32> = (0..8).map(|_| next()).collect();
    LstmWeights::from_slices(&w_ih, &w_hh, &b_ih, &b_hh, &w_out, next()).ok()
}

/// Nanoseconds this thread has run on a CPU (Linux schedstat), if available.
fn on_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: u64 = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let repeats: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(1);
    let Some(w) = weights() else {
        eprintln!("lstm_steps: weights not finite");
        std::process::exit(1);
    };
    let mut best = f64::INFINITY;
    let mut best_cpu = f64::INFINITY;
    let mut sum = 0.0f64;
    for _ in 0..repeats.max(1) {
        let mut net = Lstm::new(&w);
        let mut t = 0.0f32;
        sum = 0.0;
        let c0 = on_cpu_ns();
        let t0 = Instant::now();
        for _ in 0..n {
            // A slowly varying normalised input, as in the bench.
            t += 0.001;
            if t > 3.0 {
                t = -3.0;
            }
            if let Ok(y) = net.step(black_box(&[t, 0.5 * t])) {
                sum += f64::from(black_box(y));
            }
        }
        best = best.min(t0.elapsed().as_secs_f64());
        if let (Some(c0), Some(c1)) = (c0, on_cpu_ns()) {
            best_cpu = best_cpu.min((c1 - c0) as f64 * 1e-9);
        }
    }
    // Written with errors ignored: a closed pipe (`| head`) is not a failure here.
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "steps={n} checksum={sum:.9e}");
    if n > 0 {
        let _ = writeln!(out, "best_ns_per_step={:.2}", best / n as f64 * 1e9);
        if best_cpu.is_finite() {
            let per_step = best_cpu / n as f64 * 1e9;
            let _ = writeln!(out, "best_on_cpu_ns_per_step={per_step:.2}");
        }
    }
}

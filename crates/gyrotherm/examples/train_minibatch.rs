//! Wall time of minibatch truncated BPTT ([`Bptt::Sampled`]) for one LSTM on one static
//! log's thermal-state inputs (T, dT, T minus lags of 300, 1000, 3000 s) and its bias target.
//!
//! ```text
//! cargo run -p gyrotherm --release --example train_minibatch -- \
//!     [LOG.csv|-] [hidden 32] [adam-steps 600] [batch 128] [window 768] [burn-in 256] [f32|f64] [threads 0]
//! ```
//!
//! With no log (or `-`), a static chamber run is simulated (profile `seed-shock`, seed 7).
//! Adam at lr 5e-3 with cosine decay, gradient norm clipped at 1.

use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;

use gyrotherm::nn::{train_normalised, Bptt, LrSchedule, Precision, Sequence, TrainConfig};
use gyrotherm::targets::bias_targets;
use gyrotherm::{read_log, simulate, FeatureSpec, ReadOptions, SimConfig};

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |k: usize, d: usize| args.get(k).and_then(|a| a.parse().ok()).unwrap_or(d);
    let log = match args.first().map(String::as_str) {
        Some(p) if p != "-" => read_log(&PathBuf::from(p), &ReadOptions::default())?.0,
        _ => {
            let mut cfg = SimConfig::builtin("seed-shock")?;
            cfg.seed = 7;
            simulate(&cfg)?
        }
    };
    let (hidden, steps, batch, window, burn_in) = (
        num(1, 32),
        num(2, 600),
        num(3, 128),
        num(4, 768),
        num(5, 256),
    );
    let precision = match args.get(6).map(String::as_str) {
        Some("f64") => Precision::F64,
        _ => Precision::F32,
    };
    let threads = num(7, 0);
    let spec = FeatureSpec::THERMAL_STATE;
    let set = bias_targets(&log, &spec, 100.0)?;
    let n_in = set.table.n_features;
    let run = Sequence::new(&set.table.rows, &set.target).with_mask(&set.mask);
    let cfg = TrainConfig {
        hidden_size: hidden,
        epochs: steps,
        lr: 5e-3,
        clip_grad_norm: Some(1.0),
        bptt: Bptt::Sampled {
            window,
            burn_in,
            batch,
        },
        lr_schedule: LrSchedule::Cosine,
        precision,
        threads,
        ..TrainConfig::default()
    };
    let t0 = Instant::now();
    let fit = train_normalised(&[run], &[], n_in, &cfg, &mut |_, _| {})?;
    let dt = t0.elapsed().as_secs_f64();
    let h = &fit.output.loss_history;
    let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len().max(1) as f64;
    println!(
        "{} rows x {n_in} inputs; hidden {hidden}, {steps} Adam steps of {batch} windows x \
         {window} steps (burn-in {burn_in}), {precision:?}, threads {threads} (0: all cores)",
        set.table.n_rows()
    );
    println!(
        "batch loss (normalised MSE): first 10 steps {:.4}, last 10 steps {:.4}",
        mean(&h[..h.len().min(10)]),
        mean(&h[h.len().saturating_sub(10)..])
    );
    println!(
        "training: {dt:.2} s wall ({:.1} ms per Adam step)",
        dt / steps as f64 * 1e3
    );
    Ok(())
}

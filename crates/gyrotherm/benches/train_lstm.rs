//! Training cost of the published network (I = 2, H = 8) on a 30,000-step run with full BPTT:
//! one iteration = 10 epochs (forward, backward, Adam), so time/10 is s/epoch.
//! Target (issue 4): 1000 epochs for both networks ≤ 10 s on 2 cores, i.e. ≤ 10 ms per epoch
//! per network with the two on their own threads. Full 1000-epoch wall time:
//! `cargo run -p gyrotherm --release --example train_bench`.
//! Run: `cargo bench -p gyrotherm --bench train_lstm`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gyrotherm::nn::{train_lstm, Precision, Sequence, TrainConfig};

const EPOCHS_PER_ITER: usize = 10;

fn bench_train(c: &mut Criterion) {
    let steps = 30_000;
    let x: Vec<f64> = (0..steps)
        .flat_map(|t| {
            let ph = t as f64 / steps as f64 * std::f64::consts::TAU;
            [1.4 * ph.sin(), 1.4 * ph.cos()]
        })
        .collect();
    let y: Vec<f64> = (0..steps).map(|t| (t as f64 / 3000.0).sin()).collect();
    let runs = [Sequence::new(&x, &y)];
    let mut g = c.benchmark_group("train_lstm_30000_steps_x10_epochs");
    g.sample_size(10);
    for (name, precision) in [("f32", Precision::F32), ("f64", Precision::F64)] {
        let cfg = TrainConfig {
            epochs: EPOCHS_PER_ITER,
            precision,
            ..TrainConfig::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| black_box(train_lstm(&runs, &[], 2, &cfg, &mut |_, _| {}).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_train);
criterion_main!(benches);

//! Simulator throughput: one 30,000-sample `seed-shock` run at 1 Hz, static and with truth
//! and rate table (numbers only; targets are checked here, never in timed tests).

use criterion::{criterion_group, criterion_main, Criterion};
use gyrotherm::sim::{simulate, simulate_series, SimConfig};

fn bench_sim(c: &mut Criterion) {
    let cfg = SimConfig::default();
    c.bench_function("simulate_series seed-shock 30k samples", |b| {
        b.iter(|| simulate_series(&cfg).unwrap())
    });
    let full = SimConfig {
        truth: true,
        table_rate_dps: Some(20.0),
        ..SimConfig::default()
    };
    c.bench_function("simulate (TestLog, truth, table) seed-shock 30k", |b| {
        b.iter(|| simulate(&full).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench_sim
}
criterion_main!(benches);

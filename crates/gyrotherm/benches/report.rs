//! Report drawing cost: min/max decimation of a long run, and one full figure (PNG + SVG) of
//! a 24 h run at 10 Hz (864 000 samples).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gyrotherm::report::{decimate_min_max, raw_output_figure, RawOutputData};

fn run(n: usize) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
    let y: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, t)| (t / 3000.0).sin() + ((i * 7919) % 1000) as f64 * 1e-3)
        .collect();
    (t, y)
}

fn bench(c: &mut Criterion) {
    let (t, y) = run(864_000);
    c.bench_function("decimate_min_max 864k -> 900 columns", |b| {
        b.iter(|| decimate_min_max(black_box(&t), black_box(&y), 900))
    });
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("raw");
    let mut g = c.benchmark_group("figure");
    g.sample_size(10);
    g.bench_function("raw_output_figure 864k samples (PNG+SVG)", |b| {
        b.iter(|| {
            raw_output_figure(
                &path,
                &RawOutputData {
                    time_s: &t,
                    gyro_dph: &y,
                    window_s: 100.0,
                },
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

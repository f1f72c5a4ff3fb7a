//! Baseline fit on a 30,000-step run (the published test length at 1 Hz).
//! `cargo bench -p gyrotherm --bench baseline`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gyrotherm::baseline::{fit, PolyDegrees, Terms};
use gyrotherm::csvlog::TestLog;
use gyrotherm::features::{extract, FeatureSpec};

fn bench(c: &mut Criterion) {
    let n = 30_000;
    let time_s: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let temp_c: Vec<f64> = time_s
        .iter()
        .map(|t| 10.0 + 50.0 * (t / 4000.0).sin() + 0.3 * (t / 77.0).cos())
        .collect();
    let log = TestLog {
        gyro_dps: vec![0.0; n],
        time_s,
        temp_c,
        ..TestLog::default()
    };
    let spec = FeatureSpec::THERMAL_STATE;
    c.bench_function("extract_30000_thermal_state", |b| {
        b.iter(|| black_box(extract(black_box(&log), &spec).unwrap()))
    });
    let tab = extract(&log, &spec).unwrap();
    let y: Vec<f64> = (0..tab.n_rows()).map(|r| 1e-3 * tab.row(r)[0]).collect();
    let mut g = c.benchmark_group("fit_30000");
    g.sample_size(10);
    g.bench_function("linear_3terms", |b| {
        let tab2 = extract(&log, &FeatureSpec::PUBLISHED).unwrap();
        b.iter(|| black_box(fit(&tab2, &y, None, &Terms::linear(2)).unwrap()))
    });
    g.bench_function("poly_cubic_cross_lags_10terms", |b| {
        let terms = Terms::poly(5, PolyDegrees::default());
        b.iter(|| black_box(fit(&tab, &y, None, &terms).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

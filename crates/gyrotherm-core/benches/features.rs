//! Per-sample cost of the streaming feature pipeline and of a baseline evaluation.
//! `cargo bench -p gyrotherm-core --bench features`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::features::{FeaturePipeline, FeatureSpec, LagOutputs};

fn bench(c: &mut Criterion) {
    let specs = [
        ("published", FeatureSpec::PUBLISHED),
        (
            "thermal_state_4lags_both_ma10",
            FeatureSpec {
                smoothing_window_s: 10.0,
                ..FeatureSpec::PUBLISHED
            }
            .with_lags(&[300.0, 1000.0, 3000.0, 30.0], LagOutputs::Both)
            .unwrap(),
        ),
    ];
    for (name, spec) in specs {
        // One sample per second: every push is a step (the worst case per sample).
        c.bench_function(&format!("features_push_step_{name}"), |b| {
            let mut p = FeaturePipeline::new(spec).unwrap();
            let mut t = 0.0f64;
            b.iter(|| {
                t += 1.0;
                black_box(p.push(black_box(t), black_box(20.0 + (t * 1e-3).sin())))
            })
        });
    }
    // 100 Hz log: 99 of 100 pushes hold.
    c.bench_function("features_push_100hz_published", |b| {
        let mut p = FeaturePipeline::new(FeatureSpec::PUBLISHED).unwrap();
        let mut i = 0u64;
        b.iter(|| {
            i += 1;
            let t = i as f64 / 100.0;
            black_box(p.push(black_box(t), black_box(20.0)))
        })
    });
    let mut m = BaselineModel::new(2).unwrap();
    for p in [[0u8, 0], [1, 0], [2, 0], [3, 0], [0, 1], [1, 1]] {
        m.push_term(&p, 1e-3).unwrap();
    }
    c.bench_function("baseline_eval_cubic_cross", |b| {
        b.iter(|| black_box(m.eval(black_box(&[23.5, 0.01]))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);

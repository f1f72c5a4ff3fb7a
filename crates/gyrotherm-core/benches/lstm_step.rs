//! One streaming `Lstm::step`, H = 8, I = 2 (the published size, He et al. 2024, §2).
//! Target: ≤ 100 ns per sample. Run: `cargo bench -p gyrotherm-core --bench lstm_step`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gyrotherm_core::lstm::{Lstm, LstmWeights};

/// Deterministic weights of PyTorch's init magnitude, U(-1/√8, 1/√8)-like, from a small LCG.
fn weights() -> LstmWeights<2, 8> {
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
    LstmWeights::from_slices(&w_ih, &w_hh, &b_ih, &b_hh, &w_out, next()).expect("finite weights")
}

fn bench_step(c: &mut Criterion) {
    let w = weights();
    let mut net = Lstm::new(&w);
    let mut t = 0.0f32;
    c.bench_function("lstm_step_i2_h8", |b| {
        b.iter(|| {
            // A slowly varying normalised input, as a temperature and its rate would be.
            t += 0.001;
            if t > 3.0 {
                t = -3.0;
            }
            black_box(net.step(black_box(&[t, 0.5 * t])))
        })
    });
}

criterion_group!(benches, bench_step);
criterion_main!(benches);

//! Octave OADEV speed.
//!
//! `cargo bench -p gyrotherm --bench allan`: criterion on a 1e6-sample rate series.
//! `GYROTHERM_ALLAN_N=100000000 cargo bench -p gyrotherm --bench allan`: one timed run of
//! octave OADEV (with noise ID and Greenhall bounds) on N white-noise samples, printed as
//! `gyrotherm_oadev_octave_s=<seconds> n=<N> taus=<count>` (used by
//! `bench/allan_vs_allantools.sh`).

use std::time::Instant;

use criterion::{criterion_group, Criterion};
use gyrotherm::allan::{deviation, DevKind, NoiseModel, TauSet};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn white(n: usize) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    (0..n).map(|_| rng.gen::<f64>() - 0.5).collect()
}

fn bench_oadev(c: &mut Criterion) {
    let y = white(1_000_000);
    c.bench_function("oadev_octave_1e6", |b| {
        b.iter(|| {
            deviation(
                &y,
                1.0,
                DevKind::Oadev,
                &TauSet::Octave,
                NoiseModel::Identify,
            )
            .unwrap()
        })
    });
    c.bench_function("mdev_octave_1e6", |b| {
        b.iter(|| {
            deviation(
                &y,
                1.0,
                DevKind::Mdev,
                &TauSet::Octave,
                NoiseModel::Identify,
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, bench_oadev);

fn main() {
    if let Some(n) = std::env::var("GYROTHERM_ALLAN_N")
        .ok()
        .and_then(|s| s.parse::<usize>().ok())
    {
        let y = white(n);
        let t = Instant::now();
        let pts = deviation(
            &y,
            1.0,
            DevKind::Oadev,
            &TauSet::Octave,
            NoiseModel::Identify,
        )
        .unwrap();
        let s = t.elapsed().as_secs_f64();
        println!("gyrotherm_oadev_octave_s={s:.3} n={n} taus={}", pts.len());
        let t = Instant::now();
        let pts = deviation(
            &y,
            1.0,
            DevKind::Oadev,
            &TauSet::Octave,
            NoiseModel::Alpha(0),
        )
        .unwrap();
        let s = t.elapsed().as_secs_f64();
        println!(
            "gyrotherm_oadev_octave_fixed_alpha_s={s:.3} n={n} taus={}",
            pts.len()
        );
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}

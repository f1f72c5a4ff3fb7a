//! Octave OADEV speed.
//!
//! `cargo bench -p gyrotherm --bench allan`: criterion on a 1e6-sample rate series.
//! `GYROTHERM_ALLAN_N=100000000 cargo bench -p gyrotherm --bench allan`: one timed run of
//! octave OADEV (with noise ID and Greenhall bounds) on N white-noise samples held in memory,
//! printed as `gyrotherm_oadev_octave_s=<seconds> n=<N> taus=<count>`, then the same with α
//! given, then the process's peak RSS (`peak_rss_mb`, VmHWM: the samples plus what the
//! computation adds). The samples are handed over ([`deviation_owned`]), as a program that
//! has read a log into memory would. Used by `bench/allan_vs_allantools.sh`.

use std::time::Instant;

use criterion::{criterion_group, Criterion};
use gyrotherm::allan::{deviation, deviation_owned, DevKind, NoiseModel, TauSet};
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

/// CPU time of the process so far (user + system, all threads; Linux `/proc/self/stat`,
/// 100 ticks a second): on a shared machine, the work done, which wall time is not.
fn cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which ends with the last ')'): utime is the 12th,
    // stime the 13th.
    let rest = stat.get(stat.rfind(')')? + 2..)?;
    let mut f = rest.split_whitespace().skip(11);
    let user: f64 = f.next()?.parse().ok()?;
    let sys: f64 = f.next()?.parse().ok()?;
    Some((user + sys) / 100.0)
}

fn main() {
    if let Some(n) = std::env::var("GYROTHERM_ALLAN_N")
        .ok()
        .and_then(|s| s.parse::<usize>().ok())
    {
        for (label, noise) in [
            ("gyrotherm_oadev_octave_s", NoiseModel::Identify),
            ("gyrotherm_oadev_octave_fixed_alpha_s", NoiseModel::Alpha(0)),
        ] {
            let y = white(n);
            let (t, cpu0) = (Instant::now(), cpu_s());
            let pts = deviation_owned(y, 1.0, DevKind::Oadev, &TauSet::Octave, noise).unwrap();
            let s = t.elapsed().as_secs_f64();
            let cpu = match (cpu0, cpu_s()) {
                (Some(a), Some(b)) => format!(" cpu_s={:.2}", b - a),
                _ => String::new(),
            };
            println!("{label}={s:.3} n={n} taus={}{cpu}", pts.len());
        }
        if let Some(kb) = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|st| {
                st.lines()
                    .find_map(|l| l.strip_prefix("VmHWM:"))
                    .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
            })
        {
            println!(
                "peak_rss_mb={:.0} (samples alone: {:.0})",
                kb / 1024.0,
                n as f64 * 8.0 / 1e6 / 1.048_576
            );
        }
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}

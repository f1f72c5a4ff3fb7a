//! Criterion bench of the log reader on a 100,000-row in-memory log (throughput in bytes/s).
//! The 10-million-row file bench with peak memory is `bench/read_log.sh`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use gyrotherm::csvlog::{LogReader, ReadOptions};

/// 100 Hz rows like those of `examples/read_log_bench.rs`.
fn log_text(rows: usize) -> Vec<u8> {
    let mut s = String::from("time_s,gyro_dps,temp_c,table_dps\n");
    for i in 0..rows {
        let gyro = 0.0012 + 1e-7 * ((i * 7919) % 1000) as f64;
        let temp = (-40.0 + 100.0 * i as f64 / rows as f64 / 0.0625).round() * 0.0625;
        s += &format!("{:.3},{gyro:.13},{temp},20\n", i as f64 * 0.01);
    }
    s.into_bytes()
}

fn bench(c: &mut Criterion) {
    let text = log_text(100_000);
    let mut g = c.benchmark_group("read_log");
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.sample_size(20);
    g.bench_function("LogReader 100k rows", |b| {
        b.iter(|| {
            let mut rdr = LogReader::new(&text[..], "<bench>", &ReadOptions::default()).unwrap();
            let mut sum = 0.0;
            while let Some(s) = rdr.next_sample().unwrap() {
                sum += s.gyro_dps;
            }
            black_box(sum)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Throughput and peak memory of reading a large test log (the 10-million-row bench of `bench/read_log.sh`).
//!
//! ```text
//! read_log_bench gen PATH ROWS [--table]   write a realistic 100 Hz log
//! read_log_bench read PATH                 read_log into a TestLog: MB/s, peak RSS
//! read_log_bench stream PATH               LogReader only (nothing kept): MB/s, peak RSS
//! read_log_bench copy PATH > OUT           LogReader -> LogWriter, like `compensate --stream`
//! ```
//! Driven by `bench/read_log.sh`. Peak RSS is `VmHWM` of `/proc/self/status` (Linux).
//! The reader parses on two threads: besides wall time it prints the on-CPU time of the
//! main thread (the critical path when the machine is busy with other work) and the CPU
//! time of the whole process.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use gyrotherm::csvlog::{read_log, LogReader, LogWriter, ReadOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["gen", path, rows, rest @ ..] => gen(Path::new(path), rows.parse()?, rest == ["--table"]),
        ["read", path] => read(Path::new(path)),
        ["stream", path] => stream(Path::new(path)),
        ["copy", path] => copy(Path::new(path)),
        _ => Err("usage: read_log_bench gen PATH ROWS [--table] | read PATH | stream PATH".into()),
    }
}

/// 100 Hz rows like `12345.670,0.0012345678901,23.4375[,20]`: gyro with 13 decimals around a
/// small bias, temperature on the 0.0625 °C sensor grid.
fn gen(path: &Path, rows: u64, table: bool) -> Result<(), Box<dyn std::error::Error>> {
    let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    writeln!(w, "# synthetic bench log, 100 Hz")?;
    if table {
        writeln!(w, "time_s,gyro_dps,temp_c,table_dps")?;
    } else {
        writeln!(w, "time_s,gyro_dps,temp_c")?;
    }
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in 0..rows {
        // xorshift64: cheap deterministic noise.
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let u = (x >> 11) as f64 / (1u64 << 53) as f64;
        let t = i as f64 * 0.01;
        let gyro = 0.0012 + 0.0005 * (u - 0.5);
        let temp = ((-40.0 + 100.0 * (i as f64 / rows as f64)) / 0.0625).round() * 0.0625;
        write!(w, "{t:.3},{gyro:.13},{temp}")?;
        if table {
            let rate = if (i / 30_000) % 2 == 0 { 20 } else { 0 };
            write!(w, ",{rate}")?;
        }
        writeln!(w)?;
    }
    w.flush()?;
    Ok(())
}

fn report(
    what: &str,
    path: &Path,
    rows: usize,
    secs: f64,
    cpu0: Option<f64>,
) -> Result<(), Box<dyn std::error::Error>> {
    let bytes = std::fs::metadata(path)?.len() as f64;
    let cpu = match (cpu0, cpu_s()) {
        (Some(a), Some(b)) => format!(
            "; main thread on-CPU {:.3} s = {:.0} MB/s",
            b - a,
            bytes / 1e6 / (b - a)
        ),
        _ => String::new(),
    };
    let cpu = match process_cpu_s() {
        Some(p) => format!("{cpu}; process CPU {p:.3} s"),
        None => cpu,
    };
    println!(
        "{what}: {rows} rows, {:.1} MB in {secs:.3} s wall = {:.0} MB/s, {:.2} M rows/s{cpu}; \
         peak RSS {}",
        bytes / 1e6,
        bytes / 1e6 / secs,
        rows as f64 / 1e6 / secs,
        peak_rss().unwrap_or_else(|| "unknown".into())
    );
    Ok(())
}

/// Time the main thread has spent on a CPU, s: the first field of `/proc/self/schedstat`
/// (ns). Unlike wall time it excludes waiting for a busy machine.
fn cpu_s() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn read(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let cpu0 = cpu_s();
    let t0 = Instant::now();
    let (log, _) = read_log(path, &ReadOptions::default())?;
    let secs = t0.elapsed().as_secs_f64();
    report("read_log", path, log.len(), secs, cpu0)
}

fn stream(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let cpu0 = cpu_s();
    let t0 = Instant::now();
    let file = std::fs::File::open(path)?;
    let mut rdr = LogReader::new(file, path, &ReadOptions::default())?;
    let (mut n, mut sum) = (0usize, 0.0);
    while let Some(s) = rdr.next_sample()? {
        n += 1;
        sum += s.gyro_dps;
    }
    let secs = t0.elapsed().as_secs_f64();
    std::hint::black_box(sum);
    report("LogReader", path, n, secs, cpu0)
}

/// Read and write every sample back out with its pass-through fields plus one computed
/// column: the per-line work of `compensate --stream` without the model.
fn copy(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let cpu0 = cpu_s();
    let t0 = Instant::now();
    let file = std::fs::File::open(path)?;
    let mut rdr = LogReader::new(file, path, &ReadOptions::default())?;
    let mut header = vec!["time_s", "gyro_dps", "temp_c", "corrected_dps"];
    header.extend(rdr.extra_names().collect::<Vec<_>>());
    let header: Vec<String> = header.iter().map(|s| s.to_string()).collect();
    let mut out = LogWriter::new(std::io::stdout().lock(), &header)?;
    let mut n = 0usize;
    while let Some(s) = rdr.next_sample()? {
        out.push_f64(s.time_s);
        out.push_f64(s.gyro_dps);
        out.push_f64(s.temp_c);
        out.push_f64(s.gyro_dps - 0.0012);
        out.push_extras(rdr.extra_fields());
        out.end_row()?;
        n += 1;
    }
    out.flush()?;
    let secs = t0.elapsed().as_secs_f64();
    eprintln!(
        "copy: {n} lines in {secs:.3} s wall = {:.2} M lines/s; on-CPU {:.2} M lines/s",
        n as f64 / 1e6 / secs,
        cpu0.zip(cpu_s())
            .map_or(f64::NAN, |(a, b)| n as f64 / 1e6 / (b - a))
    );
    Ok(())
}

/// User + system CPU time of the whole process (all threads), s, from `/proc/self/stat`
/// (clock ticks of 10 ms).
fn process_cpu_s() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses): state is field 3, utime 14.
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// `VmHWM` (peak resident set) from `/proc/self/status`.
fn peak_rss() -> Option<String> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(format!("{:.0} MB", kb / 1024.0))
}

//! Write a synthetic autopilot log for the bench (`bench/autopilot_log.sh`): one three-axis
//! gyro warming from 20 to 60 °C, its bias a function of temperature and its rate of change,
//! with white noise, in PX4 ULog or ArduPilot DataFlash form.
//!
//!   cargo run --release -p gyrotherm --example autopilot_log -- FORMAT OUT MINUTES RATE_HZ
//!
//! FORMAT is `ulog` or `dataflash`. Not part of the product: no command writes these formats.

#[path = "../tests/support/autopilot_writer.rs"]
mod writer;

use std::io::Write;

use writer::{DataFlash, GyroSample, Ulog};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [format, out, minutes, rate_hz] = args.as_slice() else {
        return Err("usage: autopilot_log ulog|dataflash OUT MINUTES RATE_HZ".into());
    };
    let seconds: f64 = minutes.parse::<f64>()? * 60.0;
    let rate_hz: f64 = rate_hz.parse()?;
    let n = (seconds * rate_hz) as u64;
    let mut file = std::io::BufWriter::new(std::fs::File::create(out)?);
    let (mut ulog, mut bin) = match format.as_str() {
        "ulog" => (Some(Ulog::new(1)), None),
        "dataflash" => (None, Some(DataFlash::new())),
        _ => return Err(format!("unknown format {format:?}; use ulog or dataflash").into()),
    };
    // A small linear congruential generator: uniform noise of the same spread each run.
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut noise = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-3
    };
    for i in 0..n {
        let t = i as f64 / rate_hz;
        // First-order warm-up towards 60 °C with a 15-minute time constant.
        let tau = 900.0;
        let temp = 60.0 - 40.0 * (-t / tau).exp();
        let rate_c_per_s = 40.0 / tau * (-t / tau).exp();
        let bias = |k: f64| 1e-3 * k + 2e-5 * k * (temp - 20.0) + 4e-3 * rate_c_per_s;
        let s = GyroSample {
            t_us: 1_000_000 + (t * 1e6) as u64,
            instance: 0,
            rate: [
                (bias(1.0) + noise()) as f32,
                (bias(-0.5) + noise()) as f32,
                (bias(2.0) + noise()) as f32,
            ],
            temp_c: temp as f32,
        };
        let bytes = match (&mut ulog, &mut bin) {
            (Some(w), _) => {
                w.push(s);
                &mut w.bytes
            }
            (_, Some(w)) => {
                w.push(s);
                &mut w.bytes
            }
            _ => unreachable!("one writer is chosen above"),
        };
        if bytes.len() > 1 << 20 {
            file.write_all(bytes)?;
            bytes.clear();
        }
    }
    let rest = ulog
        .map(|w| w.bytes)
        .or(bin.map(|w| w.bytes))
        .unwrap_or_default();
    file.write_all(&rest)?;
    file.flush()?;
    eprintln!("wrote {out}: {n} samples over {seconds} s");
    Ok(())
}

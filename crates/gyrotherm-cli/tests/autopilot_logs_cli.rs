//! Autopilot logs through the real binary: a DataFlash log trains a unit model and is
//! compensated by extension, a ULog given by `--format`, and a damaged log ends with exit 2
//! and the byte at fault.

#[path = "../../gyrotherm/tests/support/autopilot_writer.rs"]
mod writer;

mod cli;
use cli::{assert_exit, gyrotherm, run_ok};
use writer::{DataFlash, GyroSample, Ulog};

/// 20 minutes at 20 Hz of a gyro warming by 20 °C, its bias following the temperature.
fn samples() -> impl Iterator<Item = GyroSample> {
    (0..24_000u64).map(|i| {
        let t = i as f64 / 20.0;
        let temp = 40.0 - 20.0 * (-t / 300.0).exp();
        let b = (1e-4 * (temp - 20.0) + 2e-5 * ((i * 7919 % 101) as f64 - 50.0)) as f32;
        GyroSample {
            t_us: 5_000_000 + i * 50_000,
            instance: 0,
            rate: [b, -b, 2.0 * b],
            temp_c: temp as f32,
        }
    })
}

#[test]
fn a_dataflash_log_trains_and_compensates_as_a_unit_and_a_ulog_reads_by_format() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = DataFlash::new();
    samples().for_each(|s| bin.push(s));
    let log = dir.path().join("00000001.BIN");
    std::fs::write(&log, &bin.bytes).unwrap();
    let model = dir.path().join("m.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "thermal", "--input"])
            .arg(&log)
            .arg("--out")
            .arg(&model),
    );
    let out = dir.path().join("comp.csv");
    let r = run_ok(
        gyrotherm()
            .arg("compensate")
            .arg("--model")
            .arg(&model)
            .arg("--input")
            .arg(&log)
            .arg("--out")
            .arg(&out),
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("time_s,gyro_x_dps,gyro_y_dps,gyro_z_dps,temp_c,samples,"),
        "{}",
        text.lines().next().unwrap_or_default()
    );
    // One row per second of the 20 minutes.
    assert_eq!(
        text.lines().count(),
        1 + 1200,
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let mut ulog = Ulog::new(1);
    samples().for_each(|s| ulog.push(s));
    let as_dat = dir.path().join("gyro.dat");
    std::fs::write(&as_dat, &ulog.bytes).unwrap();
    run_ok(
        gyrotherm()
            .args(["evaluate", "--format", "ulog", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&as_dat),
    );
}

#[test]
fn a_damaged_autopilot_log_exits_2_naming_the_byte() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = DataFlash::new();
    samples().take(100).for_each(|s| bin.push(s));
    // The first byte of the second IMU message (after the two FMT messages).
    bin.bytes[2 * 89 + writer::IMU_LEN] ^= 0xFF;
    let log = dir.path().join("bad.bin");
    std::fs::write(&log, &bin.bytes).unwrap();
    let r = gyrotherm()
        .args(["train", "--method", "thermal", "--input"])
        .arg(&log)
        .arg("--out")
        .arg(dir.path().join("m.json"))
        .output()
        .unwrap();
    assert_exit(&r, 2);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("bad.bin") && err.contains("byte "), "{err}");
}

//! PX4 ULog and ArduPilot DataFlash logs read as a three-axis unit: values, reduction to model
//! steps, instance choice, a cut-off end and a damaged header. The logs are written here.

#[path = "support/autopilot_writer.rs"]
mod writer;

use std::path::{Path, PathBuf};

use gyrotherm::csvlog::{
    read_imu_log, read_log, LogErrorKind, LogFormat, ReadOptions, SAMPLES_COL, SENSOR_GYRO_COLS,
};
use writer::{DataFlash, GyroSample, Ulog, IMU_LEN};

const DPS: f64 = 180.0 / std::f64::consts::PI;

/// 2.5 s at 1 kHz from t = 20 s, two instances: instance k turns at (0.1 + k, 0, −0.2) rad/s,
/// its temperature ramps from 30 + k °C by 1 °C/s.
fn samples() -> impl Iterator<Item = GyroSample> {
    (0..2500u64).flat_map(|i| {
        (0..2u8).map(move |k| GyroSample {
            t_us: 20_000_000 + i * 1000 + k as u64,
            instance: k,
            rate: [0.1 + k as f32, 0.0, -0.2],
            temp_c: 30.0 + k as f32 + i as f32 * 1e-3,
        })
    })
}

fn ulog() -> Vec<u8> {
    let mut w = Ulog::new(2);
    samples().for_each(|s| w.push(s));
    w.bytes
}

fn dataflash() -> Vec<u8> {
    let mut w = DataFlash::new();
    samples().for_each(|s| w.push(s));
    w.bytes
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn check_instance(path: &Path, instance: u8) {
    let opts = ReadOptions {
        instance,
        ..ReadOptions::default()
    };
    let (log, report) = read_imu_log(path, &opts, None).unwrap();
    assert_eq!(report.rows, 2500);
    assert_eq!(report.truncated_at_byte, None);
    let names: Vec<&str> = log.gyro.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, SENSOR_GYRO_COLS);
    assert_eq!(log.temp[0].name, "temp_c");
    assert_eq!(log.len(), 3);
    assert_eq!(log.extra[0].name, SAMPLES_COL);
    assert_eq!(log.extra[0].values, ["1000", "1000", "500"]);
    let k = instance as f64;
    let x = (0.1f32 + instance as f32) as f64 * DPS;
    let z = (-0.2f32) as f64 * DPS;
    for r in 0..3 {
        assert!(
            (log.gyro[0].values[r] - x).abs() < 1e-9,
            "{:?}",
            log.gyro[0]
        );
        assert_eq!(log.gyro[1].values[r], 0.0);
        assert!((log.gyro[2].values[r] - z).abs() < 1e-9);
    }
    // Means of the step: time 0.4995 s into it, temperature half a second up its ramp.
    assert!(
        (log.time_s[0] - (20.4995 + k * 1e-6)).abs() < 1e-9,
        "{}",
        log.time_s[0]
    );
    assert!((log.temp[0].values[0] - (30.4995 + k)).abs() < 1e-4);
    assert!((log.temp[0].values[2] - (32.2495 + k)).abs() < 1e-4);
}

#[test]
fn both_formats_read_as_a_unit_with_one_row_per_step_and_the_chosen_instance() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in [("a.ulg", ulog()), ("a.bin", dataflash())] {
        let p = write(dir.path(), name, &bytes);
        check_instance(&p, 0);
        check_instance(&p, 1);
        let e = read_imu_log(
            &p,
            &ReadOptions {
                instance: 3,
                ..ReadOptions::default()
            },
            None,
        )
        .unwrap_err();
        assert_eq!(e.kind, LogErrorKind::NoData);
        assert!(e.to_string().contains("instance(s) 0, 1"), "{e}");
    }
}

#[test]
fn one_axis_reads_by_its_name_and_the_format_option_overrides_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "gyro.dat", &dataflash());
    let opts = ReadOptions {
        format: Some(LogFormat::DataFlash),
        gyro_col: "gyro_z_dps".into(),
        ..ReadOptions::default()
    };
    let (log, _) = read_log(&p, &opts).unwrap();
    assert_eq!(log.len(), 3);
    assert!((log.gyro_dps[1] - (-0.2f32) as f64 * DPS).abs() < 1e-9);
    // The default gyro column names no axis: the error lists them.
    let e = read_log(
        &p,
        &ReadOptions {
            format: Some(LogFormat::DataFlash),
            ..ReadOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("gyro_x_dps,gyro_y_dps,gyro_z_dps"),
        "{e}"
    );
    // Read as CSV (no format given, an unknown extension), it is no CSV.
    assert!(read_log(&p, &ReadOptions::default()).is_err());
    // A unit's columns picked by name, in the order given.
    let (unit, _) = read_imu_log(
        &p,
        &ReadOptions {
            format: Some(LogFormat::DataFlash),
            gyro_col: "gyro_z_dps,gyro_x_dps".into(),
            ..ReadOptions::default()
        },
        None,
    )
    .unwrap();
    assert_eq!(unit.gyro[0].name, "gyro_z_dps");
    assert_eq!(unit.gyro.len(), 2);
}

#[test]
fn a_cut_off_log_is_read_to_its_last_whole_message_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in [("cut.ulg", ulog()), ("cut.bin", dataflash())] {
        // Cut in the middle of the last message.
        let cut = &bytes[..bytes.len() - 7];
        let p = write(dir.path(), name, cut);
        let (log, report) = read_imu_log(&p, &ReadOptions::default(), None).unwrap();
        let at = report.truncated_at_byte.expect("a cut-off log is reported");
        assert!(at < cut.len() as u64 && at + 60 > cut.len() as u64, "{at}");
        // Instance 0's last sample came before the cut one (instance 1's).
        assert_eq!(report.rows, 2500, "{name}");
        assert_eq!(log.extra[0].values[2], "500");
        let w = report.truncation_warning(&p).unwrap();
        assert!(w.contains(&format!("byte {at}")), "{w}");
    }
    // DataFlash cut inside a message header.
    let bytes = dataflash();
    let p = write(dir.path(), "head.bin", &bytes[..bytes.len() - IMU_LEN + 2]);
    let (_, report) = read_imu_log(&p, &ReadOptions::default(), None).unwrap();
    assert_eq!(
        report.truncated_at_byte,
        Some((bytes.len() - IMU_LEN) as u64)
    );
}

#[test]
fn a_damaged_header_is_an_error_naming_the_byte_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    for (name, mut bytes) in [("bad.ulg", ulog()), ("bad.bin", dataflash())] {
        bytes[0] ^= 0xFF;
        let p = write(dir.path(), name, &bytes);
        let e = read_imu_log(&p, &ReadOptions::default(), None).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::Corrupt, "{e}");
        let m = e.to_string();
        assert!(
            m.contains(name) && m.contains("byte 0") && m.contains("--format"),
            "{m}"
        );
    }
    // Damage after the start names its offset.
    let mut bytes = dataflash();
    let at = 2 * 89 + 5 * IMU_LEN;
    bytes[at] = 0;
    let p = write(dir.path(), "mid.bin", &bytes);
    let e = read_imu_log(&p, &ReadOptions::default(), None).unwrap_err();
    assert!(e.to_string().contains(&format!("byte {at}")), "{e}");
    // A FMT that declares a length under its header.
    let mut bytes = dataflash();
    bytes[89 + 4] = 2;
    let p = write(dir.path(), "fmt.bin", &bytes);
    let e = read_imu_log(&p, &ReadOptions::default(), None).unwrap_err();
    assert!(e.to_string().contains("byte 89"), "{e}");
}

/// A format definition holding a number no message could hold (an array's length past
/// 65535) is an error naming the byte, not a panic in the decoder (whose tokenizer unwraps
/// the number as a `usize`). Found by the `ulog` fuzz target.
#[test]
fn a_format_with_an_impossible_array_length_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let good = ulog();
    // The file header (16 bytes) and the flag bits (3 + 40): the format message follows.
    let head = 16 + 3 + 40;
    for len in ["99999999999999999999999", "65536"] {
        let mut b = good[..head].to_vec();
        let payload = format!("other:uint64_t timestamp;float[{len}] v;");
        b.extend_from_slice(&(payload.len() as u16).to_le_bytes());
        b.push(b'F');
        b.extend_from_slice(payload.as_bytes());
        b.extend_from_slice(&good[head..]);
        let p = write(dir.path(), "format.ulg", &b);
        let e = read_imu_log(&p, &ReadOptions::default(), None).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::Corrupt, "{e}");
        let m = e.to_string();
        assert!(m.contains("format definition") && m.contains("byte"), "{m}");
    }
    // 65535 is a length a message could hold: read as before.
    let mut b = good[..head].to_vec();
    let payload = b"other:uint64_t timestamp;uint8_t[65535] v;";
    b.extend_from_slice(&(payload.len() as u16).to_le_bytes());
    b.push(b'F');
    b.extend_from_slice(payload);
    b.extend_from_slice(&good[head..]);
    let p = write(dir.path(), "long.ulg", &b);
    check_instance(&p, 0);
}

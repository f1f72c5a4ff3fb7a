//! The log reader against a careless or hostile user: a sample period that does not match
//! the log, runaway gap filling, irregular steps, and `;` or tab separated logs with decimal
//! commas.

use std::io::Cursor;
use std::path::Path;

use gyrotherm::csvlog::{read_log, LogErrorKind, LogReader, ReadOptions, MAX_FILLED_SAMPLES};

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn rows_1hz(n: usize) -> String {
    let mut s = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..n {
        s.push_str(&format!("{i},0.001,{}\n", 25.0 + 0.01 * i as f64));
    }
    s
}

#[test]
fn a_given_period_that_disagrees_with_the_log_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "base.csv", &rows_1hz(1000));
    // 1 ms on a 1 Hz log: every step would be a gap of 999 samples (the runaway output).
    for period in [0.001, 1e-6, 10.0] {
        let opts = ReadOptions {
            sample_period_s: Some(period),
            fill_gaps_max_s: Some(1e6),
            ..ReadOptions::default()
        };
        let e = read_log(&p, &opts).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::BadOptions, "{e}");
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!("{}:5: column time_s:", p.display())),
            "{msg}"
        );
        assert!(msg.contains("disagrees with the log's time steps"), "{msg}");
        assert!(msg.contains("median step 1 s"), "{msg}");
    }
    // The right period, and one within jitter of it, are accepted; so are two real gaps
    // among the first steps.
    let mut text = rows_1hz(5);
    text.push_str("7,0.001,25\n10,0.001,25\n11,0.001,25\n12,0.001,25\n");
    let p = write(dir.path(), "gaps.csv", &text);
    for period in [1.0, 1.1] {
        let opts = ReadOptions {
            sample_period_s: Some(period),
            fill_gaps_max_s: Some(5.0),
            ..ReadOptions::default()
        };
        let (log, report) = read_log(&p, &opts).unwrap();
        assert_eq!(report.filled_gaps, 2);
        assert!(log.len() > 9);
    }
}

#[test]
fn gap_filling_is_bounded_in_all() {
    // Ten regular steps, then two gaps of 6 million periods each: the first is filled, the
    // second would pass the bound of 10 million filled samples.
    let mut text = rows_1hz(11);
    let g = 6_000_000.0;
    for t in [10.0 + g, 11.0 + g, 11.0 + 2.0 * g] {
        text.push_str(&format!("{t},0.001,25\n"));
    }
    let opts = ReadOptions {
        sample_period_s: Some(1.0),
        fill_gaps_max_s: Some(1e9),
        ..ReadOptions::default()
    };
    let mut r = LogReader::new(Cursor::new(text), "big.csv", &opts).unwrap();
    let mut n = 0usize;
    let e = loop {
        match r.next_sample() {
            Ok(Some(_)) => n += 1,
            Ok(None) => panic!("read to the end: {n} samples"),
            Err(e) => break e,
        }
    };
    assert_eq!(e.kind, LogErrorKind::GapTooLong, "{e}");
    assert!(
        e.to_string()
            .contains(&format!("more than {MAX_FILLED_SAMPLES}")),
        "{e}"
    );
    assert_eq!(e.line, Some(15));
    assert!(n < MAX_FILLED_SAMPLES, "{n}");
}

#[test]
fn irregular_steps_are_measured_and_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    // Steps 1.25, 0.75, 1, ... s (exact in binary): 25 % jitter, first on line 3.
    let mut s = String::from("time_s,gyro_dps,temp_c\n");
    let mut t = 0.0;
    for i in 0..300 {
        s.push_str(&format!("{t},0.001,25\n"));
        t += match i % 3 {
            0 => 1.25,
            1 => 0.75,
            _ => 1.0,
        };
    }
    let p = write(dir.path(), "jitter.csv", &s);
    let (_, report) = read_log(&p, &ReadOptions::default()).unwrap();
    assert_eq!(report.max_step_jitter, 0.25, "{report:?}");
    let w = report.jitter_warning(&p).expect("a warning");
    assert!(
        w.contains(":3:") && w.contains("up to 25 % off the 1 s period"),
        "{w}"
    );
    // An evenly sampled log gets none.
    let p = write(dir.path(), "even.csv", &rows_1hz(300));
    let (_, report) = read_log(&p, &ReadOptions::default()).unwrap();
    assert_eq!(report.max_step_jitter, 0.0);
    assert!(report.jitter_warning(&p).is_none());
}

#[test]
fn semicolon_and_tab_logs_with_decimal_commas_read_as_the_comma_log() {
    let dir = tempfile::tempdir().unwrap();
    let comma = "time_s,gyro_dps,temp_c,table_dps,note\n0,0.5,-12.25,10,a b\n1,-1.5e-3,20,10,c\n";
    let semi = "time_s;gyro_dps;temp_c;table_dps;note\n0;0,5;-12,25;10;a b\n1;-1,5e-3;20;10;c\n";
    let tab = "time_s\tgyro_dps\ttemp_c\ttable_dps\tnote\n0\t0,5\t-12.25\t10\ta b\n1\t-1.5e-3\t20\t10\tc\n";
    let want = read_log(&write(dir.path(), "c.csv", comma), &ReadOptions::default()).unwrap();
    for (name, text, delimiter) in [("s.csv", semi, b';'), ("t.csv", tab, b'\t')] {
        let opts = ReadOptions {
            delimiter,
            ..ReadOptions::default()
        };
        let got = read_log(&write(dir.path(), name, text), &opts).unwrap();
        assert_eq!(got.0, want.0, "{name}");
    }
    // Read with the default comma, each says which separator its header seems to use.
    for (name, text, hint) in [
        ("s.csv", semi, "give --delimiter ;"),
        ("t.csv", tab, "give --delimiter tab"),
    ] {
        let p = write(dir.path(), name, text);
        let e = read_log(&p, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(hint), "{e}");
    }
    // A decimal comma in a comma-separated file is still an error, with the way out.
    let opts = ReadOptions {
        delimiter: b';',
        ..ReadOptions::default()
    };
    let p = write(
        dir.path(),
        "bad.csv",
        "time_s;gyro_dps;temp_c\n0;1,2,3;25\n",
    );
    let e = read_log(&p, &opts).unwrap_err().to_string();
    assert!(
        e.contains("bad.csv:2: column gyro_dps") && e.contains("is not a number"),
        "{e}"
    );
}

/// A gyro field finite in its unit but beyond f64 in °/s (1e308 rad/s is 5.7e309 °/s) is an
/// error naming line and column, never an infinite sample: on the fast path, the CSV path,
/// and a unit's further gyro columns. Found by the `csvlog` fuzz target.
#[test]
fn a_gyro_value_that_overflows_in_degrees_per_second_is_refused() {
    use gyrotherm::csvlog::{read_imu_log, GyroUnit};
    let dir = tempfile::tempdir().unwrap();
    let rad = ReadOptions {
        gyro_unit: GyroUnit::RadPerS,
        ..ReadOptions::default()
    };
    // Plain rows (the fast path), then a quoted field (the CSV path takes the row).
    for (name, row) in [
        ("plain.csv", "2,1e308,25"),
        ("quoted.csv", "2,\"1e308\",25"),
    ] {
        let p = write(
            dir.path(),
            name,
            &format!("time_s,gyro_dps,temp_c\n0,0.5,25\n1,0.5,25\n{row}\n3,0.5,25\n"),
        );
        let e = read_log(&p, &rad).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::NonFinite, "{e}");
        let text = e.to_string();
        assert!(text.contains(":4") && text.contains("gyro_dps"), "{text}");
        // In °/s the same number is a number.
        assert_eq!(
            read_log(&p, &ReadOptions::default()).unwrap().0.gyro_dps[2],
            1e308
        );
    }
    let p = write(
        dir.path(),
        "unit.csv",
        "time_s,gx,gy,temp_c\n0,0.5,0.5,25\n1,0.5,1e308,25\n2,0.5,0.5,25\n",
    );
    let lists = ReadOptions {
        gyro_col: "gx,gy".into(),
        ..rad
    };
    let e = read_imu_log(&p, &lists, None).unwrap_err().to_string();
    assert!(e.contains("gy") && e.contains("data row 2"), "{e}");
}

/// Gap filling between values of opposite sign near f64's limit gives finite samples (the
/// difference of the two overflows).
#[test]
fn filling_a_gap_between_huge_values_stays_finite() {
    let text = "time_s,gyro_dps,temp_c\n0,1e308,25\n1,1.7e308,25\n3,-1.7e308,25\n";
    let opts = ReadOptions {
        fill_gaps_max_s: Some(5.0),
        ..ReadOptions::default()
    };
    let mut r = LogReader::new(Cursor::new(text.as_bytes()), "gap.csv", &opts).unwrap();
    let mut gyro = Vec::new();
    while let Some(s) = r.next_sample().unwrap() {
        gyro.push(s.gyro_dps);
    }
    assert_eq!(gyro.len(), 4, "{gyro:?}");
    assert!(gyro.iter().all(|g| g.is_finite()), "{gyro:?}");
    // Halfway between 1.7e308 and -1.7e308.
    assert!(gyro[2].abs() < 1e300, "{gyro:?}");
}

//! The inertial-unit simulator (`sim::imu`) and log (`csvlog::read_imu_log`): truth columns
//! that add up, a shared housing, one sensor per coil, and column lists read back exactly.

use gyrotherm::csvlog::{self, read_imu_log, write_imu_log, ReadOptions};
use gyrotherm::sim::imu::{self, ImuConfig, AXIS_NAMES};
use gyrotherm::sim::SimConfig;

/// Unit 1000 (the first of the design family, bench/generalisation.sh) on `seed-shock`.
fn config(table_axis: Option<usize>) -> ImuConfig {
    let mut run = SimConfig::builtin("seed-shock").unwrap();
    run.seed = 3;
    run.truth = true;
    run.table_rate_dps = table_axis.map(|_| 20.0);
    ImuConfig {
        run,
        unit: imu::imu_from_family(1000),
        table_axis: table_axis.unwrap_or(0),
    }
}

fn extra(log: &csvlog::ImuLog, name: &str) -> Vec<f64> {
    let c = log
        .extra
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("{name}"));
    c.values.iter().map(|v| v.parse().unwrap()).collect()
}

#[test]
fn each_axis_output_is_its_bias_plus_scaled_table_plus_noise() {
    let log = imu::simulate_imu(&config(Some(1))).unwrap();
    assert_eq!(log.table_axis.as_deref(), Some("gyro_y_dps"));
    let table = &log.table.as_ref().unwrap().values;
    for (k, a) in AXIS_NAMES.iter().enumerate() {
        let b = extra(&log, &imu::truth_col("true_bias_dps", a));
        let s = extra(&log, &imu::truth_col("true_scale", a));
        let n = extra(&log, &imu::truth_col("noise_dps", a));
        for i in 0..log.len() {
            let input = if k == 1 { table[i] } else { 0.0 };
            let want = b[i] + s[i] * input + n[i];
            // Rounding of one sum of three terms at 20 °/s: a few ulps.
            assert!(
                (log.gyro[k].values[i] - want).abs() <= 1e-13,
                "axis {a} row {i}: gyro {} want {want}",
                log.gyro[k].values[i]
            );
        }
    }
}

#[test]
fn gyros_share_the_case_and_each_sensor_sees_its_own_node() {
    let log = imu::simulate_imu(&config(None)).unwrap();
    assert_eq!(log.temp[0].name, imu::CASE_SENSOR_COL);
    let case = extra(&log, "case_temp_c");
    let coils: Vec<Vec<f64>> = AXIS_NAMES
        .iter()
        .map(|a| extra(&log, &imu::truth_col("coil_temp_c", a)))
        .collect();
    // Every reading is a whole number of DS18B20 steps (0.0625 °C, He et al. 2024 §3).
    for t in &log.temp {
        assert!(
            t.values.iter().all(|v| (v / 0.0625).fract() == 0.0),
            "{}",
            t.name
        );
    }
    // Each sensor tracks its node better than any other node: mean absolute difference.
    let mad = |a: &[f64], b: &[f64]| {
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / a.len() as f64
    };
    let nodes: Vec<&[f64]> = std::iter::once(case.as_slice())
        .chain(coils.iter().map(Vec::as_slice))
        .collect();
    for (j, t) in log.temp.iter().enumerate() {
        let own = mad(&t.values, nodes[j]);
        for (m, node) in nodes.iter().enumerate() {
            if m != j && mad(node, nodes[j]) > 1.0 {
                assert!(
                    own < mad(&t.values, node),
                    "{} is closer to node {m} than to its own",
                    t.name
                );
            }
        }
    }
    // The coils differ from the case (the gradient a housing sensor cannot see).
    assert!(coils.iter().any(|c| mad(c, &case) > 1.0));
}

#[test]
fn column_lists_read_back_exactly_and_find_the_table_axis() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.csv");
    let log = imu::simulate_imu(&config(Some(2))).unwrap();
    write_imu_log(&path, &log).unwrap();
    let opts = ReadOptions {
        gyro_col: "gyro_x_dps,gyro_y_dps,gyro_z_dps".into(),
        temp_col: "temp_case_c,temp_x_c,temp_y_c,temp_z_c".into(),
        ..ReadOptions::default()
    };
    let (back, _) = read_imu_log(&path, &opts, None).unwrap();
    assert_eq!(back.time_s, log.time_s);
    assert_eq!(back.gyro, log.gyro);
    assert_eq!(back.temp, log.temp);
    assert_eq!(back.table_axis.as_deref(), Some("gyro_z_dps"));
    // Named explicitly, the axis is taken as given; a name that is no gyro column is refused.
    let (named, _) = read_imu_log(&path, &opts, Some("gyro_x_dps")).unwrap();
    assert_eq!(named.table_axis.as_deref(), Some("gyro_x_dps"));
    let e = read_imu_log(&path, &opts, Some("temp_x_c"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("\"temp_x_c\" is not one of the gyro columns"),
        "{e}"
    );
    // One axis as a single-axis log: the table only on the axis it turns.
    assert!(back.axis_log(2, 0).table_dps.is_some());
    assert!(back.axis_log(0, 0).table_dps.is_none());
}

#[test]
fn a_missing_listed_column_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.csv");
    write_imu_log(&path, &imu::simulate_imu(&config(None)).unwrap()).unwrap();
    let opts = ReadOptions {
        gyro_col: "gyro_x_dps,gyro_w_dps".into(),
        temp_col: "temp_case_c".into(),
        ..ReadOptions::default()
    };
    let e = read_imu_log(&path, &opts, None).unwrap_err();
    assert_eq!(e.kind, csvlog::LogErrorKind::MissingColumn);
    assert!(e.to_string().contains("gyro_w_dps"), "{e}");
}

#[test]
fn one_name_each_reads_a_single_axis_log_as_read_log_does() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("one.csv");
    let mut run = SimConfig::builtin("seed-shock").unwrap();
    run.table_rate_dps = Some(20.0);
    let single = gyrotherm::simulate(&run).unwrap();
    gyrotherm::write_log(&path, &single).unwrap();
    let (imu_log, _) = read_imu_log(&path, &ReadOptions::default(), None).unwrap();
    assert_eq!(imu_log.axis_log(0, 0), single);
}

#[test]
fn several_logs_read_at_once_give_each_file_s_own_result_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    write_imu_log(&a, &imu::simulate_imu(&config(Some(2))).unwrap()).unwrap();
    write_imu_log(&b, &imu::simulate_imu(&config(None)).unwrap()).unwrap();
    let missing = dir.path().join("missing.csv");
    let opts = ReadOptions {
        gyro_col: "gyro_x_dps,gyro_y_dps,gyro_z_dps".into(),
        temp_col: "temp_case_c,temp_x_c".into(),
        ..ReadOptions::default()
    };
    let paths = [&b, &missing, &a];
    let all = csvlog::read_imu_logs(&paths, &opts, None);
    assert_eq!(all.len(), 3);
    // Each result is the one-file read of the path at its place.
    for (p, r) in paths.iter().zip(&all) {
        match (read_imu_log(p, &opts, None), r) {
            (Ok((one, _)), Ok((got, _))) => assert_eq!(&one, got),
            (Err(one), Err(got)) => assert_eq!(one.to_string(), got.to_string()),
            (one, got) => panic!("{}: {one:?} against {got:?}", p.display()),
        }
    }
    assert!(all[1].is_err());
    assert!(all[0].as_ref().unwrap().0.table.is_none());
    assert!(all[2].as_ref().unwrap().0.table.is_some());
}

/// The further columns are parsed as strictly as the first ones: the first bad field of a
/// column is named by column and data row (a later bad field, or a bad field in a later
/// column, is not the one told), and an empty field between two numbers is interpolated in
/// time (independent: the straight line between its neighbours).
#[test]
fn further_columns_name_their_first_bad_field_and_fill_empty_ones() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.csv");
    write_imu_log(&good, &imu::simulate_imu(&config(None)).unwrap()).unwrap();
    let text = std::fs::read_to_string(&good).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let edit = |edits: &[(usize, usize, &str)]| {
        let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
        for &(row, c, v) in edits {
            let mut f: Vec<String> = lines[row].split(',').map(str::to_owned).collect();
            f[c] = v.to_owned();
            lines[row] = f.join(",");
        }
        let path = dir.path().join("edited.csv");
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        path
    };
    let opts = ReadOptions {
        gyro_col: "gyro_x_dps,gyro_y_dps,gyro_z_dps".into(),
        temp_col: "temp_case_c,temp_x_c,temp_y_c,temp_z_c".into(),
        ..ReadOptions::default()
    };
    let (gy, ty) = (col("gyro_y_dps"), col("temp_y_c"));
    let bad = edit(&[(40, gy, "nope"), (30, ty, "x"), (70, gy, "inf")]);
    let e = read_imu_log(&bad, &opts, None).unwrap_err();
    assert_eq!(e.kind, csvlog::LogErrorKind::NotANumber);
    let msg = e.to_string();
    assert!(
        msg.contains("gyro_y_dps") && msg.contains("data row 40: \"nope\" is not a number"),
        "{msg}"
    );
    let inf = edit(&[(70, ty, "inf")]);
    let e = read_imu_log(&inf, &opts, None).unwrap_err();
    assert_eq!(e.kind, csvlog::LogErrorKind::NonFinite);
    assert!(e.to_string().contains("data row 70"), "{e}");
    let empty = edit(&[(25, ty, "")]);
    let (log, _) = read_imu_log(&empty, &opts, None).unwrap();
    let (back, _) = read_imu_log(&good, &opts, None).unwrap();
    let (t, v) = (&log.time_s, &back.temp[2].values);
    let want = v[23] + (t[24] - t[23]) / (t[25] - t[23]) * (v[25] - v[23]);
    assert_eq!(log.temp[2].values[24], want);
    assert_eq!(log.temp[2].values[..24], v[..24]);
    assert_eq!(log.temp[2].values[25..], v[25..]);
}

/// A single gyro's log is the unit of one axis: written as a one-axis unit it is the same
/// file byte for byte, and reads back as the same log.
#[test]
fn a_single_gyro_log_written_as_a_one_axis_unit_is_the_same_file() {
    use gyrotherm::csvlog::{read_log, write_log, ExtraColumn, ImuLog};
    let mut run = SimConfig::builtin("seed-shock").unwrap();
    run.table_rate_dps = Some(20.0);
    run.truth = true;
    let single = gyrotherm::sim::simulate(&run).unwrap();
    let unit = ImuLog::of_axis(single.clone(), "gyro_dps", "temp_c", "table_dps");
    assert_eq!(unit.axis_log(0, 0), single);
    assert!(!single.extra.is_empty(), "the truth columns pass through");
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("single.csv"), dir.path().join("unit.csv"));
    write_log(&a, &single).unwrap();
    write_imu_log(&b, &unit).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(read_log(&b, &ReadOptions::default()).unwrap().0, single);
    // A static run's all-zero table column is kept too.
    let mut zeros = single.clone();
    zeros.table_dps = Some(vec![0.0; zeros.len()]);
    let back = ImuLog::of_axis(zeros.clone(), "gyro_dps", "temp_c", "table_dps").axis_log(0, 0);
    assert_eq!(back, zeros);

    // A pass-through column shorter than the log is refused, naming it, for a unit as for a
    // single gyro (the unit's writer indexed past its end before).
    let mut short = unit.clone();
    short.extra.push(ExtraColumn {
        name: "note".into(),
        values: vec!["x".into()],
    });
    let e = write_imu_log(&b, &short).unwrap_err().to_string();
    assert!(e.contains("column note") && e.contains("timestamps"), "{e}");
    // A pass-through column named like a numeric column would read back as that column.
    let mut twice = unit;
    twice.extra.push(ExtraColumn {
        name: "gyro_dps".into(),
        values: vec!["0".into(); single.time_s.len()],
    });
    assert!(write_imu_log(&b, &twice).is_err());
}

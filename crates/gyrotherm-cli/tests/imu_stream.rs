//! `compensate --stream` with an inertial-unit model, through the real binary:
//! - batch and stream give the same file, byte for byte, on a simulated unit log with a fault
//!   in one temperature sensor (NaN burst, a DS18B20 bus error), and the fault holds only the
//!   axis that reads that sensor;
//! - with time-stamp faults (which batch refuses), every axis's four columns equal, to the
//!   last character, those of the single-axis `compensate --stream` run with that axis's own
//!   model on its gyro and sensor columns: an independent path through the same flight core;
//! - a further sensor that dies for good (the default fit, every axis on several sensors)
//!   leaves each axis reading it compensating on its fallback (status `fallback`), with the
//!   x-axis bias stability near the fault-free figure, where a model without fallbacks (as
//!   written before them) stays degraded.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Stdio;

mod cli;
use cli::{gyrotherm, run_ok, simulate_args};

const GYROS: [&str; 3] = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"];
const TEMPS: &str = "temp_case_c,temp_x_c,temp_y_c,temp_z_c";

/// Unit 1000 (design family): a linear model on all four sensors, then rewritten so that
/// axis x reads the x coil sensor, y the y coil sensor and z the case sensor (the linear
/// method keeps the first sensor; the test needs axes on different sensors), unsealed.
fn unit_model(dir: &Path) -> PathBuf {
    let unit = ["--imu", "--unit", "random", "--unit-seed", "1000"];
    let prof = ["--profile", "fast-cycle"];
    let s = simulate_args(
        dir,
        "s.csv",
        &[&unit[..], &prof[..], &["--seed", "1"]].concat(),
    );
    let t = simulate_args(
        dir,
        "t.csv",
        &[
            &unit[..],
            &prof[..],
            &["--seed", "2", "--table-rate", "20", "--table-axis", "x"],
        ]
        .concat(),
    );
    let trained = dir.join("trained.json");
    run_ok(
        gyrotherm()
            .args([
                "train",
                "--method",
                "linear",
                "--gyro-col",
                &GYROS.join(","),
            ])
            .args(["--temp-col", TEMPS, "--input"])
            .arg(&s)
            .arg("--input")
            .arg(&t)
            .arg("--out")
            .arg(&trained),
    );
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&trained).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("content_sha256");
    for (a, temp) in
        v["axes"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .zip(["temp_x_c", "temp_y_c", "temp_case_c"])
    {
        a["temps"] = serde_json::json!([temp]);
    }
    let model = dir.join("unit.json");
    std::fs::write(&model, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    model
}

/// `compensate --stream` of `input` (extra arguments `args`): stdout.
fn stream(model: &Path, input: &Path, args: &[&str]) -> String {
    let out = run_ok(
        gyrotherm()
            .args(["compensate", "--stream", "--model"])
            .arg(model)
            .args(args)
            .stdin(Stdio::from(std::fs::File::open(input).unwrap())),
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The log `text` with each data line `i` (1-based) rewritten by `edit` (fields by index).
fn edited(text: &str, mut edit: impl FnMut(usize, &mut Vec<String>)) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
            if i > 0 {
                edit(i, &mut f);
            }
            f.join(",") + "\n"
        })
        .collect()
}

fn unit_run(dir: &Path) -> String {
    let run = simulate_args(
        dir,
        "run.csv",
        &[
            "--imu",
            "--unit",
            "random",
            "--unit-seed",
            "1000",
            "--seed",
            "3",
        ],
    );
    std::fs::read_to_string(run).unwrap()
}

#[test]
fn batch_and_stream_write_the_same_file_and_a_sensor_fault_stays_on_its_axis() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = unit_model(d);
    let text = unit_run(d);
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let ty = col("temp_y_c");
    // The y coil sensor: NaN for 300 lines, a bus error (-127 °C) for 50 (batch refuses a
    // NaN gyro sample in a log file; the other test has them).
    let faulty = edited(&text, |i, f| match i {
        5_001..=5_300 => f[ty] = "NaN".into(),
        9_001..=9_050 => f[ty] = "-127".into(),
        _ => {}
    });
    let input = d.join("faulty.csv");
    std::fs::write(&input, &faulty).unwrap();
    let batch = d.join("batch.csv");
    run_ok(
        gyrotherm()
            .args(["compensate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&input)
            .arg("--out")
            .arg(&batch),
    );
    let batch = std::fs::read_to_string(&batch).unwrap();
    let streamed = stream(&model, &input, &[]);
    let lines = faulty.lines().count();
    assert_eq!(streamed.lines().count(), lines);
    let differ = batch
        .lines()
        .zip(streamed.lines())
        .filter(|(a, b)| a != b)
        .count();
    println!("batch vs stream: {lines} lines, {differ} differ");
    assert_eq!(batch.lines().count(), lines);
    assert_eq!(differ, 0, "batch and stream differ");
    assert_eq!(batch, streamed);
    // On the faulted lines axis y (the y coil sensor's) is not ok; x and z are ok throughout.
    let out_header: Vec<&str> = streamed.lines().next().unwrap().split(',').collect();
    let st = |g: &str| {
        let streamed = &streamed;
        let k = out_header
            .iter()
            .position(|h| *h == format!("{g}_status"))
            .unwrap();
        streamed
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(k).unwrap().to_owned())
            .collect::<Vec<_>>()
    };
    let (sx, sy, sz) = (st(GYROS[0]), st(GYROS[1]), st(GYROS[2]));
    for i in (5_001..=5_300).chain(9_001..=9_050) {
        assert_ne!(sy[i - 1], "ok", "line {i}");
    }
    assert!(sx.iter().chain(&sz).all(|s| s == "ok"));

    // An independent path: the library's in-memory `compensate_imu` (one compensator per
    // axis, no unit, no line handling) on the log read by the strict reader, which takes the
    // finite faults only: the bus-error lines.
    let finite = edited(&text, |i, f| {
        if (9_001..=9_050).contains(&i) {
            f[ty] = "-127".into();
        }
    });
    let input = d.join("finite.csv");
    std::fs::write(&input, &finite).unwrap();
    let streamed = stream(&model, &input, &[]);
    let m = gyrotherm::model::unit::ImuModel::load(&model).unwrap();
    let opts = m.read_options(&gyrotherm::ReadOptions::default());
    let (log, _) = gyrotherm::csvlog::read_imu_log(&input, &opts, None).unwrap();
    let want = gyrotherm::compensate::unit::compensate_imu(&m, &log).unwrap();
    let (mut n, mut differ) = (0, 0);
    for (k, g) in GYROS.iter().enumerate() {
        let get = |suffix: &str| {
            let j = out_header
                .iter()
                .position(|h| *h == format!("{g}_{suffix}"))
                .unwrap();
            streamed
                .lines()
                .skip(1)
                .map(|l| l.split(',').nth(j).unwrap().to_owned())
                .collect::<Vec<_>>()
        };
        let (b, sc, r, st) = (get("bias"), get("scale"), get("comp"), get("status"));
        let w = &want[k];
        for i in 0..log.len() {
            n += 1;
            let bits = |s: &str| s.parse::<f64>().unwrap().to_bits();
            let same = bits(&b[i]) == w.bias_dps[i].to_bits()
                && bits(&sc[i]) == w.scale[i].to_bits()
                && bits(&r[i]) == w.gyro_comp_dps[i].to_bits()
                && st[i] == w.status[i].as_str();
            differ += usize::from(!same);
        }
    }
    println!("stream vs in-memory compensate_imu: {n} axis-lines, {differ} differ");
    assert_eq!(differ, 0);
    assert!(st(GYROS[1])[9_000..9_050].iter().all(|s| s != "ok"));
}

#[test]
fn with_time_faults_each_axis_equals_its_own_single_axis_stream() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = unit_model(d);
    let text = unit_run(d);
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (ty, gx, gy) = (col("temp_y_c"), col("gyro_x_dps"), col("gyro_y_dps"));
    // Time faults (single: 1e308, NaN, +1e9 s, −1e308, five repeats; lasting: a clock reset
    // at line 20,000, a +1e9 s jump at 25,000), a y sensor fault, overflow and NaN gyro
    // samples, a malformed line (two fields) and a comment line.
    let mut prev = String::new();
    let faulty: String = edited(&text, |i, f| {
        let t: f64 = f[0].parse().unwrap();
        let t = match i {
            20_000..25_000 => t - 20_000.0,
            25_000.. => t + 1e9,
            _ => t,
        };
        f[0] = format!("{t:?}");
        match i {
            5_003 => f[0] = "1e308".into(),
            7_001 => f[0] = format!("{:?}", t + 1e9),
            9_001 => f[0] = "NaN".into(),
            10_001 => f[0] = "-1e308".into(),
            11_001..=11_005 => f[0] = prev.clone(),
            12_001..=12_100 => f[ty] = "NaN".into(),
            13_001 => f[gx] = "1.797e308".into(),
            13_003 => f[gy] = "-1.797e308".into(),
            14_001 => f[gy] = "NaN".into(),
            15_001 => f.truncate(2),
            _ => {}
        }
        prev = f[0].clone();
    })
    .replacen("\n", "\n# a comment line\n", 2);
    let input = d.join("time_faults.csv");
    std::fs::write(&input, &faulty).unwrap();
    let unit = stream(&model, &input, &[]);
    let data_lines = faulty
        .lines()
        .skip(1)
        .filter(|l| !l.starts_with('#'))
        .count();
    assert_eq!(unit.lines().count(), data_lines + 1);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let u_header: Vec<&str> = unit.lines().next().unwrap().split(',').collect();
    let mut statuses = std::collections::BTreeMap::new();
    for (k, g) in GYROS.iter().enumerate() {
        let axis = &v["axes"][k];
        let path = d.join(format!("axis{k}.json"));
        std::fs::write(&path, serde_json::to_string(&axis["model"]).unwrap()).unwrap();
        let temp = axis["temps"][0].as_str().unwrap();
        let single = stream(&path, &input, &["--gyro-col", g, "--temp-col", temp]);
        let s_header: Vec<&str> = single.lines().next().unwrap().split(',').collect();
        let si: Vec<usize> = ["bias_dps", "scale", "gyro_comp_dps", "status"]
            .iter()
            .map(|n| s_header.iter().position(|h| h == n).unwrap())
            .collect();
        let ui: Vec<usize> = ["bias", "scale", "comp", "status"]
            .iter()
            .map(|n| {
                u_header
                    .iter()
                    .position(|h| *h == format!("{g}_{n}"))
                    .unwrap()
            })
            .collect();
        let (mut n, mut differ) = (0, 0);
        for (a, b) in unit.lines().zip(single.lines()).skip(1) {
            let a: Vec<&str> = a.split(',').collect();
            let b: Vec<&str> = b.split(',').collect();
            // Both write a malformed line's fields empty and every output empty but status.
            let ua: Vec<&str> = ui.iter().map(|&j| a[j]).collect();
            let sb: Vec<&str> = si.iter().map(|&j| b[j]).collect();
            n += 1;
            if ua != sb {
                if differ < 3 {
                    eprintln!("{g} line {n}: unit {ua:?} single {sb:?}");
                }
                differ += 1;
            }
            *statuses.entry((k, ua[3].to_owned())).or_insert(0) += 1;
        }
        println!("{g} (reads {temp}): {n} lines, {differ} differ from its single-axis stream");
        assert_eq!(n, data_lines);
        assert_eq!(differ, 0, "{g}");
    }
    println!("statuses per axis: {statuses:?}");
    // Every status occurred, on every axis (the time faults reach all axes).
    for k in 0..3 {
        for s in ["ok", "held", "degraded", "invalid"] {
            assert!(statuses.contains_key(&(k, s.to_owned())), "axis {k} {s}");
        }
    }
    // A feed that ends without a final line break: the header, two comments and eight data
    // lines give the header and eight lines.
    let mut child = gyrotherm()
        .args(["compensate", "--stream", "--model"])
        .arg(&model)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let head: String = faulty.lines().take(11).collect::<Vec<_>>().join("\n");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(head.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(String::from_utf8(out.stdout).unwrap().lines().count(), 9);
}

/// The single-axis stream's line handling, for a unit: `;` with decimal commas (output with
/// `;` and decimal points, the same numbers as the comma log), a line over the 64 KiB cap and
/// a line with a broken quote written as `invalid` on every axis with the stream going on, a
/// temperature field that is empty or not a number a fault of its sensor's axes only, and a
/// log without one of the model's columns refused, naming it.
#[test]
fn line_handling_is_the_single_axis_streams() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = unit_model(d);
    let text = unit_run(d);
    let head: Vec<&str> = text.lines().take(301).collect();
    let comma = d.join("comma.csv");
    std::fs::write(&comma, head.join("\n") + "\n").unwrap();
    let want = stream(&model, &comma, &[]);
    // `;` and decimal commas.
    let semi: Vec<String> = head
        .iter()
        .map(|l| l.replace(',', ";").replace('.', ","))
        .collect();
    let semi_path = d.join("semi.csv");
    std::fs::write(&semi_path, semi.join("\n") + "\n").unwrap();
    let got = stream(&model, &semi_path, &["--delimiter", ";"]);
    let (w, g): (Vec<&str>, Vec<&str>) = (want.lines().collect(), got.lines().collect());
    assert_eq!(w.len(), g.len());
    let n_in = head[0].split(',').count();
    for (a, b) in w.iter().zip(&g).skip(1) {
        let a: Vec<&str> = a.split(',').collect();
        let b: Vec<&str> = b.split(';').collect();
        assert_eq!(a[n_in..], b[n_in..], "the added columns");
    }
    // Faults in lines 11 (too long), 21 (broken quote), 31 (y sensor empty), 41 (y sensor
    // not a number).
    let header: Vec<&str> = head[0].split(',').collect();
    let ty = header.iter().position(|h| *h == "temp_y_c").unwrap();
    let faulty: Vec<String> = head
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
            match i {
                11 => return "9".repeat(70 * 1024),
                21 => f[1] = "\"0.01".into(),
                31 => f[ty] = String::new(),
                41 => f[ty] = "bus error".into(),
                _ => {}
            }
            f.join(",")
        })
        .collect();
    let faulty_path = d.join("faulty.csv");
    std::fs::write(&faulty_path, faulty.join("\n") + "\n").unwrap();
    let got = stream(&model, &faulty_path, &[]);
    let rows: Vec<Vec<&str>> = got
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 300);
    let out_header: Vec<&str> = got.lines().next().unwrap().split(',').collect();
    let status = |g: &str| {
        out_header
            .iter()
            .position(|h| *h == format!("{g}_status"))
            .unwrap()
    };
    for line in [11, 21] {
        for g in GYROS {
            assert_eq!(rows[line - 1][status(g)], "invalid", "line {line} {g}");
        }
    }
    for line in [31, 41] {
        assert_eq!(rows[line - 1][status(GYROS[1])], "held", "line {line}");
        assert_eq!(rows[line - 1][status(GYROS[0])], "ok", "line {line}");
        assert_eq!(rows[line - 1][status(GYROS[2])], "ok", "line {line}");
    }
    assert!(rows[50..]
        .iter()
        .all(|r| GYROS.iter().all(|g| r[status(g)] == "ok")));
    // A log without the y coil sensor's column.
    let cut: Vec<String> = head
        .iter()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(ty);
            f.join(",")
        })
        .collect();
    let cut_path = d.join("cut.csv");
    std::fs::write(&cut_path, cut.join("\n") + "\n").unwrap();
    let out = gyrotherm()
        .args(["compensate", "--stream", "--model"])
        .arg(&model)
        .stdin(Stdio::from(std::fs::File::open(&cut_path).unwrap()))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("column temp_y_c"), "{err}");
}

/// Bias stability (τ = 100 s, GJB 2426A / IEEE 952 as `gyrotherm::metrics` computes it) of
/// column `col` of a compensated 1 Hz log, °/h, and the count of each status in `status_col`.
fn column_figures(text: &str, col: &str, status_col: &str) -> (f64, Vec<(String, usize)>) {
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (c, s) = (
        head.iter().position(|h| *h == col).unwrap(),
        head.iter().position(|h| *h == status_col).unwrap(),
    );
    let (mut rate, mut counts) = (Vec::new(), Vec::<(String, usize)>::new());
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        rate.push(f[c].parse::<f64>().unwrap());
        match counts.iter_mut().find(|(k, _)| k == f[s]) {
            Some((_, n)) => *n += 1,
            None => counts.push((f[s].to_owned(), 1)),
        }
    }
    let bs = gyrotherm::metrics::bias_stability_dph(&rate, 1.0, 100.0)
        .unwrap()
        .bias_stability_dph;
    (bs, counts)
}

fn count(counts: &[(String, usize)], status: &str) -> usize {
    counts.iter().find(|(k, _)| k == status).map_or(0, |c| c.1)
}

/// A further sensor dies for good: the `thermal` fit (every axis may read every sensor) of a
/// design-family unit, trained as the design family is (`seed-shock` static and one table run per
/// axis), judged on an `airborne` run of the unit whose sensor `S` (a further sensor of axis x)
/// reads nothing from line 5,061 on (5,060 s: cruise). With the model file as `train --method
/// thermal` writes it, each axis that reads `S` runs on its fallback from 60 s after the loss on,
/// and the x-axis bias stability stays near the fault-free one; the same file without its fallbacks
/// (a file written before them) keeps those axes degraded, B and K frozen.
#[test]
fn a_further_sensor_dead_for_good_leaves_its_axes_on_their_fallbacks() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let unit = ["--imu", "--unit", "random", "--unit-seed", "1000"];
    let shock = ["--profile", "seed-shock"];
    let mut inputs = vec![simulate_args(
        d,
        "static.csv",
        &[&unit[..], &shock[..], &["--seed", "1"]].concat(),
    )];
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let seed = (2 + k).to_string();
        inputs.push(simulate_args(
            d,
            &format!("table_{axis}.csv"),
            &[
                &unit[..],
                &shock[..],
                &["--seed", &seed, "--table-rate", "20", "--table-axis", axis],
            ]
            .concat(),
        ));
    }
    let model = d.join("unit.json");
    let mut train = gyrotherm();
    // `thermal`: the fallbacks are its several-sensor fit's (the default `auto` keeps that
    // fit where it wins, and takes a minute an axis).
    train.args([
        "train",
        "--method",
        "thermal",
        "--gyro-col",
        &GYROS.join(","),
    ]);
    train.args(["--temp-col", TEMPS]);
    for i in &inputs {
        train.arg("--input").arg(i);
    }
    run_ok(train.arg("--out").arg(&model));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let axes = v["axes"].as_array().unwrap();
    // Every axis with further sensors carries the one-sensor fit of its first sensor.
    for a in axes {
        let several = a["temps"].as_array().unwrap().len() > 1;
        assert_eq!(a.get("fallback").is_some(), several, "{}", a["gyro"]);
    }
    let further_x: Vec<String> = axes[0]["temps"].as_array().unwrap()[1..]
        .iter()
        .map(|t| t.as_str().unwrap().to_owned())
        .collect();
    assert!(!further_x.is_empty(), "axis x reads one sensor");
    // The further sensor of x that the most axes read.
    let readers = |t: &str| {
        axes.iter()
            .filter(|a| a["temps"].as_array().unwrap().iter().any(|s| s == t))
            .count()
    };
    let dead = further_x.iter().max_by_key(|t| readers(t)).unwrap().clone();
    // The file without fallbacks, unsealed: what `train` wrote before them.
    let mut old = v.clone();
    old.as_object_mut().unwrap().remove("content_sha256");
    for a in old["axes"].as_array_mut().unwrap() {
        a.as_object_mut().unwrap().remove("fallback");
    }
    let old_model = d.join("old.json");
    std::fs::write(&old_model, serde_json::to_string_pretty(&old).unwrap()).unwrap();

    let flight = simulate_args(
        d,
        "airborne.csv",
        &[&unit[..], &["--profile", "airborne", "--seed", "31"]].concat(),
    );
    let text = std::fs::read_to_string(&flight).unwrap();
    let col = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == dead)
        .unwrap();
    let faulty = d.join("airborne_dead.csv");
    std::fs::write(
        &faulty,
        edited(&text, |i, f| {
            if i > 5_060 {
                f[col].clear();
            }
        }),
    )
    .unwrap();
    let compensate = |m: &Path, input: &Path, name: &str| {
        let out = d.join(name);
        run_ok(
            gyrotherm()
                .args(["compensate", "--model"])
                .arg(m)
                .arg("--input")
                .arg(input)
                .arg("--out")
                .arg(&out),
        );
        column_figures(
            &std::fs::read_to_string(out).unwrap(),
            "gyro_x_dps_comp",
            "gyro_x_dps_status",
        )
    };
    let (clean, clean_counts) = compensate(&model, &flight, "clean.csv");
    let (with_fallback, fb_counts) = compensate(&model, &faulty, "fallback.csv");
    let (without, old_counts) = compensate(&old_model, &faulty, "old.csv");
    let (raw, _) = column_figures(&text, "gyro_x_dps", "gyro_x_dps");
    println!(
        "airborne, unit 1000, sensor {dead} (read by {} axes) dead from line 5,061 of {}: \
         x-axis bias stability (τ = 100 s) fault-free {clean:.4} °/h, with fallback \
         {with_fallback:.4} °/h, without (older file) {without:.4} °/h, raw {raw:.4} °/h; \
         x statuses fault-free {clean_counts:?}, with fallback {fb_counts:?}, without \
         {old_counts:?}",
        readers(&dead),
        text.lines().count() - 1
    );
    let lost = text.lines().count() - 1 - 5_060;
    // Without fallbacks: degraded from 60 s after the loss to the end (the defect).
    assert!(
        count(&old_counts, "degraded") >= lost - 61,
        "{old_counts:?}"
    );
    // With them: on the fallback instead, never degraded after the first minute.
    assert!(count(&fb_counts, "fallback") >= lost - 61, "{fb_counts:?}");
    assert_eq!(
        count(&fb_counts, "degraded"),
        count(&clean_counts, "degraded"),
        "{fb_counts:?}"
    );
    assert_eq!(count(&clean_counts, "fallback"), 0);
    // The error stays near the fault-free one (and well below the frozen model's).
    assert!(with_fallback < 1.5 * clean, "{with_fallback} vs {clean}");
    assert!(
        without > 2.0 * with_fallback,
        "{without} vs {with_fallback}"
    );
}

//! An inertial unit through the real binary: `simulate --imu`, `train` with column lists
//! (one model file for the unit), `compensate` with per-axis columns, a missing column named,
//! and a fault in one sensor reaching only the axis that reads it.

use std::path::Path;

mod cli;
use cli::{gyrotherm, outcome, run_ok, simulate_args};

const GYROS: &str = "gyro_x_dps,gyro_y_dps,gyro_z_dps";

/// Columns of a CSV text by header name.
fn column(text: &str, name: &str) -> Vec<String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(k).unwrap().to_owned())
        .collect()
}

/// Unit 1000 (design family) in the simulator.
const UNIT: [&str; 5] = ["--imu", "--unit", "random", "--unit-seed", "1000"];

/// Unit 1000's training runs on `fast-cycle`: a static run (seed 1) and one table run per
/// axis (seed 2).
fn training_runs(dir: &Path) -> Vec<std::path::PathBuf> {
    let prof = ["--profile", "fast-cycle"];
    let mut inputs = vec![simulate_args(
        dir,
        "s.csv",
        &[&UNIT[..], &prof[..], &["--seed", "1"]].concat(),
    )];
    for ax in ["x", "y", "z"] {
        inputs.push(simulate_args(
            dir,
            &format!("t{ax}.csv"),
            &[
                &UNIT[..],
                &prof[..],
                &["--seed", "2", "--table-rate", "20", "--table-axis", ax],
            ]
            .concat(),
        ));
    }
    inputs
}

/// `compensate --model MODEL --input RUN --out DIR/comp.csv`: the output file's text and what
/// it told on stderr.
fn compensate(dir: &Path, model: &Path, run: &Path) -> (String, String) {
    let comp = dir.join("comp.csv");
    let out = run_ok(
        gyrotherm()
            .args(["compensate", "--model"])
            .arg(model)
            .arg("--input")
            .arg(run)
            .arg("--out")
            .arg(&comp),
    );
    (
        std::fs::read_to_string(&comp).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A linear model of unit 1000 with the case sensor and the x coil sensor.
fn train_linear(dir: &Path) -> std::path::PathBuf {
    let inputs = training_runs(dir);
    let model = dir.join("imu.json");
    let mut cmd = gyrotherm();
    cmd.args(["train", "--method", "linear", "--gyro-col", GYROS]);
    cmd.args(["--temp-col", "temp_case_c,temp_x_c", "--out"])
        .arg(&model);
    for i in &inputs {
        cmd.arg("--input").arg(i);
    }
    let out = run_ok(&mut cmd);
    let err = String::from_utf8_lossy(&out.stderr);
    for ax in ["x", "y", "z"] {
        assert!(
            err.contains(&format!("t{ax}.csv: rate table on gyro_{ax}_dps")),
            "{err}"
        );
    }
    model
}

#[test]
fn one_model_for_the_unit_compensates_each_axis() {
    let dir = tempfile::tempdir().unwrap();
    let model = train_linear(dir.path());
    let text = std::fs::read_to_string(&model).unwrap();
    assert!(text.contains("\"imu_format_version\": 1"), "{text}");
    let run = simulate_args(
        dir.path(),
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
    let (out, _) = compensate(dir.path(), &model, &run);
    for g in GYROS.split(',') {
        let raw: Vec<f64> = column(&out, g).iter().map(|v| v.parse().unwrap()).collect();
        let bias: Vec<f64> = column(&out, &format!("{g}_bias"))
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        let scale: Vec<f64> = column(&out, &format!("{g}_scale"))
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        let rate: Vec<f64> = column(&out, &format!("{g}_comp"))
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        // G = (Ĝ − B)/K (He et al. 2024 eq. 4), computed the same way: exact.
        for i in 0..raw.len() {
            assert_eq!(rate[i], (raw[i] - bias[i]) / scale[i], "{g} line {}", i + 2);
        }
        assert!(column(&out, &format!("{g}_status"))
            .iter()
            .all(|s| s == "ok"));
    }
}

#[test]
fn a_missing_column_is_named_and_a_sensor_fault_stays_on_its_axes() {
    let dir = tempfile::tempdir().unwrap();
    let model = train_linear(dir.path());
    let json = std::fs::read_to_string(&model).unwrap();
    // The linear method has no cross-validation: every axis reads the first sensor.
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    for a in v["axes"].as_array().unwrap() {
        assert_eq!(a["temps"], serde_json::json!(["temp_case_c"]));
    }
    let run = simulate_args(
        dir.path(),
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
    let text = std::fs::read_to_string(&run).unwrap();
    // Without the case sensor's column.
    let no_case: String = text
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(4);
            f.join(",") + "\n"
        })
        .collect();
    let cut = dir.path().join("cut.csv");
    std::fs::write(&cut, no_case).unwrap();
    let m = model.to_str().unwrap();
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        m,
        "--input",
        cut.to_str().unwrap(),
        "--out",
        dir.path().join("x.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("column temp_case_c"), "{err}");
    // The x coil sensor reads -127 °C (a DS18B20 bus error) for 200 s: no axis reads it, so
    // every axis stays ok.
    let faulty: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
            if (5001..5201).contains(&i) {
                f[5] = "-127".into();
            }
            f.join(",") + "\n"
        })
        .collect();
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, faulty).unwrap();
    let (code, _, err) = outcome(&[
        "compensate",
        "--model",
        m,
        "--input",
        bad.to_str().unwrap(),
        "--out",
        dir.path().join("y.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    for g in GYROS.split(',') {
        assert!(
            err.contains(&format!("{g}: 30000 ok, 0 held, 0 degraded")),
            "{err}"
        );
    }
}

/// `compensate` with a unit model writes each axis's coverage verdict and σ as
/// `G_coverage` and `G_sigma_dph`: the same, to the bit, as the library's
/// `Model::coverage_log` (which steps each axis's first-sensor compensator on its own and
/// reads its map) gives for the log, on every axis, including one that reads several sensors.
#[test]
fn compensate_writes_each_axis_coverage_and_sigma_as_the_model_gives_them() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = training_runs(dir.path());
    let model = dir.path().join("imu.json");
    let mut cmd = gyrotherm();
    cmd.args(["train", "--method", "thermal", "--gyro-col", GYROS]);
    cmd.args([
        "--temp-col",
        "temp_case_c,temp_x_c,temp_y_c,temp_z_c",
        "--out",
    ])
    .arg(&model);
    for i in &inputs {
        cmd.arg("--input").arg(i);
    }
    run_ok(&mut cmd);
    let run = simulate_args(
        dir.path(),
        "run.csv",
        &[&UNIT[..], &["--profile", "airborne", "--seed", "3"]].concat(),
    );
    let (out, err) = compensate(dir.path(), &model, &run);
    let m = gyrotherm::unit_model::Model::load(&model).unwrap();
    let unit_model = m.to_unit(&gyrotherm::ReadOptions::default());
    assert!(
        unit_model.axes.iter().any(|a| a.temps.len() > 1),
        "no axis reads several sensors: {:?}",
        unit_model.axes.iter().map(|a| &a.temps).collect::<Vec<_>>()
    );
    let opts = unit_model.read_options(&gyrotherm::ReadOptions::default());
    let (log, _) = gyrotherm::csvlog::read_imu_log(&run, &opts, None).unwrap();
    let (want, notes) = m.coverage_log(&log).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    for (g, w) in GYROS.split(',').zip(&want) {
        let codes = column(&out, &format!("{g}_coverage"));
        let sigma = column(&out, &format!("{g}_sigma_dph"));
        assert_eq!(codes.len(), w.codes.len());
        for i in 0..codes.len() {
            let name = ["inside", "edge", "outside"]
                .get(w.codes[i] as usize)
                .copied()
                .unwrap_or("");
            assert_eq!(codes[i], name, "{g} line {}", i + 2);
            if name.is_empty() {
                assert_eq!(sigma[i], "", "{g} line {}", i + 2);
            } else {
                let s: f64 = sigma[i].parse().unwrap();
                assert_eq!(s.to_bits(), w.sigma_dph[i].to_bits(), "{g} line {}", i + 2);
            }
        }
        // The summary counts the verdicts.
        let n = |c: u8| w.codes.iter().filter(|k| **k == c).count();
        let want_line = format!(
            "{g}: {} ok, 0 held, 0 degraded, 0 invalid, coverage: inside {}, edge {}, outside {}",
            codes.len(),
            n(0),
            n(1),
            n(2)
        );
        assert!(err.contains(&want_line), "{want_line}: {err}");
    }
}

/// `plan` with column lists plans for the unit: every axis on every sensor listed gets the
/// single gyro's coverage lines, prefixed with its columns, and the first soaks are sized by
/// the slowest lag of any pair (the soak line names that lag).
#[test]
fn plan_with_lists_covers_every_axis_on_every_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let s = simulate_args(
        dir.path(),
        "s.csv",
        &[&UNIT[..], &["--profile", "seed-shock", "--seed", "1"]].concat(),
    );
    let out = run_ok(
        gyrotherm()
            .args([
                "plan",
                "--gyro-col",
                GYROS,
                "--temp-col",
                "temp_case_c,temp_x_c",
            ])
            .args(["--temp-min-c", "-40", "--temp-max-c", "50"])
            .args(["--max-rate-c-per-min", "8", "--input"])
            .arg(&s),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lags = Vec::new();
    for g in GYROS.split(',') {
        for t in ["temp_case_c", "temp_x_c"] {
            let pair = format!("{g} on {t}: ");
            assert!(
                text.contains(&format!("{pair}training covers ")),
                "{pair}\n{text}"
            );
            let lag = text
                .lines()
                .find_map(|l| l.strip_prefix(&format!("{pair}slowest thermal lag identified: ")))
                .and_then(|l| l.split(' ').next())
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or_else(|| panic!("{pair}: no lag\n{text}"));
            lags.push(lag);
        }
    }
    let slowest = lags.iter().copied().fold(f64::NAN, f64::max);
    assert!(
        text.contains(&format!(
            "slowest thermal lag of the unit: {slowest:.0} s ("
        )),
        "{text}"
    );
    let soak = text.lines().find(|l| l.starts_with("soaks: ")).unwrap();
    assert!(soak.contains(&format!("({slowest:.0} s)")), "{soak}");
}

/// `allan` on a unit's log read with column lists analyses the column `--column` names, the
/// same numbers as reading that gyro alone; without `--column` it says to name one.
#[test]
fn allan_on_a_unit_log_analyses_the_named_column() {
    let dir = tempfile::tempdir().unwrap();
    let log = simulate_args(dir.path(), "u.csv", &UNIT);
    let log = log.to_str().unwrap();
    let lists = ["--gyro-col", GYROS, "--temp-col", "temp_case_c"];
    let (code, _, err) = outcome(&[&["allan", "--input", log][..], &lists[..]].concat());
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--column") && err.contains("gyro_y_dps"),
        "{err}"
    );
    let (code, unit, err) = outcome(
        &[
            &["allan", "--input", log, "--column", "gyro_z_dps"][..],
            &lists[..],
        ]
        .concat(),
    );
    assert_eq!(code, 0, "{err}");
    let (code, alone, err) = outcome(&[
        "allan",
        "--input",
        log,
        "--gyro-col",
        "gyro_z_dps",
        "--temp-col",
        "temp_case_c",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(unit.starts_with("OADEV of gyro_z_dps"), "{unit}");
    assert_eq!(unit, alone);
}

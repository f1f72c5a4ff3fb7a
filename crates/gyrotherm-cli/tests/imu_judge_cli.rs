//! An inertial unit's figures per axis through the real binary: `evaluate` (raw, and with a
//! unit model compensated), `compare` and `report` with column lists, and `train`'s progress
//! per axis. Each per-axis figure is checked against the single-axis command run on the same
//! numbers by another path (one gyro column read alone; the compensated column `compensate`
//! wrote), so the expected values are independent computations.

use std::path::{Path, PathBuf};

mod cli;
use cli::{gyrotherm, run_ok, simulate_args};

const GYROS: &str = "gyro_x_dps,gyro_y_dps,gyro_z_dps";
const UNIT: [&str; 7] = [
    "--imu",
    "--unit",
    "random",
    "--unit-seed",
    "1000",
    "--profile",
    "fast-cycle",
];

fn sim(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    simulate_args(dir, name, &[&UNIT[..], &["--truth"], extra].concat())
}

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

/// A linear unit model on the case and x coil sensors: one static run, a table run on y.
fn train(dir: &Path) -> (PathBuf, String) {
    let s = sim(dir, "s.csv", &["--seed", "1"]);
    let t = sim(
        dir,
        "t.csv",
        &["--seed", "2", "--table-rate", "20", "--table-axis", "y"],
    );
    let model = dir.join("unit.json");
    let out = run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--gyro-col", GYROS])
            .args(["--temp-col", "temp_case_c,temp_x_c", "--out"])
            .arg(&model)
            .arg("--input")
            .arg(&s)
            .arg("--input")
            .arg(&t),
    );
    (model, String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn train_says_when_each_axis_and_sensor_starts_and_finishes() {
    let dir = tempfile::tempdir().unwrap();
    let (_, err) = train(dir.path());
    for g in ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"] {
        let starts = format!("{g}: axis starts (2 sensor(s) to try)");
        assert!(err.contains(&starts), "{starts:?} missing:\n{err}");
        for (k, t) in ["temp_case_c", "temp_x_c"].iter().enumerate() {
            let start = format!("{g}: fitting on {t} (sensor {} of 2)", k + 1);
            let done = format!("{g}: {t} done (cross-validated RMS");
            assert!(err.contains(&start), "{start:?} missing:\n{err}");
            assert!(err.contains(&done), "{done:?} missing:\n{err}");
        }
        let axis = err
            .lines()
            .find(|l| l.contains(&format!("{g}: axis done, reads ")))
            .unwrap_or_else(|| panic!("no axis line for {g}:\n{err}"));
        // Each line carries the seconds since the fit began: "gyrotherm: [   1.2 s] …".
        let secs: f64 = axis
            .split('[')
            .nth(1)
            .and_then(|r| r.split(" s]").next())
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or_else(|| panic!("no elapsed seconds in {axis:?}"));
        assert!(secs >= 0.0, "{axis}");
    }
}

/// `evaluate` with a list: each axis's raw figures are those of `evaluate --gyro-col G` on
/// the same log; with `--model`, each axis's compensated figures are those of the column
/// `G_comp` that `compensate` writes, evaluated alone. A static held-out run for every axis
/// (read alone, a table run would be a table run for every gyro), and a table run on y for
/// y's scale-factor figures.
#[test]
fn evaluate_per_axis_matches_each_column_evaluated_alone() {
    let dir = tempfile::tempdir().unwrap();
    let (model, _) = train(dir.path());
    let held = sim(dir.path(), "h.csv", &["--seed", "3"]);
    let held_table = sim(
        dir.path(),
        "ht.csv",
        &["--seed", "4", "--table-rate", "20", "--table-axis", "y"],
    );
    let per_axis = |log: &Path| {
        json(&run_ok(
            gyrotherm()
                .args(["evaluate", "--json", "--model"])
                .arg(&model)
                .arg("--input")
                .arg(log),
        ))
    };
    let compensated_file = |log: &Path, name: &str| {
        let out = dir.path().join(name);
        run_ok(
            gyrotherm()
                .args(["compensate", "--model"])
                .arg(&model)
                .arg("--input")
                .arg(log)
                .arg("--out")
                .arg(&out),
        );
        out
    };
    let alone = |file: &Path, col: &str| {
        json(&run_ok(
            gyrotherm()
                .args(["evaluate", "--json", "--gyro-col", col])
                .args(["--temp-col", "temp_case_c", "--input"])
                .arg(file),
        ))
    };
    let unit = per_axis(&held);
    let axes = unit["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 3);
    let comp = compensated_file(&held, "comp.csv");
    for (a, g) in axes.iter().zip(["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]) {
        assert_eq!(a["gyro"], g);
        let raw = alone(&held, g);
        let compensated = alone(&comp, &format!("{g}_comp"));
        for key in ["bias_dph", "bias_stability_dph", "means", "samples"] {
            assert_eq!(a["raw"][key], raw[key], "{g} raw {key}");
            assert_eq!(a["compensated"][key], compensated[key], "{g} comp {key}");
        }
        assert!(a["raw"]["scale_factor"].is_null(), "{g}: a static run");
    }
    // The table turns y only: the scale-factor figures are y's alone.
    let unit = per_axis(&held_table);
    let comp = compensated_file(&held_table, "comp_t.csv");
    let y = &unit["axes"][1];
    let alone_y = alone(&comp, "gyro_y_dps_comp");
    assert!(unit["axes"][0]["raw"]["scale_factor"].is_null());
    assert!(unit["axes"][2]["raw"]["scale_factor"].is_null());
    for key in ["sf_thermal_error_ppm", "scale_factor", "nonlinearity_ppm"] {
        let v = &y["compensated"][key];
        assert!(v.is_number(), "{key}: {y}");
        assert_eq!(v, &alone_y[key], "{key}");
    }
    // Text: a block per axis naming the sensor its model reads.
    let out = run_ok(
        gyrotherm()
            .args(["evaluate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&held),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    for g in ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"] {
        assert!(
            text.contains(&format!(": {g} (model reads temp_")),
            "{text}"
        );
        assert!(text.contains(&format!("{g}_comp (")), "{text}");
    }
}

/// `compare` with a gyro list and one sensor on static runs: each axis's table is the
/// single-axis comparison of that gyro column, number for number; the floor is the axis's
/// own noise truth.
#[test]
fn compare_per_axis_matches_each_axis_compared_alone() {
    let dir = tempfile::tempdir().unwrap();
    let s = sim(dir.path(), "s.csv", &["--seed", "1"]);
    let h = sim(dir.path(), "h.csv", &["--seed", "3"]);
    let args = |cmd: &mut std::process::Command| {
        cmd.args(["compare", "--json", "--methods", "linear,poly"])
            .args(["--temp-col", "temp_case_c", "--train"])
            .arg(&s)
            .arg("--test")
            .arg(&h);
    };
    let mut c = gyrotherm();
    args(&mut c);
    let unit = json(&run_ok(c.args(["--gyro-col", GYROS])));
    let axes = unit["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 3);
    let mut floors = Vec::new();
    for (a, g) in axes.iter().zip(["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]) {
        let mut c = gyrotherm();
        args(&mut c);
        let alone = json(&run_ok(c.args(["--gyro-col", g])));
        let (u, s) = (&a["comparison"]["tests"][0], &alone["tests"][0]);
        assert_eq!(u["raw"], s["raw"], "{g}");
        assert_eq!(u["methods"], s["methods"], "{g}");
        // Alone, the log has no `noise_dps` column (only `noise_dps_x` …): no floor.
        assert!(s["floor_dph"].is_null());
        floors.push(u["floor_dph"].as_f64().expect("the axis's floor"));
    }
    assert!(
        floors[0] != floors[1] && floors[1] != floors[2],
        "{floors:?}"
    );
    // The table across axes: a row per axis for each figure.
    let rows = unit["across_axes"]["rows"].as_array().unwrap();
    let axis_col: Vec<&str> = rows.iter().map(|r| r[2].as_str().unwrap()).collect();
    assert_eq!(
        axis_col,
        [
            "gyro_x_dps",
            "gyro_y_dps",
            "gyro_z_dps",
            "gyro_x_dps",
            "gyro_y_dps",
            "gyro_z_dps"
        ]
    );
}

#[test]
fn report_has_a_page_across_axes_and_one_per_axis() {
    let dir = tempfile::tempdir().unwrap();
    let s = sim(dir.path(), "s.csv", &["--seed", "1"]);
    let t = sim(
        dir.path(),
        "t.csv",
        &["--seed", "2", "--table-rate", "20", "--table-axis", "z"],
    );
    let h = sim(dir.path(), "h.csv", &["--seed", "3"]);
    let out_dir = dir.path().join("rep");
    let out = run_ok(
        gyrotherm()
            .args(["report", "--methods", "linear", "--gyro-col", GYROS])
            .args(["--temp-col", "temp_case_c,temp_z_c", "--train"])
            .arg(&s)
            .arg("--train")
            .arg(&t)
            .arg("--test")
            .arg(&h)
            .arg("--out")
            .arg(&out_dir),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("across axes:"), "{stdout}");
    let page = std::fs::read_to_string(out_dir.join("index.html")).unwrap();
    assert!(page.contains("<table class=\"across-axes\">"), "{page}");
    for (k, g) in ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]
        .iter()
        .enumerate()
    {
        assert!(
            page.contains(&format!("<h2>Axis {}: {g} (temperature temp_", k + 1)),
            "{g}"
        );
        let folder = out_dir.join(format!("axis{}", k + 1));
        assert!(folder.join("index.html").is_file(), "{}", folder.display());
        assert!(folder.join("fig7_compensation.png").is_file());
        assert!(page.contains(&format!("src=\"axis{}/fig7_compensation.png\"", k + 1)));
    }
}

#[test]
fn spec_with_a_list_is_refused_with_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let h = sim(dir.path(), "h.csv", &["--seed", "3"]);
    let out = gyrotherm()
        .args([
            "evaluate",
            "--gyro-col",
            GYROS,
            "--spec",
            "x.toml",
            "--input",
        ])
        .arg(&h)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--spec judges one column"), "{err}");
}

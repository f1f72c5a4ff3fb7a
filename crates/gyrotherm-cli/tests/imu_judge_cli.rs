//! An inertial unit's figures per axis through the real binary: `evaluate` (raw, and with a
//! unit model compensated), `compare` and `report` with column lists, and `train`'s progress
//! per axis. Each per-axis figure is checked against the single-axis command run on the same
//! numbers by another path (one gyro column read alone; the compensated column `compensate`
//! wrote), so the expected values are independent computations.

use std::path::{Path, PathBuf};

mod cli;
use cli::{assert_exit, gyrotherm, run_ok, simulate_args};

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
        cmd.args([
            "compare",
            "--json",
            "--method",
            "thermal",
            "--methods",
            "linear,poly",
        ])
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
        // One sensor: no unit fit beside the methods (it would be the thermal column).
        assert!(a.get("unit_fit").is_none(), "{g}");
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

/// `compare` with several sensors: beside the one-sensor methods each axis's table holds
/// the unit's own fit, the model `train` with the same lists builds. Its sensors are the
/// trained model's, the one-sensor methods read that model's first sensor (the one-sensor
/// choice), its label says what it holds and how many sensors it reads, and its bias
/// stability on the held-out run is that of the column `compensate` writes with the trained
/// model, evaluated alone with the same τ (an independent path: the file, the reader and
/// the single-axis `evaluate`).
#[test]
fn compare_per_axis_holds_the_unit_fit_on_all_its_sensors() {
    let dir = tempfile::tempdir().unwrap();
    let temps = ALL_TEMPS;
    let (s, t, h, model) = unit_on_all_sensors(dir.path());
    let trained: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let comp = dir.path().join("comp.csv");
    run_ok(
        gyrotherm()
            .args(["compensate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&h)
            .arg("--out")
            .arg(&comp),
    );
    let compare = |json: bool| {
        let mut c = gyrotherm();
        c.args([
            "compare",
            "--method",
            "thermal",
            "--methods",
            "linear,thermal",
            "--tau-s",
            "100",
        ])
        .args(["--gyro-col", GYROS, "--temp-col", temps, "--train"])
        .arg(&s)
        .arg("--train")
        .arg(&t)
        .arg("--test")
        .arg(&h);
        if json {
            c.arg("--json");
        }
        run_ok(&mut c)
    };
    let unit = json(&compare(true));
    let mut several = false;
    for (k, g) in ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]
        .iter()
        .enumerate()
    {
        let a = &unit["axes"][k];
        let m = &trained["axes"][k];
        let u = &a["unit_fit"];
        assert_eq!(u["temps"], m["temps"], "{g}: the trained model's sensors");
        assert_eq!(a["temp"], m["temps"][0], "{g}: the one-sensor choice");
        let n = m["temps"].as_array().unwrap().len();
        several |= n > 1;
        let label = u["label"].as_str().unwrap();
        let sensors = if n == 1 { "sensor" } else { "sensors" };
        assert!(label.contains(&format!("({n} {sensors}: ")), "{label}");
        let holds_lstm = [&m["model"]["bias"], &m["model"]["scale"]]
            .iter()
            .any(|s| s.to_string().contains("\"lstm\"") || s.to_string().contains("residual"));
        assert_eq!(label.to_lowercase().contains("lstm"), holds_lstm, "{label}");
        let alone = json(&run_ok(
            gyrotherm()
                .args(["evaluate", "--json", "--tau-s", "100"])
                .args([
                    "--gyro-col",
                    &format!("{g}_comp"),
                    "--temp-col",
                    "temp_case_c",
                ])
                .arg("--input")
                .arg(&comp),
        ));
        let want = alone["bias_stability_dph"].as_f64().unwrap();
        let got = u["performance"][0]["bias_stability_dph"].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-12 * want.abs(),
            "{g}: compare {got} vs evaluate {want}"
        );
    }
    eprintln!(
        "unit fit sensors per axis: {}",
        trained["axes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a["temps"].to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    assert!(
        several,
        "no axis kept more than one sensor: the column is not tested"
    );
    let headers = unit["across_axes"]["headers"].as_array().unwrap();
    assert!(
        headers.iter().any(|h| h == "unit fit (axis's sensors)"),
        "{headers:?}"
    );
    let text = String::from_utf8_lossy(&compare(false).stdout).into_owned();
    assert_eq!(text.matches("the unit's fit on ").count(), 3, "{text}");
    for a in unit["axes"].as_array().unwrap() {
        let header = a["unit_fit"]["header"].as_str().unwrap();
        assert!(text.contains(&format!("{header:>22}")), "{header}: {text}");
    }
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
            .args([
                "report",
                "--method",
                "thermal",
                "--methods",
                "linear",
                "--gyro-col",
                GYROS,
            ])
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
    assert!(page.contains("unit fit (axis"), "{page}");
    for (k, g) in ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]
        .iter()
        .enumerate()
    {
        assert!(
            page.contains(&format!("<h2>Axis {}: {g} (temperature temp_", k + 1)),
            "{g}"
        );
        // Two sensors: the axis's table has the unit's own fit beside the methods.
        assert!(
            page.contains("; the unit&#39;s fit on temp_")
                || page.contains("; the unit's fit on temp_"),
            "{g}"
        );
        let folder = out_dir.join(format!("axis{}", k + 1));
        assert!(folder.join("index.html").is_file(), "{}", folder.display());
        assert!(folder.join("fig7_compensation.png").is_file());
        assert!(page.contains(&format!("src=\"axis{}/fig7_compensation.png\"", k + 1)));
        // The axis's coverage figures are of the unit's own fit (what the unit's `compensate`
        // writes σ from), named by its label with its sensors, not of a one-sensor column.
        let axis_page = std::fs::read_to_string(folder.join("index.html")).unwrap();
        for caption in ["Coverage map of the ", "after the "] {
            let at = axis_page
                .find(caption)
                .unwrap_or_else(|| panic!("{caption}: {g}"));
            let named = &axis_page[at..at + 200.min(axis_page.len() - at)];
            assert!(
                named.contains(" sensors: temp_") || named.contains(" sensor: temp_"),
                "{g}: {named}"
            );
        }
    }
}

/// Every temperature column of the simulated unit, the case sensor first.
const ALL_TEMPS: &str = "temp_case_c,temp_x_c,temp_y_c,temp_z_c";

/// A static, a table (on y) and a held-out run, and the default (`thermal`) unit model
/// `train` builds on the first two with every sensor: (static, table, held-out, model).
fn unit_on_all_sensors(dir: &Path) -> (PathBuf, PathBuf, PathBuf, PathBuf) {
    let s = sim(dir, "s.csv", &["--seed", "1"]);
    let t = sim(
        dir,
        "t.csv",
        &["--seed", "2", "--table-rate", "20", "--table-axis", "y"],
    );
    let h = sim(dir, "h.csv", &["--seed", "3"]);
    let model = dir.join("unit.json");
    run_ok(
        gyrotherm()
            .args([
                "train",
                "--method",
                "thermal",
                "--gyro-col",
                GYROS,
                "--temp-col",
                ALL_TEMPS,
                "--out",
            ])
            .arg(&model)
            .arg("--input")
            .arg(&s)
            .arg("--input")
            .arg(&t),
    );
    (s, t, h, model)
}

fn write_spec(dir: &Path, name: &str, limits: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!("name = \"unit acceptance\"\n[limits]\n{limits}"),
    )
    .unwrap();
    p
}

/// The figure verdicts of a JSON verdict without the log's name (which is the path judged).
fn figure_verdicts(v: &serde_json::Value) -> Vec<serde_json::Value> {
    v["figures"]
        .as_array()
        .expect("figures")
        .iter()
        .map(|f| {
            let mut f = f.clone();
            f.as_object_mut().unwrap().remove("log");
            f
        })
        .collect()
}

/// `evaluate --spec` with a unit model: each axis's verdict is the single-axis
/// `evaluate --spec` verdict of the compensated column `compensate` wrote for it (figure,
/// value, limits, pass, margin: an independent path through the reader and the single-axis
/// command); the unit passes when every axis passes, and fails, naming the axis and exiting
/// 1, when a limit sits between the axes' values so that one axis misses it.
#[test]
fn evaluate_spec_judges_every_axis_and_the_unit_fails_when_one_axis_misses() {
    let dir = tempfile::tempdir().unwrap();
    let (model, _) = train(dir.path());
    let held = sim(dir.path(), "h.csv", &["--seed", "3"]);
    let comp = dir.path().join("comp.csv");
    run_ok(
        gyrotherm()
            .args(["compensate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&held)
            .arg("--out")
            .arg(&comp),
    );
    let loose = write_spec(
        dir.path(),
        "loose.toml",
        "bias_dph = { min = -1e6, max = 1e6 }\nbias_stability_dph = { max = 1e6 }\n\
         arw_deg_rt_h = { max = 1e6 }\n",
    );
    let unit_run = |spec: &Path| {
        gyrotherm()
            .args(["evaluate", "--json", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&held)
            .arg("--spec")
            .arg(spec)
            .output()
            .unwrap()
    };
    let out = unit_run(&loose);
    assert_exit(&out, 0);
    let unit = json(&out);
    assert_eq!(unit["verdict"]["pass"], true);
    assert_eq!(unit["verdict"]["judged"], "compensated");
    assert_eq!(unit["verdict"]["failed_axes"], serde_json::json!([]));
    let gyros = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"];
    let mut stability = Vec::new();
    for (a, g) in unit["axes"].as_array().unwrap().iter().zip(gyros) {
        let alone = json(&run_ok(
            gyrotherm()
                .args(["evaluate", "--json", "--gyro-col", &format!("{g}_comp")])
                .args(["--temp-col", "temp_case_c", "--input"])
                .arg(&comp)
                .arg("--spec")
                .arg(&loose),
        ));
        let (u, s) = (
            figure_verdicts(&a["verdict"]),
            figure_verdicts(&alone["verdict"]),
        );
        assert_eq!(u.len(), 3, "{g}: {u:?}");
        assert_eq!(u, s, "{g}");
        assert_eq!(
            a["verdict"]["figures"][0]["log"],
            held.display().to_string()
        );
        stability.push(a["compensated"]["bias_stability_dph"].as_f64().unwrap());
    }
    // A limit between the worst axis and the next: that axis, and so the unit, fails.
    let worst = (0..3)
        .max_by(|&i, &j| stability[i].total_cmp(&stability[j]))
        .unwrap();
    let mut sorted = stability.clone();
    sorted.sort_by(f64::total_cmp);
    assert!(sorted[1] < sorted[2], "{stability:?}");
    let tight = write_spec(
        dir.path(),
        "tight.toml",
        &format!(
            "bias_stability_dph = {{ max = {} }}\n",
            (sorted[1] + sorted[2]) / 2.0
        ),
    );
    let out = unit_run(&tight);
    assert_exit(&out, 1);
    let unit = json(&out);
    assert_eq!(unit["verdict"]["pass"], false);
    assert_eq!(
        unit["verdict"]["failed_axes"],
        serde_json::json!([gyros[worst]])
    );
    for (k, a) in unit["axes"].as_array().unwrap().iter().enumerate() {
        assert_eq!(a["verdict"]["pass"], k != worst, "{}", gyros[k]);
    }
    // Text: each axis's verdict lines with units, then the unit's line naming the axis.
    let out = gyrotherm()
        .args(["evaluate", "--model"])
        .arg(&model)
        .arg("--input")
        .arg(&held)
        .arg("--spec")
        .arg(&tight)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("against the spec:").count(), 3, "{text}");
    assert!(text.contains("°/h"), "{text}");
    let last = text.lines().last().unwrap();
    assert_eq!(
        last,
        format!(
            "unit verdict: FAIL (spec unit acceptance, 3 axes, compensated output; failed: {})",
            gyros[worst]
        )
    );
    // Without a model the raw columns are judged, each as `evaluate --gyro-col G --spec`.
    let raw = json(&run_ok(
        gyrotherm()
            .args(["evaluate", "--json", "--gyro-col", GYROS])
            .args(["--temp-col", "temp_case_c", "--input"])
            .arg(&held)
            .arg("--spec")
            .arg(&loose),
    ));
    assert_eq!(raw["verdict"]["judged"], "raw");
    let alone = json(&run_ok(
        gyrotherm()
            .args(["evaluate", "--json", "--gyro-col", "gyro_y_dps"])
            .args(["--temp-col", "temp_case_c", "--input"])
            .arg(&held)
            .arg("--spec")
            .arg(&loose),
    ));
    assert_eq!(
        figure_verdicts(&raw["axes"][1]["verdict"]),
        figure_verdicts(&alone["verdict"])
    );
}

/// A limit no axis's log can give (a scale-factor figure on a static run) is an error naming
/// the axis and what to do, exit 2, never a silent pass.
#[test]
fn evaluate_spec_with_a_figure_the_log_cannot_give_names_the_axis() {
    let dir = tempfile::tempdir().unwrap();
    let h = sim(dir.path(), "h.csv", &["--seed", "3"]);
    let spec = write_spec(
        dir.path(),
        "sf.toml",
        "sf_thermal_error_ppm = { max = 30 }\n",
    );
    let out = gyrotherm()
        .args(["evaluate", "--gyro-col", GYROS, "--temp-col", "temp_case_c"])
        .arg("--spec")
        .arg(&spec)
        .arg("--input")
        .arg(&h)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("axis gyro_x_dps (raw output)"), "{err}");
    assert!(err.contains("add such a log or remove the limit"), "{err}");
    assert!(err.contains(&h.display().to_string()), "{err}");
}

/// `compare --spec` with column lists: the unit fit's verdict on each axis equals
/// `evaluate --model UNIT.json --spec` of the unit `train` builds with the same lists (the
/// same fit reached by another command, judged through another path), each one-sensor
/// column gets its own verdict, and a limit between the columns' values fails the run
/// (exit 1) while loose limits pass it (exit 0).
#[test]
fn compare_spec_judges_every_column_of_every_axis() {
    let dir = tempfile::tempdir().unwrap();
    let temps = ALL_TEMPS;
    let (s, t, h, model) = unit_on_all_sensors(dir.path());
    let loose = write_spec(
        dir.path(),
        "loose.toml",
        "bias_stability_dph = { max = 1e6 }\narw_deg_rt_h = { max = 1e6 }\n",
    );
    let compare = |spec: &Path| {
        gyrotherm()
            .args([
                "compare",
                "--json",
                "--method",
                "thermal",
                "--methods",
                "linear,thermal",
            ])
            .args(["--gyro-col", GYROS, "--temp-col", temps, "--train"])
            .arg(&s)
            .arg("--train")
            .arg(&t)
            .arg("--test")
            .arg(&h)
            .arg("--spec")
            .arg(spec)
            .output()
            .unwrap()
    };
    let out = compare(&loose);
    assert_exit(&out, 0);
    let cmp = json(&out);
    let evaluated = json(&run_ok(
        gyrotherm()
            .args(["evaluate", "--json", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&h)
            .arg("--spec")
            .arg(&loose),
    ));
    let axes = cmp["verdicts"].as_array().expect("verdicts per axis");
    assert_eq!(axes.len(), 3);
    let mut stability = Vec::new();
    for (a, e) in axes.iter().zip(evaluated["axes"].as_array().unwrap()) {
        let cols = a["columns"].as_array().unwrap();
        assert_eq!(cols.len(), 2, "linear and thermal: {a}");
        let unit = &a["unit_fit"];
        assert!(unit[0].as_str().unwrap().contains("sensor"), "{unit}");
        assert_eq!(
            figure_verdicts(&unit[1]),
            figure_verdicts(&e["verdict"]),
            "{}",
            a["gyro"]
        );
        for c in cols {
            stability.push(
                c["verdict"]["figures"][0]["value"]
                    .as_f64()
                    .expect("bias stability value"),
            );
        }
    }
    // A limit between the smallest and the largest column value: some column misses it.
    let (lo, hi) = stability
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    assert!(lo < hi, "{stability:?}");
    let tight = write_spec(
        dir.path(),
        "tight.toml",
        &format!("bias_stability_dph = {{ max = {} }}\n", (lo + hi) / 2.0),
    );
    let out = compare(&tight);
    assert_exit(&out, 1);
    let text = run_text_compare(&s, &t, &h, temps, &tight);
    assert!(text.contains("across the axes:"), "{text}");
    assert!(text.contains(": FAIL on "), "{text}");
}

fn run_text_compare(s: &Path, t: &Path, h: &Path, temps: &str, spec: &Path) -> String {
    let out = gyrotherm()
        .args([
            "compare",
            "--method",
            "thermal",
            "--methods",
            "linear,thermal",
        ])
        .args(["--gyro-col", GYROS, "--temp-col", temps, "--train"])
        .arg(s)
        .arg("--train")
        .arg(t)
        .arg("--test")
        .arg(h)
        .arg("--spec")
        .arg(spec)
        .output()
        .unwrap();
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The bias stability each axis's verdict holds (the first `bias_stability_dph` figure).
fn stability_per_axis(unit: &serde_json::Value) -> Vec<f64> {
    unit["axes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| {
            a["verdict"]["figures"]
                .as_array()
                .unwrap()
                .iter()
                .find(|f| f["figure"] == "bias_stability_dph")
                .and_then(|f| f["value"].as_f64())
                .expect("bias stability in the axis's verdict")
        })
        .collect()
}

/// A limit halfway between the largest of `v` and the next: exactly the worst one misses it.
/// Returns (limit, index of the worst).
fn limit_failing_the_worst(v: &[f64]) -> (f64, usize) {
    let worst = (0..v.len()).max_by(|&i, &j| v[i].total_cmp(&v[j])).unwrap();
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    assert!(sorted[n - 2] < sorted[n - 1], "{v:?}");
    ((sorted[n - 2] + sorted[n - 1]) / 2.0, worst)
}

/// `lot add` with a unit model records a verdict per axis and the unit's, each axis's figures
/// equal to what `evaluate --model UNIT.json --spec` measures and judges on the same log (an
/// independent path: the evaluate command), the unit failing when one axis misses; `lot list`
/// and `lot report` show the axes and count the unit as passed only when every axis passed.
#[test]
fn lot_add_records_each_axis_and_the_unit_as_evaluate_judges_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (model, _) = train(d);
    let held = sim(d, "h.csv", &["--seed", "3"]);
    let loose = write_spec(
        d,
        "loose.toml",
        "bias_stability_dph = { max = 1e6 }\narw_deg_rt_h = { max = 1e6 }\n",
    );
    let evaluate = |spec: &Path| {
        let out = gyrotherm()
            .args(["evaluate", "--json", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&held)
            .arg("--spec")
            .arg(spec)
            .output()
            .unwrap();
        (out.status.code(), json(&out))
    };
    let (_, ev) = evaluate(&loose);
    let (limit, worst) = limit_failing_the_worst(&stability_per_axis(&ev));
    let tight = write_spec(
        d,
        "tight.toml",
        &format!("bias_stability_dph = {{ max = {limit} }}\n"),
    );
    let (code, ev_tight) = evaluate(&tight);
    assert_eq!(code, Some(1));
    let db = d.join("lot.sqlite");
    let add = |serial: &str, spec: &Path, json_out: bool| {
        let mut c = gyrotherm();
        c.args(["lot", "add", "--db"])
            .arg(&db)
            .args(["--unit", serial, "--model"])
            .arg(&model)
            .arg("--test")
            .arg(&held)
            .arg("--spec")
            .arg(spec);
        if json_out {
            c.arg("--json");
        }
        c.output().unwrap()
    };
    let out = add("IMU-1", &loose, false);
    assert_exit(&out, 0);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("against the spec:").count(), 3, "{text}");
    assert!(
        text.contains("unit verdict: PASS (spec unit acceptance, 3 axes, compensated output)"),
        "{text}"
    );
    let out = add("IMU-2", &tight, true);
    assert_exit(&out, 1);
    let run = json(&out);
    assert_eq!(run["verdict"], "fail");
    let gyros = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"];
    for (k, g) in gyros.iter().enumerate() {
        let a = &run["axes"][k];
        assert_eq!(
            (a["axis"].as_u64(), a["gyro"].as_str()),
            (Some(k as u64), Some(*g))
        );
        assert_eq!(
            a["verdict"],
            if k == worst { "fail" } else { "pass" },
            "{g}"
        );
        assert_eq!(ev_tight["axes"][k]["verdict"]["pass"], k != worst);
        // Each limited figure of the axis: value, pass and margin as evaluate gives them.
        let recorded: Vec<(String, f64, bool, f64)> = run["figures"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|f| f["axis"] == k && !f["pass"].is_null())
            .map(figure_fields)
            .collect();
        let judged: Vec<(String, f64, bool, f64)> = ev_tight["axes"][k]["verdict"]["figures"]
            .as_array()
            .unwrap()
            .iter()
            .map(figure_fields)
            .collect();
        assert_eq!(recorded, judged, "{g}");
    }
    let db_s = db.to_str().unwrap();
    let list = run_ok(gyrotherm().args(["lot", "list", "--db", db_s]));
    let list = String::from_utf8_lossy(&list.stdout);
    assert!(
        list.contains(&format!("axis {}: {} (temp_", worst + 1, gyros[worst])),
        "{list}"
    );
    assert!(list.contains("2 units: 1 passed, 1 failed"), "{list}");
    let rep = d.join("rep");
    let out = run_ok(
        gyrotherm()
            .args(["lot", "report", "--db", db_s, "--out"])
            .arg(&rep),
    );
    let out = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.contains("2 units (2 runs): 1 passed, 1 failed"),
        "{out}"
    );
    let page = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(page.contains("<table id=\"axes\">"), "{page}");
    let csv = std::fs::read_to_string(rep.join("lot.csv")).unwrap();
    assert!(
        csv.lines().any(|l| l.contains(",bias_stability_dph,")
            && l.ends_with(&format!(",{},fail", gyros[worst]))),
        "{csv}"
    );

    // A single-axis model given column lists: refused with what to do, nothing recorded.
    let single = d.join("single.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--gyro-col", "gyro_x_dps"])
            .args(["--temp-col", "temp_case_c", "--out"])
            .arg(&single)
            .arg("--input")
            .arg(&held),
    );
    let out = gyrotherm()
        .args(["lot", "add", "--db", db_s, "--unit", "X", "--model"])
        .arg(&single)
        .args(["--gyro-col", GYROS, "--temp-col", "temp_case_c", "--test"])
        .arg(&held)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("need an inertial unit's model"), "{err}");
}

/// The lines of the verdict that follows the line `header` in `text`, up to and including its
/// `verdict:` line.
fn verdict_after(text: &str, header: &str) -> Vec<String> {
    let mut lines = text.lines().skip_while(|l| *l != header);
    assert!(lines.next().is_some(), "{header:?} not in:\n{text}");
    let mut out = Vec::new();
    for l in lines {
        out.push(l.to_owned());
        if l.starts_with("verdict: ") {
            return out;
        }
    }
    panic!("no verdict line after {header:?}:\n{text}");
}

/// `report --spec` with column lists: each axis's verdicts and the unit's on stdout and on
/// the page; the unit fit's verdict on each axis equals `evaluate --model UNIT.json --spec`
/// of the unit `train` builds with the same lists (line for line, the same held-out log),
/// exit 0 when every column passes, 1 when a limit between the axes fails one axis.
#[test]
fn report_spec_with_lists_gives_each_axis_and_the_unit_as_evaluate_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (s, t, h, model) = unit_on_all_sensors(d);
    let loose = write_spec(
        d,
        "loose.toml",
        "bias_stability_dph = { max = 1e6 }\narw_deg_rt_h = { max = 1e6 }\n",
    );
    let report = |spec: &Path, out: &Path| {
        gyrotherm()
            .args([
                "report",
                "--method",
                "thermal",
                "--methods",
                "linear,thermal",
            ])
            .args(["--gyro-col", GYROS, "--temp-col", ALL_TEMPS, "--train"])
            .arg(&s)
            .arg("--train")
            .arg(&t)
            .arg("--test")
            .arg(&h)
            .arg("--spec")
            .arg(spec)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap()
    };
    let evaluate = |spec: &Path, json_out: bool| {
        let mut c = gyrotherm();
        c.args(["evaluate", "--model"])
            .arg(&model)
            .arg("--input")
            .arg(&h)
            .arg("--spec")
            .arg(spec);
        if json_out {
            c.arg("--json");
        }
        c.output().unwrap()
    };
    let gyros = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"];
    let rep = d.join("rep");
    let out = report(&loose, &rep);
    assert_exit(&out, 0);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let ev = String::from_utf8_lossy(&evaluate(&loose, false).stdout).into_owned();
    let unit_fit_verdicts = |text: &str| -> Vec<Vec<String>> {
        gyros
            .iter()
            .enumerate()
            .map(|(k, g)| {
                let from_axis: String = text
                    .split(&format!("axis {} ({g}) against the spec:", k + 1))
                    .nth(1)
                    .expect("the axis's verdicts")
                    .to_owned();
                let header = from_axis
                    .lines()
                    .find(|l| l.ends_with("(unit fit):"))
                    .expect("the unit fit's verdict")
                    .to_owned();
                verdict_after(&from_axis, &header)
            })
            .collect()
    };
    for (k, (r, g)) in unit_fit_verdicts(&text).iter().zip(gyros).enumerate() {
        let e = verdict_after(&ev, &format!("axis {} ({g}) against the spec:", k + 1));
        assert_eq!(r, &e, "{g}");
    }
    assert!(text.contains("unit fit: PASS on every axis"), "{text}");
    let page = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(page.contains("<table class=\"unit-verdicts\">"), "{page}");
    assert!(
        page.contains(
            "<tr><td>unit fit</td><td>PASS</td><td>PASS</td><td>PASS</td><td>PASS</td></tr>"
        ),
        "{page}"
    );
    for k in 1..=3 {
        assert!(
            page.contains(&format!("<h3>Axis {k} against the spec: PASS</h3>")),
            "{page}"
        );
    }

    // A limit between the unit's worst axis and the next: that axis and the unit fail, in
    // the report as in evaluate.
    let unit = json(&evaluate(&loose, true));
    let (limit, worst) = limit_failing_the_worst(&stability_per_axis(&unit));
    let tight = write_spec(
        d,
        "tight.toml",
        &format!("bias_stability_dph = {{ max = {limit} }}\n"),
    );
    let out = evaluate(&tight, true);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        json(&out)["verdict"]["failed_axes"],
        serde_json::json!([gyros[worst]])
    );
    let rep = d.join("rep_tight");
    let out = report(&tight, &rep);
    assert_exit(&out, 1);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let ev = String::from_utf8_lossy(&evaluate(&tight, false).stdout).into_owned();
    for (k, (r, g)) in unit_fit_verdicts(&text).iter().zip(gyros).enumerate() {
        let e = verdict_after(&ev, &format!("axis {} ({g}) against the spec:", k + 1));
        assert_eq!(r, &e, "{g}");
    }
    assert!(
        text.contains(&format!("unit fit: FAIL on {}", gyros[worst])),
        "{text}"
    );
    let page = std::fs::read_to_string(rep.join("index.html")).unwrap();
    let cells: String = (0..3)
        .map(|k| {
            if k == worst {
                "<td>FAIL</td>"
            } else {
                "<td>PASS</td>"
            }
        })
        .collect();
    assert!(
        page.contains(&format!("<tr><td>unit fit</td>{cells}<td>FAIL</td></tr>")),
        "{page}"
    );
}

/// A judged figure's name, value, pass and margin, as the JSON of `lot add` and `evaluate`
/// give them.
fn figure_fields(f: &serde_json::Value) -> (String, f64, bool, f64) {
    (
        f["figure"].as_str().unwrap().to_owned(),
        f["value"].as_f64().unwrap(),
        f["pass"].as_bool().unwrap(),
        f["margin"].as_f64().unwrap(),
    )
}

//! An inertial unit's model file through the real binary, as a single-axis file: `model
//! check` and `model seal` take it, `compensate` and `export` warn when it has no
//! `content_sha256`, and `train` refuses more gyro columns than `compensate` runs before it
//! fits anything.
//!
//! The model is the `imu_flight` example's (`gyrotherm train` of three gyros and four
//! sensors).

use std::path::{Path, PathBuf};

mod cli;
use cli::{gyrotherm, run_ok, simulate_args};

/// A copy of the example's model in `dir`.
fn example_model(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gyrotherm-core/examples/imu_flight/model.json");
    let path = dir.join("unit.json");
    std::fs::copy(src, &path).unwrap();
    path
}

/// The model at `path` hand-edited: one of axis x's bias coefficients changed by a part in
/// 10⁶ (still plausible), and without its `content_sha256`.
fn hand_edit(path: &Path) {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("content_sha256");
    let c = &mut v["axes"][0]["more"][0]["bias"]["baseline"]["coefficients"][0];
    *c = serde_json::json!(c.as_f64().unwrap() * (1.0 + 1e-6));
    std::fs::write(path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

fn outcome(cmd: &mut std::process::Command) -> (i32, String, String) {
    let out = cmd.output().expect("run gyrotherm");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const UNSEALED: &str = "no content_sha256";

#[test]
fn model_check_and_seal_take_a_unit_model() {
    let dir = tempfile::tempdir().unwrap();
    let model = example_model(dir.path());
    let check = || outcome(gyrotherm().args(["model", "check"]).arg(&model));
    let (code, out, err) = check();
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("ok, sealed") && !err.contains(UNSEALED),
        "{out}{err}"
    );

    hand_edit(&model);
    let (code, out, err) = check();
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("ok but not sealed") && err.contains(UNSEALED),
        "{out}{err}"
    );

    let (code, _, err) = outcome(gyrotherm().args(["model", "seal"]).arg(&model));
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("sealed"), "{err}");
    let (code, out, err) = check();
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("ok, sealed") && !err.contains(UNSEALED),
        "{out}{err}"
    );
    let digest = gyrotherm::model::unit::ImuModel::load(&model)
        .unwrap()
        .content_digest()
        .unwrap();
    assert!(out.contains(&digest), "{out}");

    // An edit under a seal that no longer matches: refused.
    let text = std::fs::read_to_string(&model).unwrap();
    let tampered = text.replacen("\"temp_z_c\"", "\"temp_y_c\"", 1);
    assert_ne!(tampered, text);
    std::fs::write(&model, &tampered).unwrap();
    let (code, _, err) = check();
    assert_ne!(code, 0);
    assert!(err.contains("does not match"), "{err}");
}

#[test]
fn compensate_and_export_warn_on_an_unsealed_unit_model() {
    let dir = tempfile::tempdir().unwrap();
    let model = example_model(dir.path());
    let log = simulate_args(
        dir.path(),
        "run.csv",
        &[
            "--imu",
            "--unit",
            "random",
            "--unit-seed",
            "1000",
            "--profile",
            "fast-cycle",
            "--seed",
            "3",
        ],
    );
    let compensate = |model: &Path| {
        let out = run_ok(
            gyrotherm()
                .args(["compensate", "--model"])
                .arg(model)
                .arg("--input")
                .arg(&log)
                .arg("--out")
                .arg(dir.path().join("comp.csv")),
        );
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let export = |model: &Path| {
        let out = run_ok(
            gyrotherm()
                .args(["export", "--target", "c", "--model"])
                .arg(model)
                .arg("--out")
                .arg(dir.path().join("c")),
        );
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    for err in [compensate(&model), export(&model)] {
        assert!(!err.contains(UNSEALED), "{err}");
    }
    hand_edit(&model);
    for err in [compensate(&model), export(&model)] {
        assert!(
            err.contains(&format!("{}: {UNSEALED}", model.display())),
            "{err}"
        );
    }
}

#[test]
fn train_refuses_more_gyro_columns_than_compensate_runs() {
    let dir = tempfile::tempdir().unwrap();
    let n = 20;
    let gyros: Vec<String> = (0..n).map(|k| format!("gyro_{k}_dps")).collect();
    let mut csv = format!("time_s,{},temp_c\n", gyros.join(","));
    for i in 0..2000 {
        let t = i as f64;
        let temp = 20.0 + 10.0 * (t / 500.0).sin();
        let g = vec![format!("{:e}", 1e-3 + 1e-5 * temp); n].join(",");
        csv.push_str(&format!("{t},{g},{temp}\n"));
    }
    let log = dir.path().join("wide.csv");
    std::fs::write(&log, csv).unwrap();
    let (code, _, err) = outcome(
        gyrotherm()
            .args(["train", "--method", "linear", "--gyro-col"])
            .arg(gyros.join(","))
            .args(["--temp-col", "temp_c", "--input"])
            .arg(&log)
            .arg("--out")
            .arg(dir.path().join("m.json")),
    );
    assert_ne!(code, 0, "{err}");
    assert!(
        err.contains("20 gyro columns") && err.contains("at most 16 axes"),
        "{err}"
    );
    // Refused before any axis is fitted.
    assert!(!err.contains("axis starts"), "{err}");
    assert!(!dir.path().join("m.json").exists());
}

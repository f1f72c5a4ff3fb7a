//! An inertial unit's model file gets every check a single-axis file gets: each further
//! sensor's part has plausible coefficients, one per term, and keeps B and K plausible over
//! the training range; a key named twice is refused before the seal is checked; a file
//! without its seal loads with a warning; the axes are at least one, at most the
//! compensator's capacity, each on a gyro column of its own; and a log needs only the
//! temperature columns the axes read.
//!
//! The files are the `imu_flight` example's model (`gyrotherm train` of three gyros and four
//! sensors, every axis reading several), hand-edited as a hostile probe would.

use gyrotherm::compensate::unit::compensate_imu;
use gyrotherm::compensate_lines::unit::{compensate_imu_lines, MAX_STREAM_AXES};
use gyrotherm::compensate_lines::Mode;
use gyrotherm::csvlog::ReadOptions;
use gyrotherm::model::unit::{ImuError, ImuModel};
use gyrotherm::model::Seal;
use gyrotherm::sim::imu::{imu_from_family, simulate_imu, ImuConfig};
use gyrotherm::sim::{Profile, SimConfig};
use gyrotherm_core::compensator::Status;
use serde_json::{json, Value};

fn example_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gyrotherm-core/examples/imu_flight/model.json")
}

/// The example's sealed text, as `train` wrote it.
fn example_text() -> String {
    std::fs::read_to_string(example_path()).unwrap()
}

fn example() -> Value {
    serde_json::from_str(&example_text()).unwrap()
}

/// `v` as a hand edit leaves it: without its `content_sha256`.
fn unsealed(mut v: Value) -> String {
    v.as_object_mut().unwrap().remove("content_sha256");
    serde_json::to_string_pretty(&v).unwrap()
}

/// The whole message of the refusal of `text`.
fn refusal(text: &str) -> String {
    match ImuModel::from_json(text) {
        Ok(_) => panic!("the edited model loads"),
        Err(e) => gyrotherm::error_chain(&e),
    }
}

#[test]
fn the_example_loads_sealed_and_unsealed() {
    let (_, seal) = ImuModel::from_json_sealed(&example_text()).unwrap();
    assert_eq!(seal, Seal::Verified);
    let (_, seal) = ImuModel::from_json_sealed(&unsealed(example())).unwrap();
    assert_eq!(seal, Seal::Absent);
    let (_, seal) = ImuModel::load_sealed(&example_path()).unwrap();
    assert_eq!(seal, Seal::Verified);
}

#[test]
fn a_further_sensors_implausible_part_is_refused() {
    // The probe's values: 1e300 is past the coefficient bound (1e15) of a single-axis file;
    // 1e3 on T is a plausible coefficient, but at the training range's lowest temperature
    // (−9.375 °C for gyro x) it adds about −9.4·10³ °/s to B, past the 10³ °/s bound, and
    // takes K below zero.
    for part in ["bias", "scale"] {
        let predicts = if part == "bias" {
            "predicts B"
        } else {
            "predicts K"
        };
        for (c, why) in [(1e300, "implausibly large"), (1e3, predicts)] {
            let mut v = example();
            // Term 0 of every further part is T (powers [1, 0, 0, 0, 0]).
            assert_eq!(
                v["axes"][0]["more"][0][part]["baseline"]["terms"]["powers"][0],
                json!([1, 0, 0, 0, 0])
            );
            v["axes"][0]["more"][0][part]["baseline"]["coefficients"][0] = json!(c);
            let msg = refusal(&unsealed(v));
            assert!(
                msg.contains("gyro_x_dps") && msg.contains(why),
                "{part} {c}: {msg}"
            );
        }
    }
}

#[test]
fn a_further_sensors_coefficients_must_match_its_terms() {
    for n in [2, 7, 0] {
        let mut v = example();
        v["axes"][1]["more"][0]["bias"]["baseline"]["coefficients"] = json!(vec![1e-7; n]);
        let msg = refusal(&unsealed(v));
        // Axis y's first further sensor is temp_case_c; its part has 4 terms.
        assert!(
            msg.contains("gyro_y_dps")
                && msg.contains("temp_case_c")
                && msg.contains(&format!("coefficients has {n} values for 4 terms")),
            "{n}: {msg}"
        );
    }
}

#[test]
fn a_key_named_twice_is_refused_before_the_seal() {
    // A decoy array before the real one: the last value wins in serde_json, so the content,
    // and with it the seal, is the real one's, while a reader keeping the first uses 0.5.
    let text = example_text();
    let decoy = text.replacen(
        "\"coefficients\": [",
        "\"coefficients\": [0.5],\n\"coefficients\": [",
        1,
    );
    assert_ne!(decoy, text);
    match ImuModel::from_json(&decoy) {
        Err(ImuError::DuplicateKey(d)) => {
            assert_eq!(d.key, "coefficients");
            assert!(d.path.starts_with("axes[0].model."), "{}", d.path);
        }
        other => panic!("{:?}", other.map(|_| ())),
    }
}

#[test]
fn axes_are_one_to_the_compensators_capacity_each_on_its_own_gyro() {
    // No axes: said as such, not as a version mismatch.
    let mut v = example();
    v["axes"] = json!([]);
    v["gyro_cols"] = json!([]);
    let msg = refusal(&unsealed(v));
    assert!(
        msg.contains("no gyro axes") && !msg.contains("imu_format_version"),
        "{msg}"
    );

    // The same gyro column on two axes would write repeated output columns.
    let mut v = example();
    v["axes"][1]["gyro"] = json!("gyro_x_dps");
    v["gyro_cols"][1] = json!("gyro_x_dps");
    let msg = refusal(&unsealed(v));
    assert!(
        msg.contains("\"gyro_x_dps\" is listed twice") && msg.contains("axes 1 and 2"),
        "{msg}"
    );

    // One axis past what compensate runs.
    let mut v = example();
    let axis = v["axes"][0].clone();
    let n = MAX_STREAM_AXES + 1;
    v["axes"] = Value::Array(
        (0..n)
            .map(|k| {
                let mut a = axis.clone();
                a["gyro"] = json!(format!("gyro_{k}_dps"));
                a
            })
            .collect(),
    );
    v["gyro_cols"] = json!((0..n).map(|k| format!("gyro_{k}_dps")).collect::<Vec<_>>());
    let msg = refusal(&unsealed(v));
    assert!(
        msg.contains(&format!("{n} gyro columns")) && msg.contains("at most 16 axes"),
        "{msg}"
    );
}

/// The example with every axis reading only `temp_case_c` (first sensor's model kept).
fn case_sensor_only() -> ImuModel {
    let mut v = example();
    v["imu_format_version"] = json!(1);
    for a in v["axes"].as_array_mut().unwrap() {
        a["temps"] = json!(["temp_case_c"]);
        a.as_object_mut().unwrap().remove("more");
        a.as_object_mut().unwrap().remove("multi_cv_rms");
    }
    ImuModel::from_json(&unsealed(v)).unwrap()
}

#[test]
fn a_log_needs_only_the_temperature_columns_the_axes_read() {
    let model = case_sensor_only();
    assert_eq!(model.temps_read(), ["temp_case_c"]);
    assert_eq!(
        model.read_options(&ReadOptions::default()).temp_col,
        "temp_case_c"
    );
    let full = simulate_imu(&ImuConfig {
        run: SimConfig {
            seed: 7,
            ..SimConfig::new(Profile::builtin("fast-cycle").unwrap())
        },
        unit: imu_from_family(1000),
        table_axis: 0,
    })
    .unwrap();
    let mut case_only = full.clone();
    case_only.temp.retain(|s| s.name == "temp_case_c");
    assert_eq!(case_only.temp.len(), 1);
    // Batch: the columns no axis reads change nothing.
    let want = compensate_imu(&model, &full).unwrap();
    let got = compensate_imu(&model, &case_only).unwrap();
    // Compared as text: equal to the bit, NaN included.
    assert_eq!(format!("{got:?}"), format!("{want:?}"));
    assert!(got[0].status.iter().filter(|s| **s == Status::Ok).count() > got[0].status.len() / 2);

    // The stream, on a CSV without the other sensors.
    let mut csv = String::from("time_s,gyro_x_dps,gyro_y_dps,gyro_z_dps,temp_case_c\n");
    for i in 0..case_only.len() {
        csv.push_str(&format!(
            "{},{},{},{},{}\n",
            case_only.time_s[i],
            case_only.gyro[0].values[i],
            case_only.gyro[1].values[i],
            case_only.gyro[2].values[i],
            case_only.temp[0].values[i]
        ));
    }
    let mut out = Vec::new();
    let summary = compensate_imu_lines(
        &model,
        csv.as_bytes(),
        "case.csv".as_ref(),
        &ReadOptions::default(),
        &mut out,
        Mode::Strict,
        false,
    )
    .unwrap();
    assert_eq!(summary.rows as usize, case_only.len());
    assert_eq!(
        summary.per_axis[0][Status::Ok as usize],
        got[0].status.iter().filter(|s| **s == Status::Ok).count() as u64
    );
}

//! Coverage and σ per sample on a unit's axis that reads several temperature sensors. The map
//! is on the first sensor's (T, dT), which the flight axis steps; its σ is the first sensor's
//! one-sensor map (the axis's fallback keeps it as fitted) times the ratio of the
//! several-sensor fit's cross-validated bias RMS to the first sensor's alone, both recorded in
//! the file (`multi_cv_rms`, `scores`). `Model::coverage_log` gives a verdict on every sample
//! of such an axis once its filters have run.

use gyrotherm::fit::unit::{fit_imu_with, ImuFitSettings, ImuSensors};
use gyrotherm::model::unit::ImuModel;
use gyrotherm::model::TempSensorDef;
use gyrotherm::settings::{FitSettings, Method};
use gyrotherm::unit_model::{Model, NO_COVERAGE};

#[path = "support/unit_1000.rs"]
mod unit_1000;
use unit_1000::{run, training};

/// Unit 1000's x axis on both its sensors (a gain threshold of -1 keeps the second sensor
/// unless it doubles the cross-validated RMS: the test is about the map, not the choice).
fn several_sensor_model() -> ImuModel {
    fit_imu_with(
        &training(),
        &FitSettings {
            method: Method::Thermal,
            ..FitSettings::default()
        }
        .fit_config()
        .unwrap(),
        &ImuFitSettings {
            sensors: ImuSensors::All,
            min_gain: -1.0,
            ..ImuFitSettings::default()
        },
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap()
}

#[test]
fn an_axis_on_several_sensors_carries_its_first_sensors_map_scaled_by_what_the_others_took_out() {
    let model = several_sensor_model();
    let a = &model.axes[0];
    assert_eq!(a.temps.len(), 2, "{:?}", a.scores);
    let map = a
        .model
        .coverage
        .as_ref()
        .expect("a several-sensor axis has a map");
    let one = a
        .fallback
        .as_ref()
        .and_then(|f| f.coverage.as_ref())
        .expect("its fallback keeps the one-sensor map");
    // The ratio from the file's own scores: the several-sensor fit's and the first sensor's.
    let several = a.multi_cv_rms.expect("several-sensor score");
    let first = a
        .scores
        .iter()
        .find(|s| s.temp == a.temps[0])
        .and_then(|s| s.cv_rms)
        .expect("first sensor's score");
    let ratio = several / first;
    assert!(ratio.is_finite() && ratio > 0.0, "{ratio}");
    // Same cells, same counts and held-out RMS; σ scaled, to the bit, cell by cell.
    assert_eq!(map.grid(), one.grid());
    assert_eq!(map.count, one.count);
    assert_eq!(map.rms_dph, one.rms_dph);
    assert_eq!(map.growth_per_cell, one.growth_per_cell);
    for (s, s1) in map.sigma_dph.iter().zip(&one.sigma_dph) {
        assert_eq!(s.to_bits(), (s1 * ratio).to_bits(), "{s} vs {s1} × {ratio}");
    }
    assert!(map.covered_cells() > 0);
    // The file round-trips through its checks with the map.
    let text = model.to_json().unwrap();
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
}

/// `Model::coverage_log` on a several-sensor axis gives, sample by sample, the verdicts of its
/// first sensor's one-sensor model (the fallback, with its own unscaled map) stepped on its own
/// by the single-gyro compensator: the same cells and distances, so the same codes, and σ in
/// the ratio of the two maps.
#[test]
fn coverage_log_gives_a_several_sensor_axis_its_first_sensors_verdicts() {
    let fitted = several_sensor_model();
    let a = fitted.axes[0].clone();
    // Through the file, as `compensate` and Python load it.
    let dir = std::env::temp_dir().join(format!("gyrotherm-unit-coverage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("unit.json");
    fitted.save(&path).unwrap();
    let model = Model::load(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let test = run(3, None);
    let (axes, notes) = model.coverage_log(&test).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    let cov = &axes[0];
    assert_eq!(cov.codes.len(), test.len());
    // The independent path: the fallback's compensator on the first sensor's column.
    let one = a.fallback.as_ref().unwrap();
    let map = one.coverage.as_ref().unwrap().to_core().unwrap();
    let ratio = a
        .model
        .coverage
        .as_ref()
        .unwrap()
        .sigma_dph
        .iter()
        .zip(&one.coverage.as_ref().unwrap().sigma_dph)
        .find(|(_, s1)| **s1 > 0.0)
        .map(|(s, s1)| s / s1)
        .unwrap();
    let t = test.temp.iter().position(|c| c.name == a.temps[0]).unwrap();
    let mut comp = gyrotherm::compensate::compensator(one).unwrap();
    let mut judged = 0;
    for i in 0..test.len() {
        comp.step(
            test.time_s[i],
            test.gyro[0].values[i],
            test.temp[t].values[i],
        );
        match map.verdict_of(comp.features()) {
            Some(v) => {
                judged += 1;
                assert_eq!(cov.codes[i], v.coverage as u8, "sample {i}");
                // σ·(1 + g·d) of the scaled map against the unscaled one's times the ratio: the
                // same product in another order, equal to rounding.
                let want = v.sigma_dph * ratio;
                assert!(
                    (cov.sigma_dph[i] - want).abs() <= 1e-12 * want,
                    "sample {i}: {} vs {want}",
                    cov.sigma_dph[i]
                );
            }
            None => assert_eq!(cov.codes[i], NO_COVERAGE, "sample {i}"),
        }
    }
    // The comparison ran: the compensator gives features on all but its first steps.
    assert!(
        judged > test.len() / 2,
        "{judged} of {} samples judged",
        test.len()
    );
}

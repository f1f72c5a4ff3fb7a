//! The inertial-unit fit (`imu_model::fit_imu_with`): with one sensor per axis each axis keeps
//! the sensor with the lowest cross-validated RMS; with every sensor an axis reads the ones
//! cross-validation keeps; the file round-trips sealed, a sensor fault reaches only the axes
//! that read it.

use gyrotherm::compensate::compensate_log;
use gyrotherm::compensate::unit::compensate_imu;
use gyrotherm::fit::unit::{fit_imu_with, ImuFitSettings, ImuSensors};
use gyrotherm::model::unit::{ImuModel, IMU_FORMAT_VERSION, IMU_FORMAT_VERSION_ONE_SENSOR};
use gyrotherm::model::TempSensorDef;
use gyrotherm::settings::{FitSettings, Method};
use gyrotherm_core::compensator::Status;

#[path = "support/unit_1000.rs"]
mod unit_1000;
use unit_1000::{run, training};

fn thermal() -> gyrotherm::fit::FitConfig {
    FitSettings {
        method: Method::Thermal,
        ..FitSettings::default()
    }
    .fit_config()
    .unwrap()
}

#[test]
fn gyro_x_of_unit_1000_reads_its_coil_sensor() {
    let one = ImuFitSettings {
        sensors: ImuSensors::ChooseOne,
        ..ImuFitSettings::default()
    };
    let model = fit_imu_with(
        &training(),
        &thermal(),
        &one,
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    let a = &model.axes[0];
    // Measured (`gyrotherm simulate --imu --unit random --unit-seed 1000`, seeds as above,
    // then `gyrotherm train --gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps --temp-col
    // temp_case_c,temp_x_c,temp_y_c,temp_z_c`): case 3.93e-6 °/s, coil 3.30e-6 °/s. Unit
    // 1000's x coil lags its case by several minutes, so the coil sensor predicts better.
    // With the static run alone beside the x table run, the case sensor scores better
    // (2.73e-6 against 2.99e-6): the choice depends on the bias data.
    assert_eq!(a.temps, ["temp_x_c"], "{:?}", a.scores);
    let (case, coil) = (a.scores[0].cv_rms.unwrap(), a.scores[1].cv_rms.unwrap());
    assert!(coil < case, "{case} {coil}");
    let text = model.to_json().unwrap();
    // One sensor per axis: the first layout, as older builds wrote and read it.
    assert_eq!(model.imu_format_version, IMU_FORMAT_VERSION_ONE_SENSOR);
    assert!(!text.contains("\"more\"") && !text.contains("multi_cv_rms"));
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
    let tampered = text.replacen("\"temp_x_c\"", "\"temp_case_c\"", 1);
    assert!(ImuModel::from_json(&tampered).is_err());

    // A bus-error reading (-127 °C) on the case sensor, which the model does not read: ok.
    let mut test = run(3, None);
    for v in &mut test.temp[0].values[5000..5200] {
        *v = -127.0;
    }
    let comp = compensate_imu(&model, &test).unwrap();
    assert!(comp[0].status.iter().all(|s| *s == Status::Ok));
    // The same on its own sensor: held, then degraded after 60 s.
    let mut test = run(3, None);
    for v in &mut test.temp[1].values[5000..5200] {
        *v = -127.0;
    }
    let comp = compensate_imu(&model, &test).unwrap();
    assert!(comp[0].status.contains(&Status::Degraded));
}

#[test]
fn every_sensor_when_cross_validation_keeps_it() {
    // A gain threshold of -1 keeps every sensor unless it doubles the cross-validated RMS:
    // the test is about the layout and the flight path, not about which sensors help.
    let all = ImuFitSettings {
        sensors: ImuSensors::All,
        min_gain: -1.0,
        ..ImuFitSettings::default()
    };
    let model = fit_imu_with(
        &training(),
        &thermal(),
        &all,
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    let a = &model.axes[0];
    assert_eq!(a.temps.len(), 2, "{:?}", a.scores);
    assert_eq!(a.more.len(), 1);
    assert_eq!(model.imu_format_version, IMU_FORMAT_VERSION);
    // The further sensor's bias part: T and each of its lag differences, linearly, over the
    // features (T, dT, D1, …), no constant (the default further terms, written out here).
    let power = |n: usize, i: usize, q: u8| {
        let mut p = vec![0u8; n];
        p[i] = q;
        p
    };
    let further_terms = |a: &gyrotherm::model::unit::ImuAxis, cubic: bool| {
        let lags = a.more[0].lags_s.len();
        let n = 2 + lags;
        let mut want = vec![power(n, 0, 1)];
        if cubic {
            want.extend([power(n, 0, 2), power(n, 0, 3)]);
        }
        want.extend((0..lags).map(|j| power(n, 2 + j, 1)));
        match a.more[0].bias.as_ref() {
            Some(gyrotherm::model::SubModel::Baseline {
                terms,
                coefficients,
            }) => {
                assert_eq!(terms.powers, want);
                assert_eq!(coefficients.len(), want.len());
            }
            other => panic!("further bias part: {other:?}"),
        }
    };
    further_terms(a, false);
    // The experiment's cubic further terms: T, T², T³ and each lag difference.
    let cubic = fit_imu_with(
        &training(),
        &thermal(),
        &ImuFitSettings {
            multi_extra: gyrotherm::fit::thermal::multi::ExtraTerms::Cubic,
            ..all
        },
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    assert_eq!(cubic.axes[0].temps.len(), 2, "{:?}", cubic.axes[0].scores);
    further_terms(&cubic.axes[0], true);
    let text = model.to_json().unwrap();
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
    // A further sensor that is not a column of the unit is refused.
    let mut bad = model.clone();
    bad.axes[0].temps[1] = "temp_q_c".into();
    assert!(bad.validate().is_err());
    // Nor a further sensor without its part.
    let mut bad = model.clone();
    bad.axes[0].more.clear();
    assert!(bad.validate().is_err());

    // Without the further sensor's part the axis is its first sensor's model: the same
    // output as the single-axis compensator on that sensor's column.
    let test = run(3, None);
    let mut first_only = model.clone();
    first_only.axes[0].temps.truncate(1);
    first_only.axes[0].more.clear();
    first_only.imu_format_version = IMU_FORMAT_VERSION_ONE_SENSOR;
    let j = model
        .temp_cols
        .iter()
        .position(|t| *t == a.temps[0])
        .unwrap();
    let single = compensate_log(&a.model, &test.axis_data(0, j)).unwrap();
    let unit = compensate_imu(&first_only, &test).unwrap();
    assert_eq!(single.gyro_comp_dps, unit[0].gyro_comp_dps);
    // With it, the output differs.
    let both = compensate_imu(&model, &test).unwrap();
    assert_ne!(single.gyro_comp_dps, both[0].gyro_comp_dps);

    // A fault on either sensor the axis reads holds it. On its first sensor the axis then
    // degrades; on the further sensor it goes on with its fallback (the first sensor's own
    // model, kept in the file), and is ok again once the sensor is back.
    assert!(a.fallback.is_some());
    for k in 0..2 {
        let mut test = run(3, None);
        for v in &mut test.temp[k].values[5000..5200] {
            *v = f64::NAN;
        }
        let comp = compensate_imu(&model, &test).unwrap();
        let s = &comp[0].status;
        assert_eq!(s[5000], Status::Held, "sensor {k}");
        if k == j {
            assert!(s.contains(&Status::Degraded), "sensor {k}");
            assert!(!s.contains(&Status::Fallback), "sensor {k}");
        } else {
            assert!(s[5000..5200].contains(&Status::Fallback), "sensor {k}");
            assert!(!s.contains(&Status::Degraded), "sensor {k}");
            assert_eq!(s[5300], Status::Ok, "sensor {k}");
        }
    }
}

#[test]
fn the_stream_runs_an_axis_on_several_sensors_as_compensate_imu_does() {
    let all = ImuFitSettings {
        sensors: ImuSensors::All,
        min_gain: -1.0,
        ..ImuFitSettings::default()
    };
    let model = fit_imu_with(
        &training(),
        &thermal(),
        &all,
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    assert_eq!(model.axes[0].temps.len(), 2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.csv");
    let mut test = run(3, None);
    // A fault on the further sensor: the stream and the in-memory path must both hold.
    let further = model
        .temp_cols
        .iter()
        .position(|t| *t == model.axes[0].temps[1])
        .unwrap();
    test.temp[further].values[5000] = f64::NAN;
    gyrotherm::csvlog::write_imu_log(&path, &test).unwrap();
    let want = compensate_imu(&model, &test).unwrap();
    assert_eq!(want[0].status[5000], Status::Held);
    let mut out = Vec::new();
    gyrotherm::compensate_lines::unit::compensate_imu_lines(
        &model,
        std::io::BufReader::new(std::fs::File::open(&path).unwrap()),
        &path,
        &gyrotherm::csvlog::ReadOptions::default(),
        &mut out,
        gyrotherm::compensate_lines::Mode::Stream,
        false,
    )
    .unwrap();
    let text = String::from_utf8(out).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let comp = header.iter().position(|h| *h == "gyro_x_dps_comp").unwrap();
    let status = header
        .iter()
        .position(|h| *h == "gyro_x_dps_status")
        .unwrap();
    for (i, l) in lines.enumerate() {
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!(f[status], want[0].status[i].as_str(), "line {}", i + 2);
        if want[0].status[i] != Status::Invalid {
            assert_eq!(f[comp].parse::<f64>().unwrap(), want[0].gyro_comp_dps[i]);
        }
    }
}

//! An axis reading several temperature sensors (`multi::AxisCompensator`): B and K are the
//! first sensor's model plus each further sensor's part; a fault on a sensor the axis reads
//! holds it, a fault elsewhere changes nothing; with one sensor it is the one-sensor
//! compensator bit for bit.

use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::compensator::{Compensator, ModelError, Status, TargetModel};
use gyrotherm_core::features::{FeatureSpec, LagOutputs};
use gyrotherm_core::multi::{AxisCompensator, MAX_SENSORS};

fn target(m: BaselineModel) -> TargetModel {
    TargetModel {
        offset: 0.0,
        baseline: Some(m),
        lstm: None,
        lstm_reads_base: false,
    }
}

/// First sensor: bias = 1e-3 + 2e-5·T0 (°/s), K = 1 + 1e-5·T0, on the published features.
fn first() -> Compensator {
    let mut b = BaselineModel::new(2).unwrap();
    b.push_term(&[0, 0], 1e-3).unwrap();
    b.push_term(&[1, 0], 2e-5).unwrap();
    let mut k = BaselineModel::new(2).unwrap();
    k.push_term(&[0, 0], 1.0).unwrap();
    k.push_term(&[1, 0], 1e-5).unwrap();
    Compensator::new(FeatureSpec::PUBLISHED, target(b), target(k)).unwrap()
}

/// A further sensor's part: `c·T` over the published features.
fn part(c: f64) -> BaselineModel {
    let mut m = BaselineModel::new(2).unwrap();
    m.push_term(&[1, 0], c).unwrap();
    m
}

/// The temperatures of four sensors at time t (°C): a ramp each, different slopes.
fn temps(t: f64) -> [f64; 4] {
    [
        20.0 + 0.01 * t,
        21.0 + 0.02 * t,
        19.0 - 0.005 * t,
        25.0 + 0.001 * t,
    ]
}

#[test]
fn one_sensor_is_the_compensator_bit_for_bit() {
    let mut one = first();
    let mut axis = AxisCompensator::new(first(), 2);
    for i in 0..3000 {
        let t = i as f64 * 0.5;
        let mut x = temps(t);
        // Faults of every kind on the axis's sensor and elsewhere.
        if (1000..1200).contains(&i) {
            x[2] = f64::NAN;
        }
        if (1500..1510).contains(&i) {
            x[2] = -127.0;
        }
        if (2000..2100).contains(&i) {
            x[0] = f64::NAN;
        }
        let time = if i == 2500 { f64::NAN } else { t };
        let g = 20.0 + 0.001 * t;
        let a = one.step(time, g, x[2]);
        let b = axis.step(time, g, &x);
        assert_eq!(
            (
                a.status,
                a.bias_dps.to_bits(),
                a.scale.to_bits(),
                a.rate_dps.to_bits()
            ),
            (
                b.status,
                b.bias_dps.to_bits(),
                b.scale.to_bits(),
                b.rate_dps.to_bits()
            ),
            "sample {i}"
        );
    }
}

#[test]
fn further_sensors_add_their_parts() {
    let mut axis = AxisCompensator::new(first(), 0)
        .with_sensor(1, FeatureSpec::PUBLISHED, Some(part(3e-5)), None)
        .unwrap()
        .with_sensor(
            3,
            FeatureSpec::PUBLISHED,
            Some(part(-1e-5)),
            Some(part(2e-6)),
        )
        .unwrap();
    assert_eq!(axis.sensors().collect::<Vec<_>>(), [0, 1, 3]);
    for i in 0..200 {
        let t = i as f64;
        let x = temps(t);
        let out = axis.step(t, 20.0, &x);
        assert_eq!(out.status, Status::Ok);
        // Independent: the generating formulas, first sensor then the further ones.
        let b = 1e-3 + 2e-5 * x[0] + 3e-5 * x[1] - 1e-5 * x[3];
        let k = 1.0 + 1e-5 * x[0] + 2e-6 * x[3];
        assert!((out.bias_dps - b).abs() < 1e-15, "{} {b}", out.bias_dps);
        assert!((out.scale - k).abs() < 1e-15);
        assert!((out.rate_dps - (20.0 - b) / k).abs() < 1e-12);
    }
}

#[test]
fn a_fault_holds_only_the_axes_that_read_the_sensor() {
    let mut reads = AxisCompensator::new(first(), 0)
        .with_sensor(1, FeatureSpec::PUBLISHED, Some(part(3e-5)), None)
        .unwrap();
    let mut other = AxisCompensator::new(first(), 0)
        .with_sensor(2, FeatureSpec::PUBLISHED, Some(part(3e-5)), None)
        .unwrap();
    for i in 0..400 {
        let t = i as f64;
        let mut x = temps(t);
        if (100..200).contains(&i) {
            x[1] = f64::NAN;
        }
        let a = reads.step(t, 20.0, &x);
        let b = other.step(t, 20.0, &x);
        assert_eq!(b.status, Status::Ok, "sample {i}");
        // Last good sample at t = 99 s; degraded once more than 60 s have passed.
        let expected = match i {
            100..=159 => Status::Held,
            160..=199 => Status::Degraded,
            _ => Status::Ok,
        };
        assert_eq!(a.status, expected, "sample {i}");
    }
    // A log that lacks the sensor (too few readings) is a fault of that sensor.
    let out = reads.step(400.0, 20.0, &temps(400.0)[..1]);
    assert_eq!(out.status, Status::Held);
}

#[test]
fn further_sensors_are_checked() {
    let lags = FeatureSpec::THERMAL_STATE
        .with_lags(&[100.0], LagOutputs::DiffFromT)
        .unwrap();
    // Same index twice, a model over the wrong feature count, another step period.
    assert_eq!(
        AxisCompensator::new(first(), 0)
            .with_sensor(0, FeatureSpec::PUBLISHED, None, None)
            .err(),
        Some(ModelError::Sensors)
    );
    assert!(matches!(
        AxisCompensator::new(first(), 0).with_sensor(1, lags, Some(part(1.0)), None),
        Err(ModelError::FeatureCount {
            expected: 3,
            got: 2
        })
    ));
    let slow = FeatureSpec {
        step_period_s: 2.0,
        ..FeatureSpec::PUBLISHED
    };
    assert_eq!(
        AxisCompensator::new(first(), 0)
            .with_sensor(1, slow, None, None)
            .err(),
        Some(ModelError::Sensors)
    );
    let mut axis = AxisCompensator::new(first(), 0);
    for i in 1..MAX_SENSORS {
        axis = axis
            .with_sensor(i, FeatureSpec::PUBLISHED, None, None)
            .unwrap();
    }
    assert_eq!(
        axis.with_sensor(MAX_SENSORS, FeatureSpec::PUBLISHED, None, None)
            .err(),
        Some(ModelError::Sensors)
    );
}

//! The flight compensator fed arbitrary sample sequences: time, gyro and temperature each
//! either plausible (small steps around a chamber test) or any bit pattern, on a trained
//! model (linear, polynomial, LSTM) or on a polynomial with arbitrary coefficients.
//!
//! Holds: no panic; every sample gets a status; a sample with a rate has a finite gyro, a
//! finite rate, a finite bias and a finite positive scale factor; one without is
//! `Status::Invalid` (documented: gyro not finite, or its corrected rate beyond f64).

#![no_main]

use std::sync::OnceLock;

use arbitrary::{Result, Unstructured};
use gyrotherm::compensate::compensator;
use gyrotherm::flight_size::FlightCompensator;
use gyrotherm::model::ModelFile;
use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::compensator::{Compensator, Status, TargetModel};
use gyrotherm_core::features::FeatureSpec;
use libfuzzer_sys::fuzz_target;

/// Samples per case at most.
const MAX_STEPS: usize = 4096;

const MODELS: [&str; 3] = [
    include_str!("../seeds/model_file/linear.json"),
    include_str!("../seeds/model_file/poly.json"),
    include_str!("../seeds/model_file/lstm.json"),
];

fn trained() -> &'static [FlightCompensator] {
    static C: OnceLock<Vec<FlightCompensator>> = OnceLock::new();
    C.get_or_init(|| {
        MODELS
            .iter()
            .map(|text| compensator(&ModelFile::from_json(text).unwrap()).unwrap())
            .collect()
    })
}

/// A polynomial in the published features (T, dT) with arbitrary finite coefficients.
fn arbitrary_target(u: &mut Unstructured, offset: f64) -> Result<TargetModel> {
    let n = FeatureSpec::PUBLISHED.n_features();
    let mut b = BaselineModel::new(n).unwrap();
    for _ in 0..u.int_in_range(0..=4)? {
        let powers: Vec<u8> = (0..n)
            .map(|_| u.int_in_range(0..=3))
            .collect::<Result<_>>()?;
        let _ = b.push_term(&powers, value(u, 1e-3)?);
    }
    Ok(TargetModel {
        offset,
        baseline: Some(b),
        lstm: None,
        lstm_reads_base: false,
    })
}

/// Either any bit pattern or `scale` times a small integer.
fn value(u: &mut Unstructured, scale: f64) -> Result<f64> {
    Ok(if u.ratio(1, 8)? {
        f64::from_bits(u.arbitrary()?)
    } else {
        f64::from(u.arbitrary::<i16>()?) * scale
    })
}

fn run(data: &[u8]) -> Result<()> {
    let mut u = Unstructured::new(data);
    let pick = u.int_in_range(0..=3)?;
    let mut comp = if pick < 3 {
        trained()[pick].clone()
    } else {
        let bias = arbitrary_target(&mut u, 0.0)?;
        let scale = arbitrary_target(&mut u, 1.0)?;
        match Compensator::new(FeatureSpec::PUBLISHED, bias, scale) {
            Ok(c) => FlightCompensator::H8(Box::new(c)),
            Err(_) => return Ok(()),
        }
    };
    let (mut t, mut temp) = (0.0f64, 25.0f64);
    for _ in 0..MAX_STEPS {
        if u.is_empty() {
            break;
        }
        let dt = value(&mut u, 0.01)?;
        t = if u.ratio(1, 16)? { dt } else { t + dt.abs() };
        let dtemp = value(&mut u, 0.01)?;
        temp = if u.ratio(1, 16)? { dtemp } else { temp + dtemp };
        let gyro = value(&mut u, 1e-3)?;
        if u.ratio(1, 64)? {
            comp.reset();
        }
        let c = comp.step(t, gyro, temp);
        match c.rate() {
            Some(rate) => {
                assert!(gyro.is_finite(), "a rate for gyro {gyro}: {c:?}");
                assert!(rate.is_finite(), "{c:?} at t={t} T={temp} gyro={gyro}");
                assert!(
                    c.bias_dps.is_finite(),
                    "{c:?} at t={t} T={temp} gyro={gyro}"
                );
                assert!(
                    c.scale.is_finite() && c.scale > 0.0,
                    "{c:?} at t={t} T={temp} gyro={gyro}"
                );
            }
            // `Status::Invalid`: no rate, for a gyro sample that is not finite or whose
            // corrected rate would overflow.
            None => assert_eq!(c.status, Status::Invalid),
        }
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(data);
});

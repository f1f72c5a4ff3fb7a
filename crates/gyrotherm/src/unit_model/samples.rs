//! A [`Model`] run over samples in memory, for a binding that holds arrays rather than files:
//! each axis's flight compensator stepped sample by sample, giving the numbers `compensate`
//! writes for the same samples, and per sample the coverage verdict and σ.

use super::{Form, Model};
use crate::compensate::unit::{compensate_imu, AxisCompensated};
use crate::compensate::{compensator, extrapolation_warnings, CompensateError};
use crate::csvlog::{ImuLog, ReadOptions, TestLog};
use crate::model::unit::ImuError;

/// Why samples could not be compensated.
#[derive(Debug)]
#[non_exhaustive]
pub enum SamplesError {
    /// A single-gyro model's flight compensator could not be built.
    Compensate(CompensateError),
    /// An inertial unit's model refused the samples or could not be built.
    Unit(ImuError),
}

impl std::fmt::Display for SamplesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SamplesError::Compensate(e) => e.fmt(f),
            SamplesError::Unit(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for SamplesError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        // Transparent: the cause's message is this error's own.
        match self {
            SamplesError::Compensate(e) => e.source(),
            SamplesError::Unit(e) => e.source(),
        }
    }
}

/// One axis's coverage verdict per sample: the code (`Coverage as u8`, [`NO_COVERAGE`] where
/// there is none) and σ, °/h (NaN where there is none).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AxisCoverage {
    pub codes: Vec<u8>,
    pub sigma_dph: Vec<f64>,
}

/// The code of "no verdict" in [`AxisCoverage::codes`].
pub const NO_COVERAGE: u8 = 255;

impl Model {
    /// The gyro and temperature columns a log must hold for this model, in its orders: a
    /// single-gyro file's own names, or the standard ones where it names none.
    pub fn columns(&self) -> (Vec<String>, Vec<String>) {
        let unit = self.to_unit(&ReadOptions::default());
        (unit.gyro_cols.clone(), unit.temp_cols.clone())
    }

    /// Compensate `log` (holding [`Model::columns`]) with each axis's flight compensator,
    /// sample by sample: per axis, in axis order, the numbers `compensate` writes; then the
    /// extrapolation warnings `compensate` tells (a single-gyro model's).
    pub fn compensate_log(
        &self,
        log: &ImuLog,
    ) -> Result<(Vec<AxisCompensated>, Vec<String>), SamplesError> {
        match &self.form {
            Form::Single(m) => {
                let one = one_axis(log);
                let mut comp = compensator(m).map_err(SamplesError::Compensate)?;
                let mut r = AxisCompensated::default();
                for i in 0..one.len() {
                    let c = comp.step(one.time_s[i], one.gyro_dps[i], one.temp_c[i]);
                    r.bias_dps.push(c.bias_dps);
                    r.scale.push(c.scale);
                    r.gyro_comp_dps.push(c.rate_dps);
                    r.status.push(c.status);
                }
                Ok((vec![r], extrapolation_warnings(m, &one)))
            }
            Form::Unit(m) => Ok((
                compensate_imu(m, log).map_err(SamplesError::Unit)?,
                Vec::new(),
            )),
        }
    }

    /// Per axis, whether each sample's temperature and rate lie inside, at the edge of or
    /// outside the region training covered, and σ there: the `coverage` and `sigma_dph`
    /// columns a single-gyro `compensate` writes (an axis that reads several sensors: on its
    /// first sensor's T and dT, as its flight compensator steps them). Then a note per axis
    /// without a verdict: a model file without a coverage map.
    pub fn coverage_log(
        &self,
        log: &ImuLog,
    ) -> Result<(Vec<AxisCoverage>, Vec<String>), SamplesError> {
        let unit = self.to_unit(&ReadOptions::default());
        let mut out = Vec::with_capacity(unit.axes.len());
        let mut notes = Vec::new();
        for a in &unit.axes {
            let none = || AxisCoverage {
                codes: vec![NO_COVERAGE; log.len()],
                sigma_dph: vec![f64::NAN; log.len()],
            };
            let Some(map) = a.model.coverage.as_ref().and_then(|m| m.to_core().ok()) else {
                if let Some(n) = crate::coverage::missing_note(&a.model) {
                    notes.push(match self.form {
                        Form::Single(_) => n,
                        Form::Unit(_) => format!("{}: {n}", a.gyro),
                    });
                }
                out.push(none());
                continue;
            };
            let axis = log.gyro.iter().position(|g| g.name == a.gyro);
            let temp = log.temp.iter().position(|t| t.name == a.temps[0]);
            let (Some(axis), Some(temp)) = (axis, temp) else {
                return Err(SamplesError::Unit(ImuError::MissingColumn {
                    column: if axis.is_none() { &a.gyro } else { &a.temps[0] }.clone(),
                    role: if axis.is_none() {
                        "gyro"
                    } else {
                        "temperature"
                    },
                }));
            };
            let mut comp = compensator(&a.model).map_err(SamplesError::Compensate)?;
            let mut cov = AxisCoverage::default();
            for i in 0..log.len() {
                comp.step(
                    log.time_s[i],
                    log.gyro[axis].values[i],
                    log.temp[temp].values[i],
                );
                match map.verdict_of(comp.features()) {
                    Some(v) => {
                        cov.codes.push(v.coverage as u8);
                        cov.sigma_dph.push(v.sigma_dph);
                    }
                    None => {
                        cov.codes.push(NO_COVERAGE);
                        cov.sigma_dph.push(f64::NAN);
                    }
                }
            }
            out.push(cov);
        }
        Ok((out, notes))
    }
}

/// The first gyro and temperature columns of `log` as a single-axis log.
fn one_axis(log: &ImuLog) -> TestLog {
    let column = |s: &[crate::csvlog::NamedSeries]| s.first().map(|c| c.values.clone());
    TestLog {
        time_s: log.time_s.clone(),
        gyro_dps: column(&log.gyro).unwrap_or_default(),
        temp_c: column(&log.temp).unwrap_or_default(),
        ..Default::default()
    }
}

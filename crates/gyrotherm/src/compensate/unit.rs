//! An inertial unit's log compensated axis by axis, each axis's flight compensator fed with
//! its gyro column and the model's temperature columns.

use gyrotherm_core::compensator::Status;

use crate::csvlog::ImuLog;
use crate::flight_size::FlightAxis;
use crate::model::unit::{ImuError, ImuModel};

/// The compensated series of one axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AxisCompensated {
    pub bias_dps: Vec<f64>,
    pub scale: Vec<f64>,
    pub gyro_comp_dps: Vec<f64>,
    pub status: Vec<Status>,
}

/// The flight compensators of every axis, in axis order, each reading its own sensors
/// among `temps[]` in the order of [`ImuModel::temp_cols`].
pub fn imu_axis_compensators(model: &ImuModel) -> Result<Vec<FlightAxis>, ImuError> {
    model
        .axes
        .iter()
        .map(|a| model.axis_compensator(a))
        .collect()
}

/// Compensate an inertial unit's log: each axis's flight compensator fed, sample by sample,
/// with its gyro column and the model's temperature columns. The log must hold the model's
/// gyro columns and the temperature columns its axes read (the error names the first one
/// missing); a column no axis reads is not looked for.
pub fn compensate_imu(model: &ImuModel, log: &ImuLog) -> Result<Vec<AxisCompensated>, ImuError> {
    let find = |list: &[crate::csvlog::NamedSeries], name: &str, role| {
        list.iter()
            .position(|s| s.name == name)
            .ok_or_else(|| ImuError::MissingColumn {
                column: name.to_owned(),
                role,
            })
    };
    let mut comps = imu_axis_compensators(model)?;
    let read = model.temps_read();
    let temps: Vec<Option<&[f64]>> = model
        .temp_cols
        .iter()
        .map(|t| {
            if !read.contains(&t.as_str()) {
                return Ok(None);
            }
            find(&log.temp, t, "temperature").map(|i| Some(log.temp[i].values.as_slice()))
        })
        .collect::<Result<_, _>>()?;
    let n = log.len();
    let mut out = Vec::with_capacity(model.axes.len());
    let mut row = vec![0.0; temps.len()];
    for (a, comp) in model.axes.iter().zip(&mut comps) {
        let g = &log.gyro[find(&log.gyro, &a.gyro, "gyro")?].values;
        let mut r = AxisCompensated {
            bias_dps: Vec::with_capacity(n),
            scale: Vec::with_capacity(n),
            gyro_comp_dps: Vec::with_capacity(n),
            status: Vec::with_capacity(n),
        };
        for i in 0..n {
            for (v, t) in row.iter_mut().zip(&temps) {
                *v = t.map_or(f64::NAN, |t| t[i]);
            }
            let c = comp.step(log.time_s[i], g[i], &row);
            r.bias_dps.push(c.bias_dps);
            r.scale.push(c.scale);
            r.gyro_comp_dps.push(c.rate_dps);
            r.status.push(c.status);
        }
        out.push(r);
    }
    Ok(out)
}

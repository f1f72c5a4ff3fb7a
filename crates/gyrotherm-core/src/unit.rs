//! An inertial unit in flight: one [`AxisCompensator`] per gyro axis, all fed by one call per
//! sample with the unit's time stamp, its gyro outputs and all its temperature sensors.
//!
//! Each axis reads its own temperature channel(s) ([`AxisCompensator::step`]: one sensor, as
//! [`Compensator::step_unit`], or several), so:
//! - a fault on one temperature sensor (NaN, out of range, too fast) is a temperature fault
//!   only for the axes that read it (as first or as further sensor); the others stay `ok`;
//! - a bad time stamp reaches every axis, and every axis's time axis (see
//!   [`crate::compensator`]) judges it alike: the same sample is placed, held or re-bases on
//!   all axes;
//! - a non-finite gyro sample makes only its own axis `invalid`.
//!
//! The capacity is a const generic (default [`MAX_AXES`], three gyros); the unit holds up to
//! that many axes, no heap. [`Unit::step`] is panic-free for every input: a gyro slice shorter
//! than the axis count gives NaN (`invalid`) for the missing axes, a temperature slice shorter
//! than a channel a fault (NaN) for the axes reading it.
//!
//! ```
//! use gyrotherm_core::compensator::{Status, TargetModel};
//! use gyrotherm_core::unit::Unit;
//! use gyrotherm_core::{Compensator, FeatureSpec};
//!
//! let axis = |channel| {
//!     Compensator::new(
//!         FeatureSpec::PUBLISHED,
//!         TargetModel::constant(1e-3),
//!         TargetModel::constant(1.0),
//!     )
//!     .unwrap()
//!     .with_channel(channel)
//! };
//! // Axis 0 reads sensor 1, axis 1 reads sensor 2; sensor 0 (the case) is read by neither.
//! let mut unit: Unit = Unit::new(3);
//! unit.push_axis(axis(1)).unwrap();
//! unit.push_axis(axis(2)).unwrap();
//! let out = unit.step(0.0, &[0.01, 0.02], &[20.0, 21.0, 22.0]);
//! assert_eq!(out[0].status, Status::Ok);
//! // Sensor 2 fails: only axis 1 is held.
//! let out = unit.step(1.0, &[0.01, 0.02], &[20.0, 21.0, f64::NAN]);
//! assert_eq!((out[0].status, out[1].status), (Status::Ok, Status::Held));
//! ```

use crate::compensator::{Compensator, Corrected, ModelError, Status, HIDDEN};
use crate::multi::AxisCompensator;
use crate::static_model::{StaticModel, StaticSensor};
use core::fmt;

/// Default capacity of a [`Unit`]: three gyro axes.
pub const MAX_AXES: usize = 3;

/// What a unit's slots beyond its axis count give: no rate.
const NO_AXIS: Corrected = Corrected {
    status: Status::Invalid,
    bias_dps: 0.0,
    scale: 1.0,
    rate_dps: 0.0,
};

/// Why a unit cannot be built.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum UnitError {
    /// More axes than the unit's capacity.
    TooManyAxes { capacity: usize },
    /// An axis reads a temperature channel the unit does not have.
    Channel {
        axis: usize,
        channel: usize,
        n_temps: usize,
    },
    /// The model lists differ in length (axes and their channels or further sensors).
    Layout { axes: usize, channels: usize },
    /// An axis's model cannot be built.
    Model { axis: usize, source: ModelError },
}

impl fmt::Display for UnitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            UnitError::TooManyAxes { capacity } => {
                write!(f, "more than {capacity} axes for this unit")
            }
            UnitError::Channel {
                axis,
                channel,
                n_temps,
            } => write!(
                f,
                "axis {axis} reads temperature channel {channel}, but the unit has {n_temps}"
            ),
            UnitError::Layout { axes, channels } => {
                write!(f, "{axes} axis models but {channels} channels")
            }
            UnitError::Model { axis, .. } => write!(f, "the model of axis {axis}"),
        }
    }
}

impl core::error::Error for UnitError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            UnitError::Model { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// An inertial unit's compensators (see the module doc).
#[derive(Debug, Clone)]
pub struct Unit<const N: usize = MAX_AXES, const H: usize = HIDDEN> {
    axes: [Option<AxisCompensator<H>>; N],
    n_axes: usize,
    n_temps: usize,
}

impl<const N: usize, const H: usize> Unit<N, H> {
    /// An empty unit whose samples carry `n_temps` temperature channels.
    pub fn new(n_temps: usize) -> Self {
        Unit {
            axes: [const { None }; N],
            n_axes: 0,
            n_temps,
        }
    }

    /// Add the next axis (gyro index = the number of axes so far): a [`Compensator`] (one
    /// sensor, its [`Compensator::channel`]) or an [`AxisCompensator`]; every sensor it reads
    /// must be below the unit's channel count.
    pub fn push_axis(&mut self, axis: impl Into<AxisCompensator<H>>) -> Result<(), UnitError> {
        let axis = axis.into();
        if let Some(channel) = axis.sensors().find(|&c| c >= self.n_temps) {
            return Err(UnitError::Channel {
                axis: self.n_axes,
                channel,
                n_temps: self.n_temps,
            });
        }
        let slot = self
            .axes
            .get_mut(self.n_axes)
            .ok_or(UnitError::TooManyAxes { capacity: N })?;
        *slot = Some(axis);
        self.n_axes += 1;
        Ok(())
    }

    /// The unit of exported static models (`gyrotherm export --target rust` of a unit model
    /// whose axes read one sensor each): axis `i` runs `models[i]` on temperature channel
    /// `channels[i]` of `n_temps`.
    pub fn from_static(
        models: &[StaticModel<H>],
        channels: &[u8],
        n_temps: usize,
    ) -> Result<Self, UnitError> {
        Self::from_static_sensors(models, channels, &[], n_temps)
    }

    /// [`Unit::from_static`] with further sensors: axis `i` also reads `sensors[i]` (each
    /// further sensor's channel, features and parts; an axis beyond `sensors` reads none).
    pub fn from_static_sensors(
        models: &[StaticModel<H>],
        channels: &[u8],
        sensors: &[&[StaticSensor]],
        n_temps: usize,
    ) -> Result<Self, UnitError> {
        Self::from_static_fallbacks(models, channels, sensors, &[], n_temps)
    }

    /// [`Unit::from_static_sensors`] with fallbacks: axis `i` also carries `fallbacks[i]`
    /// (when `Some`), the model on its first sensor alone that it runs on while a further
    /// sensor is given up on ([`AxisCompensator::with_fallback`]; an axis beyond `fallbacks`
    /// has none).
    pub fn from_static_fallbacks(
        models: &[StaticModel<H>],
        channels: &[u8],
        sensors: &[&[StaticSensor]],
        fallbacks: &[Option<StaticModel<H>>],
        n_temps: usize,
    ) -> Result<Self, UnitError> {
        if models.len() != channels.len()
            || sensors.len() > models.len()
            || fallbacks.len() > models.len()
        {
            return Err(UnitError::Layout {
                axes: models.len(),
                channels: channels.len().max(sensors.len()).max(fallbacks.len()),
            });
        }
        let mut unit = Unit::new(n_temps);
        for (axis, (m, ch)) in models.iter().zip(channels).enumerate() {
            let c =
                Compensator::from_static(m).map_err(|source| UnitError::Model { axis, source })?;
            let mut a = AxisCompensator::new(c, usize::from(*ch));
            for s in sensors.get(axis).copied().unwrap_or(&[]) {
                let part = |b: &Option<crate::static_model::StaticBaseline>| {
                    b.as_ref().map(|b| b.to_model()).transpose()
                };
                a = part(&s.bias)
                    .and_then(|bias| {
                        a.with_sensor(usize::from(s.channel), s.spec, bias, part(&s.scale)?)
                    })
                    .map_err(|source| UnitError::Model { axis, source })?;
            }
            if let Some(f) = fallbacks.get(axis).and_then(Option::as_ref) {
                let f = Compensator::from_static(f)
                    .map_err(|source| UnitError::Model { axis, source })?;
                a = a.with_fallback(f);
            }
            unit.push_axis(a)?;
        }
        Ok(unit)
    }

    /// Number of axes.
    pub fn n_axes(&self) -> usize {
        self.n_axes
    }

    /// Number of temperature channels a sample carries.
    pub fn n_temps(&self) -> usize {
        self.n_temps
    }

    /// Axis `i`'s compensator (its first sensor's features, its sensors).
    pub fn axis(&self, i: usize) -> Option<&AxisCompensator<H>> {
        self.axes.get(i).and_then(Option::as_ref)
    }

    /// One sample of the unit: time (s), the gyro outputs (°/s, axis order) and every
    /// temperature channel (°C). Entry `i` of the result is axis `i`'s; entries from
    /// [`Unit::n_axes`] on are `invalid` with no rate. Never fails (see the module doc).
    pub fn step(&mut self, time_s: f64, gyro_dps: &[f64], temps_c: &[f64]) -> [Corrected; N] {
        let mut out = [NO_AXIS; N];
        for (i, (slot, axis)) in out.iter_mut().zip(self.axes.iter_mut()).enumerate() {
            if let Some(c) = axis {
                let g = gyro_dps.get(i).copied().unwrap_or(f64::NAN);
                *slot = c.step(time_s, g, temps_c);
            }
        }
        out
    }

    /// Start over on every axis (see [`AxisCompensator::reset`]).
    pub fn reset(&mut self) {
        for c in self.axes.iter_mut().flatten() {
            c.reset();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensator::TargetModel;
    use crate::features::FeatureSpec;

    fn axis(channel: usize) -> Compensator {
        Compensator::new(
            FeatureSpec::PUBLISHED,
            TargetModel::constant(1e-3),
            TargetModel::constant(1.0),
        )
        .unwrap()
        .with_channel(channel)
    }

    #[test]
    fn each_axis_equals_its_own_compensator_on_its_channel() {
        let mut unit: Unit = Unit::new(4);
        let mut alone = [axis(1), axis(3), axis(1)];
        for a in &alone {
            unit.push_axis(a.clone()).unwrap();
        }
        for i in 0..300 {
            let x = f64::from(i);
            // Faults: sensor 3 NaN for a while, a NaN time, a backward time, a NaN gyro.
            let t = match i {
                100 => f64::NAN,
                150 => x - 40.0,
                _ => x,
            };
            let s3 = if (50..80).contains(&i) {
                f64::NAN
            } else {
                25.0
            };
            let temps = [20.0, 21.0 + 0.01 * x, 22.0, s3];
            let gyro = [0.01, if i == 7 { f64::NAN } else { 0.02 }, 0.03];
            let out = unit.step(t, &gyro, &temps);
            for k in 0..3 {
                let want = alone[k].step(t, gyro[k], temps[alone[k].channel()]);
                assert_eq!(out[k], want, "sample {i} axis {k}");
            }
            if (50..80).contains(&i) {
                assert_eq!(out[0].status, Status::Ok);
                assert_ne!(out[1].status, Status::Ok);
            }
        }
    }

    /// An axis on sensor `first` reading `more` further sensors, each a part of B linear in
    /// its `T` (coefficient 1e-5 per sensor index, an independent choice) and one lag.
    fn multi_axis(first: usize, more: &[usize]) -> AxisCompensator {
        let mut a = AxisCompensator::new(axis(first), first);
        for &j in more {
            let spec = FeatureSpec::PUBLISHED
                .with_lags(&[50.0], crate::features::LagOutputs::DiffFromT)
                .unwrap();
            let mut b = crate::baseline::BaselineModel::new(spec.n_features()).unwrap();
            let mut p = [0u8; crate::features::MAX_FEATURES];
            p[0] = 1;
            b.push_term(&p[..spec.n_features()], 1e-5 * (j as f64 + 1.0))
                .unwrap();
            a = a.with_sensor(j, spec, Some(b), None).unwrap();
        }
        a
    }

    #[test]
    fn multi_sensor_axes_equal_their_own_axis_compensators() {
        let mut unit: Unit = Unit::new(4);
        let mut alone = [
            multi_axis(1, &[0, 3]),
            multi_axis(2, &[]),
            multi_axis(3, &[2, 1, 0]),
        ];
        for a in &alone {
            unit.push_axis(a.clone()).unwrap();
        }
        let (mut held0, mut held1) = (0, 0);
        for i in 0..300 {
            let x = f64::from(i);
            let t = if i == 100 { f64::NAN } else { x };
            // Sensor 0 (read by axes 0 and 2 as a further sensor) fails for a while.
            let s0 = if (50..80).contains(&i) {
                f64::NAN
            } else {
                20.0
            };
            let temps = [s0, 21.0 + 0.01 * x, 22.0, 25.0];
            let gyro = [0.01, 0.02, 0.03];
            let out = unit.step(t, &gyro, &temps);
            for k in 0..3 {
                assert_eq!(
                    out[k],
                    alone[k].step(t, gyro[k], &temps),
                    "sample {i} axis {k}"
                );
            }
            if (50..80).contains(&i) {
                held0 += usize::from(out[0].status != Status::Ok);
                held1 += usize::from(out[1].status != Status::Ok);
            }
        }
        // The fault reaches the axes that read sensor 0 only.
        assert_eq!((held0, held1), (30, 0));
    }

    /// A further sensor dies for good: the axis holds for `degraded_after_s` (60 s), then
    /// gives its fallback's output (a compensator on the first sensor alone, stepped beside
    /// it here) with status fallback, its held status while the first sensor glitches, and its
    /// own output again once the further sensor is back. Without a fallback it stays degraded.
    #[test]
    fn a_further_sensor_dead_for_good_runs_the_axis_on_its_fallback() {
        let fallback = || {
            Compensator::new(
                FeatureSpec::PUBLISHED,
                TargetModel::constant(2e-3),
                TargetModel::constant(1.01),
            )
            .unwrap()
        };
        let mut with = multi_axis(1, &[3]).with_fallback(fallback());
        let mut without = multi_axis(1, &[3]);
        let mut alone = fallback().with_channel(1);
        let mut counts = [0usize; 5];
        for i in 0..600 {
            let x = f64::from(i);
            // Sensor 3 is lost from 100 s to 400 s; sensor 1 glitches at 250 s.
            let s3 = if (100..400).contains(&i) {
                f64::NAN
            } else {
                25.0
            };
            let s1 = if i == 250 { f64::NAN } else { 21.0 + 0.01 * x };
            let temps = [20.0, s1, 22.0, s3];
            let got = with.step(x, 0.01, &temps);
            let old = without.step(x, 0.01, &temps);
            let fb = alone.step(x, 0.01, s1);
            counts[got.status as usize] += 1;
            match i {
                // Sensor 3 lost: held for 60 s, then the fallback (held at the glitch).
                100..=159 => assert_eq!((got, old.status), (old, Status::Held), "{i}"),
                160..=399 => {
                    assert_eq!(old.status, Status::Degraded, "{i}");
                    let want = if i == 250 {
                        Status::Held
                    } else {
                        Status::Fallback
                    };
                    assert_eq!(got, Corrected { status: want, ..fb }, "{i}");
                    assert!(with.on_fallback());
                }
                // Back on all sensors as soon as sensor 3 is believed again.
                _ => assert_eq!(got, old, "{i}"),
            }
        }
        assert_eq!(counts[Status::Fallback as usize], 239);
        // Reset starts over on all sensors.
        with.reset();
        assert!(!with.on_fallback());
    }

    #[test]
    fn one_sensor_axis_is_step_unit() {
        let mut a = AxisCompensator::from(axis(2));
        let mut c = axis(2);
        for i in 0..200 {
            let x = f64::from(i);
            let temps = [f64::NAN, 20.0, 21.0 + 0.02 * x];
            let t = if i == 40 { x - 10.0 } else { x };
            assert_eq!(
                a.step(t, 0.01, &temps),
                c.step_unit(t, 0.01, &temps),
                "sample {i}"
            );
        }
    }

    #[test]
    fn refuses_what_it_cannot_hold_and_never_panics_on_short_inputs() {
        let mut unit: Unit<2> = Unit::new(2);
        assert_eq!(
            unit.push_axis(axis(2)),
            Err(UnitError::Channel {
                axis: 0,
                channel: 2,
                n_temps: 2
            })
        );
        unit.push_axis(axis(0)).unwrap();
        unit.push_axis(axis(1)).unwrap();
        assert_eq!(
            unit.push_axis(axis(0)),
            Err(UnitError::TooManyAxes { capacity: 2 })
        );
        // A further sensor beyond the unit's channels is refused too.
        let mut small: Unit<2> = Unit::new(2);
        assert_eq!(
            small.push_axis(multi_axis(0, &[3])),
            Err(UnitError::Channel {
                axis: 0,
                channel: 3,
                n_temps: 2
            })
        );
        let out = unit.step(0.0, &[0.01], &[20.0]);
        assert_eq!(out[0].status, Status::Ok);
        // No gyro for axis 1: invalid; its channel is missing: not ok either way.
        assert_eq!(out[1].status, Status::Invalid);
        let out = unit.step(1.0, &[0.01, 0.02], &[20.0]);
        assert_eq!(out[1].status, Status::Degraded);
    }
}

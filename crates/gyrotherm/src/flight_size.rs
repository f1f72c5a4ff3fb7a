//! The flight LSTM's hidden size, chosen at run time from the model file.
//!
//! Flight code fixes the size at compile time (`Compensator<H>`, 8 by default); the ground
//! reads it from the model and holds one of the supported sizes
//! ([`HIDDEN_SIZES`]) in an enum, boxed: a 64-unit compensator holds two networks of some
//! 80 KB each, and each size is built in a function of its own (`build_sized!`) so that
//! no stack frame holds the largest size's value for a smaller model.
//!
//! A model file, or a unit file with all its axes and fallbacks, runs at one size: the
//! largest LSTM it holds. A smaller LSTM beside it (say an 8-unit scale-factor network next to
//! a 32-unit bias network) is widened with hidden units whose weights are all zero: their
//! state stays 0 and their read-out weight is 0, so every gate sum of the real units adds
//! exact zeros and the output is the same bits.

use gyrotherm_core::compensator::{Compensator, Corrected, TempLimits, HIDDEN_SIZES};
use gyrotherm_core::features::{FeatureSpec, Features};
use gyrotherm_core::multi::AxisCompensator;
use gyrotherm_core::unit::UnitError;

/// Most gyro axes a unit model can have: the capacity of the ground stream's unit, which
/// `compensate` runs, checked at `train` and at load (flight code fixes its own capacity,
/// three by default: [`gyrotherm_core::unit::MAX_AXES`]).
pub const MAX_STREAM_AXES: usize = 16;

/// A hidden size the flight types are built for (see [`HIDDEN_SIZES`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum HiddenSize {
    /// 8 units, as published.
    #[default]
    H8,
    /// 16 units.
    H16,
    /// 32 units.
    H32,
    /// 64 units.
    H64,
}

impl HiddenSize {
    /// The size of `units` hidden units, `None` when flight code is not built for it.
    pub(crate) fn of_units(units: usize) -> Option<Self> {
        match units {
            8 => Some(HiddenSize::H8),
            16 => Some(HiddenSize::H16),
            32 => Some(HiddenSize::H32),
            64 => Some(HiddenSize::H64),
            _ => None,
        }
    }

    /// Number of hidden units.
    pub fn units(self) -> usize {
        match self {
            HiddenSize::H8 => 8,
            HiddenSize::H16 => 16,
            HiddenSize::H32 => 32,
            HiddenSize::H64 => 64,
        }
    }
}

// The enum and the core's list name the same sizes.
const _: () = assert!(
    HIDDEN_SIZES[0] == 8 && HIDDEN_SIZES[1] == 16 && HIDDEN_SIZES[2] == 32 && HIDDEN_SIZES[3] == 64
);

/// Evaluate `$body` with the const `$h` set to `$size`'s number of units.
macro_rules! with_hidden {
    ($size:expr, $h:ident => $body:expr) => {
        match $size {
            $crate::flight_size::HiddenSize::H8 => {
                const $h: usize = 8;
                $body
            }
            $crate::flight_size::HiddenSize::H16 => {
                const $h: usize = 16;
                $body
            }
            $crate::flight_size::HiddenSize::H32 => {
                const $h: usize = 32;
                $body
            }
            $crate::flight_size::HiddenSize::H64 => {
                const $h: usize = 64;
                $body
            }
        }
    };
}

/// The variant of `$ty` (an enum over the sizes) for `$size`, holding `$body` (a box)
/// evaluated with the const `$h` set to the size.
macro_rules! build_sized {
    ($ty:ident, $size:expr, $h:ident => $body:expr) => {{
        match $size {
            $crate::flight_size::HiddenSize::H8 => {
                const $h: usize = 8;
                $ty::H8($body)
            }
            $crate::flight_size::HiddenSize::H16 => {
                const $h: usize = 16;
                $ty::H16($body)
            }
            $crate::flight_size::HiddenSize::H32 => {
                const $h: usize = 32;
                $ty::H32($body)
            }
            $crate::flight_size::HiddenSize::H64 => {
                const $h: usize = 64;
                $ty::H64($body)
            }
        }
    }};
}

// Used by path (`crate::flight_size::build_sized`), not exported from the crate.
pub(crate) use build_sized;
pub(crate) use with_hidden;

/// Apply `$body` to the compensator held by any variant of `$e`.
macro_rules! each {
    ($ty:ident, $e:expr, $c:ident => $body:expr) => {
        match $e {
            $ty::H8($c) => $body,
            $ty::H16($c) => $body,
            $ty::H32($c) => $body,
            $ty::H64($c) => $body,
        }
    };
}

/// A single-gyro flight compensator of the model's LSTM size.
#[derive(Debug, Clone)]
pub enum FlightCompensator {
    /// 8 hidden units (also a model without an LSTM).
    H8(Box<Compensator<8>>),
    /// 16 hidden units.
    H16(Box<Compensator<16>>),
    /// 32 hidden units.
    H32(Box<Compensator<32>>),
    /// 64 hidden units.
    H64(Box<Compensator<64>>),
}

impl FlightCompensator {
    /// The LSTM size it runs.
    pub fn hidden(&self) -> HiddenSize {
        match self {
            FlightCompensator::H8(_) => HiddenSize::H8,
            FlightCompensator::H16(_) => HiddenSize::H16,
            FlightCompensator::H32(_) => HiddenSize::H32,
            FlightCompensator::H64(_) => HiddenSize::H64,
        }
    }

    /// [`Compensator::step`].
    pub fn step(&mut self, time_s: f64, gyro_dps: f64, temp_c: f64) -> Corrected {
        each!(FlightCompensator, self, c => c.step(time_s, gyro_dps, temp_c))
    }

    /// [`Compensator::step_unit`].
    pub fn step_unit(&mut self, time_s: f64, gyro_dps: f64, temps: &[f64]) -> Corrected {
        each!(FlightCompensator, self, c => c.step_unit(time_s, gyro_dps, temps))
    }

    /// [`Compensator::features`].
    pub fn features(&self) -> Option<&Features> {
        each!(FlightCompensator, self, c => c.features())
    }

    /// [`Compensator::spec`].
    pub fn spec(&self) -> &FeatureSpec {
        each!(FlightCompensator, self, c => c.spec())
    }

    /// [`Compensator::limits`].
    pub fn limits(&self) -> &TempLimits {
        each!(FlightCompensator, self, c => c.limits())
    }

    /// [`Compensator::channel`].
    pub fn channel(&self) -> usize {
        each!(FlightCompensator, self, c => c.channel())
    }

    /// [`Compensator::reset`].
    pub fn reset(&mut self) {
        each!(FlightCompensator, self, c => c.reset())
    }
}

/// One compensator of an axis (its first sensor's, or its fallback): its feature
/// definition, limits, channel and latest features.
#[derive(Debug, Clone, Copy)]
pub struct SensorView<'a> {
    spec: &'a FeatureSpec,
    limits: &'a TempLimits,
    channel: usize,
    features: Option<&'a Features>,
}

impl<'a> SensorView<'a> {
    fn of<const H: usize>(c: &'a Compensator<H>) -> Self {
        SensorView {
            spec: c.spec(),
            limits: c.limits(),
            channel: c.channel(),
            features: c.features(),
        }
    }

    /// The features of the latest step ([`Compensator::features`]).
    pub fn features(&self) -> Option<&'a Features> {
        self.features
    }

    /// The first sensor's features.
    pub fn spec(&self) -> &'a FeatureSpec {
        self.spec
    }

    /// The temperature-sensor limits.
    pub fn limits(&self) -> &'a TempLimits {
        self.limits
    }

    /// The first sensor's index among the unit's temperatures.
    pub fn channel(&self) -> usize {
        self.channel
    }
}

/// A unit axis's flight compensator of the unit's LSTM size.
#[derive(Debug, Clone)]
pub enum FlightAxis {
    /// 8 hidden units (also an axis without an LSTM).
    H8(Box<AxisCompensator<8>>),
    /// 16 hidden units.
    H16(Box<AxisCompensator<16>>),
    /// 32 hidden units.
    H32(Box<AxisCompensator<32>>),
    /// 64 hidden units.
    H64(Box<AxisCompensator<64>>),
}

/// A further sensor as [`AxisCompensator::further`] gives it.
pub(crate) type FurtherSensor<'a> = (
    usize,
    &'a FeatureSpec,
    Option<&'a gyrotherm_core::baseline::BaselineModel>,
    Option<&'a gyrotherm_core::baseline::BaselineModel>,
);

impl FlightAxis {
    /// The LSTM size it runs.
    pub fn hidden(&self) -> HiddenSize {
        match self {
            FlightAxis::H8(_) => HiddenSize::H8,
            FlightAxis::H16(_) => HiddenSize::H16,
            FlightAxis::H32(_) => HiddenSize::H32,
            FlightAxis::H64(_) => HiddenSize::H64,
        }
    }

    /// [`AxisCompensator::step`].
    pub fn step(&mut self, time_s: f64, gyro_dps: f64, temps: &[f64]) -> Corrected {
        each!(FlightAxis, self, c => c.step(time_s, gyro_dps, temps))
    }

    /// The first sensor (as [`AxisCompensator::first`]).
    pub fn first(&self) -> SensorView<'_> {
        each!(FlightAxis, self, c => SensorView::of(c.first()))
    }

    /// [`AxisCompensator::features`].
    pub fn features(&self) -> Option<&Features> {
        each!(FlightAxis, self, c => c.features())
    }

    /// [`AxisCompensator::further`].
    pub fn further(&self) -> Vec<FurtherSensor<'_>> {
        each!(FlightAxis, self, c => c.further().collect())
    }

    /// [`AxisCompensator::sensors`].
    pub fn sensors(&self) -> Vec<usize> {
        each!(FlightAxis, self, c => c.sensors().collect())
    }

    /// The fallback's compensator ([`AxisCompensator::fallback`]).
    pub fn fallback(&self) -> Option<SensorView<'_>> {
        each!(FlightAxis, self, c => c.fallback().map(SensorView::of))
    }

    /// [`AxisCompensator::on_fallback`].
    pub fn on_fallback(&self) -> bool {
        each!(FlightAxis, self, c => c.on_fallback())
    }

    /// [`AxisCompensator::reset`].
    pub fn reset(&mut self) {
        each!(FlightAxis, self, c => c.reset())
    }
}

/// What a stream unit's slots beyond its axis count give: no rate (as the core's unit).
const NO_AXIS: Corrected = Corrected {
    status: gyrotherm_core::compensator::Status::Invalid,
    bias_dps: 0.0,
    scale: 1.0,
    rate_dps: 0.0,
};

/// The ground stream's unit: the core unit's step ([`Unit`](gyrotherm_core::unit::Unit)) (axis `i` steps on gyro `i` and every
/// temperature), with room for [`MAX_STREAM_AXES`] axes of the unit's one LSTM size, each
/// axis boxed (a core unit of 16 axes of 64 units would be some 5 MB in one value).
#[derive(Debug, Clone)]
pub struct StreamUnit {
    axes: Vec<FlightAxis>,
    n_temps: usize,
}

impl StreamUnit {
    /// A unit of `axes` (all of one size) on `n_temps` temperature channels, refused as
    /// [`Unit::push_axis`](gyrotherm_core::unit::Unit::push_axis) refuses an axis. The error names the axis (0-based) that does not
    /// fit.
    pub(crate) fn of_axes(
        n_temps: usize,
        axes: Vec<FlightAxis>,
    ) -> Result<Self, (usize, UnitError)> {
        let size = axes.first().map(FlightAxis::hidden);
        for (i, a) in axes.iter().enumerate() {
            if i >= MAX_STREAM_AXES {
                let capacity = MAX_STREAM_AXES;
                return Err((i, UnitError::TooManyAxes { capacity }));
            }
            if let Some(channel) = a.sensors().into_iter().find(|&c| c >= n_temps) {
                let e = UnitError::Channel {
                    axis: i,
                    channel,
                    n_temps,
                };
                return Err((i, e));
            }
            // Unreachable: the ground builds a unit's axes at the unit's one size.
            if Some(a.hidden()) != size {
                let e = UnitError::Layout {
                    axes: axes.len(),
                    channels: i,
                };
                return Err((i, e));
            }
        }
        Ok(StreamUnit { axes, n_temps })
    }

    /// [`Unit::step`](gyrotherm_core::unit::Unit::step).
    pub fn step(
        &mut self,
        time_s: f64,
        gyro_dps: &[f64],
        temps_c: &[f64],
    ) -> [Corrected; MAX_STREAM_AXES] {
        let mut out = [NO_AXIS; MAX_STREAM_AXES];
        for (i, (slot, axis)) in out.iter_mut().zip(self.axes.iter_mut()).enumerate() {
            let g = gyro_dps.get(i).copied().unwrap_or(f64::NAN);
            *slot = axis.step(time_s, g, temps_c);
        }
        out
    }

    /// Axis `i`.
    pub fn axis(&self, i: usize) -> Option<&FlightAxis> {
        self.axes.get(i)
    }

    /// [`Unit::n_axes`](gyrotherm_core::unit::Unit::n_axes).
    pub fn n_axes(&self) -> usize {
        self.axes.len()
    }

    /// [`Unit::n_temps`](gyrotherm_core::unit::Unit::n_temps).
    pub fn n_temps(&self) -> usize {
        self.n_temps
    }

    /// [`Unit::reset`](gyrotherm_core::unit::Unit::reset).
    pub fn reset(&mut self) {
        self.axes.iter_mut().for_each(FlightAxis::reset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setting_rule::Rule;

    #[test]
    fn the_sizes_are_the_cores_and_the_settings_rule_takes_them_alone() {
        for h in HIDDEN_SIZES {
            assert_eq!(HiddenSize::of_units(h).map(HiddenSize::units), Some(h));
            assert!(Rule::HiddenUnits.holds(h as f64));
        }
        for h in [0usize, 1, 4, 12, 24, 48, 128] {
            assert_eq!(HiddenSize::of_units(h), None);
            assert!(!Rule::HiddenUnits.holds(h as f64));
        }
    }
}

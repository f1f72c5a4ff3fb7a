//! An axis that reads several temperature sensors: one gyro of an inertial unit whose bias and
//! scale factor follow its coil and the housing, seen by a sensor beside the coil and one on
//! the case (their difference is the radial gradient a single sensor cannot see).
//!
//! [`AxisCompensator`] is stepped with all of the unit's sensor readings, `temps`, and reads
//! its own indices among them: its first sensor through an ordinary [`Compensator`] (the time
//! axis, the fault handling, the bias and scale-factor models over that sensor's features,
//! unchanged), and up to [`MAX_SENSORS`]` − 1` further sensors, each with its own feature
//! pipeline (its own lags) and its own part of B and K, a [`BaselineModel`] over that
//! sensor's features without a constant:
//!
//! `B = bias(f_0) + Σ_s bias_s(f_s)`, `K = scale(f_0) + Σ_s scale_s(f_s)`,
//!
//! the first sensor's model first, then each further sensor's in the order they were added.
//! Differences between sensors (gradients) are linear combinations of these terms.
//!
//! Faults: a sample is used only when every sensor the axis reads is believed (each judged as
//! [`Compensator`] judges its one sensor, against its own latest accepted reading); otherwise
//! the axis holds, as with a rejected temperature. A reading the axis does not read changes
//! nothing. A missing index (`temps` shorter than the axis expects) is a fault of that sensor.
//!
//! Fallback: an axis may also carry a fallback model on its first sensor alone
//! ([`AxisCompensator::with_fallback`]), a [`Compensator`] stepped alongside on every sample
//! (so its lags, rate window and LSTM states are warm when it is needed). When the axis on
//! all its sensors is [`Status::Degraded`] (a further sensor not believed for longer than
//! [`TempLimits::degraded_after_s`], the same clock that makes any axis degraded) while the
//! fallback alone is not, the axis gives the fallback's output, with status
//! [`Status::Fallback`] where the fallback's is ok (its held or invalid status otherwise). It
//! goes back to all its sensors as soon as they give a sample that is not degraded again.
//! Which one is used is decided on samples where neither output is invalid (an invalid
//! sample keeps the latest choice: an invalid status hides whether the temperatures were
//! believed).
//!
//! No allocation, fixed sizes, no panics on any input.

use crate::baseline::BaselineModel;
use crate::compensator::{
    plausible_reading, Compensator, Corrected, ModelError, MoreSensors, Status, TempLimits, HIDDEN,
};
use crate::features::{FeaturePipeline, FeatureSpec};

// Defined beside the model error that states the bound; the axis is its one user.
pub use crate::compensator::MAX_SENSORS;

/// A further sensor of an axis: its pipeline and its parts of B and K.
#[derive(Debug, Clone)]
struct SensorPart {
    index: usize,
    pipeline: FeaturePipeline,
    bias: Option<BaselineModel>,
    scale: Option<BaselineModel>,
    last_good: Option<(f64, f64)>,
}

/// The further sensors of an axis, in the order they were added.
#[derive(Debug, Clone)]
struct MoreParts {
    parts: [Option<SensorPart>; MAX_SENSORS - 1],
}

fn reading(temps: &[f64], index: usize) -> f64 {
    temps.get(index).copied().unwrap_or(f64::NAN)
}

impl MoreSensors for MoreParts {
    fn plausible(&self, limits: &TempLimits, time_s: f64, temps: &[f64]) -> bool {
        let mut ok = true;
        for p in self.parts.iter().flatten() {
            ok = ok && plausible_reading(limits, p.last_good, time_s, reading(temps, p.index));
        }
        ok
    }

    fn push(&mut self, time_s: f64, temps: &[f64]) -> bool {
        let mut ok = true;
        for p in self.parts.iter_mut().flatten() {
            let t = reading(temps, p.index);
            ok = p.pipeline.push(time_s, t).is_ok() && ok;
        }
        ok
    }

    fn accepted(&mut self, time_s: f64, temps: &[f64]) {
        for p in self.parts.iter_mut().flatten() {
            p.last_good = Some((time_s, reading(temps, p.index)));
        }
    }

    fn add(&mut self, bias_dps: &mut f64, scale: &mut f64) -> bool {
        for p in self.parts.iter().flatten() {
            let Some(f) = p.pipeline.current() else {
                return false;
            };
            if let Some(m) = &p.bias {
                match m.eval_features(f) {
                    Ok(v) => *bias_dps += v,
                    Err(_) => return false,
                }
            }
            if let Some(m) = &p.scale {
                match m.eval_features(f) {
                    Ok(v) => *scale += v,
                    Err(_) => return false,
                }
            }
        }
        true
    }

    fn rebase(&mut self) {
        for p in self.parts.iter_mut().flatten() {
            p.pipeline.reset();
            p.last_good = None;
        }
    }
}

/// One gyro axis reading one or more of the unit's temperature sensors (see the module doc).
#[derive(Debug, Clone)]
pub struct AxisCompensator<const H: usize = HIDDEN> {
    /// The first sensor's compensator; its [`Compensator::channel`] is the first sensor's
    /// index among `temps`.
    first: Compensator<H>,
    more: MoreParts,
    /// The fallback on the first sensor alone (see the module doc), stepped alongside.
    fallback: Option<Compensator<H>>,
    /// Whether the latest sample that decided it ran on the fallback.
    on_fallback: bool,
}

impl<const H: usize> From<Compensator<H>> for AxisCompensator<H> {
    /// A one-sensor axis reading `temps[c.channel()]`: it steps exactly as
    /// [`Compensator::step_unit`].
    fn from(c: Compensator<H>) -> Self {
        let channel = c.channel();
        AxisCompensator::new(c, channel)
    }
}

impl<const H: usize> AxisCompensator<H> {
    /// An axis whose first (or only) sensor is `temps[first_index]`, with that sensor's
    /// compensator.
    pub fn new(first: Compensator<H>, first_index: usize) -> Self {
        AxisCompensator {
            first: first.with_channel(first_index),
            more: MoreParts {
                parts: core::array::from_fn(|_| None),
            },
            fallback: None,
            on_fallback: false,
        }
    }

    /// Add a further sensor, `temps[index]`, read through `spec` (the same step period and
    /// rate lag as the first sensor's; its own lags), with its parts of B and K (each over
    /// `spec`'s features, no constant needed). Refused: more than [`MAX_SENSORS`] sensors,
    /// a sensor already read, a spec or model that does not fit.
    pub fn with_sensor(
        mut self,
        index: usize,
        spec: FeatureSpec,
        bias: Option<BaselineModel>,
        scale: Option<BaselineModel>,
    ) -> Result<Self, ModelError> {
        let pipeline = FeaturePipeline::new(spec).map_err(ModelError::Spec)?;
        let first = self.first.spec();
        if spec.step_period_s != first.step_period_s || spec.rate_lag_s != first.rate_lag_s {
            return Err(ModelError::Sensors);
        }
        let n = spec.n_features();
        for m in bias.iter().chain(scale.iter()) {
            if m.n_features() != n {
                return Err(ModelError::FeatureCount {
                    expected: n,
                    got: m.n_features(),
                });
            }
        }
        if index == self.first.channel() || self.sensors().any(|i| i == index) {
            return Err(ModelError::Sensors);
        }
        let Some(slot) = self.more.parts.iter_mut().find(|p| p.is_none()) else {
            return Err(ModelError::Sensors);
        };
        *slot = Some(SensorPart {
            index,
            pipeline,
            bias,
            scale,
            last_good: None,
        });
        Ok(self)
    }

    /// The same axis with a fallback: `fallback`, a compensator whose models read the first
    /// sensor's features alone, run on the first sensor (whatever its own channel) alongside
    /// the axis and used while the axis on all its sensors is degraded and the fallback is
    /// not (see the module doc). A later call replaces an earlier fallback.
    pub fn with_fallback(mut self, fallback: Compensator<H>) -> Self {
        self.fallback = Some(fallback.with_channel(self.first.channel()));
        self.on_fallback = false;
        self
    }

    /// The fallback compensator, if the axis has one.
    pub fn fallback(&self) -> Option<&Compensator<H>> {
        self.fallback.as_ref()
    }

    /// Whether the latest sample's output came from the fallback (false without one).
    pub fn on_fallback(&self) -> bool {
        self.on_fallback
    }

    /// The indices into `temps` this axis reads, first sensor first.
    pub fn sensors(&self) -> impl Iterator<Item = usize> + '_ {
        core::iter::once(self.first.channel())
            .chain(self.more.parts.iter().flatten().map(|p| p.index))
    }

    /// The further sensors, in the order they were added: each one's index among `temps`,
    /// its features and its parts of B and K (what an export writes).
    pub fn further(
        &self,
    ) -> impl Iterator<
        Item = (
            usize,
            &FeatureSpec,
            Option<&BaselineModel>,
            Option<&BaselineModel>,
        ),
    > + '_ {
        self.more.parts.iter().flatten().map(|p| {
            (
                p.index,
                p.pipeline.spec(),
                p.bias.as_ref(),
                p.scale.as_ref(),
            )
        })
    }

    /// The first sensor's features of the latest step (as [`Compensator::features`]).
    pub fn features(&self) -> Option<&crate::features::Features> {
        self.first.features()
    }

    /// The first sensor's compensator (its spec and limits).
    pub fn first(&self) -> &Compensator<H> {
        &self.first
    }

    /// One sample: time (s), gyro output (°/s), and every sensor of the unit (°C), of which
    /// this axis reads its own. Never fails; see [`Compensator::step`]. With no further
    /// sensor this is `Compensator::step` on `temps[first_index]` exactly
    /// ([`Compensator::step_unit`]).
    pub fn step(&mut self, time_s: f64, gyro_dps: f64, temps: &[f64]) -> Corrected {
        let t0 = reading(temps, self.first.channel());
        let all = self
            .first
            .step_with(time_s, gyro_dps, t0, &mut self.more, temps);
        let Some(fallback) = &mut self.fallback else {
            return all;
        };
        let alone = fallback.step(time_s, gyro_dps, t0);
        if all.status != Status::Invalid && alone.status != Status::Invalid {
            self.on_fallback = all.status == Status::Degraded && alone.status != Status::Degraded;
        }
        if !self.on_fallback {
            return all;
        }
        Corrected {
            status: match alone.status {
                Status::Ok => Status::Fallback,
                other => other,
            },
            ..alone
        }
    }

    /// Start over (as [`Compensator::reset`], for every sensor and the fallback).
    pub fn reset(&mut self) {
        self.first.reset();
        self.more.rebase();
        if let Some(f) = &mut self.fallback {
            f.reset();
        }
        self.on_fallback = false;
    }
}

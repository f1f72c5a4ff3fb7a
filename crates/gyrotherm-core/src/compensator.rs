//! The compensator: gyro output, temperature and time in; corrected rate out, sample by sample.
//!
//! G = (Ĝ - B) / K (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, eq. 4), where
//! B (°/s) and K (dimensionless, 1 nominal) come from two separate models (the paper's two
//! networks, §2) evaluated on the streaming features of [`crate::features`]. The models step
//! once per feature step (1 s by default) and their B and K are held between steps, so logs at
//! 1 Hz and at 100 Hz see the same model.
//!
//! [`Compensator`] is the one value flight code holds. Its [`Compensator::step`] is
//! panic-free and allocation-free for every input, and gives a corrected rate for every
//! finite gyro sample, whatever the temperature sensor does.
//!
//! # Temperature-sensor faults
//! Every sample gets a [`Status`]:
//! - [`Status::Ok`]: the temperature was accepted and B and K are current (from the latest
//!   feature step).
//! - [`Status::Held`]: this temperature sample was rejected, or its time stamp could not be
//!   placed (see the time axis below). The feature pipeline (thermal state, rate window, lags)
//!   and the LSTM states are not advanced, and B and K keep their last good values. Also given
//!   when the models produced no usable B or K at a step (non-finite, or K ≤ 0): the last good
//!   values are kept.
//! - [`Status::Degraded`]: as held, but no good temperature for longer than
//!   [`TempLimits::degraded_after_s`] (60 s by default) on the degraded clock (below), or never
//!   since the start: before the first accepted temperature there is no model output, so B = 0
//!   and K = 1 (the rate is the raw gyro output). Also given while a restarted pipeline
//!   settles after a new time base (below), with B and K current.
//! - [`Status::Invalid`]: the gyro sample itself is not finite, or so large that
//!   (Ĝ − B) / K is beyond f64; there is no rate
//!   ([`Corrected::rate`] is `None`, `rate_dps` is 0). The temperature and time are still
//!   judged and used.
//! - [`Status::Fallback`]: only from an axis that reads further sensors and carries a
//!   fallback model ([`crate::multi::AxisCompensator::with_fallback`]): a further sensor is
//!   given up on (the axis on all its sensors is degraded while its first sensor alone is
//!   believed), and B and K are current from the fallback model on the first sensor alone.
//!
//! A temperature sample is rejected when it is not finite; when it lies outside
//! [`TempLimits::min_c`]..=[`TempLimits::max_c`]; when it implies a rate of change no chamber or
//! aircraft bay produces: `|T − T_good| > max_rate_c_per_s · (t − t_good) + step_allowance_c`
//! against the last accepted sample (`T_good` at `t_good`); or when its time stamp cannot be
//! placed on the time base. The allowance absorbs sensor noise and resolution at high sample
//! rates (a one-LSB flip of a DS18B20 at 100 Hz is 6 °C/s); because the allowed change grows
//! with the time since the last good reading, a real temperature that moved during a long
//! outage is accepted again after at most `|ΔT| / max_rate_c_per_s` seconds. The first sample's
//! temperature (and the first on a new time base) is judged by the range alone.
//!
//! # The time axis
//! A state machine with one current **time base** (`t_base`, the time of the latest placed
//! sample) and at most one **candidate** base (the latest unplaced finite time and how many
//! consecutive samples agree on it). With `D` = [`TempLimits::degraded_after_s`], a sample at
//! time `t`:
//! 1. **Placed** when `t` is finite and `0 < t − t_base ≤ D` (or there is no base yet: the first
//!    finite time is placed). `t_base = t`, the candidate is dropped, and the temperature is
//!    judged and used as above; the pipeline bridges the gap exactly (next section).
//! 2. **Not placed** when `t` is NaN or ±∞, repeats `t_base`, is before it (a clock reset,
//!    `−1e308`), or jumps more than `D` past it (`1e308`, `+1e9` s, a long silence): status
//!    held (or degraded, below); its temperature is not used, the pipeline and the LSTM states
//!    do not advance, B and K are held. A finite `t` becomes the candidate: count 1, or one
//!    more than the candidate's count when `0 < t − t_cand ≤ D`. A non-finite `t` drops the
//!    candidate.
//! 3. **New base**: when the candidate's count reaches [`REBASE_AFTER`] (3 consecutive samples
//!    that agree with each other but not with `t_base`), this sample is placed on a new base:
//!    the pipeline restarts (rate window, moving average and lags, as at start), the LSTM
//!    states are zeroed, and the temperature history is forgotten (the next good temperature
//!    is judged by range alone); B and K stay held until the new pipeline's first step. From
//!    that first step on, for [`FeatureSpec::settle_s`](crate::features::FeatureSpec::settle_s)
//!    seconds (max of the rate lag and the smoothing window: 20 s published) the status is
//!    degraded, with B and K from the new steps; then ok again. A single glitch (one bad time
//!    among good ones) never re-bases: the next good sample is placed on the old base and
//!    drops the candidate, so the glitch costs exactly what one rejected temperature costs.
//!
//! The **degraded clock** runs on placed time plus one step period per unplaced sample:
//! a sample is degraded when `(t_base − t_ok) + P · n_unplaced > D`, with `t_ok` the time of
//! the latest ok sample on this base and `n_unplaced` the samples since the latest placed one,
//! so a stream of NaN, repeated or backward times turns degraded after `D / P` samples (60 at
//! the default 1 s step; sooner in seconds for faster logs, which errs on the safe side).
//! Nothing is held for good: once clean 1 Hz samples follow any faults, the status is ok
//! again after at most `max(REBASE_AFTER − 1 + settle_s, (max_c − min_c − step_allowance_c) /
//! max_rate_c_per_s)` seconds: either the samples fit the old base and only the rate limit
//! can delay a temperature that moved, or they re-base and the new base judges temperature by
//! range alone (80 s for the published spec and default limits). The pipeline's step index
//! stays below
//! [`MAX_STEP_INDEX`](crate::features::MAX_STEP_INDEX): a placed sample that would reach it
//! re-bases at once.
//!
//! # Recovery without a transient
//! Rejected samples never enter the pipeline, so nothing stale or spiky reaches the 20 s rate
//! window. The first accepted sample after a gap is one step of the pipeline, which bridges
//! the gap as it bridges a gap in the log: the rate's earlier value is the last good step at
//! or before `t − L`, divided by the true elapsed time, which is the slope of the straight line
//! across the gap (linear interpolation of the missing steps); the lags advance exactly over
//! the elapsed time. The LSTM resumes from its held state at the new step.

use crate::baseline::BaselineModel;
use crate::error::{Channel, InputError};
use crate::features::{FeaturePipeline, FeatureSpec, Features, SpecError, MAX_FEATURES};
use crate::lstm::{Lstm, LstmWeights};
use core::fmt;

/// Consecutive samples that must agree on a new time base before it replaces the current one
/// (see the module doc's time axis): three, so that one or two glitched time stamps among good
/// ones never restart the pipeline, while a real clock reset costs two held samples.
pub const REBASE_AFTER: u8 = 3;

/// Hidden units of the flight LSTM by default: 8, as published (He et al. 2024, §2). The
/// types that hold an LSTM ([`NormalisedLstm`], [`TargetModel`], [`Compensator`], the axis and
/// unit built on it, the static model) take the size as a const parameter defaulting to this,
/// so an 8-unit model's storage does not grow for the larger networks.
pub const HIDDEN: usize = 8;

/// The LSTM sizes the ground tools train, check, compensate with and export: each a
/// compile-time size of the flight types.
pub const HIDDEN_SIZES: [usize; 4] = [8, 16, 32, 64];

/// LSTM inputs in flight: every feature slot; slots beyond the spec's feature count are fed 0
/// (their weights are 0 after export).
pub const LSTM_INPUTS: usize = MAX_FEATURES;

/// An LSTM with its z-score normalisation: y = target_mean + target_std · lstm((x - mean)/std).
#[derive(Debug, Clone)]
pub struct NormalisedLstm<const H: usize = HIDDEN> {
    lstm: Lstm<LSTM_INPUTS, H>,
    input_mean: [f64; MAX_FEATURES],
    input_std: [f64; MAX_FEATURES],
    n_inputs: usize,
    target_mean: f64,
    target_std: f64,
}

/// Most sensors one axis reads (the first included): the bound
/// [`ModelError::Sensors`] states, and the size of [`crate::multi::AxisCompensator`]'s parts.
pub const MAX_SENSORS: usize = 4;

/// Why a model cannot be built.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// The feature specification is invalid.
    Spec(SpecError),
    /// A normalisation value is not finite, or a standard deviation is not positive.
    BadNormalisation,
    /// More inputs than [`MAX_FEATURES`], or a model's input count differs from the spec's.
    FeatureCount { expected: usize, got: usize },
    /// The temperature-sensor limits are unusable.
    Limits(LimitsError),
    /// A baseline model cannot be built.
    Baseline(crate::baseline::BaselineError),
    /// LSTM weights refused (wrong shape or not finite).
    Weights(crate::lstm::WeightError),
    /// A further sensor of an axis ([`crate::multi::AxisCompensator::with_sensor`]): more
    /// than [`MAX_SENSORS`], one already read, or a step period or rate lag
    /// other than the first sensor's.
    Sensors,
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::Spec(_) => f.write_str("feature spec"),
            ModelError::BadNormalisation => {
                f.write_str("normalisation has a non-finite value or a non-positive std")
            }
            ModelError::FeatureCount { expected, got } => {
                write!(f, "model takes {got} features, the spec gives {expected}")
            }
            ModelError::Limits(_) => f.write_str("temperature-sensor limits"),
            ModelError::Baseline(_) => f.write_str("baseline"),
            ModelError::Weights(_) => f.write_str("lstm weights"),
            ModelError::Sensors => write!(
                f,
                "further sensors: at most {} per axis, each read once, with the first \
                 sensor's step period and rate lag",
                MAX_SENSORS
            ),
        }
    }
}

/// The message states this level (which part of the model); `source()` gives the cause.
impl core::error::Error for ModelError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            ModelError::Spec(e) => Some(e),
            ModelError::Limits(e) => Some(e),
            ModelError::Baseline(e) => Some(e),
            ModelError::Weights(e) => Some(e),
            ModelError::BadNormalisation
            | ModelError::FeatureCount { .. }
            | ModelError::Sensors => None,
        }
    }
}

impl<const H: usize> NormalisedLstm<H> {
    /// Checked constructor: `input_mean`/`input_std` give the first `n_inputs` channels.
    pub fn new(
        weights: &LstmWeights<LSTM_INPUTS, H>,
        input_mean: &[f64],
        input_std: &[f64],
        target_mean: f64,
        target_std: f64,
    ) -> Result<Self, ModelError> {
        let n = input_mean.len();
        if n > MAX_FEATURES || input_std.len() != n {
            return Err(ModelError::FeatureCount {
                expected: MAX_FEATURES.min(input_std.len()),
                got: n,
            });
        }
        let ok = |m: f64, s: f64| m.is_finite() && s.is_finite() && s > 0.0;
        if !ok(target_mean, target_std)
            || input_mean.iter().zip(input_std).any(|(m, s)| !ok(*m, *s))
        {
            return Err(ModelError::BadNormalisation);
        }
        let mut mean = [0.0; MAX_FEATURES];
        let mut std = [1.0; MAX_FEATURES];
        for (dst, src) in mean.iter_mut().zip(input_mean) {
            *dst = *src;
        }
        for (dst, src) in std.iter_mut().zip(input_std) {
            *dst = *src;
        }
        Ok(NormalisedLstm {
            lstm: Lstm::new(weights),
            input_mean: mean,
            input_std: std,
            n_inputs: n,
            target_mean,
            target_std,
        })
    }

    /// Number of feature channels the network reads.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    /// One step: normalise, run the cell, de-normalise. Non-finite features are refused
    /// with the LSTM state untouched.
    pub fn step(&mut self, features: &[f64]) -> Result<f64, InputError> {
        let mut x = [0.0f32; LSTM_INPUTS];
        let norm = self.input_mean.iter().zip(&self.input_std);
        for (k, (slot, (mean, std))) in x.iter_mut().zip(norm).enumerate().take(self.n_inputs) {
            let v = features.get(k).copied().unwrap_or(f64::NAN);
            let z = (v - mean) / std;
            if !z.is_finite() {
                return Err(InputError::NonFinite(Channel::Feature(k as u8)));
            }
            *slot = z as f32;
        }
        let y = self.lstm.step(&x)?;
        Ok(self.target_mean + self.target_std * f64::from(y))
    }

    /// Zero the LSTM state.
    pub fn reset(&mut self) {
        self.lstm.reset();
    }
}

/// One target's model: value = offset + baseline(features) + lstm(features), each part
/// optional (a residual LSTM on top of a physical fit has both). With
/// [`lstm_reads_base`](Self::lstm_reads_base) the LSTM reads
/// `(features..., baseline(features))` instead: the base prediction as one more input.
#[derive(Debug, Clone)]
pub struct TargetModel<const H: usize = HIDDEN> {
    /// Constant part (e.g. K = 1 when no scale-factor model was fitted).
    pub offset: f64,
    /// Fitted polynomial in the features.
    pub baseline: Option<BaselineModel>,
    /// LSTM (normalised), added to the rest.
    pub lstm: Option<NormalisedLstm<H>>,
    /// When both a baseline and an LSTM are present: the LSTM's inputs are the features
    /// followed by the baseline's value (`n_features + 1` inputs). Ignored otherwise.
    pub lstm_reads_base: bool,
}

impl<const H: usize> TargetModel<H> {
    /// A model that always gives `value`.
    pub const fn constant(value: f64) -> Self {
        TargetModel {
            offset: value,
            baseline: None,
            lstm: None,
            lstm_reads_base: false,
        }
    }

    /// Whether the LSTM reads the baseline's value as its last input.
    fn base_input(&self) -> bool {
        self.lstm_reads_base && self.baseline.is_some() && self.lstm.is_some()
    }

    fn check(&self, n_features: usize) -> Result<(), ModelError> {
        if let Some(b) = &self.baseline {
            if b.n_features() != n_features {
                return Err(ModelError::FeatureCount {
                    expected: n_features,
                    got: b.n_features(),
                });
            }
        }
        if let Some(l) = &self.lstm {
            let expected = n_features + usize::from(self.base_input());
            if l.n_inputs() != expected {
                return Err(ModelError::FeatureCount {
                    expected,
                    got: l.n_inputs(),
                });
            }
        }
        Ok(())
    }

    /// Evaluate on one feature step. The baseline is evaluated before the LSTM steps, so an
    /// error leaves the LSTM state untouched.
    pub fn eval(&mut self, f: &Features) -> Result<f64, InputError> {
        let base_input = self.base_input();
        let mut y = self.offset;
        let mut base = 0.0;
        if let Some(b) = &self.baseline {
            base = b
                .eval_features(f)
                .map_err(|_| InputError::NonFinite(Channel::Temperature))?;
            y += base;
        }
        if let Some(l) = &mut self.lstm {
            let feats = f.as_slice();
            y += if base_input {
                // Features, then the base value (checked: n_features + 1 ≤ MAX_FEATURES).
                let mut x = [0.0f64; MAX_FEATURES];
                let n = feats.len().min(MAX_FEATURES - 1);
                for (dst, src) in x.iter_mut().zip(feats) {
                    *dst = *src;
                }
                if let Some(slot) = x.get_mut(n) {
                    *slot = base;
                }
                l.step(x.get(..n + 1).unwrap_or(&x))?
            } else {
                l.step(feats)?
            };
        }
        if y.is_finite() {
            Ok(y)
        } else {
            Err(InputError::NonFinite(Channel::Temperature))
        }
    }

    fn reset(&mut self) {
        if let Some(l) = &mut self.lstm {
            l.reset();
        }
    }
}

/// What a sample's output is worth; see the module doc for each case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Status {
    /// Temperature accepted; B and K current.
    Ok = 0,
    /// Temperature rejected or time stamp not placed: features, thermal state and LSTM states
    /// held; B and K held.
    Held = 1,
    /// No good temperature for longer than [`TempLimits::degraded_after_s`] on the degraded
    /// clock (or none yet), or settling on a new time base.
    Degraded = 2,
    /// The gyro sample is not finite (or its corrected rate would overflow): no rate.
    Invalid = 3,
    /// Temperature accepted; B and K current from the axis's fallback model on its first
    /// sensor alone, because a further sensor it reads is given up on
    /// ([`crate::multi::AxisCompensator::with_fallback`]).
    Fallback = 4,
}

impl Status {
    /// Every status, in the order of their codes (`status as usize`).
    pub const ALL: [Status; 5] = [
        Status::Ok,
        Status::Held,
        Status::Degraded,
        Status::Invalid,
        Status::Fallback,
    ];

    /// Lower-case name, as in the `status` column of `gyrotherm compensate`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Held => "held",
            Status::Degraded => "degraded",
            Status::Invalid => "invalid",
            Status::Fallback => "fallback",
        }
    }

    /// The status from its name (`as_str`).
    pub fn parse(s: &str) -> Option<Status> {
        Status::ALL.into_iter().find(|v| v.as_str() == s)
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// When a temperature sample is believed (see the module doc). Stored in the model file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TempLimits {
    /// Lowest plausible reading, °C.
    pub min_c: f64,
    /// Highest plausible reading, °C.
    pub max_c: f64,
    /// Fastest plausible temperature change, °C/s.
    pub max_rate_c_per_s: f64,
    /// Change always allowed between readings, °C (sensor noise and resolution).
    pub step_allowance_c: f64,
    /// Held for longer than this (s since the last good temperature) is degraded.
    pub degraded_after_s: f64,
}

impl TempLimits {
    /// −60…+100 °C (beyond an aircraft bay's −50…+50 °C, inside a DS18B20's −55…+125 °C but
    /// excluding its −127 °C bus-error value), 2 °C/s, 1 °C allowance (16 DS18B20 LSBs, 100 σ of
    /// the simulated sensor noise), degraded after 60 s.
    pub const DEFAULT: TempLimits = TempLimits {
        min_c: -60.0,
        max_c: 100.0,
        max_rate_c_per_s: 2.0,
        step_allowance_c: 1.0,
        degraded_after_s: 60.0,
    };

    /// Check the limits: finite, `min_c < max_c`, rate and degraded time > 0, allowance ≥ 0.
    pub fn validate(&self) -> Result<(), LimitsError> {
        let fin = |v: f64| v.is_finite();
        if !(fin(self.min_c) && fin(self.max_c) && self.min_c < self.max_c) {
            return Err(LimitsError::Range);
        }
        if !(fin(self.max_rate_c_per_s) && self.max_rate_c_per_s > 0.0) {
            return Err(LimitsError::Rate);
        }
        if !(fin(self.step_allowance_c) && self.step_allowance_c >= 0.0) {
            return Err(LimitsError::Allowance);
        }
        if !(fin(self.degraded_after_s) && self.degraded_after_s > 0.0) {
            return Err(LimitsError::DegradedAfter);
        }
        Ok(())
    }
}

impl Default for TempLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A [`TempLimits`] field that cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LimitsError {
    /// `min_c`/`max_c` not finite or not `min_c < max_c`.
    Range,
    /// `max_rate_c_per_s` not finite and > 0.
    Rate,
    /// `step_allowance_c` not finite and ≥ 0.
    Allowance,
    /// `degraded_after_s` not finite and > 0.
    DegradedAfter,
}

impl fmt::Display for LimitsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LimitsError::Range => "temperature range: min and max must be finite with min < max",
            LimitsError::Rate => "temperature rate limit must be finite and > 0 °C/s",
            LimitsError::Allowance => "temperature step allowance must be finite and >= 0 °C",
            LimitsError::DegradedAfter => "degraded-after time must be finite and > 0 s",
        })
    }
}

impl core::error::Error for LimitsError {}

/// A corrected sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corrected {
    /// What this output is worth.
    pub status: Status,
    /// Predicted bias B, °/s (held since the last feature step; 0 before the first).
    pub bias_dps: f64,
    /// Predicted scale factor K, dimensionless (held since the last feature step; 1 before
    /// the first).
    pub scale: f64,
    /// Compensated rate G = (Ĝ - B) / K, °/s; 0 when the status is [`Status::Invalid`].
    pub rate_dps: f64,
}

impl Corrected {
    /// The compensated rate, `None` when the gyro sample was not finite.
    pub fn rate(&self) -> Option<f64> {
        match self.status {
            Status::Invalid => None,
            _ => Some(self.rate_dps),
        }
    }
}

/// What an axis reads besides its first sensor: the hook through which
/// [`crate::multi::AxisCompensator`] shares the time axis and the fault handling of
/// [`Compensator`]. Every method of [`NoMoreSensors`] does nothing, so the one-sensor path is
/// unchanged.
pub(crate) trait MoreSensors {
    /// Whether every further sensor's reading in `temps` at `time_s` (placed) is believed.
    fn plausible(&self, limits: &TempLimits, time_s: f64, temps: &[f64]) -> bool;
    /// Feed the further pipelines the sample (believed); false if one refused it.
    fn push(&mut self, time_s: f64, temps: &[f64]) -> bool;
    /// The sample was used: remember each reading as the sensor's latest good one.
    fn accepted(&mut self, time_s: f64, temps: &[f64]);
    /// Add each further sensor's part to B and K at a new step; false if one gave none.
    fn add(&mut self, bias_dps: &mut f64, scale: &mut f64) -> bool;
    /// A new time base: restart the pipelines, forget the readings.
    fn rebase(&mut self);
}

/// No further sensors: the one-sensor compensator.
pub(crate) struct NoMoreSensors;

impl MoreSensors for NoMoreSensors {
    fn plausible(&self, _: &TempLimits, _: f64, _: &[f64]) -> bool {
        true
    }
    fn push(&mut self, _: f64, _: &[f64]) -> bool {
        true
    }
    fn accepted(&mut self, _: f64, _: &[f64]) {}
    fn add(&mut self, _: &mut f64, _: &mut f64) -> bool {
        true
    }
    fn rebase(&mut self) {}
}

/// Whether a temperature reading at `time_s` is believed against the limits and the
/// sensor's latest accepted reading.
pub(crate) fn plausible_reading(
    l: &TempLimits,
    last_good: Option<(f64, f64)>,
    time_s: f64,
    temp_c: f64,
) -> bool {
    if !(temp_c >= l.min_c && temp_c <= l.max_c) {
        return false;
    }
    match last_good {
        None => true,
        Some((t, v)) => {
            let allowed = l.max_rate_c_per_s * (time_s - t) + l.step_allowance_c;
            libm::fabs(temp_c - v) <= allowed
        }
    }
}

/// Bias and scale-factor models on one streaming feature pipeline (see the module doc).
#[derive(Debug, Clone)]
pub struct Compensator<const H: usize = HIDDEN> {
    pipeline: FeaturePipeline,
    bias: TargetModel<H>,
    scale: TargetModel<H>,
    limits: TempLimits,
    /// B and K of the latest good step.
    held: Option<(f64, f64)>,
    /// `held` came from the latest step (false after a step whose models failed).
    current: bool,
    /// Time of the latest placed sample, s: the current time base.
    base_s: Option<f64>,
    /// Samples since the latest placed one (saturating): the degraded clock's count.
    unplaced: u32,
    /// Candidate new time base: latest unplaced finite time and how many consecutive samples
    /// agree on it.
    candidate: Option<(f64, u8)>,
    /// Re-based, and the new pipeline has not had its first step yet.
    rebased: bool,
    /// After a re-base: degraded while the time base is before this time.
    settle_end_s: Option<f64>,
    /// Time and value of the latest accepted temperature.
    last_good: Option<(f64, f64)>,
    /// Time of the latest sample with fresh B and K on this base.
    last_ok_s: Option<f64>,
    /// Which of a unit's temperature channels [`Compensator::step_unit`] reads (0 alone).
    channel: usize,
}

impl<const H: usize> Compensator<H> {
    /// Checked constructor with the default [`TempLimits`]: both models must read the spec's
    /// feature count.
    pub fn new(
        spec: FeatureSpec,
        bias: TargetModel<H>,
        scale: TargetModel<H>,
    ) -> Result<Self, ModelError> {
        Self::with_limits(spec, bias, scale, TempLimits::DEFAULT)
    }

    /// Checked constructor with temperature-sensor limits.
    pub fn with_limits(
        spec: FeatureSpec,
        bias: TargetModel<H>,
        scale: TargetModel<H>,
        limits: TempLimits,
    ) -> Result<Self, ModelError> {
        let pipeline = FeaturePipeline::new(spec).map_err(ModelError::Spec)?;
        limits.validate().map_err(ModelError::Limits)?;
        let n = spec.n_features();
        bias.check(n)?;
        scale.check(n)?;
        Ok(Compensator {
            pipeline,
            bias,
            scale,
            limits,
            held: None,
            current: false,
            base_s: None,
            unplaced: 0,
            candidate: None,
            rebased: false,
            settle_end_s: None,
            last_good: None,
            last_ok_s: None,
            channel: 0,
        })
    }

    /// The same compensator reading temperature channel `channel` of a unit's sensors in
    /// [`Compensator::step_unit`] (0 by default).
    pub fn with_channel(mut self, channel: usize) -> Self {
        self.channel = channel;
        self
    }

    /// The unit temperature channel this compensator reads.
    pub fn channel(&self) -> usize {
        self.channel
    }

    /// One sample of a unit with several temperature sensors: `temps` holds every sensor's
    /// reading and the compensator picks its own (a sensor it does not read cannot fault it).
    /// A channel missing from `temps` reads as NaN, a sensor fault. Otherwise as
    /// [`Compensator::step`].
    pub fn step_unit(&mut self, time_s: f64, gyro_dps: f64, temps: &[f64]) -> Corrected {
        let temp_c = temps.get(self.channel).copied().unwrap_or(f64::NAN);
        self.step(time_s, gyro_dps, temp_c)
    }

    /// The feature specification.
    pub fn spec(&self) -> &FeatureSpec {
        self.pipeline.spec()
    }

    /// The temperature-sensor limits.
    pub fn limits(&self) -> &TempLimits {
        &self.limits
    }

    /// Whether a temperature reading at `time_s` (already placed on the time base) is
    /// believed.
    fn plausible(&self, time_s: f64, temp_c: f64) -> bool {
        plausible_reading(&self.limits, self.last_good, time_s, temp_c)
    }

    /// One sample: time (s, increasing), gyro output Ĝ (°/s), temperature (°C). Never fails:
    /// the [`Status`] says what the output is worth (see the module doc).
    pub fn step(&mut self, time_s: f64, gyro_dps: f64, temp_c: f64) -> Corrected {
        self.step_with(time_s, gyro_dps, temp_c, &mut NoMoreSensors, &[])
    }

    /// [`step`](Self::step) for an axis that reads further sensors (`more`, their readings
    /// among `temps`): the sample is used only when every sensor the axis reads is believed,
    /// and all pipelines step together. With [`NoMoreSensors`] this is `step` exactly.
    pub(crate) fn step_with<M: MoreSensors>(
        &mut self,
        time_s: f64,
        gyro_dps: f64,
        temp_c: f64,
        more: &mut M,
        temps: &[f64],
    ) -> Corrected {
        let mut fresh = false;
        if self.place(time_s, more)
            && self.plausible(time_s, temp_c)
            && more.plausible(&self.limits, time_s, temps)
        {
            fresh = self.push(time_s, temp_c, more, temps);
        }
        if fresh {
            self.last_ok_s = self.base_s;
        }
        let (bias_dps, scale) = self.held.unwrap_or((0.0, 1.0));
        let settling = match (self.settle_end_s, self.base_s) {
            (Some(end), Some(now)) => now < end,
            _ => false,
        };
        // A finite sample so large that (Ĝ − B) / K overflows has no rate either.
        let status = if !(gyro_dps.is_finite() && ((gyro_dps - bias_dps) / scale).is_finite()) {
            Status::Invalid
        } else if settling {
            Status::Degraded
        } else if fresh {
            Status::Ok
        } else {
            let unplaced_s = self.spec().step_period_s * f64::from(self.unplaced);
            match (self.last_ok_s, self.base_s) {
                (Some(ok), Some(now))
                    if (now - ok) + unplaced_s <= self.limits.degraded_after_s =>
                {
                    Status::Held
                }
                _ => Status::Degraded,
            }
        };
        let rate_dps = match status {
            Status::Invalid => 0.0,
            _ => (gyro_dps - bias_dps) / scale,
        };
        Corrected {
            status,
            bias_dps,
            scale,
            rate_dps,
        }
    }

    /// The time axis (module doc): whether `time_s` is placed on the time base, re-basing
    /// when the candidate has gathered [`REBASE_AFTER`] samples.
    fn place<M: MoreSensors>(&mut self, time_s: f64, more: &mut M) -> bool {
        let d = self.limits.degraded_after_s;
        let fits = |base: f64| time_s > base && time_s - base <= d;
        if !time_s.is_finite() {
            self.candidate = None;
            self.unplaced = self.unplaced.saturating_add(1);
            return false;
        }
        if self.base_s.is_none_or(fits) {
            self.base_s = Some(time_s);
            self.unplaced = 0;
            self.candidate = None;
            return true;
        }
        let n = match self.candidate {
            Some((t, n)) if fits(t) => n.saturating_add(1),
            _ => 1,
        };
        if n >= REBASE_AFTER {
            self.rebase(more);
            self.base_s = Some(time_s);
            self.unplaced = 0;
            self.candidate = None;
            return true;
        }
        self.candidate = Some((time_s, n));
        self.unplaced = self.unplaced.saturating_add(1);
        false
    }

    /// Start a new time base: restart the pipeline and the LSTM states, forget the
    /// temperature history; B and K stay held until the new pipeline's first step.
    fn rebase<M: MoreSensors>(&mut self, more: &mut M) {
        more.rebase();
        self.pipeline.reset();
        self.bias.reset();
        self.scale.reset();
        self.current = false;
        self.last_good = None;
        self.last_ok_s = None;
        self.rebased = true;
        self.settle_end_s = None;
    }

    /// Feed a placed, believed sample to the pipeline; true when B and K are fresh.
    fn push<M: MoreSensors>(
        &mut self,
        time_s: f64,
        temp_c: f64,
        more: &mut M,
        temps: &[f64],
    ) -> bool {
        let pushed = match self.pipeline.push(time_s, temp_c) {
            // Steps can no longer be counted exactly on this base: start a new one here.
            Err(InputError::TimeOutOfRange) => {
                self.rebase(more);
                self.pipeline.push(time_s, temp_c)
            }
            r => r,
        };
        // The further pipelines see the same times, so they step when the first one does.
        // Unreachable failure (time and temperatures were checked): start a new base, so
        // that the pipelines stay in step.
        if pushed.is_ok() && !more.push(time_s, temps) {
            self.rebase(more);
            return false;
        }
        match pushed {
            Ok(Some(step)) => {
                self.last_good = Some((time_s, temp_c));
                more.accepted(time_s, temps);
                if self.rebased {
                    self.rebased = false;
                    self.settle_end_s = Some(time_s + self.spec().settle_s());
                }
                self.eval(&step.features, more)
            }
            Ok(None) => {
                self.last_good = Some((time_s, temp_c));
                more.accepted(time_s, temps);
                self.current
            }
            // Unreachable: time and temperature were checked before.
            Err(_) => false,
        }
    }

    /// Evaluate both models on a new step (the first sensor's part, then each further
    /// sensor's, added in order); keep B and K only if both are usable.
    fn eval<M: MoreSensors>(&mut self, f: &Features, more: &mut M) -> bool {
        self.current = false;
        let (Ok(mut b), Ok(mut k)) = (self.bias.eval(f), self.scale.eval(f)) else {
            return false;
        };
        if !more.add(&mut b, &mut k) {
            return false;
        }
        // K > 0 also refuses NaN; a finite rate needs a finite quotient.
        if !(k > 0.0 && b.is_finite() && k.is_finite()) {
            return false;
        }
        self.held = Some((b, k));
        self.current = true;
        true
    }

    /// The feature vector of the latest step (None before the first accepted sample).
    pub fn features(&self) -> Option<&Features> {
        self.pipeline.current()
    }

    /// Start over: clear the feature history, the LSTM states, the held values and the
    /// sensor-fault history.
    pub fn reset(&mut self) {
        self.pipeline.reset();
        self.bias.reset();
        self.scale.reset();
        self.held = None;
        self.current = false;
        self.base_s = None;
        self.unplaced = 0;
        self.candidate = None;
        self.rebased = false;
        self.settle_end_s = None;
        self.last_good = None;
        self.last_ok_s = None;
    }
}

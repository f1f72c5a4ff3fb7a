//! The streaming feature pipeline: temperature samples in, one model input vector per step out.
//!
//! The model steps at a fixed period on the **time axis** (1 s by default), not per sample, so a
//! log at 1 Hz and the same temperature history logged at 100 Hz give identical model inputs
//! (the model must not depend on the logger's rate). [`FeaturePipeline::push`] takes `(time_s, temp_c)` per sample and emits a
//! [`Step`] when the sample reaches the next step boundary; between boundaries it holds.
//!
//! # Step boundaries and the value at a step
//! The first sample defines `t0` and is step 0. Step `k` has the boundary time `t0 + k·P`
//! (`P` = [`FeatureSpec::step_period_s`]). The value at step `k` is the **first sample at or
//! after that boundary** (a sample up to [`BOUNDARY_TOL_STEPS`] step periods before it counts
//! as at it, which absorbs round-off in logged time stamps such as `i·0.01`). No averaging
//! over the step: a 100 Hz log and a 1 Hz log that agree at the whole seconds give bit-equal
//! features. If a gap in the log skips boundaries, one step is emitted for the latest boundary
//! reached, and the filters advance by the elapsed time (nothing is invented for the skipped
//! steps).
//!
//! # Features, in this order ([`FeatureSpec::kind`] names each index)
//! 1. `T`, °C: the temperature at the step.
//! 2. `dT`, °C/s: `(T(t) - T(t - L)) / L` with `L` = [`FeatureSpec::rate_lag_s`] (20 s: He et
//!    al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, a 20-sample difference at 1 Hz). The
//!    earlier value is the latest stored step at or before `t - L`; before `L` seconds of history
//!    exist, the oldest stored step (the first sample) is used, with the actual time difference
//!    in the denominator; at step 0 `dT = 0`.
//! 3. optional trailing moving average of `T` over [`FeatureSpec::smoothing_window_s`] (steps
//!    inside the window, the current one included; fewer at the start), °C.
//! 4. optional thermal-state inputs: `T` through first-order lags `τ·dy/dt = T - y`, one per
//!    time constant in [`FeatureSpec::lag_tau_s`], exposed as the lag outputs `y_j` (°C) and/or
//!    the differences `T - y_j` (°C) ([`LagOutputs`]). Discretised exactly for an input held at
//!    the new step's value: `y += (1 - exp(-Δt/τ))·(T - y)`, so a unit step gives
//!    `y(k·P) = 1 - exp(-k·P/τ)`. Each lag starts at the first sample's `T` (a gyro that has
//!    been sitting at the starting temperature).
//!
//! # Numbers
//! Internally and at the output this pipeline is **f64**, unlike the f32 LSTM: time stamps of a
//! 30,000 s run need f64 (f32 resolves only ~2 ms at 30,000 s), and the ground trains on
//! exactly these numbers (it runs this same code over whole logs). It runs once per step
//! (1 Hz), so the cost of soft f64 on a small MCU is irrelevant. Convert to f32 at the LSTM.
//!
//! No allocation, fixed sizes, no panics on any input.

use crate::error::{Channel, InputError};
use core::fmt;

/// Most features a [`FeatureSpec`] can produce: T, dT, moving average, 4 lags × 2 outputs.
pub const MAX_FEATURES: usize = 12;
/// Most first-order lags (thermal-state inputs).
pub const MAX_LAGS: usize = 4;
/// Steps of temperature history kept: the rate lag and the moving-average window must fit.
pub const HISTORY_STEPS: usize = 64;
/// A sample this many step periods before a boundary counts as at the boundary.
pub const BOUNDARY_TOL_STEPS: f64 = 1e-6;
/// Step indices stay below 2^53, so that every index and every difference of indices is an
/// exact f64 (and `f64 as u64` never saturates); a later sample is refused with
/// [`InputError::TimeOutOfRange`].
pub const MAX_STEP_INDEX: u64 = 1 << 53;

/// Which lag outputs are features.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LagOutputs {
    /// The lag outputs `y_j`, °C.
    Level,
    /// The differences `T - y_j`, °C.
    #[default]
    DiffFromT,
    /// Both: all `y_j` first, then all `T - y_j`.
    Both,
}

/// What a feature index means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeatureKind {
    /// T, °C.
    Temperature,
    /// dT, °C/s.
    Rate,
    /// Trailing moving average of T, °C.
    MovingAverage,
    /// Output of lag `j` (index into `lag_tau_s`), °C.
    Lag(u8),
    /// `T` minus the output of lag `j`, °C.
    LagDiff(u8),
}

/// The feature definition. Small and `Copy`; check it with [`FeatureSpec::validate`] (the
/// pipeline does so in [`FeaturePipeline::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureSpec {
    /// Model step period P, s (1 s in He et al. 2024).
    pub step_period_s: f64,
    /// Rate lag L, s: a whole number of steps, 1..=HISTORY_STEPS-1 of them (20 s published).
    pub rate_lag_s: f64,
    /// Moving-average window of T, s: 0 for none, else a whole number of steps,
    /// 1..=HISTORY_STEPS of them.
    pub smoothing_window_s: f64,
    /// Lag time constants τ, s; the first `n_lags` are used (each finite and > 0).
    pub lag_tau_s: [f64; MAX_LAGS],
    /// Number of lags in use, 0..=MAX_LAGS.
    pub n_lags: u8,
    /// Which lag outputs become features.
    pub lag_outputs: LagOutputs,
}

impl Default for FeatureSpec {
    fn default() -> Self {
        Self::PUBLISHED
    }
}

/// A [`FeatureSpec`] that cannot be used; `Display` says what to change.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum SpecError {
    /// The step period is not finite and > 0.
    StepPeriod(f64),
    /// The rate lag is not a whole number of steps in 1..=HISTORY_STEPS-1.
    RateLag(f64),
    /// The smoothing window is not 0 or a whole number of steps in 1..=HISTORY_STEPS.
    SmoothingWindow(f64),
    /// More than MAX_LAGS lags.
    TooManyLags(u8),
    /// Lag time constant `index` is not finite and > 0.
    LagTau { index: u8, tau_s: f64 },
}

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            SpecError::StepPeriod(p) => {
                write!(f, "step period {p} s: must be finite and > 0 (1 s is usual)")
            }
            SpecError::RateLag(l) => write!(
                f,
                "rate lag {l} s: must be a whole number of step periods, 1 to {} of them",
                HISTORY_STEPS - 1
            ),
            SpecError::SmoothingWindow(w) => write!(
                f,
                "smoothing window {w} s: must be 0 (off) or a whole number of step periods, 1 to {} of them",
                HISTORY_STEPS
            ),
            SpecError::TooManyLags(n) => {
                write!(f, "{n} thermal-state lags: at most {MAX_LAGS} are supported")
            }
            SpecError::LagTau { index, tau_s } => write!(
                f,
                "lag time constant #{index} is {tau_s} s: must be finite and > 0"
            ),
        }
    }
}

impl core::error::Error for SpecError {}

/// `x / p` as a whole number of steps, if it is one (within 1e-9 relative) and in `lo..=hi`.
fn whole_steps(x: f64, p: f64, lo: usize, hi: usize) -> Option<usize> {
    if !x.is_finite() {
        return None;
    }
    let q = x / p;
    let r = libm::round(q);
    if !(r >= lo as f64 && r <= hi as f64) || libm::fabs(q - r) > 1e-9 * r.max(1.0) {
        return None;
    }
    Some(r as usize)
}

impl FeatureSpec {
    /// The published inputs: T and its 20 s rate, stepped at 1 s (He et al. 2024, §2).
    pub const PUBLISHED: FeatureSpec = FeatureSpec {
        step_period_s: 1.0,
        rate_lag_s: 20.0,
        smoothing_window_s: 0.0,
        lag_tau_s: [0.0; MAX_LAGS],
        n_lags: 0,
        lag_outputs: LagOutputs::DiffFromT,
    };

    /// The published inputs plus thermal-state lags of 300, 1000 and 3000 s exposed as
    /// `T - y_j` (the inputs that helped held-out runs; docs/experiments/lstm-recipes.md).
    pub const THERMAL_STATE: FeatureSpec = FeatureSpec {
        step_period_s: 1.0,
        rate_lag_s: 20.0,
        smoothing_window_s: 0.0,
        lag_tau_s: [300.0, 1000.0, 3000.0, 0.0],
        n_lags: 3,
        lag_outputs: LagOutputs::DiffFromT,
    };

    /// This spec with the lags set to `tau_s` (at most [`MAX_LAGS`]).
    pub fn with_lags(mut self, tau_s: &[f64], outputs: LagOutputs) -> Result<Self, SpecError> {
        if tau_s.len() > MAX_LAGS {
            return Err(SpecError::TooManyLags(tau_s.len().min(255) as u8));
        }
        self.lag_tau_s = [0.0; MAX_LAGS];
        for (dst, src) in self.lag_tau_s.iter_mut().zip(tau_s) {
            *dst = *src;
        }
        self.n_lags = tau_s.len() as u8;
        self.lag_outputs = outputs;
        self.validate()?;
        Ok(self)
    }

    /// The lag time constants in use, s.
    pub fn lags(&self) -> &[f64] {
        let n = (self.n_lags as usize).min(MAX_LAGS);
        self.lag_tau_s.get(..n).unwrap_or(&[])
    }

    /// Check every field; the error names the one at fault.
    pub fn validate(&self) -> Result<(), SpecError> {
        let p = self.step_period_s;
        if !(p.is_finite() && p > 0.0) {
            return Err(SpecError::StepPeriod(p));
        }
        if whole_steps(self.rate_lag_s, p, 1, HISTORY_STEPS - 1).is_none() {
            return Err(SpecError::RateLag(self.rate_lag_s));
        }
        if self.smoothing_window_s != 0.0
            && whole_steps(self.smoothing_window_s, p, 1, HISTORY_STEPS).is_none()
        {
            return Err(SpecError::SmoothingWindow(self.smoothing_window_s));
        }
        if self.n_lags as usize > MAX_LAGS {
            return Err(SpecError::TooManyLags(self.n_lags));
        }
        for (j, &tau_s) in self.lags().iter().enumerate() {
            if !(tau_s.is_finite() && tau_s > 0.0) {
                return Err(SpecError::LagTau {
                    index: j as u8,
                    tau_s,
                });
            }
        }
        Ok(())
    }

    /// The longest history a feature reads step by step: the rate lag or the smoothing
    /// window, s. A restarted pipeline has its full windows again this long after its first
    /// sample (20 s for [`PUBLISHED`](Self::PUBLISHED)).
    pub fn settle_s(&self) -> f64 {
        self.rate_lag_s.max(self.smoothing_window_s)
    }

    fn has_smoothing(&self) -> bool {
        self.smoothing_window_s != 0.0
    }

    fn lag_levels(&self) -> bool {
        matches!(self.lag_outputs, LagOutputs::Level | LagOutputs::Both)
    }

    fn lag_diffs(&self) -> bool {
        matches!(self.lag_outputs, LagOutputs::DiffFromT | LagOutputs::Both)
    }

    /// Number of features this spec produces (≤ [`MAX_FEATURES`]).
    pub fn n_features(&self) -> usize {
        let n = (self.n_lags as usize).min(MAX_LAGS);
        2 + usize::from(self.has_smoothing())
            + n * (usize::from(self.lag_levels()) + usize::from(self.lag_diffs()))
    }

    /// What feature `i` is (None past the end).
    pub fn kind(&self, i: usize) -> Option<FeatureKind> {
        let n = (self.n_lags as usize).min(MAX_LAGS);
        let mut at = 0usize;
        let mut order = [None; MAX_FEATURES];
        let mut put = |k: FeatureKind| {
            if let Some(slot) = order.get_mut(at) {
                *slot = Some(k);
                at += 1;
            }
        };
        put(FeatureKind::Temperature);
        put(FeatureKind::Rate);
        if self.has_smoothing() {
            put(FeatureKind::MovingAverage);
        }
        if self.lag_levels() {
            for j in 0..n {
                put(FeatureKind::Lag(j as u8));
            }
        }
        if self.lag_diffs() {
            for j in 0..n {
                put(FeatureKind::LagDiff(j as u8));
            }
        }
        order.get(i).copied().flatten()
    }
}

/// One feature vector: the first `len` values of `values` are in use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Features {
    values: [f64; MAX_FEATURES],
    len: u8,
}

impl Features {
    /// The features in use.
    pub fn as_slice(&self) -> &[f64] {
        self.values.get(..self.len as usize).unwrap_or(&[])
    }
    /// Number of features.
    pub fn len(&self) -> usize {
        self.len as usize
    }
    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// A step the pipeline emitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// Step number k since the first sample (gaps skip numbers).
    pub index: u64,
    /// Boundary time `t0 + k·P`, s (the sample that made it may be a little later).
    pub time_s: f64,
    /// The model inputs at this step.
    pub features: Features,
}

/// The streaming pipeline. Holds no references; keep one per gyro axis in static memory.
#[derive(Debug, Clone)]
pub struct FeaturePipeline {
    spec: FeatureSpec,
    rate_lag_steps: u64,
    window_steps: u64,
    /// `1 - exp(-P/τ_j)` for a one-step update.
    lag_gain: [f64; MAX_LAGS],
    /// Ring of (step index, T), oldest overwritten.
    hist: [(u64, f64); HISTORY_STEPS],
    hist_head: usize,
    hist_len: usize,
    lag_c: [f64; MAX_LAGS],
    t0_s: f64,
    last_time_s: f64,
    last_step: u64,
    started: bool,
    current: Features,
}

impl FeaturePipeline {
    /// A pipeline for `spec`, after checking it.
    pub fn new(spec: FeatureSpec) -> Result<Self, SpecError> {
        spec.validate()?;
        let p = spec.step_period_s;
        let rate_lag_steps = whole_steps(spec.rate_lag_s, p, 1, HISTORY_STEPS - 1).unwrap_or(1);
        let window_steps = if spec.has_smoothing() {
            whole_steps(spec.smoothing_window_s, p, 1, HISTORY_STEPS).unwrap_or(1)
        } else {
            0
        };
        let mut lag_gain = [0.0; MAX_LAGS];
        for (g, &tau) in lag_gain.iter_mut().zip(spec.lags()) {
            *g = -libm::expm1(-p / tau);
        }
        Ok(FeaturePipeline {
            spec,
            rate_lag_steps: rate_lag_steps as u64,
            window_steps: window_steps as u64,
            lag_gain,
            hist: [(0, 0.0); HISTORY_STEPS],
            hist_head: 0,
            hist_len: 0,
            lag_c: [0.0; MAX_LAGS],
            t0_s: 0.0,
            last_time_s: 0.0,
            last_step: 0,
            started: false,
            current: Features {
                values: [0.0; MAX_FEATURES],
                len: 0,
            },
        })
    }

    /// The spec in use.
    pub fn spec(&self) -> &FeatureSpec {
        &self.spec
    }

    /// Forget everything: the next sample is step 0 again.
    pub fn reset(&mut self) {
        self.hist_head = 0;
        self.hist_len = 0;
        self.lag_c = [0.0; MAX_LAGS];
        self.started = false;
        self.last_step = 0;
        self.current.len = 0;
    }

    /// The features of the latest step, held until the next one (None before the first sample).
    pub fn current(&self) -> Option<&Features> {
        if self.started {
            Some(&self.current)
        } else {
            None
        }
    }

    /// The `i`-th newest stored step (0 = newest).
    fn hist_back(&self, i: usize) -> (u64, f64) {
        // hist_head < HISTORY_STEPS and i < HISTORY_STEPS, so one wrap is enough.
        let back = self.hist_head + HISTORY_STEPS - 1 - i.min(HISTORY_STEPS - 1);
        let idx = if back >= HISTORY_STEPS {
            back - HISTORY_STEPS
        } else {
            back
        };
        self.hist.get(idx).copied().unwrap_or((0, 0.0))
    }

    /// Feed one sample. Returns `Ok(Some(step))` when the sample reaches a step boundary (the
    /// first sample always does), `Ok(None)` while holding between boundaries.
    ///
    /// Errors, with the pipeline left exactly as it was: `NonFinite(Time)`,
    /// `NonFinite(Temperature)`, `TimeNotIncreasing` (time not above the previous sample's),
    /// `TimeOutOfRange` (the step index since the first sample would reach
    /// [`MAX_STEP_INDEX`]; only [`reset`](Self::reset) makes the pipeline usable again).
    pub fn push(&mut self, time_s: f64, temp_c: f64) -> Result<Option<Step>, InputError> {
        if !time_s.is_finite() {
            return Err(InputError::NonFinite(Channel::Time));
        }
        if !temp_c.is_finite() {
            return Err(InputError::NonFinite(Channel::Temperature));
        }
        if !self.started {
            self.started = true;
            self.t0_s = time_s;
            self.last_time_s = time_s;
            self.last_step = 0;
            self.lag_c = [temp_c; MAX_LAGS];
            self.hist_len = 0;
            self.hist_head = 0;
            return Ok(Some(self.emit(0, 0, temp_c)));
        }
        if time_s <= self.last_time_s {
            return Err(InputError::TimeNotIncreasing);
        }
        let q = (time_s - self.t0_s) / self.spec.step_period_s + BOUNDARY_TOL_STEPS;
        // q > 0 and not NaN here. A huge or infinite q would saturate `as u64`, and every later sample
        // would fall on the same step and hold for good: refuse it instead.
        if q >= MAX_STEP_INDEX as f64 {
            return Err(InputError::TimeOutOfRange);
        }
        let k = libm::floor(q) as u64;
        self.last_time_s = time_s;
        if k <= self.last_step {
            return Ok(None);
        }
        let n = k - self.last_step;
        self.last_step = k;
        Ok(Some(self.emit(k, n, temp_c)))
    }

    /// Advance to step `k`, `n` steps after the previous one (0 for the first), with value `t`.
    fn emit(&mut self, k: u64, n: u64, t: f64) -> Step {
        let p = self.spec.step_period_s;
        // Lags first (they need the elapsed time only).
        let n_lags = (self.spec.n_lags as usize).min(MAX_LAGS);
        let lags = self.lag_c.iter_mut().zip(&self.lag_gain);
        for ((c, &g1), &tau) in lags.zip(&self.spec.lag_tau_s).take(n_lags) {
            let gain = if n == 1 {
                g1
            } else if n == 0 {
                0.0
            } else {
                -libm::expm1(-(n as f64) * p / tau)
            };
            *c += gain * (t - *c);
        }
        // History ring.
        if let Some(slot) = self.hist.get_mut(self.hist_head) {
            *slot = (k, t);
        }
        self.hist_head = if self.hist_head + 1 == HISTORY_STEPS {
            0
        } else {
            self.hist_head + 1
        };
        self.hist_len = (self.hist_len + 1).min(HISTORY_STEPS);
        // Rate: latest stored step at or before k - L, else the oldest stored.
        let mut earlier = self.hist_back(self.hist_len - 1);
        if let Some(target) = k.checked_sub(self.rate_lag_steps) {
            // Without gaps the entry L back is the one (O(1)); else search back.
            let l = self.rate_lag_steps as usize;
            let direct = if l < self.hist_len {
                Some(self.hist_back(l))
            } else {
                None
            };
            if let Some(e) = direct.filter(|e| e.0 == target) {
                earlier = e;
            } else {
                for i in 1..self.hist_len {
                    let e = self.hist_back(i);
                    if e.0 <= target {
                        earlier = e;
                        break;
                    }
                }
            }
        }
        let rate = if earlier.0 < k {
            (t - earlier.1) / ((k - earlier.0) as f64 * p)
        } else {
            0.0
        };
        let mut v = [0.0; MAX_FEATURES];
        let mut at = 0usize;
        let mut put = |x: f64| {
            if let Some(slot) = v.get_mut(at) {
                *slot = x;
                at += 1;
            }
        };
        put(t);
        put(rate);
        if self.window_steps > 0 {
            let mut sum = 0.0;
            let mut count = 0u32;
            for i in 0..self.hist_len {
                let e = self.hist_back(i);
                if k - e.0 >= self.window_steps {
                    break;
                }
                sum += e.1;
                count += 1;
            }
            put(sum / f64::from(count.max(1)));
        }
        if self.spec.lag_levels() {
            for &c in self.lag_c.iter().take(n_lags) {
                put(c);
            }
        }
        if self.spec.lag_diffs() {
            for &c in self.lag_c.iter().take(n_lags) {
                put(t - c);
            }
        }
        self.current = Features {
            values: v,
            len: at as u8,
        };
        Step {
            index: k,
            time_s: self.t0_s + k as f64 * p,
            features: self.current,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_spec_is_valid_and_has_two_features() {
        let p = FeaturePipeline::new(FeatureSpec::PUBLISHED).unwrap();
        assert_eq!(p.spec().n_features(), 2);
        assert_eq!(FeatureSpec::THERMAL_STATE.n_features(), 5);
        assert_eq!(
            FeatureSpec::THERMAL_STATE.kind(4),
            Some(FeatureKind::LagDiff(2))
        );
        assert_eq!(FeatureSpec::THERMAL_STATE.kind(5), None);
    }
}

//! The compensator: gyro output, temperature and time in; corrected rate out, sample by sample.
//!
//! G = (Ĝ - B) / K (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, eq. 4), where
//! B (°/s) and K (dimensionless, 1 nominal) come from two separate models (the paper's two
//! networks, §2) evaluated on the streaming features of [`crate::features`]. The models step
//! once per feature step (1 s by default) and their B and K are held between steps, so logs at
//! 1 Hz and at 100 Hz see the same model.
//!
//! [`Compensator`] is the one value flight code holds. Its [`Compensator::step`] is
//! panic-free and allocation-free for every input.

use crate::baseline::BaselineModel;
use crate::error::{Channel, InputError};
use crate::features::{FeaturePipeline, FeatureSpec, Features, SpecError, MAX_FEATURES};
use crate::lstm::{Lstm, LstmWeights};

/// Hidden units of the flight LSTM: 8, as published (He et al. 2024, §2).
pub const HIDDEN: usize = 8;

/// LSTM inputs in flight: every feature slot; slots beyond the spec's feature count are fed 0
/// (their weights are 0 after export).
pub const LSTM_INPUTS: usize = MAX_FEATURES;

/// An LSTM with its z-score normalisation: y = target_mean + target_std · lstm((x - mean)/std).
#[derive(Debug, Clone)]
pub struct NormalisedLstm {
    lstm: Lstm<LSTM_INPUTS, HIDDEN>,
    input_mean: [f64; MAX_FEATURES],
    input_std: [f64; MAX_FEATURES],
    n_inputs: usize,
    target_mean: f64,
    target_std: f64,
}

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
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::Spec(e) => write!(f, "feature spec: {e}"),
            ModelError::BadNormalisation => {
                f.write_str("normalisation has a non-finite value or a non-positive std")
            }
            ModelError::FeatureCount { expected, got } => {
                write!(f, "model takes {got} features, the spec gives {expected}")
            }
        }
    }
}

impl NormalisedLstm {
    /// Checked constructor: `input_mean`/`input_std` give the first `n_inputs` channels.
    pub fn new(
        weights: &LstmWeights<LSTM_INPUTS, HIDDEN>,
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
        mean[..n].copy_from_slice(input_mean);
        std[..n].copy_from_slice(input_std);
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
        for (k, slot) in x.iter_mut().enumerate().take(self.n_inputs) {
            let v = features.get(k).copied().unwrap_or(f64::NAN);
            let z = (v - self.input_mean[k]) / self.input_std[k];
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
pub struct TargetModel {
    /// Constant part (e.g. K = 1 when no scale-factor model was fitted).
    pub offset: f64,
    /// Fitted polynomial in the features.
    pub baseline: Option<BaselineModel>,
    /// LSTM (normalised), added to the rest.
    pub lstm: Option<NormalisedLstm>,
    /// When both a baseline and an LSTM are present: the LSTM's inputs are the features
    /// followed by the baseline's value (`n_features + 1` inputs). Ignored otherwise.
    pub lstm_reads_base: bool,
}

impl TargetModel {
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
                x[..n].copy_from_slice(&feats[..n]);
                x[n] = base;
                l.step(&x[..n + 1])?
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

/// A corrected sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corrected {
    /// Predicted bias B, °/s (held since the last feature step).
    pub bias_dps: f64,
    /// Predicted scale factor K, dimensionless (held since the last feature step).
    pub scale: f64,
    /// Compensated rate G = (Ĝ - B) / K, °/s.
    pub rate_dps: f64,
}

/// Bias and scale-factor models on one streaming feature pipeline (see the module doc).
#[derive(Debug, Clone)]
pub struct Compensator {
    pipeline: FeaturePipeline,
    bias: TargetModel,
    scale: TargetModel,
    held: Option<(f64, f64)>,
}

impl Compensator {
    /// Checked constructor: both models must read the spec's feature count.
    pub fn new(
        spec: FeatureSpec,
        bias: TargetModel,
        scale: TargetModel,
    ) -> Result<Self, ModelError> {
        let pipeline = FeaturePipeline::new(spec).map_err(ModelError::Spec)?;
        let n = spec.n_features();
        bias.check(n)?;
        scale.check(n)?;
        Ok(Compensator {
            pipeline,
            bias,
            scale,
            held: None,
        })
    }

    /// The feature specification.
    pub fn spec(&self) -> &FeatureSpec {
        self.pipeline.spec()
    }

    /// One sample: time (s, increasing), gyro output Ĝ (°/s), temperature (°C).
    ///
    /// Errors, each leaving the feature pipeline and the models untouched where the input is
    /// at fault: non-finite time, gyro or temperature, time not increasing. A model that gives a
    /// non-finite or non-positive scale factor is reported as
    /// `NonFinite(Channel::Temperature)` (the temperature drove it out of range). A finite
    /// gyro sample whose corrected rate is not finite (|Ĝ − B| / K beyond f64) is reported as
    /// `NonFinite(Channel::Gyro)`: every `Ok` rate is finite.
    pub fn step(
        &mut self,
        time_s: f64,
        gyro_dps: f64,
        temp_c: f64,
    ) -> Result<Corrected, InputError> {
        if !gyro_dps.is_finite() {
            return Err(InputError::NonFinite(Channel::Gyro));
        }
        if let Some(step) = self.pipeline.push(time_s, temp_c)? {
            let b = self.bias.eval(&step.features)?;
            let k = self.scale.eval(&step.features)?;
            if k <= 0.0 {
                return Err(InputError::NonFinite(Channel::Temperature));
            }
            self.held = Some((b, k));
        }
        // After the first accepted sample there is always a held value (step 0).
        let (bias_dps, scale) = match self.held {
            Some(v) => v,
            None => return Err(InputError::NonFinite(Channel::Temperature)),
        };
        let rate_dps = (gyro_dps - bias_dps) / scale;
        if !rate_dps.is_finite() {
            return Err(InputError::NonFinite(Channel::Gyro));
        }
        Ok(Corrected {
            bias_dps,
            scale,
            rate_dps,
        })
    }

    /// The feature vector of the latest step (None before the first sample).
    pub fn features(&self) -> Option<&Features> {
        self.pipeline.current()
    }

    /// Start over: clear the feature history, the LSTM states and the held values.
    pub fn reset(&mut self) {
        self.pipeline.reset();
        self.bias.reset();
        self.scale.reset();
        self.held = None;
    }
}

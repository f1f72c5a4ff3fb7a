//! Model-file checks: every sub-model's shapes, norms and terms, and the whole file's
//! plausibility over its training range (range probing).

use super::*;

impl SubModel {
    /// What the sub-model is made of: `"lstm"`, `"least squares"` or
    /// `"least squares + lstm"`.
    pub fn kind(&self) -> &'static str {
        match self {
            SubModel::Lstm { .. } => "lstm",
            SubModel::Baseline { .. } => "least squares",
            SubModel::Residual { .. } => "least squares + lstm",
        }
    }

    /// The LSTM part, if any: parameters, input and target normalisation.
    pub fn lstm(&self) -> Option<(&LstmParams, &ZScore, &ZScore)> {
        match self {
            SubModel::Lstm {
                params,
                input_norm,
                target_norm,
            }
            | SubModel::Residual {
                params,
                input_norm,
                target_norm,
                ..
            } => Some((params, input_norm, target_norm)),
            SubModel::Baseline { .. } => None,
        }
    }

    /// Whether the residual LSTM reads the least-squares base value as one more input.
    pub fn reads_base(&self) -> bool {
        matches!(
            self,
            SubModel::Residual {
                lstm_reads_base: true,
                ..
            }
        )
    }

    /// A baseline sub-model from a fit.
    pub fn from_fit(fit: &baseline::BaselineFit) -> SubModel {
        SubModel::Baseline {
            terms: fit.terms.clone(),
            coefficients: fit.coefficients.clone(),
        }
    }

    /// The flight evaluator of a baseline sub-model (None for an LSTM).
    pub fn baseline_core(&self) -> Option<Result<BaselineModel, BaselineError>> {
        match self {
            SubModel::Baseline {
                terms,
                coefficients,
            }
            | SubModel::Residual {
                terms,
                coefficients,
                ..
            } => Some(baseline::to_core(terms, coefficients)),
            SubModel::Lstm { .. } => None,
        }
    }

    /// Shapes and finiteness for `n_features` inputs; the message names the tensor at fault.
    pub fn validate(&self, n_features: usize) -> Result<(), SubModelError> {
        match self {
            SubModel::Residual {
                terms,
                coefficients,
                params,
                input_norm,
                target_norm,
                lstm_reads_base,
            } => {
                SubModel::Baseline {
                    terms: terms.clone(),
                    coefficients: coefficients.clone(),
                }
                .validate(n_features)?;
                let lstm_inputs = n_features + usize::from(*lstm_reads_base);
                if lstm_inputs > gyrotherm_core::features::MAX_FEATURES {
                    return Err(SubModelError::Invalid(format!(
                        "lstm_reads_base: {n_features} features plus the base value exceed the \
                         flight LSTM's {} inputs",
                        gyrotherm_core::features::MAX_FEATURES
                    )));
                }
                SubModel::Lstm {
                    params: params.clone(),
                    input_norm: input_norm.clone(),
                    target_norm: target_norm.clone(),
                }
                .validate(lstm_inputs)
                .map_err(|e| {
                    if *lstm_reads_base {
                        SubModelError::ReadsBase(Box::new(e))
                    } else {
                        e
                    }
                })
            }
            SubModel::Lstm {
                params,
                input_norm,
                target_norm,
            } => {
                params.validate().map_err(SubModelError::Params)?;
                if params.input_size != n_features {
                    return Err(SubModelError::Invalid(format!(
                        "params.input_size is {} but the feature definition gives {n_features} features",
                        params.input_size
                    )));
                }
                check_norm("input_norm", input_norm, n_features)?;
                check_norm("target_norm", target_norm, 1)
            }
            SubModel::Baseline {
                terms,
                coefficients,
            } => {
                terms.validate().map_err(SubModelError::Terms)?;
                if terms.n_features != n_features {
                    return Err(SubModelError::Invalid(format!(
                        "terms.n_features is {} but the feature definition gives {n_features} features",
                        terms.n_features
                    )));
                }
                if coefficients.len() != terms.len() {
                    return Err(SubModelError::Invalid(format!(
                        "coefficients has {} values for {} terms",
                        coefficients.len(),
                        terms.len()
                    )));
                }
                if let Some(k) = coefficients.iter().position(|c| !c.is_finite()) {
                    return Err(SubModelError::Invalid(format!(
                        "coefficients[{k}] is not finite"
                    )));
                }
                if let Some(k) = coefficients
                    .iter()
                    .position(|c| c.abs() > MAX_PLAUSIBLE_COEFFICIENT)
                {
                    return Err(SubModelError::Invalid(format!(
                        "coefficients[{k}] is {:e}: implausibly large (|c| ≤ {MAX_PLAUSIBLE_COEFFICIENT:e}); \
                         re-train, or check a hand edit",
                        coefficients[k]
                    )));
                }
                Ok(())
            }
        }
    }
}

pub(super) fn check_norm(name: &str, z: &ZScore, channels: usize) -> Result<(), SubModelError> {
    if z.mean.len() != channels || z.std.len() != channels {
        return Err(SubModelError::Invalid(format!(
            "{name} has {} means and {} stds, expected {channels} each",
            z.mean.len(),
            z.std.len()
        )));
    }
    if let Some(k) = z.mean.iter().position(|v| !v.is_finite()) {
        return Err(SubModelError::Invalid(format!(
            "{name}.mean[{k}] is not finite"
        )));
    }
    if let Some(k) = z.std.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(SubModelError::Invalid(format!(
            "{name}.std[{k}] is {}: must be finite and > 0",
            z.std[k]
        )));
    }
    Ok(())
}

/// A further sensor of an axis in the training-range check
/// ([`ModelFile::check_outputs_with_further`]): its features and its parts of B and K.
pub(crate) type FurtherPart<'a> = (
    &'a FeatureSpec,
    Option<&'a BaselineModel>,
    Option<&'a BaselineModel>,
);

/// A sub-model that cannot be evaluated: the tensor or field at fault.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SubModelError {
    /// The LSTM parameters.
    Params(ParamsError),
    /// The least-squares terms.
    Terms(TermsError),
    /// A field's value (the message names the field).
    Invalid(String),
    /// The LSTM part, which reads the features plus the base value.
    ReadsBase(Box<SubModelError>),
}

impl std::fmt::Display for SubModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SubModelError::Params(e) => e.fmt(f),
            SubModelError::Terms(_) => f.write_str("terms"),
            SubModelError::Invalid(m) => f.write_str(m),
            SubModelError::ReadsBase(_) => {
                f.write_str("lstm_reads_base (the LSTM reads the features plus the base value)")
            }
        }
    }
}

impl std::error::Error for SubModelError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the parameters' message is this error's own.
            SubModelError::Params(e) => e.source(),
            SubModelError::Terms(e) => Some(e),
            SubModelError::ReadsBase(e) => Some(e.as_ref()),
            SubModelError::Invalid(_) => None,
        }
    }
}

impl ModelFile {
    /// Check everything [`load`](Self::load) checks after parsing; the message names the field.
    pub fn validate(&self) -> Result<(), ModelFileError> {
        if !SUPPORTED_VERSIONS.contains(&self.format_version) {
            return Err(ModelFileError::UnsupportedVersion {
                found: self.format_version.to_string(),
            });
        }
        let spec = self.features.to_spec()?;
        self.features.temp_sensor.to_core()?;
        if let Some(c) = &self.columns {
            c.validate()?;
        }
        let nf = spec.n_features();
        if self.bias.is_none() && self.scale.is_none() {
            return Err(ModelFileError::invalid(
                "",
                "neither a bias nor a scale model: nothing to compensate".to_owned(),
            ));
        }
        for (target, sub) in [(Target::Bias, &self.bias), (Target::Scale, &self.scale)] {
            let Some(sub) = sub else { continue };
            let name = target.as_str();
            if matches!(self.method, Method::Linear | Method::Poly)
                && matches!(sub, SubModel::Lstm { .. } | SubModel::Residual { .. })
            {
                return Err(ModelFileError::invalid(
                    name,
                    format!(
                        "an lstm sub-model in a model whose method is {}",
                        self.method.as_str()
                    ),
                ));
            }
            sub.validate(nf)
                .map_err(|source| ModelFileError::SubModel { target, source })?;
        }
        let t = &self.training;
        for (name, r) in [
            ("temp_range_c", t.temp_range_c),
            ("rate_range_c_per_s", t.rate_range_c_per_s),
        ] {
            if !(r.min.is_finite() && r.max.is_finite() && r.min <= r.max) {
                return Err(ModelFileError::invalid(
                    &format!("training.{name}"),
                    format!(
                        "min {} and max {} must be finite with min ≤ max",
                        r.min, r.max
                    ),
                ));
            }
        }
        let d = &t.data_digest_sha256;
        if d.len() != 64 || !d.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(ModelFileError::invalid(
                "training.data_digest_sha256",
                format!("{d:?} is not 64 hexadecimal digits"),
            ));
        }
        if let Some(l) = t.final_loss {
            if !l.is_finite() {
                return Err(ModelFileError::Invalid {
                    field: "training.final_loss".to_owned(),
                    problem: format!("{l}, must be finite"),
                });
            }
        }
        if let Some(c) = &self.coverage {
            c.to_core()
                .map_err(|e| ModelFileError::invalid("coverage", e.to_string()))?;
        }
        self.check_outputs_in_training_range(&spec)
    }

    /// Runs the bias and scale models through the training range (holds at its lowest,
    /// middle and highest temperature, ramps between them at its fastest rates, each long
    /// enough for the slowest lag to settle) and refuses a model whose bias is not finite or
    /// beyond [`MAX_PLAUSIBLE_BIAS_DPS`], or whose scale factor leaves [`PLAUSIBLE_SCALE`]
    /// (K ≤ 0 included) anywhere on the way. The message names the target, T and dT.
    pub(super) fn check_outputs_in_training_range(
        &self,
        spec: &FeatureSpec,
    ) -> Result<(), ModelFileError> {
        self.check_outputs_with_further(spec, &[])
    }

    /// [`check_outputs_in_training_range`](Self::check_outputs_in_training_range) of the
    /// model with further sensors' parts added to B and K (an axis of an inertial unit that
    /// reads several sensors, as its flight compensator adds them): each further sensor runs
    /// its own features over the same temperatures as the first, the one training range the
    /// file keeps.
    pub(crate) fn check_outputs_with_further(
        &self,
        spec: &FeatureSpec,
        further: &[FurtherPart<'_>],
    ) -> Result<(), ModelFileError> {
        let size = hidden_size([self.bias.as_ref(), self.scale.as_ref()])
            .map_err(|e| ModelFileError::invalid("lstm", e.to_string()))?;
        crate::flight_size::with_hidden!(size, H => self.check_outputs_sized::<H>(spec, further))
    }

    /// [`check_outputs_with_further`](Self::check_outputs_with_further) with the LSTMs run
    /// at `H` hidden units.
    fn check_outputs_sized<const H: usize>(
        &self,
        spec: &FeatureSpec,
        further: &[FurtherPart<'_>],
    ) -> Result<(), ModelFileError> {
        use gyrotherm_core::features::FeaturePipeline;
        let t = &self.training;
        let (t_lo, t_hi) = (t.temp_range_c.min, t.temp_range_c.max);
        let (r_lo, r_hi) = (t.rate_range_c_per_s.min, t.rate_range_c_per_s.max);
        let dt = spec.step_period_s;
        let slowest = further
            .iter()
            .flat_map(|(s, _, _)| s.lags())
            .chain(spec.lags())
            .fold(spec.rate_lag_s, |a, &b| a.max(b));
        let hold = ((3.0 * slowest / dt).ceil() as usize + 2).min(MAX_PROBE_STEPS);
        let ramp = |from: f64, to: f64, rate: f64| -> Vec<f64> {
            let n = ((to - from) / (rate * dt)).ceil();
            let n = if n.is_finite() && n > 0.0 {
                (n as usize).min(MAX_PROBE_STEPS)
            } else {
                0
            };
            (0..=n).map(|k| from + rate * dt * k as f64).collect()
        };
        let mut probes: Vec<Vec<f64>> = [t_lo, 0.5 * t_lo + 0.5 * t_hi, t_hi]
            .iter()
            .map(|&temp| vec![temp; hold])
            .collect();
        if r_hi > 0.0 {
            probes.push(ramp(t_lo, t_hi, r_hi));
        }
        if r_lo < 0.0 {
            probes.push(ramp(t_hi, t_lo, r_lo));
        }
        let field = |target: Target| {
            if further.is_empty() {
                target.as_str().to_owned()
            } else {
                format!("{} with the further sensors' parts", target.as_str())
            }
        };
        let build = |target: Target, sub: Option<&SubModel>, absent: f64| {
            target_model::<H>(sub, absent)
                .map_err(|e| ModelFileError::invalid(target.as_str(), e.to_string()))
        };
        let bias0 = build(Target::Bias, self.bias.as_ref(), 0.0)?;
        let scale0 = build(Target::Scale, self.scale.as_ref(), 1.0)?;
        for temps in probes {
            let (mut bias, mut scale) = (bias0.clone(), scale0.clone());
            let mut pipeline = FeaturePipeline::new(*spec).map_err(ModelFileError::Features)?;
            let mut more = further
                .iter()
                .map(|(s, _, _)| FeaturePipeline::new(**s).map_err(ModelFileError::Features))
                .collect::<Result<Vec<_>, _>>()?;
            for (k, &temp) in temps.iter().enumerate() {
                let time_s = k as f64 * dt;
                let mut more_ok = true;
                for p in &mut more {
                    more_ok = p.push(time_s, temp).is_ok() && more_ok;
                }
                let Ok(Some(step)) = pipeline.push(time_s, temp) else {
                    continue;
                };
                // The further sensors' parts, as the flight compensator adds them.
                let (mut b_more, mut k_more) = (0.0, 0.0);
                for (p, (_, b, k)) in more.iter().zip(further) {
                    let f = p.current().filter(|_| more_ok);
                    let eval = |m: Option<&BaselineModel>| match (m, f) {
                        (None, _) => 0.0,
                        (Some(m), Some(f)) => m.eval_features(f).unwrap_or(f64::NAN),
                        (Some(_), None) => f64::NAN,
                    };
                    b_more += eval(*b);
                    k_more += eval(*k);
                }
                let rate = (0..spec.n_features())
                    .find(|&i| spec.kind(i) == Some(FeatureKind::Rate))
                    .and_then(|i| step.features.as_slice().get(i).copied())
                    .unwrap_or(0.0);
                let at = || {
                    format!("at T = {temp:.3} °C, dT = {rate:.3e} °C/s, inside the training range ({t_lo} to {t_hi} °C, {r_lo:.3e} to {r_hi:.3e} °C/s)")
                };
                let b = bias.eval(&step.features).unwrap_or(f64::NAN) + b_more;
                if !(b.is_finite() && b.abs() <= MAX_PLAUSIBLE_BIAS_DPS) {
                    return Err(ModelFileError::invalid(
                        &field(Target::Bias),
                        format!(
                            "predicts B = {b:e} °/s {}: not a gyro bias (|B| ≤ {MAX_PLAUSIBLE_BIAS_DPS} °/s); re-train, or check a hand edit",
                            at()
                        ),
                    ));
                }
                let k_sf = scale.eval(&step.features).unwrap_or(f64::NAN) + k_more;
                let (k_lo, k_hi) = PLAUSIBLE_SCALE;
                if !(k_sf >= k_lo && k_sf <= k_hi) {
                    return Err(ModelFileError::invalid(
                        &field(Target::Scale),
                        format!(
                            "predicts K = {k_sf:e} {}: a scale factor must stay within {k_lo} to {k_hi} (nominal 1); re-train, or check a hand edit",
                            at()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

//! What a model reads: its features (lags and their outputs) and its temperature sensor's
//! plausibility limits.

use gyrotherm_core::compensator::TempLimits;
use gyrotherm_core::features::{FeatureSpec, LagOutputs, MAX_LAGS};
use serde::{Deserialize, Serialize};

use super::ModelFileError;

/// [`LagOutputs`] in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LagOutputsDef {
    /// Lag outputs y_j.
    Level,
    /// T - y_j.
    DiffFromT,
    /// Both.
    Both,
}

/// The feature definition in the file (the core's [`FeatureSpec`], with the lags as a list).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeatureDef {
    /// Model step period, s.
    pub step_period_s: f64,
    /// Rate lag, s (dT = (T(t) - T(t - lag)) / lag).
    pub rate_lag_s: f64,
    /// Moving-average window of T, s (0: none).
    pub smoothing_window_s: f64,
    /// Thermal-state lag time constants, s.
    pub lag_tau_s: Vec<f64>,
    /// Which lag outputs are features.
    pub lag_outputs: LagOutputsDef,
    /// Which temperature readings are believed (absent in older files: the defaults).
    #[serde(default)]
    pub temp_sensor: TempSensorDef,
}

/// Temperature-sensor fault limits in the file (the core's [`TempLimits`]): a reading outside
/// `min_c..=max_c`, or changing faster than `max_rate_c_per_s` (plus `step_allowance_c`)
/// since the last good one, is held; held longer than `degraded_after_s` is degraded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TempSensorDef {
    /// Lowest plausible reading, °C.
    pub min_c: f64,
    /// Highest plausible reading, °C.
    pub max_c: f64,
    /// Fastest plausible change, °C/s.
    pub max_rate_c_per_s: f64,
    /// Change always allowed between readings, °C.
    pub step_allowance_c: f64,
    /// Seconds without a good reading before the output is degraded.
    pub degraded_after_s: f64,
}

impl Default for TempSensorDef {
    fn default() -> Self {
        Self::from_core(&TempLimits::DEFAULT)
    }
}

impl TempSensorDef {
    /// The file form of core limits.
    pub(crate) fn from_core(l: &TempLimits) -> Self {
        TempSensorDef {
            min_c: l.min_c,
            max_c: l.max_c,
            max_rate_c_per_s: l.max_rate_c_per_s,
            step_allowance_c: l.step_allowance_c,
            degraded_after_s: l.degraded_after_s,
        }
    }

    /// The core limits, checked (the error names `features.temp_sensor`).
    pub fn to_core(&self) -> Result<TempLimits, ModelFileError> {
        let l = TempLimits {
            min_c: self.min_c,
            max_c: self.max_c,
            max_rate_c_per_s: self.max_rate_c_per_s,
            step_allowance_c: self.step_allowance_c,
            degraded_after_s: self.degraded_after_s,
        };
        l.validate()
            .map_err(|e| ModelFileError::invalid("features.temp_sensor", e.to_string()))?;
        Ok(l)
    }
}

impl FeatureDef {
    /// The file form of `spec`.
    pub fn from_spec(spec: &FeatureSpec) -> FeatureDef {
        FeatureDef {
            step_period_s: spec.step_period_s,
            rate_lag_s: spec.rate_lag_s,
            smoothing_window_s: spec.smoothing_window_s,
            lag_tau_s: spec.lags().to_vec(),
            lag_outputs: match spec.lag_outputs {
                LagOutputs::Level => LagOutputsDef::Level,
                LagOutputs::DiffFromT => LagOutputsDef::DiffFromT,
                LagOutputs::Both => LagOutputsDef::Both,
            },
            temp_sensor: TempSensorDef::default(),
        }
    }

    /// The core spec, checked.
    pub fn to_spec(&self) -> Result<FeatureSpec, ModelFileError> {
        if self.lag_tau_s.len() > MAX_LAGS {
            return Err(ModelFileError::invalid(
                "features",
                format!(
                    "{} lag time constants, at most {MAX_LAGS} supported",
                    self.lag_tau_s.len()
                ),
            ));
        }
        let base = FeatureSpec {
            step_period_s: self.step_period_s,
            rate_lag_s: self.rate_lag_s,
            smoothing_window_s: self.smoothing_window_s,
            ..FeatureSpec::PUBLISHED
        };
        let outputs = match self.lag_outputs {
            LagOutputsDef::Level => LagOutputs::Level,
            LagOutputsDef::DiffFromT => LagOutputs::DiffFromT,
            LagOutputsDef::Both => LagOutputs::Both,
        };
        base.with_lags(&self.lag_tau_s, outputs)
            .map_err(ModelFileError::Features)
    }
}

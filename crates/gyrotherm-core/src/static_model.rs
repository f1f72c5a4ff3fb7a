//! A compensation model as plain static data: what `gyrotherm export --target rust` writes, so
//! flight code builds its [`Compensator`] without parsing JSON.
//!
//! ```
//! use gyrotherm_core::features::FeatureSpec;
//! use gyrotherm_core::static_model::{StaticBaseline, StaticModel, StaticTarget};
//! use gyrotherm_core::{Compensator, TempLimits};
//!
//! // bias = 1e-3 + 2e-5·T °/s; no scale-factor model (K = 1).
//! const fn powers() -> [[u8; 12]; 16] {
//!     let mut p = [[0u8; 12]; 16];
//!     p[1][0] = 1; // term 1: T
//!     p
//! }
//! static MODEL: StaticModel = StaticModel {
//!     spec: FeatureSpec::PUBLISHED,
//!     limits: TempLimits::DEFAULT,
//!     bias: StaticTarget {
//!         offset: 0.0,
//!         baseline: Some(StaticBaseline {
//!             n_features: 2,
//!             n_terms: 2,
//!             powers: powers(),
//!             coefficients: [1e-3, 2e-5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
//!                            0.0, 0.0, 0.0],
//!         }),
//!         lstm: None,
//!         lstm_reads_base: false,
//!     },
//!     scale: StaticTarget::constant(1.0),
//!     coverage: None,
//! };
//! let mut c = Compensator::from_static(&MODEL).unwrap();
//! let out = c.step(0.0, 0.01, 20.0);
//! assert!((out.bias_dps - (1e-3 + 2e-5 * 20.0)).abs() < 1e-15);
//! // No coverage map in this model: no verdict.
//! assert!(MODEL.coverage_map().is_none());
//! ```
//!
//! With a map ([`StaticCoverage`]), the verdict of each sample is
//! `map.verdict_of(c.features())`, `map` built once by [`StaticModel::coverage_map`].

use crate::baseline::{BaselineModel, MAX_TERMS};
use crate::compensator::{
    Compensator, ModelError, NormalisedLstm, TargetModel, TempLimits, HIDDEN, LSTM_INPUTS,
};
use crate::coverage::{CoverageError, CoverageMap, Grid, MAX_RATE_CELLS, MAX_TEMP_CELLS};
use crate::features::{FeatureSpec, MAX_FEATURES};
use crate::lstm::LstmWeights;

/// A whole model: feature definition, sensor limits, bias and scale-factor models.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticModel<const H: usize = HIDDEN> {
    /// The model inputs.
    pub spec: FeatureSpec,
    /// Temperature-sensor fault limits.
    pub limits: TempLimits,
    /// Bias model, °/s.
    pub bias: StaticTarget<H>,
    /// Scale-factor model (dimensionless, ≈ 1).
    pub scale: StaticTarget<H>,
    /// The training region and its error (None: the model file has no coverage map).
    pub coverage: Option<StaticCoverage>,
}

/// A coverage map as plain data (see [`crate::coverage`]): `sigma_dph[i · n_rate + j]` is
/// the σ (°/h) of temperature cell i and rate cell j, 0 where training did not cover the cell;
/// the slots after the first `n_temp · n_rate` are unused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticCoverage {
    /// The geometry.
    pub grid: Grid,
    /// σ per cell, row-major by temperature.
    pub sigma_dph: [f64; MAX_TEMP_CELLS * MAX_RATE_CELLS],
    /// Growth of σ per cell of distance outside the covered cells.
    pub growth_per_cell: f64,
}

impl StaticCoverage {
    /// The checked map, as [`CoverageMap::new`] checks it.
    pub fn to_map(&self) -> Result<CoverageMap, CoverageError> {
        let n = self.grid.n_temp.saturating_mul(self.grid.n_rate);
        // More cells than the slots hold is a cell count the map refuses anyway.
        let sigma = self.sigma_dph.get(..n).ok_or(CoverageError::CellCount)?;
        CoverageMap::new(self.grid, sigma, self.growth_per_cell)
    }
}

impl<const H: usize> StaticModel<H> {
    /// The model's coverage map, checked (None: the model has none).
    pub fn coverage_map(&self) -> Option<Result<CoverageMap, CoverageError>> {
        self.coverage.as_ref().map(StaticCoverage::to_map)
    }
}

/// One target: `offset + baseline(features) + lstm(features)` (see [`TargetModel`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticTarget<const H: usize = HIDDEN> {
    /// Constant part.
    pub offset: f64,
    /// Polynomial part.
    pub baseline: Option<StaticBaseline>,
    /// LSTM part.
    pub lstm: Option<StaticLstm<H>>,
    /// The LSTM reads the features followed by the baseline's value.
    pub lstm_reads_base: bool,
}

impl<const H: usize> StaticTarget<H> {
    /// A target that is always `value`.
    pub const fn constant(value: f64) -> Self {
        StaticTarget {
            offset: value,
            baseline: None,
            lstm: None,
            lstm_reads_base: false,
        }
    }
}

/// A polynomial in the features: term `j` is `coefficients[j] · Π_i x_i^powers[j][i]`, for
/// the first `n_terms` terms over the first `n_features` features.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticBaseline {
    pub n_features: u8,
    pub n_terms: u8,
    pub powers: [[u8; MAX_FEATURES]; MAX_TERMS],
    pub coefficients: [f64; MAX_TERMS],
}

/// An LSTM (PyTorch layout, `LSTM_INPUTS` input slots of which the first `n_inputs` are used,
/// the rest with zero weights; `H` hidden units) with its z-score normalisation.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticLstm<const H: usize = HIDDEN> {
    pub w_ih: [[[f32; LSTM_INPUTS]; H]; 4],
    pub w_hh: [[[f32; H]; H]; 4],
    pub b_ih: [[f32; H]; 4],
    pub b_hh: [[f32; H]; 4],
    pub w_out: [f32; H],
    pub b_out: f32,
    pub n_inputs: u8,
    pub input_mean: [f64; MAX_FEATURES],
    pub input_std: [f64; MAX_FEATURES],
    pub target_mean: f64,
    pub target_std: f64,
}

impl StaticBaseline {
    /// The checked model.
    pub fn to_model(&self) -> Result<BaselineModel, ModelError> {
        let mut m = BaselineModel::new(self.n_features as usize).map_err(ModelError::Baseline)?;
        let terms = self.powers.iter().zip(&self.coefficients);
        for (powers, &c) in terms.take(self.n_terms as usize) {
            let p = powers.get(..self.n_features as usize).unwrap_or(&[]);
            m.push_term(p, c).map_err(ModelError::Baseline)?;
        }
        Ok(m)
    }
}

/// A further sensor of an axis as plain data (see [`crate::multi`]): the index of its reading
/// among the unit's temperatures, its feature definition (the axis's step period and rate
/// lag, its own lags) and its parts of the bias and the scale factor (no constant).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticSensor {
    /// Index of the sensor's reading among the unit's temperatures.
    pub channel: u8,
    /// Its features.
    pub spec: FeatureSpec,
    /// Its part of the bias, °/s.
    pub bias: Option<StaticBaseline>,
    /// Its part of the scale factor.
    pub scale: Option<StaticBaseline>,
}

impl<const H: usize> StaticTarget<H> {
    /// The compensator's model of this target, checked as [`Compensator::from_static`]
    /// checks it.
    pub fn to_target(&self) -> Result<TargetModel<H>, ModelError> {
        let baseline = match &self.baseline {
            None => None,
            Some(b) => Some(b.to_model()?),
        };
        let lstm = match &self.lstm {
            None => None,
            Some(l) => {
                let w = LstmWeights::new(l.w_ih, l.w_hh, l.b_ih, l.b_hh, l.w_out, l.b_out)
                    .map_err(ModelError::Weights)?;
                let n = l.n_inputs as usize;
                let mean = l.input_mean.get(..n).ok_or(ModelError::FeatureCount {
                    expected: MAX_FEATURES,
                    got: n,
                })?;
                let std = l.input_std.get(..n).unwrap_or(&[]);
                Some(NormalisedLstm::new(
                    &w,
                    mean,
                    std,
                    l.target_mean,
                    l.target_std,
                )?)
            }
        };
        Ok(TargetModel {
            offset: self.offset,
            baseline,
            lstm,
            lstm_reads_base: self.lstm_reads_base,
        })
    }
}

impl<const H: usize> Compensator<H> {
    /// The compensator of a static model, checked like [`Compensator::with_limits`].
    pub fn from_static(m: &StaticModel<H>) -> Result<Compensator<H>, ModelError> {
        Compensator::with_limits(m.spec, m.bias.to_target()?, m.scale.to_target()?, m.limits)
    }
}

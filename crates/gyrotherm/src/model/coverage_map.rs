//! The coverage map a model file carries: the (T, dT) region training covered and the
//! cross-validated bias error there (how training makes it: [`crate::coverage`]).
//!
//! In the file (`"coverage"`, absent in files written before it, and for LSTM bias models,
//! which cannot be re-fitted per fold in reasonable time):
//! ```json
//! "coverage": {"temp_min_c": -45.0, "temp_cell_c": 6.5, "n_temp": 16,
//!              "rate_min_c_per_s": -0.06, "rate_cell_c_per_s": 0.01, "n_rate": 12,
//!              "folds": 5, "count": [...], "rms_dph": [...], "sigma_dph": [...],
//!              "growth_per_cell": 1.5}
//! ```
//! with one value per cell, row-major by temperature.

use gyrotherm_core::coverage::{CoverageError, CoverageMap, Grid};
use serde::{Deserialize, Serialize};

/// The coverage map in the model file (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoverageDef {
    /// Lower edge of the first temperature cell, °C.
    pub temp_min_c: f64,
    /// Temperature cell width, °C.
    pub temp_cell_c: f64,
    /// Temperature cells.
    pub n_temp: usize,
    /// Lower edge of the first rate cell, °C/s.
    pub rate_min_c_per_s: f64,
    /// Rate cell width, °C/s.
    pub rate_cell_c_per_s: f64,
    /// Rate cells.
    pub n_rate: usize,
    /// Cross-validation folds.
    pub folds: usize,
    /// Held-out steps per cell.
    pub count: Vec<u64>,
    /// RMS of the held-out residual per cell, °/h (0 where the count is 0).
    pub rms_dph: Vec<f64>,
    /// σ per cell, °/h (0: not covered).
    pub sigma_dph: Vec<f64>,
    /// Growth of σ per cell of distance outside the covered cells.
    pub growth_per_cell: f64,
}

impl CoverageDef {
    /// The grid geometry.
    pub fn grid(&self) -> Grid {
        Grid {
            temp_min_c: self.temp_min_c,
            temp_cell_c: self.temp_cell_c,
            n_temp: self.n_temp,
            rate_min_c_per_s: self.rate_min_c_per_s,
            rate_cell_c_per_s: self.rate_cell_c_per_s,
            n_rate: self.n_rate,
        }
    }

    /// The flight crate's map, checked (also the count and RMS lists' lengths).
    pub fn to_core(&self) -> Result<CoverageMap, CoverageError> {
        let n = self.n_temp.saturating_mul(self.n_rate);
        if self.count.len() != n || self.rms_dph.len() != n {
            return Err(CoverageError::SigmaLength);
        }
        if self.rms_dph.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(CoverageError::Sigma);
        }
        CoverageMap::new(self.grid(), &self.sigma_dph, self.growth_per_cell)
    }

    /// Covered cells.
    pub fn covered_cells(&self) -> usize {
        self.sigma_dph.iter().filter(|s| **s > 0.0).count()
    }

    /// Pooled RMS of the held-out residual over all cells, °/h.
    pub(crate) fn pooled_rms_dph(&self) -> f64 {
        let (ss, n) = self
            .count
            .iter()
            .zip(&self.rms_dph)
            .fold((0.0, 0u64), |(ss, n), (&c, &r)| {
                (ss + c as f64 * r * r, n + c)
            });
        (ss / n.max(1) as f64).sqrt()
    }

    /// The same map with other σ scale and growth (for calibration): σ of every cell times
    /// `scale`.
    pub fn rescaled(&self, scale: f64, growth_per_cell: f64) -> CoverageDef {
        CoverageDef {
            sigma_dph: self.sigma_dph.iter().map(|s| s * scale).collect(),
            growth_per_cell,
            ..self.clone()
        }
    }
}

//! A log's path through a model's coverage map, sample by sample: the (T, dT) the flight
//! compensator computed and its verdict, for the report's coverage figures and for
//! `gyrotherm plan`. The samples are stepped exactly as `compensate` steps them
//! ([`crate::coverage::shares`] counts the same verdicts).

use gyrotherm_core::coverage::{Coverage, Verdict};

use crate::compensate::{compensator, CompensateError};
use crate::csvlog::TestLog;
use crate::model::CoverageDef;
use crate::model::ModelFile;

/// One value per sample of the log (NaN / None before the compensator's first feature
/// vector, or where it refused the sample).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CoverageTrack {
    /// Temperature feature, °C.
    pub temp_c: Vec<f64>,
    /// Temperature-rate feature, °C/s.
    pub rate_c_per_s: Vec<f64>,
    /// Verdict against the training region.
    pub verdict: Vec<Option<Verdict>>,
}

impl CoverageTrack {
    /// Shares of the samples with a verdict that are inside, edge and outside (None when
    /// no sample got one).
    pub fn shares(&self) -> Option<[f64; 3]> {
        let mut n = [0u64; 3];
        for v in self.verdict.iter().flatten() {
            n[v.coverage as usize] += 1;
        }
        let total: u64 = n.iter().sum();
        (total > 0).then(|| n.map(|k| k as f64 / total as f64))
    }

    /// Coverage of each sample.
    pub fn coverage(&self) -> Vec<Option<Coverage>> {
        self.verdict.iter().map(|v| v.map(|v| v.coverage)).collect()
    }

    /// σ of each sample, °/h (NaN without a verdict).
    pub fn sigma_dph(&self) -> Vec<f64> {
        self.verdict
            .iter()
            .map(|v| v.map_or(f64::NAN, |v| v.sigma_dph))
            .collect()
    }
}

/// The track of `log` under `model`'s coverage map; None when the model has no (valid) map.
pub fn track(model: &ModelFile, log: &TestLog) -> Result<Option<CoverageTrack>, CompensateError> {
    let Some(map) = model.coverage.as_ref().and_then(|c| c.to_core().ok()) else {
        return Ok(None);
    };
    let mut comp = compensator(model)?;
    let n = log.len();
    let mut out = CoverageTrack {
        temp_c: Vec::with_capacity(n),
        rate_c_per_s: Vec::with_capacity(n),
        verdict: Vec::with_capacity(n),
    };
    for i in 0..n {
        comp.step(log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        let f = comp.features().map(|f| f.as_slice()).unwrap_or(&[]);
        let (t, r) = match f {
            [t, r, ..] => (*t, *r),
            _ => (f64::NAN, f64::NAN),
        };
        out.temp_c.push(t);
        out.rate_c_per_s.push(r);
        out.verdict.push(map.verdict_of(comp.features()));
    }
    Ok(Some(out))
}

/// One covered cell of a map: its temperature span (°C) and rate span (°C/s), and σ (°/h).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoveredCell {
    pub temp_c: (f64, f64),
    pub rate_c_per_s: (f64, f64),
    pub sigma_dph: f64,
}

/// The covered cells of `def`, row-major by temperature.
pub fn covered_cells(def: &CoverageDef) -> Vec<CoveredCell> {
    let mut out = Vec::new();
    for i in 0..def.n_temp {
        for j in 0..def.n_rate {
            let s = def
                .sigma_dph
                .get(i * def.n_rate + j)
                .copied()
                .unwrap_or(0.0);
            if s > 0.0 {
                let t0 = def.temp_min_c + i as f64 * def.temp_cell_c;
                let r0 = def.rate_min_c_per_s + j as f64 * def.rate_cell_c_per_s;
                out.push(CoveredCell {
                    temp_c: (t0, t0 + def.temp_cell_c),
                    rate_c_per_s: (r0, r0 + def.rate_cell_c_per_s),
                    sigma_dph: s,
                });
            }
        }
    }
    out
}

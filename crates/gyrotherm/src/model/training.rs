//! What a model file records of its training: the data's ranges and digest, and who made it.

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::csvlog::TestLog;
use crate::features::FeatureTable;

/// A closed range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    pub min: f64,
    pub max: f64,
}

impl Range {
    /// (min, max) of `x` (None if empty).
    pub fn of(x: &[f64]) -> Option<Range> {
        if x.is_empty() {
            return None;
        }
        let (min, max) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        Some(Range { min, max })
    }
    /// True when `v` lies inside.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// Training temperature range (feature 0, °C) and rate range (feature 1, °C/s) over the
/// steps of `tables` (None if there are no steps).
pub fn training_ranges(tables: &[&FeatureTable]) -> Option<(Range, Range)> {
    let mut t = Vec::new();
    let mut r = Vec::new();
    for tab in tables {
        if tab.n_features >= 2 {
            t.extend(tab.column(0));
            r.extend(tab.column(1));
        }
    }
    Some((Range::of(&t)?, Range::of(&r)?))
}

/// How the model was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingInfo {
    /// Temperature range seen in training, °C.
    pub temp_range_c: Range,
    /// Temperature-rate (dT) range seen in training, °C/s.
    pub rate_range_c_per_s: Range,
    /// SHA-256 (lower-case hex) of the training inputs, see [`data_digest`].
    pub data_digest_sha256: String,
    /// Training epochs (None for a least-squares fit).
    #[serde(default)]
    pub epochs: Option<u64>,
    /// Final training loss (normalised MSE for LSTMs; RMS residual for baselines).
    #[serde(default)]
    pub final_loss: Option<f64>,
    /// Random seed (None when nothing was random).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Program and version that wrote the file, e.g. `gyrotherm 0.1.0`.
    pub created_by: String,
    /// Names of the training input files.
    pub inputs: Vec<String>,
}

/// `gyrotherm <version>`, for [`TrainingInfo::created_by`].
pub fn created_by() -> String {
    format!("gyrotherm {}", env!("CARGO_PKG_VERSION"))
}

/// Digest of training logs: SHA-256 over, per log in order, the sample count (u64 LE), then
/// `time_s`, `gyro_dps`, `temp_c` as f64 LE bytes, then a table flag byte and `table_dps` if
/// present. Pass-through columns are not included. Same numbers, same digest.
pub fn data_digest(logs: &[&TestLog]) -> String {
    let mut h = Sha256::new();
    for log in logs {
        h.update((log.len() as u64).to_le_bytes());
        for col in [&log.time_s, &log.gyro_dps, &log.temp_c] {
            for v in col.iter() {
                h.update(v.to_le_bytes());
            }
        }
        match &log.table_dps {
            Some(t) => {
                h.update([1u8]);
                for v in t {
                    h.update(v.to_le_bytes());
                }
            }
            None => h.update([0u8]),
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

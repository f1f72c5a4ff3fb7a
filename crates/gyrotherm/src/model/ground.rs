//! A sub-model's output over a whole feature table, on the ground in f64, the LSTM starting
//! from zero state at the table's first row (as flight code starts at a log's first sample):
//! how `auto` scores its candidates on a held-out run, and how a model whose LSTM size
//! flight code does not run yet is evaluated in memory.

use super::*;
use crate::nn::{predict, TrainError};

/// Why a sub-model could not be run over a table: its LSTM's shapes do not fit the table's
/// features.
pub(crate) type GroundPredictError = TrainError;

impl SubModel {
    /// The sub-model's output (bias °/s, or scale factor) at every row of `table`.
    pub fn predict_table(&self, table: &FeatureTable) -> Result<Vec<f64>, GroundPredictError> {
        let n = table.n_rows();
        let base: Vec<f64> = match self {
            SubModel::Baseline {
                terms,
                coefficients,
            }
            | SubModel::Residual {
                terms,
                coefficients,
                ..
            } => (0..n)
                .map(|r| baseline::evaluate(terms, coefficients, table.row(r)))
                .collect(),
            SubModel::Lstm { .. } => vec![0.0; n],
        };
        let Some((params, input_norm, target_norm)) = self.lstm() else {
            return Ok(base);
        };
        let reads_base = self.reads_base();
        let n_in = table.n_features + usize::from(reads_base);
        let mut x = Vec::with_capacity(n * n_in);
        for (r, b) in base.iter().enumerate() {
            let row = table.row(r);
            let extra = reads_base.then_some(*b);
            for (c, v) in row.iter().copied().chain(extra).enumerate() {
                x.push(input_norm.apply(c, v));
            }
        }
        let y = predict(params, &x)?;
        Ok(base
            .iter()
            .zip(&y)
            .map(|(b, z)| b + z * target_norm.std[0] + target_norm.mean[0])
            .collect())
    }
}

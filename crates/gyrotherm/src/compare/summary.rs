//! The comparison as `gyrotherm compare --json` prints it (serialised, never assembled).

use std::collections::BTreeMap;

use serde::Serialize;

use super::{CompareConfig, Comparison, FailedColumn, Performance};

/// The comparison as `gyrotherm compare --json` prints it: per held-out log the raw and
/// per-method performance, per model what was fitted and how its training went.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonSummary {
    /// Bias-stability smoothing time, s.
    pub tau_s: f64,
    /// What to read first: one line per held-out log on which every model judged is worse
    /// than the raw output ([`Comparison::headline`]); empty otherwise.
    pub headline: Vec<String>,
    pub tests: Vec<TestSummary>,
    pub models: Vec<ModelSummary>,
    /// Columns whose fit failed, with why (not in `models`, nor in any test's `methods`).
    pub failed: Vec<FailedColumn>,
}

/// One held-out log in a [`ComparisonSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TestSummary {
    pub name: String,
    #[serde(rename = "static")]
    pub is_static: bool,
    pub floor_dph: Option<f64>,
    pub raw: Performance,
    /// Keyed by column ([`Candidate::key`](super::Candidate::key): `"linear"`, `"poly"`,
    /// `"lstm"`, `"published"`).
    pub methods: BTreeMap<&'static str, Performance>,
    /// Fitted columns that could not compensate or be judged on this log, with why.
    pub failed: Vec<FailedColumn>,
    pub warnings: Vec<String>,
}

/// One fitted model in a [`ComparisonSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSummary {
    /// The column's key, as in [`TestSummary::methods`].
    pub key: &'static str,
    pub method: &'static str,
    /// The LSTM recipe (method `lstm` only).
    pub recipe: Option<&'static str>,
    /// The name its column has in the table: what the model holds
    /// ([`ModelFile::label`](crate::model::ModelFile::label)), or `LSTM, He et al.` for the
    /// published recipe.
    pub label: &'static str,
    /// Kind of the bias and scale-factor sub-models (None: not fitted).
    pub bias_model: Option<&'static str>,
    pub scale_model: Option<&'static str>,
    pub bias_epochs: Option<usize>,
    pub bias_final_loss: Option<f64>,
    pub scale_epochs: Option<usize>,
    pub scale_final_loss: Option<f64>,
    /// Why a residual LSTM was kept or left out: the relative validation-loss reduction on
    /// the validation blocks and, with `validate_on_runs`, on each left-out training run
    /// (fractions; None where not measured).
    pub bias_lstm_validation_improvement: Option<f64>,
    pub bias_lstm_run_gate: Option<Vec<f64>>,
    pub scale_lstm_validation_improvement: Option<f64>,
    pub scale_lstm_run_gate: Option<Vec<f64>>,
}

impl Comparison {
    /// The serialisable summary (no per-sample data).
    pub fn summary(&self, cfg: &CompareConfig) -> ComparisonSummary {
        ComparisonSummary {
            tau_s: cfg.tau_s,
            headline: self.headline(cfg),
            failed: self.failed.clone(),
            tests: self
                .tests
                .iter()
                .map(|t| TestSummary {
                    name: t.name.clone(),
                    is_static: t.is_static,
                    floor_dph: t.floor_dph.filter(|v| v.is_finite()),
                    raw: t.raw.clone(),
                    methods: t
                        .methods
                        .iter()
                        .map(|m| (m.key, m.performance.clone()))
                        .collect(),
                    failed: t.failed.clone(),
                    warnings: t.warnings.clone(),
                })
                .collect(),
            models: self
                .fits
                .iter()
                .zip(&self.columns)
                .zip(&cfg.candidates)
                .map(|((f, col), cand)| {
                    let (b, s) = (f.bias_training.as_ref(), f.scale_training.as_ref());
                    ModelSummary {
                        key: col.key,
                        method: f.model.method.as_str(),
                        recipe: f
                            .model
                            .method
                            .is_recipe()
                            .then(|| cand.fit_config(&cfg.fit).recipe.kind.as_str()),
                        label: col.label,
                        bias_model: f.model.bias.as_ref().map(|b| b.kind()),
                        scale_model: f.model.scale.as_ref().map(|b| b.kind()),
                        bias_epochs: b.map(|t| t.epochs),
                        bias_final_loss: b.map(|t| t.final_loss),
                        scale_epochs: s.map(|t| t.epochs),
                        scale_final_loss: s.map(|t| t.final_loss),
                        bias_lstm_validation_improvement: b.and_then(|t| t.val_improvement),
                        bias_lstm_run_gate: b.and_then(|t| t.run_gate.clone()),
                        scale_lstm_validation_improvement: s.and_then(|t| t.val_improvement),
                        scale_lstm_run_gate: s.and_then(|t| t.run_gate.clone()),
                    }
                })
                .collect(),
        }
    }
}

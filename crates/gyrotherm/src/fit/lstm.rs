//! LSTM recipes: how the LSTM method turns target sets into a fitted sub-model.
//!
//! `Published`: exactly He et al. 2024 (DOI 10.19452/j.issn1007-5453.2024.02.004, §2–3):
//! inputs T and its 20 s rate, 8 hidden units, the whole run as one sequence, one Adam step per
//! epoch at lr 0.01, 1000 epochs, MSE on z-scored data.

use crate::features::FeatureSpec;
use crate::model::SubModel;
use crate::targets::TargetSet;
use crate::train::{train_normalised, Bptt, Sequence, TrainConfig};

/// Which recipe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecipeKind {
    /// As published (see the module doc).
    Published,
}

/// An LSTM recipe and its knobs.
#[derive(Debug, Clone, PartialEq)]
pub struct LstmRecipe {
    pub kind: RecipeKind,
    /// Adam steps (epochs); 1000 as published.
    pub epochs: usize,
}

impl LstmRecipe {
    /// The published recipe.
    pub fn published() -> Self {
        LstmRecipe {
            kind: RecipeKind::Published,
            epochs: 1000,
        }
    }
}

impl Default for LstmRecipe {
    fn default() -> Self {
        Self::published()
    }
}

/// What training reports besides the model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrainSummary {
    /// Training loss per epoch (normalised MSE).
    pub loss_history: Vec<f64>,
    /// Epochs run.
    pub epochs: usize,
    /// Last training loss.
    pub final_loss: f64,
}

/// The feature specification a recipe's models read.
pub fn feature_spec(recipe: &LstmRecipe) -> FeatureSpec {
    match recipe.kind {
        RecipeKind::Published => FeatureSpec::PUBLISHED,
    }
}

/// Fit one target (bias or scale factor) on the training runs.
pub fn fit_target(
    train: &[TargetSet],
    recipe: &LstmRecipe,
    seed: u64,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, TrainSummary), String> {
    let n_in = train
        .first()
        .map(|t| t.table.n_features)
        .ok_or("no training runs")?;
    let runs: Vec<Sequence> = train
        .iter()
        .map(|t| Sequence::new(&t.table.rows, &t.target).with_mask(&t.mask))
        .collect();
    let cfg = TrainConfig {
        epochs: recipe.epochs,
        seed,
        bptt: Bptt::Full,
        ..TrainConfig::default()
    };
    let fit = train_normalised(&runs, &[], n_in, &cfg, progress).map_err(|e| e.to_string())?;
    let summary = TrainSummary {
        epochs: fit.output.loss_history.len(),
        final_loss: fit.output.loss_history.last().copied().unwrap_or(f64::NAN),
        loss_history: fit.output.loss_history,
    };
    Ok((
        SubModel::Lstm {
            params: fit.output.params,
            input_norm: fit.input_z,
            target_norm: fit.target_z,
        },
        summary,
    ))
}

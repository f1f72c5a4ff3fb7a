//! The published recipe, exactly He et al. 2024 (DOI 10.19452/j.issn1007-5453.2024.02.004,
//! §2–3): inputs T and its 20 s rate, 8 hidden units, the whole run as one sequence, one Adam
//! step per epoch at lr 0.01, 1000 epochs, MSE on z-scored data. Kept for comparison: it
//! stalls and does worse than a linear fit on a held-out run
//! (`docs/experiments/lstm-recipes.md`).

use super::error::FitError;
use super::recipe::{LstmVerdict, RecipeSettings, TrainSummary};
use crate::model::{SubModel, Target};
use crate::nn::{train_normalised, Bptt, Sequence, TrainConfig};
use crate::settings::method::Method;
use crate::targets::TargetSet;

impl RecipeSettings {
    /// The published recipe.
    pub fn published() -> Self {
        RecipeSettings {
            kind: Method::Published,
            epochs: 1000,
            lr: 0.01,
            ..Self::residual()
        }
    }
}

pub(crate) fn fit(
    train: &[TargetSet],
    recipe: &RecipeSettings,
    _target: Target,
    n_in: usize,
    seed: u64,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, TrainSummary), FitError> {
    let runs: Vec<Sequence> = train
        .iter()
        .map(|t| Sequence::new(&t.table.rows, &t.target).with_mask(&t.mask))
        .collect();
    let cfg = TrainConfig {
        hidden_size: recipe.hidden,
        epochs: recipe.epochs,
        lr: recipe.lr,
        seed,
        bptt: Bptt::Full,
        ..TrainConfig::default()
    };
    let fit = train_normalised(&runs, &[], n_in, &cfg, progress)?;
    let summary = TrainSummary {
        epochs: fit.output.loss_history.len(),
        final_loss: fit.output.loss_history.last().copied().unwrap_or(f64::NAN),
        loss_history: fit.output.loss_history,
        lstm_verdict: Some(LstmVerdict::Kept),
        ..TrainSummary::default()
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

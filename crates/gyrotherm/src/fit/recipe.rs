//! A fitting recipe (the recipe methods `thermal`, `residual`, `generic`, `direct`,
//! `published`): which one, its knobs, and what training reports. The recipes themselves
//! are one module each ([`super::published`], [`super::residual`], [`super::generic`],
//! [`super::direct`]).

use super::select::TermSelection;
use super::terms::BaseTerms;
use crate::nn::LrSchedule;
use crate::settings::method::Method;

/// A recipe and its knobs: how a recipe method fits (not called an LSTM recipe: the
/// thermal recipe holds no LSTM) (knobs marked `Residual` apply to `Generic` and `Direct` too).
#[derive(Debug, Clone, PartialEq)]
pub struct RecipeSettings {
    /// The recipe method these knobs train ([`Method::is_own_recipe`]).
    pub kind: Method,
    /// Maximum epochs: Adam steps for `Published` (1000 as published); passes over all
    /// training windows for `Residual`.
    pub epochs: usize,
    /// Adam learning rate (0.01 as published).
    pub lr: f64,
    /// Hidden units of the LSTM (8 as published:
    /// `DEFAULT_HIDDEN`).
    pub hidden: usize,
    /// `Residual`: steps per truncated-BPTT window.
    pub window: usize,
    /// `Residual`: leading steps of each window (and of each block) left out of the loss.
    pub burn_in: usize,
    /// `Residual`: windows per Adam step.
    pub batch: usize,
    /// `Residual`: steps per block when cutting the training runs for validation.
    pub block_steps: usize,
    /// `Residual`: every this-many-th block is held out for validation (0: none; then the
    /// last parameters are kept).
    pub validation_every: usize,
    /// `Residual`: stop after this many epochs without a better validation loss.
    pub patience: Option<usize>,
    /// `Residual`: also fit a residual LSTM to the scale factor (default: baseline only).
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub scale_lstm: bool,
    #[cfg(not(feature = "experiments"))]
    pub(crate) scale_lstm: bool,
    /// `Residual`: the least relative validation-loss reduction for which the residual LSTM is
    /// kept; below it the sub-model is the physical fit alone.
    pub min_val_improvement: f64,
    /// `Residual`: least-squares base of the bias model.
    pub base: BaseTerms,
    /// `Residual`: least-squares base of the scale-factor model.
    pub scale_base: BaseTerms,
    /// `Residual`: centred moving average (steps) applied to the base's residual before the
    /// LSTM is trained on it (1: none), to take the sensor noise out of its target.
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub residual_smooth_steps: usize,
    #[cfg(not(feature = "experiments"))]
    pub(crate) residual_smooth_steps: usize,
    /// `Residual`: the LSTM reads the base (least-squares) prediction as one more input after
    /// the features, so that its correction can depend on the predicted level
    /// ([`SubModel::Residual::lstm_reads_base`](crate::model::SubModel::Residual)). Off by
    /// default: not a consistent held-out improvement (`docs/experiments/lstm-base-input.md`).
    pub base_input: bool,
    /// `Residual`: with two or more training runs, the LSTM is also kept only if, trained
    /// without each run in turn, it lowers that run's residual by `min_val_improvement`
    /// (the held-out-run question; see [`TrainSummary::run_gate`]). Off by default: on the
    /// held-out sweep it changed no outcome for the better on balance
    /// (`docs/experiments/lstm-run-gate.md`).
    pub validate_on_runs: bool,
    /// `Residual`: minibatch truncated BPTT ([`Bptt::Sampled`](crate::nn::Bptt)): each epoch
    /// is one Adam step on `batch` windows drawn at random over the training blocks, instead
    /// of a pass over tiled windows (`epochs` then counts Adam steps).
    pub sampled_windows: bool,
    /// `Residual`: the learning-rate schedule over the Adam steps.
    pub lr_schedule: LrSchedule,
}

/// What training reports besides the model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrainSummary {
    /// Training loss per epoch (normalised MSE).
    pub loss_history: Vec<f64>,
    /// Validation loss per epoch (normalised MSE; empty without validation).
    pub val_loss_history: Vec<f64>,
    /// Epoch whose parameters were kept (chosen by validation), if any.
    pub best_epoch: Option<usize>,
    /// Epochs run.
    pub epochs: usize,
    /// Last training loss (for a baseline-only model: RMS residual in target units).
    pub final_loss: f64,
    /// RMS residual of the least-squares baseline over the labelled steps, target units
    /// (`Residual` only).
    pub baseline_rms: Option<f64>,
    /// Gain the residual LSTM's output was scaled by, chosen on the validation blocks
    /// (`Residual` with an LSTM only; 0: the LSTM did not help there and contributes nothing).
    pub lstm_gain: Option<f64>,
    /// Relative reduction of the validation loss by the residual LSTM against no correction,
    /// `1 - best / epoch-0` (`Residual` with validation only).
    pub val_improvement: Option<f64>,
    /// How the least-squares terms were chosen (base [`BaseTerms::Selected`] only): every
    /// candidate's cross-validated RMS residual, so the choice can be checked.
    pub selection: Option<TermSelection>,
    /// Leave-one-run-out check of the residual LSTM (two or more training runs and
    /// [`RecipeSettings::validate_on_runs`]): per training run, the relative loss reduction on
    /// that run by an LSTM trained on the other runs' residuals (0: no help). The LSTM is kept
    /// only if every entry reaches [`RecipeSettings::min_val_improvement`].
    pub run_gate: Option<Vec<f64>>,
    /// Whether the residual LSTM was kept, and if not which check left it out (`Residual`
    /// with an LSTM trained only).
    pub lstm_verdict: Option<LstmVerdict>,
    /// What the thermal recipe identified and which degradations it took (`Thermal` only).
    pub thermal: Option<super::thermal::ThermalReport>,
    /// RMS of the base's residual on the validation blocks, target units: of the base alone
    /// and of the base with the LSTM as kept (equal when it was left out). `Residual` with an
    /// LSTM and validation blocks only.
    pub held_out_rms: Option<(f64, f64)>,
}

/// What became of a trained residual LSTM.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LstmVerdict {
    /// Kept in the model (scaled by [`TrainSummary::lstm_gain`]).
    Kept,
    /// Left out; the flags say which check it failed (neither: its validation gain fell
    /// below `MIN_GAIN`).
    LeftOut {
        /// It did not beat the base by [`RecipeSettings::min_val_improvement`] on the validation
        /// blocks.
        validation_blocks: bool,
        /// It did not do so on every left-out run ([`TrainSummary::run_gate`]).
        left_out_runs: bool,
    },
}

impl LstmVerdict {
    /// What became of the LSTM, as a sentence fragment (`kept`, `left out: …`).
    pub fn text(&self) -> &'static str {
        match self {
            LstmVerdict::Kept => "kept",
            LstmVerdict::LeftOut {
                validation_blocks: true,
                left_out_runs: true,
            } => {
                "left out: it beat the least-squares base neither on the validation blocks nor \
                 on every left-out run"
            }
            LstmVerdict::LeftOut {
                validation_blocks: true,
                left_out_runs: false,
            } => "left out: it did not beat the least-squares base on the validation blocks",
            LstmVerdict::LeftOut {
                validation_blocks: false,
                left_out_runs: true,
            } => "left out: it did not beat the least-squares base on every left-out run",
            LstmVerdict::LeftOut {
                validation_blocks: false,
                left_out_runs: false,
            } => "left out: its correction fitted none of the validation residual",
        }
    }
}

/// Below this validation gain the residual LSTM is dropped and the sub-model is the physical
/// fit alone (a gain this small changes the output by less than 0.1 % of the LSTM's swing).
pub(crate) const MIN_GAIN: f64 = 1e-3;

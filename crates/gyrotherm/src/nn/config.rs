//! What training reads and returns: runs, settings, the result.
//!
//! Defaults are the published recipe (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004,
//! §2–3): hidden 8, Adam lr 0.01, 1000 iterations, MSE; one Adam step per epoch over whole
//! runs (full BPTT). Inputs and targets must already be normalised (see
//! [`ZScore`](super::ZScore)), or use [`train_normalised`](super::train_normalised), which fits
//! the z-scores and returns them with the parameters.

use super::params::LstmParams;

/// One run: inputs (steps × I, row-major), target (steps) and an optional loss mask.
#[derive(Debug, Clone, Copy)]
pub struct Sequence<'a> {
    /// Normalised inputs, `steps·I` values, row-major (step t is `inputs[t·I..(t+1)·I]`).
    pub inputs: &'a [f64],
    /// Normalised target, one per step.
    pub target: &'a [f64],
    /// `Some(m)`: only steps with `m[t] == true` count in the loss (a masked target may be NaN).
    pub loss_mask: Option<&'a [bool]>,
}

impl<'a> Sequence<'a> {
    /// A run with every step in the loss.
    pub fn new(inputs: &'a [f64], target: &'a [f64]) -> Self {
        Sequence {
            inputs,
            target,
            loss_mask: None,
        }
    }

    /// The same run with a loss mask (`true`: the step counts).
    pub fn with_mask(self, loss_mask: &'a [bool]) -> Self {
        Sequence {
            loss_mask: Some(loss_mask),
            ..self
        }
    }

    pub(crate) fn steps(&self) -> usize {
        self.target.len()
    }

    pub(crate) fn counts(&self, t: usize) -> bool {
        self.loss_mask.is_none_or(|m| m[t])
    }
}

/// How gradients flow through time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bptt {
    /// Full BPTT over each whole run; one Adam step per epoch (the published recipe).
    Full,
    /// Truncated BPTT over windows of `window` steps, `batch` windows per Adam step.
    ///
    /// Windows start every `window - burn_in` steps, so the counted parts tile each run. The
    /// first `burn_in` steps of a window are left out of the loss, except in a run's first
    /// window, whose start state (zero) is exact. Window start states: see [`WindowStart`].
    /// No gradient flows into a window's start state. Windows are shuffled each epoch with
    /// the seeded rng. An epoch is one pass over all windows.
    Truncated {
        /// Steps per window (> burn_in).
        window: usize,
        /// Leading steps of each window left out of the loss.
        burn_in: usize,
        /// Windows per Adam step (≥ 1).
        batch: usize,
        /// Where window start states come from.
        start: WindowStart,
    },
    /// Minibatch truncated BPTT over windows drawn at random: one epoch is one Adam step on
    /// `batch` windows of `window` steps, each start drawn uniformly over every start in the
    /// training runs (a run shorter than `window` is one window, whole). Every window starts
    /// from zero state and its first `burn_in` steps are left out of the loss. The windows of
    /// a batch run side by side as matrix products, split over all cores; the result does not
    /// depend on the number of cores.
    Sampled {
        /// Steps per window (> burn_in).
        window: usize,
        /// Leading steps of each window left out of the loss.
        burn_in: usize,
        /// Windows per Adam step (≥ 1).
        batch: usize,
    },
}

/// How the learning rate changes over the Adam steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LrSchedule {
    /// `lr` throughout (the published recipe).
    #[default]
    Constant,
    /// Cosine decay from `lr` to 0 over the planned Adam steps S: before step k (from 0) the
    /// rate is `lr·(1 + cos(π k / S))/2`, as PyTorch's `CosineAnnealingLR(T_max = S,
    /// eta_min = 0)`. S is `epochs` for full and sampled BPTT, `epochs` times the batches per
    /// epoch for tiled truncated BPTT.
    Cosine,
}

/// Start state of a truncated-BPTT window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowStart {
    /// Carried: at the start of each epoch the network runs forward over each whole run with
    /// the current parameters and the states at the window starts are kept for that epoch
    /// (so they lag the Adam steps within the epoch by at most one epoch).
    Carried,
    /// Zero state at every window start; `burn_in` then lets the state settle.
    Zero,
}

/// Float type of the forward/backward kernel. Parameters, Adam state and gradient sums over
/// runs are f64 in both cases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// f64 throughout (matches PyTorch float64 to ~1e-12).
    F64,
    /// f32 forward/backward (twice the SIMD width; like PyTorch's default).
    F32,
}

/// Training settings. `Default` is the published recipe.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainConfig {
    /// Hidden units H. Default 8 (He et al. 2024, §2).
    pub hidden_size: usize,
    /// Epochs (maximum). Default 1000 (He et al. 2024, §3).
    pub epochs: usize,
    /// Adam learning rate. Default 0.01 (He et al. 2024, §3).
    pub lr: f64,
    /// Adam β1. Default 0.9.
    pub beta1: f64,
    /// Adam β2. Default 0.999.
    pub beta2: f64,
    /// Adam ε. Default 1e-8.
    pub eps: f64,
    /// Seed of the ChaCha8 rng for the initial weights (and window shuffling). Default 0.
    pub seed: u64,
    /// Clip the gradient to this Euclidean norm before each Adam step. Default None.
    pub clip_grad_norm: Option<f64>,
    /// Stop as soon as an epoch's training loss is at or below this. Default None.
    pub target_loss: Option<f64>,
    /// Full or truncated BPTT. Default [`Bptt::Full`].
    pub bptt: Bptt,
    /// Kernel float type. Default [`Precision::F32`].
    pub precision: Precision,
    /// With validation runs: stop after this many epochs without a new best validation loss.
    /// Default None (run all epochs, still return the best parameters).
    pub patience: Option<usize>,
    /// Learning-rate schedule. Default [`LrSchedule::Constant`].
    pub lr_schedule: LrSchedule,
    /// Worker threads of [`Bptt::Sampled`] (0: one per core). The result is the same for
    /// any number. Default 0.
    pub threads: usize,
    /// Start the output layer (`w_out`, `b_out`) at zero, so the untrained network predicts
    /// the target mean: for a residual network, epoch 0 is then "no correction", and early
    /// stopping on validation can choose it. Default false (PyTorch init throughout).
    pub zero_output_init: bool,
}

impl Default for TrainConfig {
    fn default() -> Self {
        TrainConfig {
            hidden_size: 8,
            epochs: 1000,
            lr: 0.01,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
            seed: 0,
            clip_grad_norm: None,
            target_loss: None,
            bptt: Bptt::Full,
            precision: Precision::F32,
            patience: None,
            lr_schedule: LrSchedule::Constant,
            threads: 0,
            zero_output_init: false,
        }
    }
}

/// Why training stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// All epochs done.
    Epochs,
    /// Training loss reached `target_loss`.
    TargetLoss,
    /// No validation improvement for `patience` epochs.
    Patience,
}

/// What training returns.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainOutput {
    /// The trained parameters: the best by validation loss when validation runs were given,
    /// else the last.
    pub params: LstmParams,
    /// Training MSE per epoch (full BPTT: of the parameters before that epoch's Adam step;
    /// truncated: mean over the epoch's batches; sampled: of the epoch's batch, before its
    /// step).
    pub loss_history: Vec<f64>,
    /// Validation MSE per epoch (of the parameters before that epoch's step); empty without
    /// validation runs.
    pub val_loss_history: Vec<f64>,
    /// Epoch (0-based) whose parameters were returned, when chosen by validation.
    pub best_epoch: Option<usize>,
    /// Why it stopped.
    pub stop: StopReason,
}

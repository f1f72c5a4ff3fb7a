//! Why training (or an evaluation) refused its input or stopped.

use super::params::ParamsError;

/// Training or evaluation refused its input, or training diverged. `set` is "training",
/// "validation" or "evaluation"; `run` counts from 0 within it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TrainError {
    /// No training runs were given.
    NoRuns,
    /// The input or hidden size is zero.
    ZeroSize {
        input_size: usize,
        hidden_size: usize,
    },
    /// A run has no steps.
    EmptyRun { set: &'static str, run: usize },
    /// A run's input values are not `steps × input_size`.
    InputLength {
        set: &'static str,
        run: usize,
        values: usize,
        steps: usize,
        input_size: usize,
    },
    /// A run's loss mask is not one entry per step.
    MaskLength {
        set: &'static str,
        run: usize,
        mask: usize,
        steps: usize,
    },
    /// An input value is not finite.
    NonFiniteInput {
        set: &'static str,
        run: usize,
        input: usize,
        step: usize,
        value: f64,
    },
    /// A counted target value is not finite.
    NonFiniteTarget {
        set: &'static str,
        run: usize,
        step: usize,
        value: f64,
    },
    /// Every step of the set is masked out.
    AllMasked { set: &'static str },
    /// Adam settings out of range.
    AdamSettings {
        lr: f64,
        eps: f64,
        beta1: f64,
        beta2: f64,
    },
    /// A gradient-norm clip that is not positive.
    ClipGradNorm { value: f64 },
    /// Truncated-BPTT window settings that cannot work.
    Window {
        window: usize,
        burn_in: usize,
        batch: usize,
    },
    /// Sampled windows: no training run is longer than the burn-in, so no window has a step
    /// in the loss.
    RunsTooShort { burn_in: usize },
    /// Sampled windows: no batch with a counted step was drawn (the loss mask leaves too few
    /// steps past the burn-ins).
    NoCountedWindow { tries: usize },
    /// The parameters became non-finite at an Adam step.
    DivergedAtStep { step: u64 },
    /// The loss became non-finite at an epoch.
    DivergedAtEpoch { epoch: usize, loss: f64 },
    /// A training thread panicked.
    ThreadPanicked,
    /// The parameters given are unusable.
    Params(ParamsError),
    /// Forward-pass inputs are not a whole, non-zero number of steps.
    PredictInput { values: usize, input_size: usize },
    /// The initial state has the wrong size.
    InitialState {
        h: usize,
        c: usize,
        hidden_size: usize,
    },
    /// An input or initial-state value (flat index) is not finite.
    NonFiniteState { index: usize },
}

impl std::fmt::Display for TrainError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TrainError::NoRuns => f.write_str("no training runs given"),
            TrainError::ZeroSize {
                input_size,
                hidden_size,
            } => write!(
                f,
                "input size {input_size} and hidden size {hidden_size} must both be at least 1"
            ),
            TrainError::EmptyRun { set, run } => write!(f, "{set} run {run} has no steps"),
            TrainError::InputLength {
                set,
                run,
                values,
                steps,
                input_size,
            } => write!(
                f,
                "{set} run {run}: {values} input values for {steps} steps of {input_size} inputs \
                 (expected {})",
                steps * input_size
            ),
            TrainError::MaskLength {
                set,
                run,
                mask,
                steps,
            } => write!(
                f,
                "{set} run {run}: loss mask has {mask} entries for {steps} steps"
            ),
            TrainError::NonFiniteInput {
                set,
                run,
                input,
                step,
                value,
            } => write!(
                f,
                "{set} run {run}: input {input} at step {step} is not finite ({value}); drop or \
                 fill the sample"
            ),
            TrainError::NonFiniteTarget {
                set,
                run,
                step,
                value,
            } => write!(
                f,
                "{set} run {run}: target at step {step} is not finite ({value}); mask it out"
            ),
            TrainError::AllMasked { set } if *set == "training" => {
                f.write_str("every training step is masked out: nothing to fit")
            }
            TrainError::AllMasked { set } => write!(f, "every {set} step is masked out"),
            TrainError::AdamSettings {
                lr,
                eps,
                beta1,
                beta2,
            } => write!(
                f,
                "Adam settings out of range: lr {lr} and eps {eps} must be > 0, beta1 {beta1} \
                 and beta2 {beta2} in [0, 1)"
            ),
            TrainError::ClipGradNorm { value } => {
                write!(f, "clip_grad_norm {value} must be > 0")
            }
            TrainError::Window {
                window,
                burn_in,
                batch,
            } => write!(
                f,
                "truncated BPTT needs window > burn_in and batch ≥ 1 (window {window}, burn_in \
                 {burn_in}, batch {batch})"
            ),
            TrainError::RunsTooShort { burn_in } => write!(
                f,
                "every training run has at most burn_in = {burn_in} steps, so no window has a \
                 step in the loss; lower the burn-in or give longer runs"
            ),
            TrainError::NoCountedWindow { tries } => write!(
                f,
                "{tries} batches of windows drawn in a row had no step in the loss (the loss \
                 mask leaves too few steps past the burn-ins); lower the burn-in or unmask more"
            ),
            TrainError::DivergedAtStep { step } => write!(
                f,
                "training diverged at Adam step {step} (non-finite parameters); lower the \
                 learning rate or set clip_grad_norm"
            ),
            TrainError::DivergedAtEpoch { epoch, loss } => write!(
                f,
                "training diverged at epoch {epoch} (loss {loss}); lower the learning rate or \
                 set clip_grad_norm"
            ),
            TrainError::ThreadPanicked => f.write_str("training thread panicked"),
            TrainError::Params(e) => e.fmt(f),
            TrainError::PredictInput { values, input_size } => write!(
                f,
                "{values} input values is not a whole, non-zero number of steps of {input_size}"
            ),
            TrainError::InitialState { h, c, hidden_size } => write!(
                f,
                "initial state has {h} h and {c} c values, expected {hidden_size}"
            ),
            TrainError::NonFiniteState { index } => {
                write!(f, "input or initial state value {index} is not finite")
            }
        }
    }
}

impl std::error::Error for TrainError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the message is the parameters' own.
            TrainError::Params(e) => e.source(),
            _ => None,
        }
    }
}

impl From<ParamsError> for TrainError {
    fn from(e: ParamsError) -> Self {
        TrainError::Params(e)
    }
}

//! The LSTM network on the ground: its parameters, training and evaluation. The fitting
//! recipes that use it are in [`crate::fit`].
//!
//! - [`params`]: LSTM parameters in PyTorch layout (f64), shared by training, model files and
//!   export to the flight crate ([`LstmParams::to_core`](params::LstmParams::to_core)).
//! - [`zscore`]: the z-score normalisation that is part of every fitted model.
//! - [`adam`]: the Adam optimiser, arithmetic as `torch.optim.Adam`; gradient-norm clipping.
//! - `config`: runs ([`Sequence`]), settings ([`TrainConfig`]) and results ([`TrainOutput`]).
//! - `train`: [`train_lstm`], [`train_pair`] (two networks on two threads),
//!   [`train_normalised`]; `epochs`: the training loop (full or truncated BPTT, early
//!   stopping).
//! - `eval`: [`predict`], [`evaluate_mse`], [`loss_and_grad`] outside training.
//! - `lstm`, `kernel`, `checks`: the hand-written forward pass and backpropagation through
//!   time (f32 or f64), its buffers, and the input checks.
//! - `batch`: the same over a batch of windows side by side, as matrix products (minibatch
//!   truncated BPTT, [`Bptt::Sampled`]).
//! - `error`: [`TrainError`].

pub mod adam;
mod batch;
mod checks;
mod config;
mod epochs;
mod error;
mod eval;
mod kernel;
pub(crate) mod lstm;
pub mod params;
mod train;
pub mod zscore;

pub use config::{
    Bptt, LrSchedule, Precision, Sequence, StopReason, TrainConfig, TrainOutput, WindowStart,
};
pub use error::TrainError;
pub use eval::{
    batch_loss_and_grad, evaluate_mse, loss_and_grad, predict, predict_with_state, RunOutput,
};
pub use params::{init_params, LstmParams, ParamsError};
pub use train::{train_lstm, train_normalised, train_pair, NormalisedFit};
pub use zscore::ZScore;

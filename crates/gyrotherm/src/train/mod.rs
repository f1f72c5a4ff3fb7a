//! Training of compensation models on the ground.
//!
//! - [`params`]: LSTM parameters in PyTorch layout (f64), shared by training, model files and
//!   export to the flight crate ([`LstmParams::to_core`](params::LstmParams::to_core)).
//! - [`zscore`]: the z-score normalisation that is part of every fitted model.
//! - [`lstm`]: the hand-written forward pass and backpropagation through time (f32 or f64).
//! - [`adam`]: the Adam optimiser, arithmetic as `torch.optim.Adam`; gradient-norm clipping.
//! - [`trainer`]: MSE training over one or more runs, full or truncated BPTT, early stopping,
//!   two networks on two threads ([`train_pair`]).

pub mod adam;
pub mod lstm;
pub mod params;
pub mod trainer;
pub mod zscore;

pub use params::LstmParams;
pub use trainer::{
    evaluate_mse, flatten, init_params, loss_and_grad, loss_and_grad_in, predict,
    predict_with_state, train_lstm, train_normalised, train_pair, unflatten, Bptt, NormalisedFit,
    Precision, RunOutput, Sequence, StopReason, TrainConfig, TrainError, TrainOutput, WindowStart,
};
pub use zscore::ZScore;

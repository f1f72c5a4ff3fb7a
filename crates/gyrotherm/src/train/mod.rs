//! Training of compensation models on the ground.
//!
//! - [`params`]: LSTM parameters in PyTorch layout (f64), shared by training, model files and
//!   export to the flight crate.
//! - [`zscore`]: the z-score normalisation that is part of every fitted model.

pub mod params;
pub mod zscore;

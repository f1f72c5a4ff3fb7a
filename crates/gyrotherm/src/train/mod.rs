//! Training of compensation models on the ground.
//!
//! - [`params`]: LSTM parameters in PyTorch layout (f64), shared by training, model files and
//!   export to the flight crate.

pub mod params;

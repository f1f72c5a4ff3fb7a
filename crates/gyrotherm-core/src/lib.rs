//! gyrotherm-core: what flies.
//!
//! `#![no_std]`, no allocation, no panics on any input. Flight code holds one
//! [`Compensator`] and calls [`Compensator::step`] once per gyro sample.
//!
//! Layers:
//! - [`lstm`]: LSTM cell + linear read-out inference in f32, hidden size a const generic (8 by
//!   default, as in He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, §2).
//! - [`features`]: the streaming feature pipeline (temperature, its 20 s rate, moving average,
//!   first-order thermal lags), in f64: a 30,000 s run needs f64 time stamps, and it runs once
//!   per step (1 s), so the cost does not matter.
//! - [`baseline`]: evaluation of fitted linear/polynomial baseline models (f64).
//! - [`compensator`]: bias and scale factor to corrected rate, G = (Ĝ − B)/K (eq. 4 of the
//!   paper), riding through temperature-sensor faults with a [`Status`] per sample.
//! - [`multi`]: an axis reading several temperature sensors ([`multi::AxisCompensator`]),
//!   each with its own lags, on the compensator's time axis and fault handling.
//! - [`coverage`]: the training region in (T, dT) and a per-sample verdict (inside, edge,
//!   outside) with a 1σ estimate of the residual bias error.
//! - [`static_model`]: a model as plain static data (`gyrotherm export --target rust`).
//! - [`unit`](mod@unit): an inertial unit, one compensator per gyro axis, each on its own temperature
//!   sensor, stepped together.
//! - [`error`]: what the core refuses instead of panicking.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(unsafe_code)]
// Panic-freedom, checked: no indexing that can fail, no unwrap/expect/panic (tests may).
#![cfg_attr(
    not(test),
    deny(
        clippy::indexing_slicing,
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic
    )
)]

pub mod baseline;
pub mod compensator;
pub mod coverage;
pub mod error;
pub mod features;
pub mod lstm;
pub mod multi;
pub mod static_model;
pub mod unit;

pub use compensator::{Compensator, Corrected, Status, TargetModel, TempLimits};
pub use error::{Channel, InputError};
pub use features::FeatureSpec;
pub use unit::Unit;

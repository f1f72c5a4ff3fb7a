//! gyrotherm-core: what flies.
//!
//! `#![no_std]`, no allocation, no panics on any input. f32 maths through `libm`.
//!
//! Layers (a flight loop holds one [`compensator`] value):
//! - [`lstm`]: LSTM cell + linear read-out inference, hidden size a const generic (8 by default,
//!   as in He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, §2).
//! - [`features`]: the streaming feature pipeline (temperature, its 20 s rate, moving averages).
//! - [`baseline`]: evaluation of fitted linear/polynomial baseline models.
//! - [`compensator`]: bias and scale factor to corrected rate, G = (Ĝ - B) / K (eq. 4 of the paper).
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(unsafe_code)]

pub mod baseline;
pub mod compensator;
pub mod error;
pub mod features;
pub mod lstm;

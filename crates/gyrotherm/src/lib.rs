//! gyrotherm: the ground library for temperature compensation of fiber optic gyroscopes.
//!
//! Pure functions over plain data where possible; I/O at the edges.
//! - [`csvlog`]: the test-log CSV format (read, validate, write).
//! - [`sim`]: thermal-chamber + FOG simulator.
//! - [`allan`], [`metrics`]: the standard gyro figures (IEEE Std 952 / GJB 2426A).
//! - [`baseline`], [`train`], [`model`]: fitting compensation models and their files.
//! - [`report`]: figures and the HTML report.
//! - [`atomic_file`]: outputs written to a temporary file and renamed into place.

pub mod allan;
pub mod atomic_file;
pub mod baseline;
pub mod compare;
pub mod compensate;
pub mod compensate_lines;
pub mod csvlog;
pub mod export;
pub mod features;
pub mod fit;
pub mod metrics;
pub mod model;
pub mod report;
pub mod sim;
pub mod targets;
pub mod train;

//! gyrotherm: the ground library for temperature compensation of fiber optic gyroscopes.
//!
//! Data flows one way, and each step is one module (no module imports one further down):
//!
//! ```text
//! log ──► features ──► targets ──► fit ──► model ──► compensate ──► figures
//! csvlog  features     targets     fit     model     compensate     compare, report
//!  (sim)                           ├ baseline (least squares)
//!                                  └ nn (LSTM training)
//! ```
//!
//! - [`csvlog`]: the test-log CSV format (read, validate, write): [`read_log`] → [`TestLog`].
//! - [`sim`]: thermal-chamber + FOG simulator, a source of logs ([`simulate`]).
//! - [`features`]: the model inputs (temperature, its rate, thermal-state lags) of a log
//!   ([`FeatureSpec`], [`FeatureTable`]).
//! - [`targets`]: what the models learn: bias from static runs, scale factor from rate-table
//!   runs ([`TargetSet`]).
//! - [`fit`]: fit a compensation model from training logs ([`fit_model`], [`FitConfig`],
//!   [`RecipeSettings`]); least squares is [`baseline`], the LSTM network and its training
//!   [`nn`].
//! - [`model`]: the model file ([`ModelFile::save`], [`ModelFile::load`]).
//! - [`compensate`]: run the flight compensator (`gyrotherm-core`) over a log or a CSV
//!   stream with a status per line ([`compensate_log`], [`compensate_lines`](mod@compensate_lines)).
//! - [`allan`], [`metrics`]: the standard gyro figures (IEEE Std 952 / GJB 2426A).
//! - [`compare`]: held-out comparison of methods (the numbers); [`report`]: the pictures and
//!   the HTML report.
//! - [`moving_average`], [`table_segments`]: the one centred moving average and the one
//!   rate-table segmentation every step above uses.
//! - [`settings`]: what a user can choose for each job, with every default, list of values
//!   and check defined once (the command line and Python only translate).
//! - [`atomic_file`]: the output helper: every output is written to a temporary file and
//!   renamed into place.
//!
//! ```no_run
//! use gyrotherm::{compensate_log, fit_model, read_log, FitConfig, Method, ModelFile, NamedLog};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let (log, _) = read_log("static.csv".as_ref(), &Default::default())?;
//! let logs = [NamedLog { name: "static.csv", log: &log }];
//! let fitted = fit_model(&logs, &FitConfig::new(Method::Linear), &|_, _, _| {})?;
//! fitted.model.save("model.json".as_ref())?;
//! let model = ModelFile::load("model.json".as_ref())?;
//! let out = compensate_log(&model, &log)?;
//! println!("{} samples compensated", out.gyro_comp_dps.len());
//! # Ok(())
//! # }
//! ```

pub mod allan;
pub mod atomic_file;
pub mod baseline;
pub mod compare;
pub mod compensate;
pub mod compensate_imu_lines;
pub mod compensate_lines;
pub mod coverage;
pub mod coverage_track;
pub mod csvlog;
pub mod export;
pub mod features;
pub mod fit;
pub mod imu_judge;
pub mod imu_model;
pub mod input_file;
pub mod json_keys;
pub mod lot;
pub mod metrics;
pub mod model;
pub mod moving_average;
pub mod nn;
pub mod plan;
pub mod report;
pub mod settings;
pub mod sim;
pub mod spec;
pub mod table_segments;
pub mod targets;

pub use compensate::{compensate_log, compensator, CompensateError};
pub use compensate_lines::{compensate_lines, LinesError, LinesSummary};
pub use csvlog::{read_log, write_log, LogError, ReadOptions, TestLog};
pub use features::{FeatureSpec, FeatureTable};
pub use fit::{fit_model, FitConfig, FitError, FitOutcome, NamedLog, RecipeSettings};
pub use model::{Method, ModelFile, ModelFileError, SubModel, Target};
pub use settings::{FitSettings, SettingError};
pub use sim::{simulate, SimConfig};
pub use targets::TargetSet;

/// An error and its causes on one line, `: `-separated, outermost first: what a front end
/// prints. Every error of this library states only its own level's fact and returns its cause
/// from `source()`, so each cause appears once.
pub fn error_chain(err: &(dyn std::error::Error + 'static)) -> String {
    let mut text = err.to_string();
    let mut cause = err.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

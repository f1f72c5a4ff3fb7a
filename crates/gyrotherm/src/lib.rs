//! gyrotherm: the ground library for temperature compensation of fiber optic gyroscopes.
//!
//! Data flows one way, from the test log to what the engineer reads and what flies:
//!
//! ```text
//! log ──► features ──► targets ──► fit ──► model ──► compensate ──► figures ──► report
//! csvlog  features     targets     fit     model     compensate     compare     report
//!  (sim)                           ├ baseline (least squares)                   export, lot
//!                                  └ nn (LSTM training)
//! ```
//!
//! The modules, from the ground up: each imports only modules listed before it. The fit
//! fills the model file and checks it as flight code runs it, so the file type and the
//! compensator sit below the fit. Settings sit below what they configure: the rules and the
//! error of a setting at the bottom, each job's settings right above the figures they name.
//!
//! - `error_chain`: an error and its causes as one line ([`error_chain()`]).
//! - `number_text`: how a number is written in a CSV field and in a message.
//! - [`setting_rule`]: the rules a setting's value may break, and [`SettingError`].
//! - [`atomic_file`]: writing an output so that nothing is lost (temporary file, then rename).
//! - [`input_file`]: reading the small input files (models, spec sheets, profiles).
//! - `json_keys`: a JSON object that names a key twice.
//! - `string_table`: a table of strings, as results are printed.
//! - [`told`]: a line a job tells the user (what it read, did or warns of).
//! - `per_thread`: work split over threads, one per item.
//! - `moving_average`: the one centred moving average on a time axis.
//! - `table_segments`: the one segmentation of a rate-table log by commanded rate.
//! - [`flight_size`]: the flight LSTM's hidden size, read from a model file at run time.
//! - [`allan`]: Allan-family deviations of rate data, with confidence intervals.
//! - [`nn`]: the LSTM network on the ground: parameters, training, evaluation.
//! - [`csvlog`]: the test logs: the log in memory ([`csvlog::ImuLog`], N axes and M sensors;
//!   [`TestLog`], one axis as a fit reads it; a single gyro's log is the unit of one axis,
//!   [`csvlog::ImuLog::of_axis`]), each file format in its own module (CSV, ULog, DataFlash;
//!   read, validate, write), and the one entry point every job reads through
//!   ([`csvlog::read_log_set`] → [`csvlog::LogSet`]; one log as named columns,
//!   [`csvlog::read_log_columns`]).
//! - [`sim`]: the thermal-chamber + FOG simulator, a source of logs ([`simulate`]).
//! - [`features`]: the model inputs of a log (temperature, its rate, thermal lags)
//!   ([`FeatureSpec`], [`FeatureTable`]).
//! - [`metrics`]: the standard gyro figures (IEEE Std 952 / GJB 2426A).
//! - [`targets`]: what the models learn: bias from static runs, scale factor from rate-table
//!   runs ([`TargetSet`]).
//! - [`baseline`]: least-squares fits over monomials of the features.
//! - [`settings`]: what a user can choose for each job, with every default, list of values
//!   and check defined once (the command line and Python only translate).
//! - [`model`]: the model file ([`ModelFile::save`], [`ModelFile::load`]), with the coverage
//!   map it carries; an inertial unit's file, a model per gyro axis, in
//!   [`model::unit`](mod@model::unit).
//! - [`compensate`]: the flight compensator (`gyrotherm-core`) run over a log
//!   ([`compensate_log`]; a unit's, axis by axis, [`compensate::unit`](mod@compensate::unit)).
//! - [`coverage`]: what training covered: the cross-validated coverage map, and a log's
//!   shares inside it.
//! - [`coverage_track`]: a log's path through a model's coverage map, sample by sample.
//! - [`fit`]: fitting a compensation model from training logs ([`fit_model`], [`FitConfig`],
//!   [`RecipeSettings`]; a unit's, axis by axis, [`fit::unit`](mod@fit::unit)).
//! - [`compare`]: held-out comparison of methods: the numbers of the results table (a unit's,
//!   axis by axis, and its table across axes: [`compare::unit`](mod@compare::unit)).
//! - [`spec`]: spec sheets: limits on the standard figures, and a run's verdict (a unit's,
//!   axis by axis: [`spec::unit`](mod@spec::unit)).
//! - [`compensate_lines`](mod@compensate_lines): a CSV stream compensated line by line, with a
//!   status per line, for one gyro or each axis of a unit ([`compensate_lines::unit`](mod@compensate_lines::unit)).
//! - [`plan`]: what the training logs cover of a flight's envelope, and the runs still needed.
//! - [`report`]: the figures and the HTML report.
//! - [`export`]: a model as flight code (C, Rust) or autopilot parameters.
//! - [`unit_model`]: the model of a unit of N axes, read from either file form through one
//!   entry point ([`unit_model::Model::load`]).
//! - [`train`]: a model trained on a job's logs, for a single gyro or a unit
//!   ([`train::train`]).
//! - [`judge`]: the held-out judgement of `compare` and `report`, for a single gyro or each
//!   axis of a unit ([`judge::judge`]).
//! - [`evaluate`](mod@evaluate): the figures of one log, raw and compensated, with a spec's
//!   verdict ([`evaluate::evaluate`]).
//! - [`lot`]: the test station's record of units judged against their spec sheet.
//!
//! One path serves a single gyro and an inertial unit: the logs are read as a set
//! ([`csvlog::read_log_set`]; column lists in [`ReadOptions`] make it a unit's), [`train`]
//! fits the set, and a [`Model`] is what every job loads, saves, compensates with and exports,
//! whichever file form it holds (a single gyro is a unit of one axis):
//!
//! ```no_run
//! use gyrotherm::model::{GivenColumns, TempSensorDef};
//! use gyrotherm::{csvlog::read_log_set, train::train, FitConfig, Method, Model, ReadOptions};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // "gyro_x,gyro_y,gyro_z" and "temp_case,temp_x" would read a unit's logs the same way.
//! let opts = ReadOptions::default();
//! let logs = read_log_set(&["static.csv".into(), "table.csv".into()], &opts, None).set?;
//! let cfg = FitConfig::new(Method::Thermal);
//! let trained = train(&logs, &cfg, &TempSensorDef::default(), &opts, &|_| {})?;
//! trained.model.save("model.json".as_ref())?;
//!
//! let model = Model::load("model.json".as_ref())?;
//! let columns = model.read_options(&opts, GivenColumns::default())?;
//! let run = model.compensate_file("flight.csv".as_ref(), "out.csv".as_ref(), &columns)?;
//! println!("{} lines compensated", run.rows());
//! # Ok(())
//! # }
//! ```
//!
//! The single gyro's own types remain for analysis code that wants one log in memory:
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
pub mod compensate_lines;
pub mod coverage;
pub mod coverage_track;
pub mod csvlog;
mod error_chain;
pub use error_chain::error_chain;
pub mod evaluate;
pub mod export;
pub mod features;
pub mod fit;
pub mod flight_size;
pub mod input_file;
pub(crate) mod json_keys;
pub mod judge;
pub mod lot;
pub mod metrics;
pub mod model;
pub(crate) mod moving_average;
pub mod nn;
mod number_text;
mod per_thread;
pub mod plan;
pub mod report;
pub mod setting_rule;
pub mod settings;
pub mod sim;
pub mod spec;
pub(crate) mod string_table;
pub(crate) mod table_segments;
pub mod targets;
pub mod told;
pub mod train;
pub mod unit_model;

pub use compensate::{compensate_log, compensator, CompensateError};
pub use compensate_lines::{compensate_lines, LinesError, LinesSummary};
pub use csvlog::{read_log, write_log, LogError, ReadOptions, TestLog};
pub use features::{FeatureSpec, FeatureTable};
pub use fit::{fit_model, FitConfig, FitError, FitOutcome, NamedLog, RecipeSettings};
pub use model::{Method, ModelFile, ModelFileError, SubModel, Target};
pub use settings::{FitSettings, SettingError};
pub use sim::{simulate, SimConfig};
pub use targets::TargetSet;
pub use unit_model::{Model, ModelError};

//! Settings: what a user can choose for each job, with the one definition of every default,
//! every list of accepted values and every check. After ripgrep's `lowargs` → `hiargs`: the
//! command line (`gyrotherm-cli`) and the Python package (`gyrotherm-py`) parse what the user
//! typed into these plain structs, call `validate()`, and only then build the real objects
//! (a [`FitConfig`](crate::fit::FitConfig), a read log). Neither restates a default or a rule.
//!
//! One file per settings struct:
//! - [`rule`]: the rules a value may break and the error naming the setting
//!   ([`SettingError`]), with the bounds those rules state.
//! - [`read`]: reading a log ([`ReadOptions`](crate::csvlog::ReadOptions), owned by `csvlog`,
//!   checked here; field separators).
//! - [`method`]: the fitting methods, one registry ([`Method`]): each method's name, help
//!   line and comparison-column label.
//! - [`fit`]: fitting ([`FitSettings`]), shared by `train`, `compare`, `report`, `demo` and
//!   Python's `fit()`.
//! - [`allan`]: Allan deviation of a log column, and which curve the noise terms are read
//!   from ([`AllanSettings`]).
//! - [`evaluate`]: the standard figures of a log column, and the τ policy
//!   ([`EvaluateSettings`]).
//! - [`compensate`]: the temperature-sensor limits a compensator believes
//!   ([`TempSensorDef`](crate::model::TempSensorDef)).
//! - [`coverage`]: the training-region map and the 1σ estimate `train` stores
//!   ([`CoverageSettings`](coverage::CoverageSettings)).
//! - [`autopilot`]: which IMU and axis an autopilot parameter file is for, and (PX4) its
//!   device id ([`AutopilotSettings`](autopilot::AutopilotSettings)).
//! - [`export`](mod@export): the export targets, one list ([`ExportTarget`](export::ExportTarget)).
//! - [`kalibr`]: the ROS topic named in a Kalibr noise file.
//! - [`plan`]: the flight envelope and the chamber's limits of `gyrotherm plan`
//!   ([`PlanSettings`](plan::PlanSettings)).
//! - [`describe`](mod@describe): every setting of every job with its default and accepted values, as the
//!   hidden `gyrotherm settings --json` prints it and the Python package exposes it, so
//!   their equality can be tested.

pub mod allan;
pub mod autopilot;
pub mod compensate;
pub mod coverage;
pub mod describe;
pub mod evaluate;
pub mod export;
pub mod fit;
pub mod kalibr;
pub mod method;
pub mod plan;
pub mod read;
pub use crate::setting_rule as rule;

pub use allan::{AllanAnalysis, AllanSettings};
pub use describe::{describe, OptionSpec};
pub use evaluate::EvaluateSettings;
pub use fit::FitSettings;
pub use method::{Method, DEFAULT_METHOD, METHODS, METHOD_NAMES};
pub(crate) use rule::check_opt;
pub use rule::{check, parse_number, Rule, SettingError};

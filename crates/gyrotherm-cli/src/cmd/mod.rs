//! One file per subcommand with its `run(args) -> anyhow::Result<ExitCode>`, and its clap
//! `Args` struct unless the struct is shared. Below the command files: `args` holds the
//! arguments of the commands that read a single gyro or an inertial unit (`train`,
//! `compensate`, `evaluate`, `compare`, `report`), which `evaluate`'s unit path `imu_judge`
//! take too; `print` the text of a comparison and an evaluation; `stream` stdin and stdout as
//! a live stream; `common` the options shared by every command that reads a log. A command
//! file imports only these lower modules and the unit paths, never a file that imports it.

pub mod allan;
pub mod args;
pub mod common;
pub mod compare;
pub mod compensate;
pub mod demo;
pub mod evaluate;
pub mod export;
pub mod lot;
pub mod model;
pub mod plan;
pub mod progress;
pub mod report;
pub mod settings;
pub mod simulate;
pub mod stream;
pub mod train;
pub mod verdict;

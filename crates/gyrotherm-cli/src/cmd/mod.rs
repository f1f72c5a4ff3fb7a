//! One file per subcommand: a clap `Args` struct and `run(args) -> anyhow::Result<ExitCode>`.
//! `common` holds the options shared by every command that reads a log.

pub mod allan;
pub mod common;
pub mod compare;
pub mod compensate;
pub mod demo;
pub mod evaluate;
pub mod export;
pub mod imu;
pub mod imu_judge;
pub mod lot;
pub mod model;
pub mod plan;
pub mod progress;
pub mod report;
pub mod settings;
pub mod simulate;
pub mod train;
pub mod verdict;

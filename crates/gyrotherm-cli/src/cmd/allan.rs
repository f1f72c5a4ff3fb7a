//! `gyrotherm allan`.

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct AllanArgs {}

pub fn run(_args: AllanArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`gyrotherm allan` is not implemented yet")
}

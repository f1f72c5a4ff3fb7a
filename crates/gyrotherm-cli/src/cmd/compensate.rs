//! `gyrotherm compensate`.

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct CompensateArgs {}

pub fn run(_args: CompensateArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`gyrotherm compensate` is not implemented yet")
}

//! `gyrotherm settings --json` (hidden): the library's description of every setting
//! (`gyrotherm::settings::describe`), so that tests can hold `--help` and the Python package
//! to it.

use std::io::Write;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct SettingsArgs {
    /// Print JSON (the only format).
    #[arg(long)]
    pub json: bool,
}

pub fn run(_args: SettingsArgs) -> anyhow::Result<ExitCode> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{}", gyrotherm::settings::describe::describe_json())?;
    Ok(ExitCode::SUCCESS)
}

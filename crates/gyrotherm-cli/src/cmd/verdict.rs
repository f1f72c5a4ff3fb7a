//! `--spec SPEC.toml` of `evaluate`, `compare`, `report` and `lot add`: load the sheet, print
//! the verdict, and turn it into the exit status (0 all limits met, 1 a limit missed; errors
//! are 2 as everywhere).

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use gyrotherm::spec::{Spec, Verdict};

/// What `--help` says about `--spec` and the exit status.
pub const SPEC_HELP: &str =
    "Spec sheet (TOML): a [limits] table of `figure = { min = …, max = … }` \
(keys as in `evaluate --json`, noise terms as in `allan --json`; docs/method.md §7). Prints a \
verdict per figure and exits 1 when a limit is missed.";

/// Load `--spec` when given (before any heavy work, so a bad sheet fails fast).
pub fn load(path: Option<&Path>) -> anyhow::Result<Option<Spec>> {
    path.map(|p| Spec::load(p).map_err(anyhow::Error::from))
        .transpose()
}

/// 0 when `pass`, 1 when a limit was missed.
pub fn exit_code(pass: bool) -> ExitCode {
    if pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// The verdict as text, one line per figure and log, then the overall line.
pub fn print(w: &mut dyn Write, v: &Verdict) -> std::io::Result<()> {
    for line in v.lines() {
        writeln!(w, "{line}")?;
    }
    Ok(())
}

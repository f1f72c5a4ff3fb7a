//! `gyrotherm model`: look after model files. `seal FILE` re-seals a model after a deliberate
//! hand edit: every check but the content checksum is applied, then the file is written back
//! with a new `content_sha256`. Both actions take a single-axis model or an inertial unit's.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use gyrotherm::unit_model::Model;

#[derive(Debug, clap::Args)]
pub struct ModelArgs {
    #[command(subcommand)]
    pub action: ModelAction,
}

#[derive(Debug, clap::Subcommand)]
pub enum ModelAction {
    /// Re-seal a hand-edited model file: check it (all but its checksum) and write it back
    /// with the checksum of its new content.
    Seal {
        /// The model file (rewritten in place).
        file: PathBuf,
    },
    /// Check a model file as `compensate` would load it, and print its checksum.
    Check {
        /// The model file.
        file: PathBuf,
    },
}

pub fn run(args: ModelArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        ModelAction::Seal { file } => {
            let digest = Model::seal_file(&file)?;
            eprintln!(
                "gyrotherm: sealed {} (content_sha256 {digest})",
                file.display()
            );
        }
        ModelAction::Check { file } => {
            let m = Model::load(&file)?;
            if let Some(w) = m.load_warning(&file) {
                eprintln!("gyrotherm: warning: {w}");
            }
            // Errors returned, not `println!`: a closed pipe ends the command quietly.
            writeln!(std::io::stdout(), "{}", m.check_line(&file)?)?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

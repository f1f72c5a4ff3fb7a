//! `gyrotherm model`: look after model files. `seal FILE` re-seals a model after a deliberate
//! hand edit: every check but the content checksum is applied, then the file is written back
//! with a new `content_sha256`.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use gyrotherm::model::ModelFile;

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
            let (_, digest) = ModelFile::seal(&file)?;
            eprintln!(
                "gyrotherm: sealed {} (content_sha256 {digest})",
                file.display()
            );
        }
        ModelAction::Check { file } => {
            let (m, seal) = ModelFile::load_sealed(&file)?;
            if let Some(w) = seal.warning(&file) {
                eprintln!("gyrotherm: warning: {w}");
            }
            let state = match seal {
                gyrotherm::model::Seal::Verified => "ok, sealed",
                gyrotherm::model::Seal::Absent => "ok but not sealed",
            };
            // Errors returned, not `println!`: a closed pipe ends the command quietly.
            writeln!(
                std::io::stdout(),
                "{}: {state}, content_sha256 {}",
                file.display(),
                m.content_digest()?
            )?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

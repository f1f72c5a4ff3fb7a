//! `gyrotherm model`: look after model files. `seal FILE` re-seals a model after a deliberate
//! hand edit: every check but the content checksum is applied, then the file is written back
//! with a new `content_sha256`. Both actions take a single-axis model or an inertial unit's.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::imu_model::ImuModel;
use gyrotherm::model::{ModelFile, Seal};

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
    let file = match &args.action {
        ModelAction::Seal { file } | ModelAction::Check { file } => file,
    };
    if super::imu::is_imu_model(file)? {
        return run_unit(args.action);
    }
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
            // Errors returned, not `println!`: a closed pipe ends the command quietly.
            writeln!(
                std::io::stdout(),
                "{}: {}, content_sha256 {}",
                file.display(),
                state(seal),
                m.content_digest()?
            )?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn state(seal: Seal) -> &'static str {
    match seal {
        Seal::Verified => "ok, sealed",
        Seal::Absent => "ok but not sealed",
    }
}

/// [`run`] with an inertial unit's model file: the same checks as `compensate` applies.
fn run_unit(action: ModelAction) -> anyhow::Result<ExitCode> {
    let context = |file: &PathBuf| format!("cannot use model {}", file.display());
    match action {
        ModelAction::Seal { file } => {
            let (_, digest) = ImuModel::seal(&file)
                .map_err(anyhow::Error::new)
                .with_context(|| context(&file))?;
            eprintln!(
                "gyrotherm: sealed {} (content_sha256 {digest})",
                file.display()
            );
        }
        ModelAction::Check { file } => {
            let (m, seal) = ImuModel::load_sealed(&file)
                .map_err(anyhow::Error::new)
                .with_context(|| context(&file))?;
            if let Some(w) = seal.warning(&file) {
                eprintln!("gyrotherm: warning: {w}");
            }
            writeln!(
                std::io::stdout(),
                "{}: {} (inertial unit, {} axes), content_sha256 {}",
                file.display(),
                state(seal),
                m.axes.len(),
                m.content_digest()?
            )?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

//! `gyrotherm export`: write a model as flight code, C99 (`gyrotherm_model.h`,
//! `gyrotherm_model.c`) or a Rust module for gyrotherm-core (`gyrotherm_model.rs`). See
//! `gyrotherm::export`.

use std::path::PathBuf;
use std::process::ExitCode;

use gyrotherm::export::{export, Lang};
use gyrotherm::model::ModelFile;

use super::common::choice;

#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Model file written by `gyrotherm train`.
    #[arg(long)]
    pub model: PathBuf,
    /// Target language.
    #[arg(long, value_parser = choice::<Lang>([Lang::C, Lang::Rust].map(|l| (l.as_str(), l.help()))))]
    pub lang: Lang,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: ExportArgs) -> anyhow::Result<ExitCode> {
    let (model, seal) = ModelFile::load_sealed(&args.model).map_err(anyhow::Error::new)?;
    if let Some(w) = seal.warning(&args.model) {
        eprintln!("gyrotherm: warning: {w}");
    }
    let lang = args.lang;
    let files = export(&model, lang, &args.out)?;
    for f in files {
        eprintln!("gyrotherm: wrote {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}

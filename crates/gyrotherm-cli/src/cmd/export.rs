//! `gyrotherm export`: write a model as flight code, C99 (`gyrotherm_model.h`,
//! `gyrotherm_model.c`) or a Rust module for gyrotherm-core (`gyrotherm_model.rs`). See
//! `gyrotherm::export`.

use std::path::PathBuf;
use std::process::ExitCode;

use gyrotherm::export::{export, Lang};
use gyrotherm::model::ModelFile;

/// `--lang` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LangArg {
    /// C99: gyrotherm_model.h and gyrotherm_model.c (no heap, no global mutable state).
    C,
    /// Rust: gyrotherm_model.rs, the model as a `static` for gyrotherm-core.
    Rust,
}

#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Model file written by `gyrotherm train`.
    #[arg(long)]
    pub model: PathBuf,
    /// Target language.
    #[arg(long, value_enum)]
    pub lang: LangArg,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: ExportArgs) -> anyhow::Result<ExitCode> {
    let (model, seal) = ModelFile::load_sealed(&args.model).map_err(anyhow::Error::new)?;
    if let Some(w) = seal.warning(&args.model) {
        eprintln!("gyrotherm: warning: {w}");
    }
    let lang = match args.lang {
        LangArg::C => Lang::C,
        LangArg::Rust => Lang::Rust,
    };
    let files = export(&model, lang, &args.out)?;
    for f in files {
        eprintln!("gyrotherm: wrote {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}

//! `gyrotherm export`: write a model as flight code, C99 (`gyrotherm_model.h`,
//! `gyrotherm_model.c`) or a Rust module for gyrotherm-core (`gyrotherm_model.rs`). See
//! `gyrotherm::export`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::export::unit::{column_map, export_imu};
use gyrotherm::export::{export, Lang};
use gyrotherm::imu_model::ImuModel;
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
    if super::imu::is_imu_model(&args.model)? {
        let (model, seal) = ImuModel::load_sealed(&args.model)
            .map_err(anyhow::Error::new)
            .with_context(|| format!("cannot use model {}", args.model.display()))?;
        if let Some(w) = seal.warning(&args.model) {
            eprintln!("gyrotherm: warning: {w}");
        }
        let files = export_imu(&model, args.lang, &args.out)?;
        for f in files {
            eprintln!("gyrotherm: wrote {}", f.display());
        }
        // The names stay out of the generated source (they come from the model file): the
        // files list the order by index, and this is the map.
        eprintln!("gyrotherm: column order of the exported unit (names from the model file):");
        for line in column_map(&model) {
            eprintln!("  {line}");
        }
        return Ok(ExitCode::SUCCESS);
    }
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

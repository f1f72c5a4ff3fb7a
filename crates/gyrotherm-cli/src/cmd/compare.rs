//! `gyrotherm compare`: fit linear, polynomial and LSTM models on training logs and judge them
//! on held-out logs — the results table of He et al. 2024, for the user's own data.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compare::{compare, CompareConfig, Comparison};
use gyrotherm::fit::NamedLog;
use gyrotherm::model::Method;

use super::common::LogArgs;
use super::common::{named, read_logs};
use super::progress::TrainingBars;
use super::train::FitArgs;

#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Training log (CSV); repeat for several (static → bias, rate-table → scale factor).
    #[arg(long, required = true)]
    pub train: Vec<PathBuf>,
    /// Held-out log to judge on (CSV); repeat for several.
    #[arg(long, required = true)]
    pub test: Vec<PathBuf>,
    /// Bias-stability smoothing time, s.
    #[arg(long, default_value_t = 100.0)]
    pub tau: f64,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub log: LogArgs,
}

/// Run the comparison with progress bars for the LSTM.
pub fn run_comparison(
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
) -> anyhow::Result<Comparison> {
    let bars = TrainingBars::new(
        cfg.methods.contains(&Method::Lstm),
        cfg.fit.recipe.epochs,
        &["lstm"],
    );
    let result = compare(train, test, cfg, &|m, t, e, l| {
        if m == Method::Lstm {
            bars.update("lstm", t, e, l)
        }
    });
    bars.finish();
    result.context("comparison failed")
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    let mut warnings = Vec::new();
    let train = read_logs(&args.train, &args.log, &mut warnings)?;
    let test = read_logs(&args.test, &args.log, &mut warnings)?;
    let train_named = named(&train);
    let test_named = named(&test);
    let cfg = args.fit.compare_config(args.tau)?;
    let cmp = run_comparison(&train_named, &test_named, &cfg)?;
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&cmp.summary(&cfg))?)?;
    } else {
        print_table(&mut out, &cmp, &cfg)?;
    }
    for t in &cmp.tests {
        for w in &t.warnings {
            eprintln!("gyrotherm: warning: {w}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The human table: the models fitted, then one block per held-out log.
pub fn print_table(
    w: &mut dyn Write,
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> std::io::Result<()> {
    for line in cmp.model_lines() {
        writeln!(w, "{line}")?;
    }
    writeln!(w)?;
    cmp.table(cfg).write_text(w)
}

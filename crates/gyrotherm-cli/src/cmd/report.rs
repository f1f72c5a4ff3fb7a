//! `gyrotherm report`: run the held-out comparison of `gyrotherm compare` and write it as an
//! HTML report with the figures a gyro engineer looks at (`DIR/index.html`, one PNG and SVG
//! per figure; see `gyrotherm::report::job`).

use std::path::PathBuf;
use std::process::ExitCode;

use std::io::Write as _;

use anyhow::Context as _;
use gyrotherm::report::write_full_report_with;

use super::common::{named, read_logs, LogArgs};
use super::compare::{print_table, resolve_tau, run_comparison, ColumnArgs};
use super::train::FitArgs;

#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// Training log (CSV); repeat for several (static → bias, rate-table → scale factor).
    #[arg(long, required = true)]
    pub train: Vec<PathBuf>,
    /// Held-out log to judge on (CSV); repeat for several.
    #[arg(long, required = true)]
    pub test: Vec<PathBuf>,
    /// Report folder (created if missing): index.html and a PNG and SVG per figure.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Bias-stability smoothing time, s (default 100 s, or the multiple of the held-out logs'
    /// sample period nearest to it when 100 s is not one; said on stderr).
    #[arg(long, value_parser = super::common::seconds("tau_s", gyrotherm::settings::Rule::PositiveSeconds))]
    pub tau_s: Option<f64>,
    #[doc = "Spec sheet (TOML) to judge every model column against; exit 1 when a column misses a limit."]
    #[arg(long, value_name = "SPEC.toml", long_help = super::verdict::SPEC_HELP)]
    pub spec: Option<PathBuf>,
    #[command(flatten)]
    pub columns: ColumnArgs,
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub log: LogArgs,
}

pub fn run(args: ReportArgs) -> anyhow::Result<ExitCode> {
    if args.log.read_options().is_multi_column() {
        return super::imu_judge::report(args);
    }
    let spec = super::verdict::load(args.spec.as_deref())?;
    let mut gap_warnings = Vec::new();
    let train = read_logs(&args.train, &args.log, &mut gap_warnings)?;
    let test = read_logs(&args.test, &args.log, &mut gap_warnings)?;
    let train_named = named(&train);
    let test_named = named(&test);
    let tau_s = resolve_tau(args.tau_s, &test_named);
    let cfg = args.columns.compare_config(&args.fit, tau_s)?;
    let cmp = run_comparison(&train_named, &test_named, &cfg)?;
    let verdicts = spec
        .as_ref()
        .map(|s| gyrotherm::spec::judge_comparison(s, &cmp, &test_named, &cfg))
        .transpose()?;
    let started = std::time::Instant::now();
    eprintln!(
        "gyrotherm: drawing the figures and writing the report in {}…",
        args.out.display()
    );
    let index = write_full_report_with(
        &args.out,
        &train_named,
        &test_named,
        &cmp,
        &cfg,
        &gap_warnings,
    )
    .with_context(|| format!("cannot write the report in {}", args.out.display()))?;
    eprintln!(
        "gyrotherm: wrote {} in {:.1} s",
        index.display(),
        started.elapsed().as_secs_f64()
    );
    let mut out = std::io::stdout().lock();
    print_table(&mut out, &cmp, &cfg)?;
    if let Some(v) = &verdicts {
        super::verdict::print_columns(&mut out, v)?;
    }
    writeln!(out, "report: {}", index.display())?;
    // Each finding once, naming the models it concerns (as the report page says it).
    for w in gyrotherm::report::grouped_warnings(&test_named, &cmp) {
        eprintln!("gyrotherm: warning: {w}");
    }
    Ok(super::verdict::exit_code(
        verdicts.iter().flatten().all(|c| c.verdict.pass),
    ))
}

//! `gyrotherm lot`: `add` judges a unit's model on its held-out logs and records it in a lot
//! database, `list` prints what is recorded, `report` writes the lot's HTML page and CSV.
//! All the work is in `gyrotherm::lot`; this file turns arguments into calls.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::lot::{self, open_store, UnitInputs};
use gyrotherm::model::GivenColumns;
use gyrotherm::unit_model::Model;

use super::common::{told_set, LogArgs};

#[derive(Debug, clap::Args)]
#[command(
    after_help = "Exit status: 0 success (lot add: the unit met every limit), 1 lot add: the unit missed a limit (the run is recorded all the same), 2 error (nothing recorded).\nSchema: docs/lot-schema.md. --db takes an SQLite file path or a postgres:// URL."
)]
pub struct LotArgs {
    #[command(subcommand)]
    pub command: LotCommand,
}

#[derive(Debug, clap::Subcommand)]
pub enum LotCommand {
    /// Judge a unit's model on its held-out logs and record the run (an inertial unit's model:
    /// each axis and the unit).
    Add(Box<AddArgs>),
    /// List the recorded runs.
    List(ListArgs),
    /// Write the lot's HTML page (yield, distributions, worst units) and CSV.
    Report(ReportArgs),
}

/// Where the lot is.
#[derive(Debug, clap::Args)]
pub struct DbArgs {
    /// The lot: an SQLite file (created by `add` if missing) or a postgres://user@host/db URL.
    #[arg(long, value_name = "LOT.sqlite|URL")]
    pub db: String,
    /// How long a writer waits for another station's write to finish, ms (SQLite).
    #[arg(long, default_value_t = 30_000, value_name = "MS")]
    pub busy_timeout: u64,
}

#[derive(Debug, clap::Args)]
pub struct AddArgs {
    #[command(flatten)]
    pub db: DbArgs,
    /// The unit's serial number.
    #[arg(long)]
    pub unit: String,
    /// The unit's compensation model (JSON, from `gyrotherm train`; an inertial unit's model
    /// from `train` with column lists records a verdict per axis and the unit's).
    #[arg(long)]
    pub model: PathBuf,
    /// Held-out log to judge on (CSV); repeat for several (static and rate-table).
    #[arg(long, required = true)]
    pub test: Vec<PathBuf>,
    /// Spec sheet (TOML); without it the figures are recorded with verdict `none`.
    #[arg(long, value_name = "SPEC.toml", long_help = super::verdict::SPEC_HELP)]
    pub spec: Option<PathBuf>,
    /// Station name recorded with the run (default: the host name).
    #[arg(long)]
    pub station: Option<String>,
    /// Bias-stability smoothing time, s (default as `compare`).
    #[arg(long, value_parser = super::common::seconds("tau_s", gyrotherm::settings::Rule::PositiveSeconds))]
    pub tau_s: Option<f64>,
    /// Time dropped at the start of each rate-table segment, s.
    #[arg(long, default_value_t = gyrotherm::settings::EvaluateSettings::default().settle_s,
          value_parser = super::common::seconds("settle_s", gyrotherm::settings::Rule::NonNegativeSeconds))]
    pub settle_s: f64,
    /// Print the recorded run as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub log: LogArgs,
}

#[derive(Debug, clap::Args)]
pub struct ListArgs {
    #[command(flatten)]
    pub db: DbArgs,
    /// Print every run with its inputs and figures as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    #[command(flatten)]
    pub db: DbArgs,
    /// Report folder (created if missing): index.html, lot.csv, a PNG and SVG per figure.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Page title.
    #[arg(long, default_value = "Lot report")]
    pub title: String,
}

/// `given`: the column options `lot add`'s command line named (they override a model's own).
pub fn run(args: LotArgs, given: GivenColumns) -> anyhow::Result<ExitCode> {
    match args.command {
        LotCommand::Add(a) => add(*a, given),
        LotCommand::List(a) => list(a),
        LotCommand::Report(a) => report(a),
    }
}

fn add(a: AddArgs, given: GivenColumns) -> anyhow::Result<ExitCode> {
    let spec = super::verdict::load(a.spec.as_deref())?;
    let cannot = || format!("cannot use model {}", a.model.display());
    let model = Model::load(&a.model)?;
    // The columns the model was trained with, unless the command line names others.
    let opts = model
        .read_options(&a.log.read_options(), given)
        .with_context(cannot)?;
    let station = a.station.clone().unwrap_or_else(lot::default_station);
    let inputs = UnitInputs {
        unit: &a.unit,
        station: &station,
        model_path: &a.model,
        tests: &[],
        spec: spec.as_ref(),
        tau_s: a.tau_s,
        settle_s: a.settle_s,
    };
    // Judge first, then open the store: a unit that cannot be judged leaves the lot as it was.
    let logs = told_set(model.read_logs(&a.test, &opts, a.log.table_axis.as_deref()))?;
    let (run, verdict) = lot::judge_model(&model, &inputs, &logs)
        .map_err(|e| anyhow::Error::new(e).context(format!("unit {}", a.unit)))?;
    record(&a, run, |w| {
        let Some(v) = &verdict else {
            return Ok(());
        };
        // As `evaluate --model UNIT.json --spec` prints it: each axis, then the unit.
        let (axes, unit) = v.parts();
        for (k, (heading, axis)) in axes.iter().enumerate() {
            if k > 0 {
                writeln!(w)?;
            }
            if let Some(h) = heading {
                writeln!(w, "{h}")?;
            }
            super::verdict::print(w, axis)?;
        }
        if let Some(line) = unit {
            writeln!(w)?;
            writeln!(w, "{line}")?;
        }
        Ok(())
    })
}

/// The judged run into the lot (judged first: a unit that cannot be judged leaves the lot as
/// it was), then what was recorded: the run as JSON, or the verdict (`print_verdict`) and a
/// line naming the run; exit status 1 on a failed run.
fn record(
    a: &AddArgs,
    mut run: lot::Run,
    print_verdict: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> anyhow::Result<ExitCode> {
    let mut store = open_store(&a.db.db, true, a.db.busy_timeout)?;
    run.id = store.add(&run)?;
    let mut w = std::io::stdout().lock();
    if a.json {
        writeln!(w, "{}", serde_json::to_string_pretty(&run)?)?;
    } else {
        print_verdict(&mut w)?;
        let axes = match run.axes.len() {
            0 => String::new(),
            n => format!("{n} axes, "),
        };
        writeln!(
            w,
            "recorded run {} of unit {}: verdict {}, {axes}{} figures on {} logs",
            run.id,
            run.unit,
            run.verdict.as_str(),
            run.figures.len(),
            run.inputs.len()
        )?;
    }
    Ok(super::verdict::exit_code(
        run.verdict != lot::RunVerdict::Fail,
    ))
}

fn list(a: ListArgs) -> anyhow::Result<ExitCode> {
    let mut store = open_store(&a.db.db, false, a.db.busy_timeout)?;
    let runs = store.runs()?;
    let mut w = std::io::stdout().lock();
    if a.json {
        writeln!(w, "{}", serde_json::to_string_pretty(&runs)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    writeln!(
        w,
        "{:>6}  {:<16} {:<24} {:<7} {:<6} {:<12} {:>7}",
        "run", "unit", "tested at (UTC)", "verdict", "latest", "method", "figures"
    )?;
    for r in &runs {
        writeln!(
            w,
            "{:>6}  {:<16} {:<24} {:<7} {:<6} {:<12} {:>7}",
            r.id,
            r.unit.escape_debug().to_string(),
            r.tested_at(),
            r.verdict.as_str(),
            if r.latest { "yes" } else { "" },
            r.model_method,
            r.figures.len()
        )?;
        // An inertial unit: a line per axis under its run.
        for a in &r.axes {
            writeln!(
                w,
                "{:>6}  {:<16} axis {}: {} ({}), {}",
                "",
                "",
                a.axis + 1,
                a.gyro.escape_debug(),
                a.temps.join(", ").escape_debug(),
                a.verdict.as_str()
            )?;
        }
    }
    let y = lot::report::lot_yield(&runs);
    writeln!(
        w,
        "{} runs, {} units: {} passed, {} failed, {} not judged{}",
        runs.len(),
        y.units,
        y.passed,
        y.failed,
        y.not_judged,
        y.fraction()
            .map_or(String::new(), |f| format!("; yield {:.1} %", 100.0 * f))
    )?;
    Ok(ExitCode::SUCCESS)
}

fn report(a: ReportArgs) -> anyhow::Result<ExitCode> {
    let mut store = open_store(&a.db.db, false, a.db.busy_timeout)?;
    let runs = store.runs()?;
    let page = lot::report::write_lot_report(&a.out, &a.title, &runs)
        .with_context(|| format!("cannot write the lot report in {}", a.out.display()))?;
    let y = lot::report::lot_yield(&runs);
    let mut w = std::io::stdout().lock();
    writeln!(
        w,
        "{} units ({} runs): {} passed, {} failed, {} not judged; yield {}",
        y.units,
        runs.len(),
        y.passed,
        y.failed,
        y.not_judged,
        y.fraction()
            .map_or("-".to_string(), |f| format!("{:.1} %", 100.0 * f))
    )?;
    writeln!(w, "report: {}", page.display())?;
    Ok(ExitCode::SUCCESS)
}

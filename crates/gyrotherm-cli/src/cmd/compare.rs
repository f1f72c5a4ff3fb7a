//! `gyrotherm compare`: fit linear, polynomial, the default `thermal` model and the
//! `published` method (He et al. 2024) on training logs and judge them on held-out logs — the
//! paper's results table, for the user's own data, one column per model.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compare::{compare_with_stages, Candidate, CompareConfig, Comparison, Stage};
use gyrotherm::fit::NamedLog;
use gyrotherm::settings::{Method, DEFAULT_METHOD};

use super::common::LogArgs;
use super::common::{named, read_logs};
use super::progress::TrainingBars;
use super::train::{method_parser, warn_deprecated, FitArgs};

#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Training log (CSV); repeat for several (static → bias, rate-table → scale factor).
    #[arg(long, required = true)]
    pub train: Vec<PathBuf>,
    /// Held-out log to judge on (CSV); repeat for several.
    #[arg(long, required = true)]
    pub test: Vec<PathBuf>,
    /// Bias-stability smoothing time, s (default 100 s, or the multiple of the held-out logs'
    /// sample period nearest to it when 100 s is not one; said on stderr).
    #[arg(long, value_parser = super::common::seconds("tau_s", gyrotherm::settings::Rule::PositiveSeconds))]
    pub tau_s: Option<f64>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
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

/// Which models the comparison fits, one column each (`compare`, `demo`, `report`).
#[derive(Debug, clap::Args)]
pub struct ColumnArgs {
    /// Methods to compare, comma-separated, in table order (the names of `train --method`;
    /// a recipe method's column is named by what its model holds, `published` is "LSTM, He
    /// et al."; `--epochs` applies to every LSTM). Default: linear, poly, thermal, published.
    #[arg(long, value_delimiter = ',', value_name = "LIST", value_parser = method_parser())]
    pub methods: Option<Vec<Method>>,
}

impl ColumnArgs {
    /// The comparison settings: the columns, the fit settings, bias stability over `tau_s`.
    pub fn compare_config(&self, fit: &FitArgs, tau_s: f64) -> anyhow::Result<CompareConfig> {
        let (cfg, note) = fit
            .settings(DEFAULT_METHOD)
            .compare_config(self.methods.as_deref(), tau_s)?;
        warn_deprecated(note);
        Ok(cfg)
    }
}

/// `--tau-s` if given, else the default for the held-out logs
/// ([`gyrotherm::compare::default_tau_s`]), said on stderr when it is not 100 s.
pub fn resolve_tau(tau: Option<f64>, test: &[NamedLog]) -> f64 {
    tau_or_default(tau, || gyrotherm::compare::default_tau_s(test))
}

/// `tau`, or the library's default (`(τ, the sample period it was adjusted to)`), saying
/// on stderr when 100 s was not a multiple of the sample period.
pub fn tau_or_default(tau: Option<f64>, default: impl FnOnce() -> (f64, Option<f64>)) -> f64 {
    if let Some(t) = tau {
        return t;
    }
    let (t, adjusted_to) = default();
    if let Some(period) = adjusted_to {
        eprintln!(
            "gyrotherm: τ = {t} s, the multiple of the {period} s sample period nearest 100 s \
             (100 s is not one; give --tau-s to choose)"
        );
    }
    t
}

/// Run the comparison with progress bars for every column that trains an LSTM.
pub fn run_comparison(
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
) -> anyhow::Result<Comparison> {
    let training: Vec<&Candidate> = cfg
        .candidates
        .iter()
        .filter(|c| c.trains_lstm(&cfg.fit))
        .collect();
    let keys: Vec<&str> = training.iter().map(|c| c.key(&cfg.fit)).collect();
    let epochs = training
        .iter()
        .map(|c| c.fit_config(&cfg.fit).recipe.epochs)
        .max()
        .unwrap_or(0);
    let bars = TrainingBars::new(!keys.is_empty(), epochs, &keys);
    // A comparison fits several models and can run for minutes: say each step on stderr,
    // as `train` says what it fitted, so a long run is never silent.
    let stage = |s: Stage| match s {
        Stage::Fitting { key, index, of } => bars.println(&format!(
            "gyrotherm: fitting {key} ({} of {of}) on {} training log{}…",
            index + 1,
            train.len(),
            if train.len() == 1 { "" } else { "s" }
        )),
        Stage::Fitted { key, ok, seconds } => bars.println(&format!(
            "gyrotherm: {key} {} in {seconds:.1} s",
            if ok { "fitted" } else { "could not be fitted" }
        )),
        Stage::Judging { log } => bars.println(&format!("gyrotherm: judging {log}…")),
        _ => {}
    };
    let result = compare_with_stages(
        train,
        test,
        cfg,
        &|key, t, e, l| bars.update(key, t, e, l),
        &stage,
    );
    bars.finish();
    let cmp = result.context("comparison failed")?;
    // The rest of the table is computed: the exit status stays 0, and each column that has
    // no figures is said here, naming the method and the cause.
    for f in &cmp.failed {
        eprintln!(
            "gyrotherm: warning: the {} column was not fitted: {}",
            f.key, f.reason
        );
    }
    for t in &cmp.tests {
        for f in &t.failed {
            eprintln!(
                "gyrotherm: warning: the {} column failed on {}: {}",
                f.key, t.name, f.reason
            );
        }
    }
    Ok(cmp)
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    if args.log.read_options().is_multi_column() {
        return super::imu_judge::compare(args);
    }
    let spec = super::verdict::load(args.spec.as_deref())?;
    let mut warnings = Vec::new();
    let train = read_logs(&args.train, &args.log, &mut warnings)?;
    let test = read_logs(&args.test, &args.log, &mut warnings)?;
    let train_named = named(&train);
    let test_named = named(&test);
    let tau_s = resolve_tau(args.tau_s, &test_named);
    let cfg = args.columns.compare_config(&args.fit, tau_s)?;
    let cmp = run_comparison(&train_named, &test_named, &cfg)?;
    let verdicts = spec
        .as_ref()
        .map(|s| gyrotherm::spec::judge_comparison(s, &cmp, &test_named, &cfg))
        .transpose()?;
    let mut out = std::io::stdout().lock();
    if args.json {
        let mut j = serde_json::to_value(cmp.summary(&cfg))?;
        if let (Some(v), Some(o)) = (&verdicts, j.as_object_mut()) {
            o.insert("verdicts".into(), serde_json::to_value(v)?);
        }
        writeln!(out, "{}", serde_json::to_string_pretty(&j)?)?;
    } else {
        print_table(&mut out, &cmp, &cfg)?;
        if let Some(v) = &verdicts {
            super::verdict::print_columns(&mut out, v)?;
        }
    }
    // Each finding once, naming the models it concerns (as the report page says it).
    for w in gyrotherm::report::grouped_warnings(&test_named, &cmp) {
        eprintln!("gyrotherm: warning: {w}");
    }
    for line in coverage_lines(&test_named, &cmp)? {
        eprintln!("gyrotherm: {line}");
    }
    Ok(super::verdict::exit_code(
        verdicts.iter().flatten().all(|c| c.verdict.pass),
    ))
}

/// Per held-out log, the share of its samples outside (and at the edge of) each model's
/// training region; models without a coverage map are left out.
fn coverage_lines(test: &[NamedLog], cmp: &Comparison) -> anyhow::Result<Vec<String>> {
    let mut out = Vec::new();
    for t in test {
        let mut parts = Vec::new();
        for (fit, col) in cmp.fits.iter().zip(&cmp.columns) {
            if let Some([_, edge, outside]) = gyrotherm::coverage::shares(&fit.model, t.log)? {
                parts.push(format!(
                    "{} outside {:.1} % (edge {:.1} %)",
                    col.label,
                    100.0 * outside,
                    100.0 * edge
                ));
            }
        }
        if !parts.is_empty() {
            out.push(format!("coverage of {}: {}", t.name, parts.join("; ")));
        }
    }
    Ok(out)
}

/// The human table: the models fitted, then one block per held-out log.
pub fn print_table(
    w: &mut dyn Write,
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> std::io::Result<()> {
    for line in cmp.headline(cfg) {
        writeln!(w, "NOTE: {line}")?;
    }
    for line in cmp.model_lines() {
        writeln!(w, "{line}")?;
    }
    writeln!(w)?;
    cmp.table(cfg).write_text(w)
}

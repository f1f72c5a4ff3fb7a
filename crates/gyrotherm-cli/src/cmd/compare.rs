//! `gyrotherm compare`: fit linear, polynomial and LSTM models on training logs and judge them
//! on held-out logs — the results table of He et al. 2024, for the user's own data.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compare::{compare, CompareConfig, Comparison, Figures};
use gyrotherm::fit::NamedLog;
use gyrotherm::model::Method;
use serde_json::{json, Value};

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
    result
        .map_err(anyhow::Error::msg)
        .context("comparison failed")
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
        writeln!(
            out,
            "{}",
            serde_json::to_string_pretty(&comparison_json(&cmp, &cfg))?
        )?;
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

fn num(v: Option<f64>) -> Value {
    match v {
        Some(x) if x.is_finite() => json!(x),
        _ => Value::Null,
    }
}

fn figures_json(f: &Figures) -> Value {
    json!({
        "bias_stability_dph": num(f.bias_stability_dph),
        "sf_error_ppm": num(f.sf_error_ppm),
        "sf_thermal_error_ppm": num(f.sf_thermal_error_ppm),
        "rate_ranges": f.rate_ranges.iter().map(|r| json!({
            "table_dps": r.table_dps, "min_dps": r.min_dps, "max_dps": r.max_dps,
        })).collect::<Vec<_>>(),
    })
}

/// The comparison as JSON (kept stable for scripts).
pub fn comparison_json(cmp: &Comparison, cfg: &CompareConfig) -> Value {
    json!({
        "tau_s": cfg.tau_s,
        "tests": cmp.tests.iter().map(|t| {
            let mut methods = serde_json::Map::new();
            for m in &t.methods {
                methods.insert(m.method.as_str().into(), figures_json(&m.figures));
            }
            json!({
                "name": t.name,
                "static": t.is_static,
                "floor_dph": num(t.floor_dph),
                "raw": figures_json(&t.raw),
                "methods": methods,
                "warnings": t.warnings,
            })
        }).collect::<Vec<_>>(),
        "models": cmp.fits.iter().map(|f| json!({
            "method": f.model.method.as_str(),
            "bias_model": f.model.bias.as_ref().map(|b| b.kind()),
            "scale_model": f.model.scale.as_ref().map(|b| b.kind()),
            "bias_epochs": f.bias_training.as_ref().map(|t| t.epochs),
            "bias_final_loss": f.bias_training.as_ref().map(|t| t.final_loss),
            "scale_epochs": f.scale_training.as_ref().map(|t| t.epochs),
            "scale_final_loss": f.scale_training.as_ref().map(|t| t.final_loss),
            // Why a residual LSTM was kept or left out: the relative validation-loss
            // reduction on the validation blocks and, with --validate-on-runs, on each
            // left-out training run (fractions; null where not measured).
            "bias_lstm_validation_improvement":
                f.bias_training.as_ref().and_then(|t| t.val_improvement),
            "bias_lstm_run_gate": f.bias_training.as_ref().and_then(|t| t.run_gate.clone()),
            "scale_lstm_validation_improvement":
                f.scale_training.as_ref().and_then(|t| t.val_improvement),
            "scale_lstm_run_gate": f.scale_training.as_ref().and_then(|t| t.run_gate.clone()),
        })).collect::<Vec<_>>(),
    })
}

fn cell(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => "-".into(),
    }
}

/// The human table: one block per held-out log, one column per method.
pub fn print_table(
    w: &mut dyn Write,
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> std::io::Result<()> {
    use gyrotherm::model::SubModel;
    for f in &cmp.fits {
        let part = |s: &Option<SubModel>| s.as_ref().map_or("none", |s| s.kind());
        write!(
            w,
            "{:>6}: bias model {}, scale-factor model {}",
            f.model.method.as_str(),
            part(&f.model.bias),
            part(&f.model.scale)
        )?;
        let lstm_kept = [&f.model.bias, &f.model.scale]
            .iter()
            .any(|s| matches!(s, Some(SubModel::Lstm { .. } | SubModel::Residual { .. })));
        if f.model.method == Method::Lstm && !lstm_kept {
            write!(w, " (no residual LSTM beat its least-squares base on the validation data, so none was kept)")?;
        }
        writeln!(w)?;
    }
    writeln!(w)?;
    for t in &cmp.tests {
        let mut cols = vec!["raw".to_string()];
        cols.extend(t.methods.iter().map(|m| m.method.as_str().to_string()));
        let all: Vec<&Figures> = std::iter::once(&t.raw)
            .chain(t.methods.iter().map(|m| &m.figures))
            .collect();
        writeln!(
            w,
            "held-out log {} ({})",
            t.name,
            if t.is_static { "static" } else { "rate table" }
        )?;
        write!(w, "  {:<36}", "figure")?;
        for c in &cols {
            write!(w, "{c:>22}")?;
        }
        if t.floor_dph.is_some() {
            write!(w, "{:>22}", "noise floor")?;
        }
        writeln!(w)?;
        if t.is_static {
            write!(
                w,
                "  {:<36}",
                format!("bias stability (°/h, τ={} s)", cfg.tau_s)
            )?;
            for f in &all {
                write!(w, "{:>22}", cell(f.bias_stability_dph, 5))?;
            }
            if let Some(fl) = t.floor_dph {
                write!(w, "{:>22}", cell(Some(fl), 5))?;
            }
            writeln!(w)?;
            if let (Some(raw), Some(fl)) = (t.raw.bias_stability_dph, t.floor_dph) {
                write!(w, "  {:<36}", "  × noise floor")?;
                write!(w, "{:>22}", cell(Some(raw / fl), 2))?;
                for m in &t.methods {
                    write!(
                        w,
                        "{:>22}",
                        cell(m.figures.bias_stability_dph.map(|b| b / fl), 2)
                    )?;
                }
                writeln!(w)?;
            }
        } else {
            write!(w, "  {:<36}", "SF error max |K(t)-1| (ppm)")?;
            for f in &all {
                write!(w, "{:>22}", cell(f.sf_error_ppm, 1))?;
            }
            writeln!(w)?;
            write!(w, "  {:<36}", "SF thermal error vs room K (ppm)")?;
            for f in &all {
                write!(w, "{:>22}", cell(f.sf_thermal_error_ppm, 1))?;
            }
            writeln!(w)?;
            for (k, r) in t.raw.rate_ranges.iter().enumerate() {
                write!(
                    w,
                    "  {:<36}",
                    format!("output at {:+} °/s (°/s)", r.table_dps)
                )?;
                for f in &all {
                    let s = f
                        .rate_ranges
                        .get(k)
                        .map(|r| format!("{:.5}..{:.5}", r.min_dps, r.max_dps))
                        .unwrap_or_else(|| "-".into());
                    write!(w, "{s:>22}")?;
                }
                writeln!(w)?;
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

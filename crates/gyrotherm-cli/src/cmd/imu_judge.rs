//! `evaluate`, `compare` and `report` for an inertial unit (`--gyro-col`/`--temp-col`
//! lists, or `evaluate --model UNIT.json`): the figures per axis and the table across axes
//! (`gyrotherm::imu_judge`, `gyrotherm::report::unit`).

use std::io::Write;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::csvlog;
use gyrotherm::imu_judge::{self, ImuComparison};
use gyrotherm::model::TempSensorDef;
use gyrotherm::settings::EvaluateSettings;
use gyrotherm::unit_model::Model;

use super::args::{tau_or_default, ColumnArgs, CompareArgs, EvaluateArgs, FitArgs, ReportArgs};
use super::common::LogArgs;
use super::imu::{fit_event_printer, read_imu_logs};
use super::print::{print_evaluation, print_table};
use super::progress::TrainingBars;

/// `evaluate` on a unit log: each gyro column's figures; with `--model`, also each axis's
/// compensated output.
pub fn evaluate(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    // The sheet first: a bad sheet fails before the log is read.
    let spec = super::verdict::load(args.spec.as_deref())?;
    // A single-gyro model is the unit of its one axis.
    let model = args.model.as_deref().map(Model::load).transpose()?;
    let base = args.log.read_options();
    let model = model.as_ref().map(|m| m.to_unit(&base));
    let opts = match &model {
        Some(m) => m.read_options(&base),
        None => base,
    };
    let (log, report) = csvlog::read_imu_log(&args.input, &opts, args.log.table_axis.as_deref())
        .with_context(|| format!("cannot use log {}", args.input.display()))?;
    if report.filled_gaps > 0 {
        eprintln!(
            "gyrotherm: {}: filled {} gap(s) with {} interpolated sample(s) (--fill-gaps-max-s)",
            args.input.display(),
            report.filled_gaps,
            report.filled_samples
        );
    }
    if let Some(w) = report.truncation_warning(&args.input) {
        eprintln!("gyrotherm: warning: {w}");
    }
    let settings = EvaluateSettings {
        column: args.column.clone(),
        tau_s: args.tau_s,
        settle_s: args.settle_s,
        reference_scale: args.reference_scale,
    };
    let input = args.input.display().to_string();
    let unit =
        imu_judge::evaluate_imu_spec(&log, model.as_deref(), &settings, spec.as_ref(), &input)
            .map_err(anyhow::Error::new)
            .with_context(|| input.clone())?;
    let (axes, tau) = (&unit.axes, &unit.tau);
    if let Some(note) = tau.note(axes[0].raw.sample_period_s) {
        eprintln!("gyrotherm: {note}");
    }
    let code = super::verdict::exit_code(unit.verdict.as_ref().is_none_or(|v| v.pass));
    let mut w = std::io::stdout().lock();
    if args.json {
        // Each axis carries its verdict as the single-axis output does; the unit's verdict
        // sits beside the axes (`UnitEvaluation::to_json`).
        writeln!(w, "{}", serde_json::to_string_pretty(&unit.to_json())?)?;
        return Ok(code);
    }
    for (k, a) in axes.iter().enumerate() {
        if k > 0 {
            writeln!(w)?;
        }
        match &a.compensated {
            Some(c) => {
                writeln!(
                    w,
                    "axis {}: {} (model reads {})",
                    k + 1,
                    a.gyro,
                    a.temps.join(", ")
                )?;
                writeln!(w, "raw:")?;
                print_evaluation(&mut w, &a.raw)?;
                writeln!(w, "compensated:")?;
                print_evaluation(&mut w, c)?;
            }
            None => {
                writeln!(w, "axis {}: {}", k + 1, a.gyro)?;
                print_evaluation(&mut w, &a.raw)?;
            }
        }
        if let Some(v) = &a.verdict {
            writeln!(w)?;
            writeln!(w, "axis {} ({}) against the spec:", k + 1, a.gyro)?;
            super::verdict::print(&mut w, v)?;
        }
    }
    if let Some(v) = &unit.verdict {
        writeln!(w)?;
        writeln!(w, "{}", v.line(axes.len()))?;
    }
    Ok(code)
}

/// The comparison per axis (train and test logs read with the lists), with progress: the
/// sensor choice's steps and a bar per axis and LSTM column.
fn run_unit_comparison(
    train: &[std::path::PathBuf],
    test: &[std::path::PathBuf],
    tau: Option<f64>,
    columns: &ColumnArgs,
    fit: &FitArgs,
    log: &LogArgs,
) -> anyhow::Result<(ImuComparison, gyrotherm::compare::CompareConfig)> {
    let train = read_imu_logs(train, log)?;
    let test = read_imu_logs(test, log)?;
    let tau_s = tau_or_default(tau, || imu_judge::default_tau_s(&test));
    let cfg = columns.compare_config(fit, tau_s)?;
    if let Some(t) = cfg.autopilot.first() {
        anyhow::bail!(
            "--methods {t}: the autopilot columns are for single-gyro logs; for a unit, \
             export --target {t} writes the unit's parameters"
        );
    }
    let started = std::time::Instant::now();
    let sensors = train.first().map_or(0, |(_, l)| l.temp.len());
    if sensors > 1 {
        eprintln!(
            "gyrotherm: choosing each axis's sensor as train does ({} fit, {sensors} sensors)",
            cfg.fit.model_method().as_str()
        );
    }
    let events = fit_event_printer(started, &train);
    let gyro: Vec<String> = train
        .first()
        .map(|(_, l)| l.gyro.iter().map(|s| s.name.clone()).collect())
        .unwrap_or_default();
    let training: Vec<&'static str> = cfg
        .candidates
        .iter()
        .filter(|c| c.trains_lstm(&cfg.fit))
        .map(|c| c.key(&cfg.fit))
        .collect();
    let labels: Vec<String> = gyro
        .iter()
        .flat_map(|g| training.iter().map(move |k| format!("{g} {k}")))
        .collect();
    let label_refs: Vec<&str> = labels.iter().map(String::as_str).collect();
    let epochs = cfg
        .candidates
        .iter()
        .filter(|c| c.trains_lstm(&cfg.fit))
        .map(|c| c.fit_config(&cfg.fit).recipe.epochs)
        .max()
        .unwrap_or(0);
    let bars = TrainingBars::new(!labels.is_empty(), epochs, &label_refs);
    let result = imu_judge::compare_imu(
        &train,
        &test,
        &cfg,
        &TempSensorDef::default(),
        &|k, key, t, e, l| {
            if let Some(g) = gyro.get(k) {
                bars.update(&format!("{g} {key}"), t, e, l);
            }
        },
        &events,
    );
    bars.finish();
    let cmp = result
        .map_err(anyhow::Error::new)
        .context("comparison failed")?;
    Ok((cmp, cfg))
}

/// Per axis the single-axis table, then the table across axes.
fn print_unit_tables(
    w: &mut dyn Write,
    cmp: &ImuComparison,
    cfg: &gyrotherm::compare::CompareConfig,
) -> std::io::Result<()> {
    for (k, a) in cmp.axes.iter().enumerate() {
        match &a.unit_fit {
            None => {
                writeln!(w, "axis {}: {} (temperature {})", k + 1, a.gyro, a.temp)?;
                print_table(w, &a.comparison, cfg)?;
            }
            Some(u) => {
                writeln!(
                    w,
                    "axis {}: {} (one-sensor methods on {}, the sensor whose one-sensor fit \
                     cross-validates best; the unit's fit on {})",
                    k + 1,
                    a.gyro,
                    a.temp,
                    u.temps.join(", ")
                )?;
                for line in a.model_lines() {
                    writeln!(w, "{line}")?;
                }
                writeln!(w)?;
                a.table(cfg).write_text(w)?;
            }
        }
        writeln!(w)?;
    }
    writeln!(w, "across axes:")?;
    imu_judge::write_text_table(w, &cmp.across_axes(cfg))
}

/// Each axis's extrapolation findings, once per finding.
fn unit_warnings(cmp: &ImuComparison) -> Vec<String> {
    let mut out = Vec::new();
    for a in &cmp.axes {
        for w in gyrotherm::report::grouped_warnings(&a.test_named(), &a.comparison) {
            out.push(format!("{}: {w}", a.gyro));
        }
    }
    out
}

/// Each axis's verdicts (every column, then the unit's own fit), then the unit's verdict of
/// each column across the axes (`compare --spec` and `report --spec` with lists).
fn print_unit_verdicts(
    out: &mut dyn Write,
    spec: &gyrotherm::spec::Spec,
    verdicts: &[imu_judge::AxisVerdicts],
) -> std::io::Result<()> {
    for (k, a) in verdicts.iter().enumerate() {
        writeln!(out, "\naxis {} ({}) against the spec:", k + 1, a.gyro)?;
        super::verdict::print_columns(out, &a.columns)?;
        if let Some((label, v)) = &a.unit_fit {
            writeln!(out, "\n{label} (unit fit):")?;
            super::verdict::print(out, v)?;
        }
    }
    writeln!(out, "\nspec {} across the axes:", spec.name.escape_debug())?;
    for line in imu_judge::verdicts_across_axes(spec, verdicts) {
        writeln!(out, "  {line}")?;
    }
    Ok(())
}

/// `compare` with column lists (with `--spec`, every column of every axis judged).
pub fn compare(args: CompareArgs) -> anyhow::Result<ExitCode> {
    let spec = super::verdict::load(args.spec.as_deref())?;
    let (cmp, cfg) = run_unit_comparison(
        &args.train,
        &args.test,
        args.tau_s,
        &args.columns,
        &args.fit,
        &args.log,
    )?;
    let verdicts = spec
        .as_ref()
        .map(|s| imu_judge::judge_unit_comparison(s, &cmp, &cfg))
        .transpose()?;
    let mut out = std::io::stdout().lock();
    if args.json {
        let j = cmp.summary_json(&cfg, verdicts.as_deref())?;
        writeln!(out, "{}", serde_json::to_string_pretty(&j)?)?;
    } else {
        print_unit_tables(&mut out, &cmp, &cfg)?;
        if let (Some(vs), Some(s)) = (&verdicts, &spec) {
            print_unit_verdicts(&mut out, s, vs)?;
        }
    }
    for w in unit_warnings(&cmp) {
        eprintln!("gyrotherm: warning: {w}");
    }
    Ok(super::verdict::exit_code(
        verdicts.iter().flatten().all(|a| a.pass()),
    ))
}

/// `report` with column lists: the unit page and a full page per axis; with `--spec`, every
/// column of every axis judged as `compare --spec` judges it (on the page and on stdout),
/// exit 1 when a column misses a limit.
pub fn report(args: ReportArgs) -> anyhow::Result<ExitCode> {
    let spec = super::verdict::load(args.spec.as_deref())?;
    let (cmp, cfg) = run_unit_comparison(
        &args.train,
        &args.test,
        args.tau_s,
        &args.columns,
        &args.fit,
        &args.log,
    )?;
    let verdicts = spec
        .as_ref()
        .map(|s| imu_judge::judge_unit_comparison(s, &cmp, &cfg))
        .transpose()?;
    let judged = spec.as_ref().zip(verdicts.as_deref());
    let index = gyrotherm::report::unit::write_unit_report(&args.out, &cmp, &cfg, &[], judged)
        .with_context(|| format!("cannot write the report in {}", args.out.display()))?;
    let mut out = std::io::stdout().lock();
    print_unit_tables(&mut out, &cmp, &cfg)?;
    if let Some((s, vs)) = judged {
        print_unit_verdicts(&mut out, s, vs)?;
    }
    writeln!(out, "report: {}", index.display())?;
    for w in unit_warnings(&cmp) {
        eprintln!("gyrotherm: warning: {w}");
    }
    Ok(super::verdict::exit_code(
        verdicts.iter().flatten().all(|a| a.pass()),
    ))
}

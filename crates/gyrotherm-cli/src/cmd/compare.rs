//! `gyrotherm compare`: fit linear, polynomial, the default `thermal` model and the
//! `published` method (He et al. 2024) on training logs and judge them on held-out logs — the
//! paper's results table, for the user's own data, one column per model.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compare::{compare_with_stages, Candidate, CompareConfig, Comparison, Stage};
use gyrotherm::fit::NamedLog;

use super::args::{resolve_tau, CompareArgs};
use super::common::{named, read_logs};
use super::print::print_table;
use super::progress::TrainingBars;

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

/// The autopilot columns asked for (`--methods …,ardupilot,px4`), after the fitted ones;
/// a polynomial that could not be fitted is said as a column that was not fitted.
pub fn add_autopilot_columns(
    cmp: &mut Comparison,
    train: &[NamedLog],
    test: &[NamedLog],
    cfg: &CompareConfig,
) -> anyhow::Result<()> {
    let before = cmp.failed.len();
    gyrotherm::export::autopilot::add_columns(cmp, train, test, cfg)
        .context("the autopilot columns failed")?;
    for f in &cmp.failed[before..] {
        eprintln!(
            "gyrotherm: warning: the {} column was not fitted: {}",
            f.key, f.reason
        );
    }
    Ok(())
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    if args
        .log
        .read_options()
        .reads_unit(&[&args.train[..], &args.test[..]].concat())
    {
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
    let mut cmp = run_comparison(&train_named, &test_named, &cfg)?;
    add_autopilot_columns(&mut cmp, &train_named, &test_named, &cfg)?;
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

//! `gyrotherm report`: run the held-out comparison of `gyrotherm compare` and write it as an
//! HTML report with the figures a gyro engineer looks at (`DIR/index.html`, one PNG and SVG
//! per figure; see `gyrotherm::report::job`).

use std::process::ExitCode;

use std::io::Write as _;

use anyhow::Context as _;
use gyrotherm::report::write_full_report_with;

use super::args::{resolve_tau, ReportArgs};
use super::common::{named, read_logs};
use super::compare::run_comparison;
use super::print::print_table;

pub fn run(args: ReportArgs) -> anyhow::Result<ExitCode> {
    if args
        .log
        .read_options()
        .reads_unit(&[&args.train[..], &args.test[..]].concat())
    {
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
    let mut cmp = run_comparison(&train_named, &test_named, &cfg)?;
    super::compare::add_autopilot_columns(&mut cmp, &train_named, &test_named, &cfg)?;
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

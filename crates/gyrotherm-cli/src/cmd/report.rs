//! `gyrotherm report`: run the held-out comparison of `gyrotherm compare` and write it as an
//! HTML report with the figures a gyro engineer looks at (`DIR/index.html`, one PNG and SVG
//! per figure; for a unit, its page and a full page per axis).

use std::io::Write as _;
use std::process::ExitCode;

use anyhow::Context as _;

use super::args::ReportArgs;
use super::common::tell;
use super::compare::Job;

pub fn run(args: ReportArgs) -> anyhow::Result<ExitCode> {
    let spec = super::verdict::load(args.spec.as_deref())?;
    let job = Job::read(
        &args.train,
        &args.test,
        args.tau_s,
        &args.columns,
        &args.fit,
        &args.log,
    )?;
    let judged = job.judge(spec.as_ref())?;
    let started = std::time::Instant::now();
    eprintln!(
        "gyrotherm: drawing the figures and writing the report in {}…",
        args.out.display()
    );
    let index = judged
        .write_report(&args.out)
        .with_context(|| format!("cannot write the report in {}", args.out.display()))?;
    eprintln!(
        "gyrotherm: wrote {} in {:.1} s",
        index.display(),
        started.elapsed().as_secs_f64()
    );
    let mut out = std::io::stdout().lock();
    judged.write_text(&mut out)?;
    writeln!(out, "report: {}", index.display())?;
    for t in judged.findings() {
        tell(&t);
    }
    Ok(super::verdict::exit_code(judged.pass()))
}

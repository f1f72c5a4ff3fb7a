//! `gyrotherm compare`: fit linear, polynomial, the default method's model and the
//! `published` method (He et al. 2024) on training logs and judge them on held-out logs — the
//! paper's results table, for the user's own data, one column per model (for a unit, per
//! axis and across the axes).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compare::CompareConfig;
use gyrotherm::csvlog::LogSet;
use gyrotherm::judge::{judge, progress_bars, tau_s, JudgeEvent, Judgement};
use gyrotherm::spec::Spec;

use super::args::{ColumnArgs, CompareArgs, FitArgs};
use super::common::{read_log_sets, tell, LogArgs};
use super::progress::TrainingBars;

/// The training and held-out logs of a comparison, read alike, and its settings.
pub struct Job {
    pub train: LogSet,
    pub test: LogSet,
    pub cfg: CompareConfig,
}

impl Job {
    /// Read both sets of logs and settle the settings (τ from the held-out logs when not
    /// given).
    pub fn read(
        train: &[PathBuf],
        test: &[PathBuf],
        tau: Option<f64>,
        columns: &ColumnArgs,
        fit: &FitArgs,
        log: &LogArgs,
    ) -> anyhow::Result<Job> {
        let [train, test] = read_log_sets([train, test], log)?;
        let (tau_s, told) = tau_s(&test, tau);
        told.iter().for_each(tell);
        let cfg = columns.compare_config(fit, tau_s)?;
        Ok(Job { train, test, cfg })
    }

    /// The judgement, with a progress bar for every column that trains an LSTM and each
    /// step told on stderr.
    pub fn judge<'a>(&'a self, spec: Option<&'a Spec>) -> anyhow::Result<Judgement<'a>> {
        let (labels, epochs) = progress_bars(&self.train, &self.cfg);
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        let bars = TrainingBars::new(!labels.is_empty(), epochs, &labels);
        let result = judge(&self.train, &self.test, &self.cfg, spec, &|e| match e {
            JudgeEvent::Epoch {
                label,
                target,
                epoch,
                loss,
            } => bars.update(&label, target, epoch, loss),
            JudgeEvent::Told(t) => bars.suspend(|| tell(&t)),
            _ => {}
        });
        bars.finish();
        Ok(result?)
    }
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
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
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&judged.to_json()?)?)?;
    } else {
        judged.write_text(&mut out)?;
    }
    for t in judged.findings() {
        tell(&t);
    }
    for t in judged.coverage().context("coverage of the held-out logs")? {
        tell(&t);
    }
    Ok(super::verdict::exit_code(judged.pass()))
}

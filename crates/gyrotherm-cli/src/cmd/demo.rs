//! `gyrotherm demo`: the main job on built-in defaults. Simulates a training pair (static and
//! rate-table runs of the default unit on one chamber profile) and a held-out pair on another
//! profile, fits linear, polynomial, the default method (`auto`: the better of `thermal` and
//! `thermal-lstm` on held-out blocks) and the `published` method (He et al. 2024), and prints
//! the held-out results table, one column per model.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::csvlog::{write_log, LogSet, TestLog};
use gyrotherm::sim::{simulate, SimConfig};

use super::args::{ColumnArgs, FitArgs};
use super::common::{builtin_profile, tell};
use super::compare::Job;

#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Folder for the simulated logs and the fitted models (created if missing).
    #[arg(long, default_value = "gyrotherm-demo")]
    pub dir: PathBuf,
    /// Chamber profile of the training runs.
    #[arg(long, default_value = "seed-shock", value_parser = builtin_profile())]
    pub train_profile: String,
    /// Chamber profile of the held-out runs (a different one: the test is held out).
    #[arg(long, default_value = "slow-ramp", value_parser = builtin_profile())]
    pub test_profile: String,
    /// Rate-table rate of the rate-table runs, °/s.
    #[arg(long, default_value_t = 20.0)]
    pub table_rate: f64,
    #[command(flatten)]
    pub columns: ColumnArgs,
    #[command(flatten)]
    pub fit: FitArgs,
}

fn sim_run(profile: &str, seed: u64, table: Option<f64>, truth: bool) -> anyhow::Result<TestLog> {
    let mut cfg = SimConfig::builtin(profile).map_err(|e| anyhow::anyhow!("{e}"))?;
    cfg.seed = seed;
    cfg.table_rate_dps = table;
    cfg.truth = truth;
    simulate(&cfg).map_err(|e| anyhow::anyhow!("simulating {profile}: {e}"))
}

pub fn run(args: DemoArgs) -> anyhow::Result<ExitCode> {
    let started = std::time::Instant::now();
    std::fs::create_dir_all(&args.dir)
        .with_context(|| format!("cannot create {}", args.dir.display()))?;
    let seed = args.fit.seed;
    let runs = [
        (
            "train_static.csv",
            args.train_profile.as_str(),
            1,
            None,
            false,
        ),
        (
            "train_table.csv",
            args.train_profile.as_str(),
            2,
            Some(args.table_rate),
            false,
        ),
        ("test_static.csv", args.test_profile.as_str(), 3, None, true),
        (
            "test_table.csv",
            args.test_profile.as_str(),
            4,
            Some(args.table_rate),
            true,
        ),
    ];
    let mut logs = Vec::new();
    for (file, profile, k, table, truth) in runs {
        let log = sim_run(profile, seed.wrapping_mul(10).wrapping_add(k), table, truth)?;
        let path = args.dir.join(file);
        write_log(&path, &log).with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!(
            "gyrotherm: simulated {} ({profile}{}, {} samples)",
            path.display(),
            table
                .map(|r| format!(", table ±{r} °/s"))
                .unwrap_or_default(),
            log.len()
        );
        logs.push((path.display().to_string(), log));
    }
    let test = LogSet::of_logs(logs.split_off(2));
    let train = LogSet::of_logs(logs);
    let cfg = args
        .columns
        .compare_config(&args.fit, gyrotherm::compare::BIAS_STABILITY_TAU_S)?;
    let keys: Vec<&str> = cfg.candidates.iter().map(|c| c.key(&cfg.fit)).collect();
    eprintln!(
        "gyrotherm: fitting the {} models on the training runs ...",
        keys.join(", ")
    );
    let job = Job { train, test, cfg };
    let judged = job.judge(None)?;
    for (key, model) in judged.fitted() {
        let path = args.dir.join(format!("model_{key}.json"));
        model.save(&path).map_err(anyhow::Error::new)?;
    }
    let mut out = std::io::stdout().lock();
    judged.write_text(&mut out)?;
    for t in judged.findings() {
        tell(&t);
    }
    eprintln!(
        "gyrotherm: demo done in {:.1} s; logs and models are in {}",
        started.elapsed().as_secs_f64(),
        args.dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

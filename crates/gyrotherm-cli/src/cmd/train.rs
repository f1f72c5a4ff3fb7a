//! `gyrotherm train`: fit a compensation model to test logs and write it as JSON.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::train::{epoch_bars, train, TrainEvent};

use super::args::TrainArgs;
use super::common::{read_log_set, tell};
use super::progress::TrainingBars;

pub fn run(args: TrainArgs) -> anyhow::Result<ExitCode> {
    super::common::refuse_outputs_over_inputs(
        [args.out.as_path()],
        args.input.iter().map(PathBuf::as_path),
    )?;
    let opts = args.log.read_options();
    let logs = read_log_set(&args.input, &opts, args.log.table_axis.as_deref())?;
    let cfg = args.fit.fit_config(args.method)?;
    let temp_sensor = args.sensor.to_def()?;
    let started = std::time::Instant::now();
    let epochs = epoch_bars(&logs, &cfg);
    let bars = TrainingBars::new(epochs.is_some(), epochs.unwrap_or(0), &[""]);
    let trained = train(&logs, &cfg, &temp_sensor, &opts, &|e| match e {
        TrainEvent::Epoch {
            target,
            epoch,
            loss,
        } => bars.update("", target, epoch, loss),
        TrainEvent::Step(line) => bars.println(&format!("gyrotherm: {line}")),
        TrainEvent::Axis(step) => bars.println(&format!("gyrotherm: {}", step.line)),
        _ => {}
    });
    bars.finish();
    let trained = trained
        .map_err(anyhow::Error::new)
        .context("training failed")?;
    trained
        .model
        .save(&args.out)
        .map_err(anyhow::Error::new)
        .context("cannot write the model")?;
    for t in trained.told(&args.out, started.elapsed().as_secs_f64()) {
        tell(&t);
    }
    Ok(ExitCode::SUCCESS)
}

//! `gyrotherm train`: fit a compensation model to test logs and write it as JSON.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::fit::{fit_model, Target};
use gyrotherm::model::ColumnsDef;

use super::args::TrainArgs;
use super::common::{named, read_logs};
use super::progress::TrainingBars;

pub fn run(args: TrainArgs) -> anyhow::Result<ExitCode> {
    super::common::refuse_outputs_over_inputs(
        [args.out.as_path()],
        args.input.iter().map(PathBuf::as_path),
    )?;
    if args.log.read_options().reads_unit(&args.input) {
        return super::imu::train(args);
    }
    let logs = read_logs(&args.input, &args.log, &mut Vec::new())?;
    let named = named(&logs);
    let cfg = args.fit.fit_config(args.method)?;
    let method = cfg.model_method();
    let temp_sensor = args.sensor.to_def()?;
    let started = std::time::Instant::now();
    let bars = TrainingBars::new(method.is_recipe(), cfg.recipe.epochs, &[""]);
    let outcome = fit_model(&named, &cfg, &|t: Target, e, l| bars.update("", t, e, l));
    bars.finish();
    let mut outcome = outcome
        .map_err(anyhow::Error::new)
        .context("training failed")?;
    outcome.model.features.temp_sensor = temp_sensor;
    // Remembered so that `compensate` reads a log of the same layout without the options.
    outcome.model.columns = Some(ColumnsDef::of(&args.log.read_options()));
    outcome
        .model
        .save(&args.out)
        .map_err(anyhow::Error::new)
        .context("cannot write the model")?;
    let m = &outcome.model;
    eprintln!(
        "gyrotherm: wrote {} ({} model; bias: {}, scale factor: {}) in {:.1} s",
        args.out.display(),
        m.method.as_str(),
        if m.bias.is_some() {
            "fitted"
        } else {
            "none (no static log)"
        },
        if m.scale.is_some() {
            "fitted"
        } else {
            "none (no rate-table log)"
        },
        started.elapsed().as_secs_f64()
    );
    for line in outcome.describe(&named, &cfg) {
        eprintln!("{line}");
    }
    Ok(ExitCode::SUCCESS)
}

//! `gyrotherm train`: fit a compensation model to test logs and write it as JSON.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::fit::{fit_model, FitConfig, Target};
use gyrotherm::model::ColumnsDef;
use gyrotherm::settings::fit::{self, RECIPE_NAMES};
use gyrotherm::settings::{Deprecation, FitSettings, Method, Rule, DEFAULT_METHOD, METHODS};

use super::common::{choice, named, read_logs, seconds, LogArgs};

/// The `--method` parser: the library's methods with their help, and the deprecated `lstm`
/// accepted but not listed.
pub fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(
        METHODS
            .iter()
            .map(|m| PossibleValue::new(m.as_str()).help(m.help()))
            .chain([PossibleValue::new(Method::Lstm.as_str()).hide(true)]),
    )
    .try_map(|s| s.parse::<Method>())
}
use super::progress::TrainingBars;

/// Fitting options shared by `train`, `compare`, `report` and `demo`: the library's
/// [`FitSettings`] (defaults, names and checks are the library's).
#[derive(Debug, Clone, clap::Args)]
pub struct FitArgs {
    /// Deprecated (one release): the recipe of the former `lstm` method, now a method of its
    /// own (`--method lstm --recipe residual` is `--method residual`).
    #[arg(long, hide = true, value_parser = choice::<Method>(RECIPE_NAMES.map(|n| (n, ""))))]
    pub recipe: Option<Method>,
    /// Training epochs of the method's LSTM (default: the method's own).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Random seed of the LSTM initialisation and window order.
    #[arg(long, default_value_t = fit::DEFAULT_SEED)]
    pub seed: u64,
    /// Hidden units of the method's LSTM (8 as published; 1 to 128).
    #[arg(long, default_value_t = fit::DEFAULT_HIDDEN)]
    pub hidden: usize,
    /// Bias target smoothing window, s (centred moving average; 100 s as published).
    #[arg(long, alias = "bias-window", default_value_t = fit::DEFAULT_BIAS_WINDOW_S,
          value_parser = seconds("bias_window_s", Rule::PositiveSeconds))]
    pub bias_window_s: f64,
    /// Time dropped at the start of each rate-table segment, s.
    #[arg(long, alias = "settle", default_value_t = fit::DEFAULT_SETTLE_S,
          value_parser = seconds("settle_s", Rule::NonNegativeSeconds))]
    pub settle_s: f64,
    /// Highest power of T in the `poly` bias model.
    #[arg(long, default_value_t = fit::DEFAULT_POLY_TEMP_DEGREE)]
    pub poly_temp_degree: u8,
    /// Highest power of dT in the `poly` bias model.
    #[arg(long, default_value_t = fit::DEFAULT_POLY_RATE_DEGREE)]
    pub poly_rate_degree: u8,
    /// Leave the T·dT cross term out of the `poly` bias model.
    #[arg(long)]
    pub no_cross: bool,
    /// With two or more static (or rate-table) training logs: keep the residual LSTM only if,
    /// trained without each log in turn, it also improves that log (slower: one more training
    /// per log; reports each log's figure).
    #[arg(long)]
    pub validate_on_runs: bool,
}

impl FitArgs {
    /// The library's settings for `method`.
    pub fn settings(&self, method: Method) -> FitSettings {
        FitSettings {
            method,
            recipe: self.recipe,
            epochs: self.epochs,
            seed: self.seed,
            hidden: self.hidden,
            bias_window_s: self.bias_window_s,
            settle_s: self.settle_s,
            poly_temp_degree: self.poly_temp_degree,
            poly_rate_degree: self.poly_rate_degree,
            cross: !self.no_cross,
            validate_on_runs: self.validate_on_runs,
        }
    }

    /// The library's fit configuration for `method`; a deprecated spelling is said on stderr.
    pub fn fit_config(&self, method: Method) -> anyhow::Result<FitConfig> {
        let (cfg, note) = self.settings(method).fit_config()?;
        if let Some(n) = note {
            eprintln!("gyrotherm: warning: {}", deprecation_text(n));
        }
        Ok(cfg)
    }
}

/// A deprecation in the command line's words.
pub fn deprecation_text(d: Deprecation) -> String {
    match d {
        Deprecation::LstmMethod { now } => {
            format!("--method lstm is deprecated: use --method {now} (same model)")
        }
        Deprecation::Recipe { now } => {
            format!("--recipe is deprecated: the recipes are methods now; use --method {now}")
        }
        Deprecation::RecipeIgnored { method } => {
            format!("--recipe is deprecated, and --method {method} has none: ignored")
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct TrainArgs {
    /// Training log (CSV); repeat for several. Static logs train the bias model, logs with
    /// table_dps the scale-factor model.
    #[arg(long, required = true)]
    pub input: Vec<PathBuf>,
    /// Fitting method.
    #[arg(long, default_value_t = DEFAULT_METHOD, value_parser = method_parser())]
    pub method: Method,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Model file to write (JSON).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub log: LogArgs,
    #[command(flatten)]
    pub sensor: super::compensate::TempSensorArgs,
}

pub fn run(args: TrainArgs) -> anyhow::Result<ExitCode> {
    super::common::refuse_outputs_over_inputs(
        [args.out.as_path()],
        args.input.iter().map(PathBuf::as_path),
    )?;
    if args.log.read_options().is_multi_column() {
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

//! `gyrotherm train`: fit a compensation model to test logs and write it as JSON.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::fit::RecipeKind;
use gyrotherm::fit::{fit_model, FitConfig, LstmVerdict, NamedLog, Target};
use gyrotherm::model::Method;

use super::common::{named, read_logs, LogArgs};
use super::progress::TrainingBars;

/// Fitting options shared by `train` and `compare`.
#[derive(Debug, Clone, clap::Args)]
pub struct FitArgs {
    /// LSTM recipe.
    #[arg(long, value_enum, default_value_t = RecipeArg::Thermal)]
    pub recipe: RecipeArg,
    /// LSTM training epochs (default: the recipe's).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Random seed of the LSTM initialisation and window order.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Bias target smoothing window, s (centred moving average; 100 s as published).
    #[arg(long, default_value_t = gyrotherm::targets::BIAS_WINDOW_S)]
    pub bias_window: f64,
    /// Time dropped at the start of each rate-table segment, s.
    #[arg(long, default_value_t = gyrotherm::targets::SETTLE_S)]
    pub settle: f64,
    /// Highest power of T in the `poly` bias model.
    #[arg(long, default_value_t = 3)]
    pub poly_temp_degree: u8,
    /// Highest power of dT in the `poly` bias model.
    #[arg(long, default_value_t = 1)]
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
    /// The comparison settings (all methods) with bias stability over `tau_s`.
    pub fn compare_config(&self, tau_s: f64) -> anyhow::Result<gyrotherm::compare::CompareConfig> {
        anyhow::ensure!(
            tau_s.is_finite() && tau_s > 0.0,
            "--tau must be a positive number of seconds"
        );
        Ok(gyrotherm::compare::CompareConfig {
            fit: self.fit_config(Method::Lstm)?,
            tau_s,
            settle_s: self.settle,
            ..Default::default()
        })
    }

    /// The library's fit configuration for `method`.
    pub fn fit_config(&self, method: Method) -> anyhow::Result<FitConfig> {
        let mut cfg = FitConfig::new(method);
        cfg.recipe = gyrotherm::fit::LstmRecipe::of_kind(self.recipe.into());
        if let Some(e) = self.epochs {
            anyhow::ensure!(e > 0, "--epochs must be at least 1");
            cfg.recipe.epochs = e;
        }
        anyhow::ensure!(
            self.bias_window.is_finite() && self.bias_window > 0.0,
            "--bias-window must be a positive number of seconds"
        );
        anyhow::ensure!(
            self.settle.is_finite() && self.settle >= 0.0,
            "--settle must be zero or a positive number of seconds"
        );
        cfg.seed = self.seed;
        cfg.bias_window_s = self.bias_window;
        cfg.settle_s = self.settle;
        cfg.poly.temp = self.poly_temp_degree;
        cfg.poly.rate = self.poly_rate_degree;
        cfg.poly.cross = !self.no_cross;
        cfg.recipe.validate_on_runs = self.validate_on_runs;
        Ok(cfg)
    }
}

/// `--recipe` values (the library's `fit::lstm::RecipeKind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RecipeArg {
    /// Thermal time constants identified from the logs and a ridge fit on them, no LSTM
    /// (the default: chosen on a family of simulated units, docs/experiments/generalisation.md);
    /// degrades on short or coarse logs and says how.
    Thermal,
    /// Least squares on thermal-state inputs (T, dT, T − first-order lags of 300/1000/3000 s)
    /// plus an LSTM on its residual, kept only where it beats the least-squares base on
    /// validation blocks.
    Residual,
    /// As `residual`, on a generic linear + T² base.
    Generic,
    /// An LSTM alone on the thermal-state inputs.
    Direct,
    /// He et al. 2024 exactly (whole run, T and dT inputs, 1000 Adam steps at lr 0.01).
    Published,
}

impl From<RecipeArg> for RecipeKind {
    fn from(r: RecipeArg) -> RecipeKind {
        match r {
            RecipeArg::Thermal => RecipeKind::Thermal,
            RecipeArg::Residual => RecipeKind::Residual,
            RecipeArg::Generic => RecipeKind::Generic,
            RecipeArg::Direct => RecipeKind::Direct,
            RecipeArg::Published => RecipeKind::Published,
        }
    }
}

/// `--method` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// LSTM networks (He et al. 2024), bias and scale factor.
    Lstm,
    /// bias = c0 + c1·T + c2·dT (the paper's comparison).
    Linear,
    /// Polynomial in T and dT (industry standard).
    Poly,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Lstm => Method::Lstm,
            MethodArg::Linear => Method::Linear,
            MethodArg::Poly => Method::Poly,
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
    #[arg(long, value_enum, default_value_t = MethodArg::Lstm)]
    pub method: MethodArg,
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
    let logs = read_logs(&args.input, &args.log, &mut Vec::new())?;
    let named = named(&logs);
    let method: Method = args.method.into();
    let cfg = args.fit.fit_config(method)?;
    let temp_sensor = args.sensor.to_def()?;
    let started = std::time::Instant::now();
    let bars = TrainingBars::new(method == Method::Lstm, cfg.recipe.epochs, &[""]);
    let outcome = fit_model(&named, &cfg, &|t: Target, e, l| bars.update("", t, e, l));
    bars.finish();
    let mut outcome = outcome
        .map_err(anyhow::Error::new)
        .context("training failed")?;
    outcome.model.features.temp_sensor = temp_sensor;
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
    eprintln!(
        "  training range: temperature {:.2} to {:.2} °C, rate {:.3} to {:.3} °C/min",
        m.training.temp_range_c.min,
        m.training.temp_range_c.max,
        m.training.rate_range_c_per_s.min * 60.0,
        m.training.rate_range_c_per_s.max * 60.0
    );
    // The training runs of each target, in the order the fit saw them.
    let (static_names, table_names): (Vec<&NamedLog>, Vec<&NamedLog>) =
        named.iter().partition(|l| l.log.is_static());
    for (name, sub, t, runs) in [
        ("bias", &m.bias, &outcome.bias_training, &static_names),
        (
            "scale factor",
            &m.scale,
            &outcome.scale_training,
            &table_names,
        ),
    ] {
        let Some(sub) = sub else { continue };
        eprintln!("  {name} model: {}", sub.kind());
        let Some(t) = t else { continue };
        if let Some(r) = &t.thermal {
            eprintln!("    {}", r.describe());
        }
        if let Some(sel) = &t.selection {
            eprintln!(
                "    least-squares terms by time-segment cross-validation (RMS, * chosen): {}",
                sel.describe()
            );
        }
        if let Some(verdict) = t.lstm_verdict {
            eprintln!(
                "    LSTM: {} epochs, final loss {:.4e} (normalised MSE); {}",
                t.epochs,
                t.final_loss,
                match verdict {
                    LstmVerdict::Kept => "kept",
                    LstmVerdict::LeftOut {
                        validation_blocks: true,
                        left_out_runs: true,
                    } => {
                        "left out: it beat the least-squares base neither on the validation \
                         blocks nor on every left-out run"
                    }
                    LstmVerdict::LeftOut {
                        validation_blocks: true,
                        left_out_runs: false,
                    } => {
                        "left out: it did not beat the least-squares base on the validation blocks"
                    }
                    LstmVerdict::LeftOut {
                        validation_blocks: false,
                        left_out_runs: true,
                    } => {
                        "left out: it did not beat the least-squares base on every left-out run"
                    }
                    LstmVerdict::LeftOut {
                        validation_blocks: false,
                        left_out_runs: false,
                    } => "left out: its correction fitted none of the validation residual",
                }
            );
            if let Some(gate) = &t.run_gate {
                let each: Vec<String> = gate
                    .iter()
                    .zip(runs.iter())
                    .map(|(g, l)| format!("{} {:.1} %", l.name, 100.0 * g))
                    .collect();
                eprintln!(
                    "    LSTM trained without each run, loss reduction on that run (needs {:.0} %): {}",
                    100.0 * cfg.recipe.min_val_improvement,
                    each.join(", ")
                );
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

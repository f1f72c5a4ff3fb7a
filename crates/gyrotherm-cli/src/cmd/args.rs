//! The arguments of the commands that run on one gyro or, with `--gyro-col`/`--temp-col`
//! lists (or a unit's model), on an inertial unit: `train`, `compensate`, `evaluate`,
//! `compare` and `report`, with the fitting, column and sensor-limit options they share. The
//! command files and the unit paths (`imu`, `imu_judge`) both take them from here.

use std::path::PathBuf;

use gyrotherm::compare::{ColumnName, CompareConfig};
use gyrotherm::fit::FitConfig;
use gyrotherm::model::TempSensorDef;
use gyrotherm::settings::fit;
use gyrotherm::settings::{EvaluateSettings, FitSettings, Method, Rule, DEFAULT_METHOD, METHODS};
use gyrotherm_core::TempLimits;

use super::common::{seconds, LogArgs};

/// The `--method` parser: the library's methods with their help.
pub fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(
        METHODS
            .iter()
            .map(|m| PossibleValue::new(m.as_str()).help(m.help())),
    )
    .try_map(|s| s.parse::<Method>())
}

/// The `--methods` parser: the library's column names with their help.
fn column_parser() -> impl clap::builder::TypedValueParser<Value = ColumnName> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(
        ColumnName::all()
            .into_iter()
            .map(|(name, help)| PossibleValue::new(name).help(help)),
    )
    .try_map(|s| s.parse::<ColumnName>())
}

/// Fitting options shared by `train`, `compare`, `report` and `demo`: the library's
/// [`FitSettings`] (defaults, names and checks are the library's).
#[derive(Debug, Clone, clap::Args)]
pub struct FitArgs {
    /// Training epochs of the method's LSTM (default: the method's own).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Random seed of the LSTM initialisation and window order.
    #[arg(long, default_value_t = fit::DEFAULT_SEED)]
    pub seed: u64,
    #[arg(long, help = fit::hidden_help())]
    pub hidden: Option<usize>,
    #[arg(long, help = fit::windows_help())]
    pub windows: Option<usize>,
    /// Bias target smoothing window, s (centred moving average; 100 s as published).
    #[arg(long, default_value_t = fit::DEFAULT_BIAS_WINDOW_S,
          value_parser = seconds("bias_window_s", Rule::PositiveSeconds))]
    pub bias_window_s: f64,
    /// Time dropped at the start of each rate-table segment, s.
    #[arg(long, default_value_t = fit::DEFAULT_SETTLE_S,
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
            epochs: self.epochs,
            seed: self.seed,
            hidden: self.hidden,
            windows: self.windows,
            bias_window_s: self.bias_window_s,
            settle_s: self.settle_s,
            poly_temp_degree: self.poly_temp_degree,
            poly_rate_degree: self.poly_rate_degree,
            cross: !self.no_cross,
            validate_on_runs: self.validate_on_runs,
        }
    }

    /// The library's fit configuration for `method`.
    pub fn fit_config(&self, method: Method) -> anyhow::Result<FitConfig> {
        Ok(self.settings(method).fit_config()?)
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
    pub sensor: TempSensorArgs,
}

/// Temperature-sensor fault limits stored in the model at `train` (see `gyrotherm compensate`:
/// a reading outside the range or changing faster than the rate limit is held).
#[derive(Debug, Clone, clap::Args)]
pub struct TempSensorArgs {
    /// Lowest plausible temperature reading, °C.
    #[arg(long, value_name = "C", allow_negative_numbers = true, default_value_t = TempLimits::DEFAULT.min_c)]
    pub temp_min_c: f64,
    /// Highest plausible temperature reading, °C.
    #[arg(long, value_name = "C", allow_negative_numbers = true, default_value_t = TempLimits::DEFAULT.max_c)]
    pub temp_max_c: f64,
    /// Fastest plausible temperature change, °C/s.
    #[arg(long, value_name = "C_PER_S", default_value_t = TempLimits::DEFAULT.max_rate_c_per_s)]
    pub temp_max_rate_c_per_s: f64,
    /// Temperature change always allowed between two readings (noise, resolution), °C.
    #[arg(long, value_name = "C", default_value_t = TempLimits::DEFAULT.step_allowance_c)]
    pub temp_step_allowance_c: f64,
    /// Seconds without a good temperature before the output is `degraded` instead of `held`.
    #[arg(long, value_name = "S", default_value_t = TempLimits::DEFAULT.degraded_after_s)]
    pub degraded_after_s: f64,
}

impl TempSensorArgs {
    /// The model-file form, checked.
    pub fn to_def(&self) -> anyhow::Result<TempSensorDef> {
        let def = TempSensorDef {
            min_c: self.temp_min_c,
            max_c: self.temp_max_c,
            max_rate_c_per_s: self.temp_max_rate_c_per_s,
            step_allowance_c: self.temp_step_allowance_c,
            degraded_after_s: self.degraded_after_s,
        };
        def.to_core().map_err(|e| {
            anyhow::anyhow!(
                "temperature-sensor limits (--temp-min-c, --temp-max-c, --temp-max-rate-c-per-s, \
                 --temp-step-allowance-c, --degraded-after-s): {e}"
            )
        })?;
        Ok(def)
    }
}

#[derive(Debug, clap::Args)]
pub struct CompensateArgs {
    /// Model file written by `gyrotherm train`.
    #[arg(long)]
    pub model: PathBuf,
    /// Log to compensate (CSV). Not with --stream.
    #[arg(long, required_unless_present = "stream", conflicts_with = "stream")]
    pub input: Option<PathBuf>,
    /// Output CSV: every input column, then bias_dps, scale, gyro_comp_dps (°/s), status
    /// (ok, held, degraded, invalid), coverage (inside, edge, outside the training region)
    /// and sigma_dph (1σ estimate of the residual bias error, °/h). With an inertial-unit
    /// model: every input column, then G_bias, G_scale, G_comp, G_status per gyro column G.
    #[arg(long, required_unless_present = "stream", conflicts_with = "stream")]
    pub out: Option<PathBuf>,
    /// Read CSV on stdin and write one output line per input line on stdout, flushed as it
    /// goes (the flight path), with the columns of --out (single-axis or inertial-unit model).
    /// A malformed line is written as `invalid` and the stream goes on.
    #[arg(long)]
    pub stream: bool,
    #[command(flatten)]
    pub log: LogArgs,
}

#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Test log (CSV).
    #[arg(long)]
    pub input: PathBuf,
    #[command(flatten)]
    pub log: LogArgs,
    /// Rate column to judge, by its name in the file: the gyro column (default; also called
    /// gyro_dps) or a numeric extra column (*_dps, *_dph, *_rad_s).
    #[arg(long, default_value_t = EvaluateSettings::default().column)]
    pub column: String,
    /// Smoothing time of the bias stability, s (default 100 s, or the multiple of the sample
    /// period nearest to it when 100 s is not one).
    #[arg(long, value_parser = seconds("tau_s", Rule::PositiveSeconds))]
    pub tau_s: Option<f64>,
    /// Time dropped at the start of each rate-table segment, s.
    #[arg(long, default_value_t = EvaluateSettings::default().settle_s,
          value_parser = seconds("settle_s", Rule::NonNegativeSeconds))]
    pub settle_s: f64,
    /// Room-temperature scale factor for the thermal error (default: first rate segment's).
    #[arg(long, value_parser = seconds("reference_scale", Rule::PositiveScaleFactor))]
    pub reference_scale: Option<f64>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Model file from `train` (an inertial unit's, or a single gyro's as a unit of one axis):
    /// judge each axis's raw and compensated output (the log is read with the model's gyro and
    /// temperature columns).
    #[arg(long, value_name = "UNIT.json")]
    pub model: Option<PathBuf>,
    #[doc = "Spec sheet (TOML) to judge the figures against; exit 1 when a limit is missed."]
    #[arg(long, value_name = "SPEC.toml", long_help = super::verdict::SPEC_HELP)]
    pub spec: Option<std::path::PathBuf>,
}

#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Training log (CSV); repeat for several (static → bias, rate-table → scale factor).
    #[arg(long, required = true)]
    pub train: Vec<PathBuf>,
    /// Held-out log to judge on (CSV); repeat for several.
    #[arg(long, required = true)]
    pub test: Vec<PathBuf>,
    /// Bias-stability smoothing time, s (default 100 s, or the multiple of the held-out logs'
    /// sample period nearest to it when 100 s is not one; said on stderr).
    #[arg(long, value_parser = super::common::seconds("tau_s", gyrotherm::settings::Rule::PositiveSeconds))]
    pub tau_s: Option<f64>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    #[doc = "Spec sheet (TOML) to judge every model column against; exit 1 when a column misses a limit."]
    #[arg(long, value_name = "SPEC.toml", long_help = super::verdict::SPEC_HELP)]
    pub spec: Option<PathBuf>,
    #[command(flatten)]
    pub columns: ColumnArgs,
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub log: LogArgs,
}

/// Which models the comparison fits, one column each (`compare`, `demo`, `report`).
#[derive(Debug, clap::Args)]
pub struct ColumnArgs {
    /// Methods to compare, comma-separated, in table order (the names of `train --method`;
    /// a recipe method's column is named by what its model holds, `published` is "LSTM, He
    /// et al."; `--epochs` applies to every LSTM), then any autopilot polynomials (`ardupilot`,
    /// `px4`: fitted to --method's model, single gyro). Default: linear, poly, --method,
    /// published.
    #[arg(long, value_delimiter = ',', value_name = "LIST", value_parser = column_parser())]
    pub methods: Option<Vec<ColumnName>>,
    /// The comparison's own method: the third default column, an inertial unit's fit (the
    /// sensor each axis reads, and the unit's column) and the model the autopilot columns are
    /// fitted to.
    #[arg(long, default_value_t = DEFAULT_METHOD, value_parser = method_parser())]
    pub method: Method,
}

impl ColumnArgs {
    /// The comparison settings: the columns, the fit settings, bias stability over `tau_s`.
    pub fn compare_config(&self, fit: &FitArgs, tau_s: f64) -> anyhow::Result<CompareConfig> {
        Ok(fit
            .settings(self.method)
            .compare_config(self.methods.as_deref(), tau_s)?)
    }
}

#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// Training log (CSV); repeat for several (static → bias, rate-table → scale factor).
    #[arg(long, required = true)]
    pub train: Vec<PathBuf>,
    /// Held-out log to judge on (CSV); repeat for several.
    #[arg(long, required = true)]
    pub test: Vec<PathBuf>,
    /// Report folder (created if missing): index.html and a PNG and SVG per figure.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Bias-stability smoothing time, s (default 100 s, or the multiple of the held-out logs'
    /// sample period nearest to it when 100 s is not one; said on stderr).
    #[arg(long, value_parser = super::common::seconds("tau_s", gyrotherm::settings::Rule::PositiveSeconds))]
    pub tau_s: Option<f64>,
    #[doc = "Spec sheet (TOML) to judge every model column against; exit 1 when a column misses a limit."]
    #[arg(long, value_name = "SPEC.toml", long_help = super::verdict::SPEC_HELP)]
    pub spec: Option<PathBuf>,
    #[command(flatten)]
    pub columns: ColumnArgs,
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub log: LogArgs,
}

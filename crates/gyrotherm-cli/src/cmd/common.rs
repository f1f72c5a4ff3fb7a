//! Options shared by every command that reads a test log (column mapping, units, gaps).
//!
//! Flatten into a command's arguments with `#[command(flatten)] log: LogArgs`.

use std::path::{Path, PathBuf};

use clap::Args;
use gyrotherm::csvlog::{self, GyroUnit, LogFormat, ReadOptions, LOG_FORMATS};
use gyrotherm::model::GivenColumns;
use gyrotherm::settings::{read, Rule};

/// How to read test logs: which columns hold what, the gyro unit, the gap policy (the
/// library's [`ReadOptions`], with its defaults, names and checks).
#[derive(Debug, Clone, Args)]
pub struct LogArgs {
    /// Header of the time column (seconds).
    #[arg(long, value_name = "NAME", default_value = csvlog::TIME_COL)]
    pub time_col: String,
    /// Header of the gyro-output column (unit: --gyro-unit); for an inertial unit, the gyro
    /// columns separated by commas (`gyro_x_dps,gyro_y_dps,gyro_z_dps`).
    #[arg(long, value_name = "NAME[,NAME...]", default_value = csvlog::GYRO_COL)]
    pub gyro_col: String,
    /// Header of the temperature column (°C); for several sensors, their columns separated by
    /// commas (`temp_case_c,temp_x_c,temp_y_c,temp_z_c`).
    #[arg(long, value_name = "NAME[,NAME...]", default_value = csvlog::TEMP_COL)]
    pub temp_col: String,
    /// With several gyro columns: the one the table column drives in every table log read
    /// (default: the gyro whose output follows the table rate, found per log).
    #[arg(long, value_name = "GYRO_COL")]
    pub table_axis: Option<String>,
    /// Header of the rate-table column (°/s); optional unless renamed here.
    #[arg(long, value_name = "NAME", default_value = csvlog::DEFAULT_TABLE_COL)]
    pub table_col: String,
    /// Unit of the gyro column (dps: °/s, dph: °/h, rad/s); converted to °/s on reading.
    #[arg(long, value_name = "UNIT", default_value_t = ReadOptions::default().gyro_unit,
          value_parser = choice::<GyroUnit>(read::GYRO_UNIT_NAMES.map(|n| (n, ""))))]
    pub gyro_unit: GyroUnit,
    /// Interpolate gaps (steps over 1.5 sample periods) up to MAX_S seconds long, instead of
    /// stopping with an error.
    #[arg(long, value_name = "MAX_S",
          value_parser = seconds("fill_gaps_max_s", Rule::PositiveSeconds))]
    pub fill_gaps_max_s: Option<f64>,
    /// Nominal sample period in seconds (default: median of the first 100 time steps).
    #[arg(long, value_name = "SECONDS",
          value_parser = seconds("sample_period_s", Rule::PositiveSeconds))]
    pub sample_period_s: Option<f64>,
    /// Field separator of the log: `,` (default), `;` or `tab`. With `;` or `tab`, numbers
    /// may use a decimal comma (`0,5`).
    #[arg(long, value_name = "SEP", default_value = read::delimiter_name(ReadOptions::default().delimiter),
          value_parser = |s: &str| read::parse_delimiter(s))]
    pub delimiter: u8,
    /// Log file format (default: by extension: .ulg PX4 ULog, .bin ArduPilot DataFlash, any
    /// other CSV). An autopilot log is read as a three-axis unit, averaged per model step.
    #[arg(long, value_name = "FORMAT",
          value_parser = choice::<LogFormat>(LOG_FORMATS.map(|f| (f.as_str(), f.help()))))]
    pub format: Option<LogFormat>,
    /// Which of an autopilot's gyros to read (PX4 multi-instance, ArduPilot IMU instance).
    #[arg(long, value_name = "N", default_value_t = ReadOptions::default().instance)]
    pub instance: u8,
}

/// A value parser for a library setting with a list of names: the names (with their help
/// texts, empty for none) are the possible values `--help` lists, the library's `FromStr`
/// turns the one given into its value.
pub fn choice<T>(
    values: impl IntoIterator<Item = (&'static str, &'static str)>,
) -> impl clap::builder::TypedValueParser<Value = T>
where
    T: std::str::FromStr + Clone + Send + Sync + 'static,
    T::Err: std::fmt::Display,
{
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(values.into_iter().map(|(n, h)| {
        let v = PossibleValue::new(n);
        if h.is_empty() {
            v
        } else {
            v.help(h)
        }
    }))
    .try_map(|s| s.parse::<T>().map_err(|e| e.to_string()))
}

/// A value parser for a numeric library setting: the library's parser and rule.
pub fn seconds(
    setting: &'static str,
    rule: Rule,
) -> impl Fn(&str) -> Result<f64, gyrotherm::SettingError> + Clone + Send + Sync + 'static {
    move |s: &str| gyrotherm::settings::parse_number(setting, s, rule)
}

impl LogArgs {
    /// The library's read options for these arguments.
    pub fn read_options(&self) -> ReadOptions {
        ReadOptions {
            time_col: self.time_col.clone(),
            gyro_col: self.gyro_col.clone(),
            temp_col: self.temp_col.clone(),
            table_col: self.table_col.clone(),
            gyro_unit: self.gyro_unit,
            fill_gaps_max_s: self.fill_gaps_max_s,
            sample_period_s: self.sample_period_s,
            delimiter: self.delimiter,
            format: self.format,
            instance: self.instance,
        }
    }
}

/// Which column options of [`LogArgs`] the command line named (`matches`: the subcommand's),
/// as opposed to their defaults: those override a model's own columns.
pub fn given_columns(matches: Option<&clap::ArgMatches>) -> GivenColumns {
    let given = |id: &str| {
        matches.is_some_and(|m| m.value_source(id) == Some(clap::parser::ValueSource::CommandLine))
    };
    GivenColumns {
        time_col: given("time_col"),
        gyro_col: given("gyro_col"),
        temp_col: given("temp_col"),
        table_col: given("table_col"),
        gyro_unit: given("gyro_unit"),
    }
}

/// Read a job's logs through the library's one entry point, telling what reading did for
/// each file and each failure, then stop if any failed.
pub fn read_log_set(
    paths: &[PathBuf],
    opts: &ReadOptions,
    table_axis: Option<&str>,
) -> anyhow::Result<csvlog::LogSet> {
    told_set(csvlog::read_log_set(paths, opts, table_axis))
}

/// [`read_log_set`] for a comparison's training and held-out logs, read alike.
pub fn read_log_sets<const N: usize>(
    sets: [&[PathBuf]; N],
    args: &LogArgs,
) -> anyhow::Result<[csvlog::LogSet; N]> {
    let reads = csvlog::read_log_sets(&sets, &args.read_options(), args.table_axis.as_deref());
    let mut out = Vec::with_capacity(N);
    for read in reads {
        out.push(told_set(read)?);
    }
    out.try_into()
        .map_err(|_| anyhow::anyhow!("internal: a set of logs went missing"))
}

/// Tell what reading did for each file and each failure, then stop if any failed.
pub fn told_set(read: csvlog::SetRead) -> anyhow::Result<csvlog::LogSet> {
    for f in read.files {
        for t in &f.told {
            tell(t);
        }
        if let Some(e) = f.error {
            let e = anyhow::Error::new(e).context(format!("cannot use log {}", f.path.display()));
            eprintln!("gyrotherm: {}", error_message(&e));
        }
    }
    Ok(read.set?)
}

/// Refuse, before any work, an output path that names one of the command's inputs
/// (`gyrotherm::atomic_file::refuse_outputs_over_inputs`): `train --out static.csv` would
/// replace the raw log with the model.
pub fn refuse_outputs_over_inputs<'a>(
    outputs: impl IntoIterator<Item = &'a Path>,
    inputs: impl IntoIterator<Item = &'a Path>,
) -> anyhow::Result<()> {
    let outputs: Vec<&Path> = outputs.into_iter().collect();
    let inputs: Vec<&Path> = inputs.into_iter().collect();
    gyrotherm::atomic_file::refuse_outputs_over_inputs(&outputs, &inputs)?;
    Ok(())
}

/// Values of the options that name a built-in chamber profile (`gyrotherm::sim`'s list,
/// so the two cannot drift apart).
pub fn builtin_profile() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        gyrotherm::sim::BUILTIN_PROFILES
            .iter()
            .map(|(name, what)| clap::builder::PossibleValue::new(*name).help(*what)),
    )
}

/// An error and its causes on one line, `: `-separated, outermost first. Each error of the
/// library states only its own level's fact and returns its cause from `source()`, so the
/// chain printed as it is says each cause once.
/// Print a line the library tells about a model and what was done with it.
pub fn tell(t: &gyrotherm::unit_model::Told) {
    use gyrotherm::unit_model::Told;
    match t {
        Told::Line(l) => eprintln!("gyrotherm: {l}"),
        Told::Note(n) => eprintln!("gyrotherm: note: {n}"),
        Told::Warning(w) => eprintln!("gyrotherm: warning: {w}"),
        Told::Item(i) => eprintln!("  {i}"),
    }
}

pub fn error_message(err: &anyhow::Error) -> String {
    format!("{err:#}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        log: LogArgs,
    }

    #[test]
    fn defaults_are_the_standard_names() {
        let cli = Cli::try_parse_from(["t"]).unwrap();
        assert_eq!(cli.log.read_options(), ReadOptions::default());
    }

    #[test]
    fn flags_map_to_read_options() {
        let cli = Cli::try_parse_from([
            "t",
            "--time-col",
            "t",
            "--gyro-col",
            "w",
            "--temp-col",
            "T",
            "--table-col",
            "rt",
            "--gyro-unit",
            "rad/s",
            "--fill-gaps-max-s",
            "5",
            "--sample-period-s",
            "0.01",
        ])
        .unwrap();
        let o = cli.log.read_options();
        assert_eq!(
            (
                o.time_col.as_str(),
                o.gyro_col.as_str(),
                o.temp_col.as_str()
            ),
            ("t", "w", "T")
        );
        assert_eq!(o.table_col, "rt");
        assert_eq!(o.gyro_unit, GyroUnit::RadPerS);
        assert_eq!(o.fill_gaps_max_s, Some(5.0));
        assert_eq!(o.sample_period_s, Some(0.01));
    }

    #[test]
    fn bad_values_are_refused() {
        assert!(Cli::try_parse_from(["t", "--gyro-unit", "mrad"]).is_err());
        assert!(Cli::try_parse_from(["t", "--fill-gaps-max-s", "-1"]).is_err());
        assert!(Cli::try_parse_from(["t", "--fill-gaps-max-s", "nan"]).is_err());
    }
}

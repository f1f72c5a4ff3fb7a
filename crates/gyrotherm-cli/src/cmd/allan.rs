//! `gyrotherm allan`: Allan-family deviation of a rate column, with 68.3 % bounds and noise
//! terms. JSON: `{"kind", "points": [{"tau_s", "dev", "n", "lo", "hi", …}], "noise":
//! {"arw_deg_rt_h": {"value", "tau_read_s", "fit_tau_min_s", "fit_tau_max_s"} or null, …}}`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use gyrotherm::allan::{self, AllanPoint, DevKind, NoiseTerms, TauSet};
use gyrotherm::csvlog::{self, rate_column_to_dph};
use gyrotherm::report;
use gyrotherm::settings::allan as allan_settings;
use gyrotherm::settings::kalibr as kalibr_settings;
use gyrotherm::settings::{AllanAnalysis, AllanSettings};
use serde::Serialize;

use super::common::{choice, tell, LogArgs};

#[derive(Debug, clap::Args)]
pub struct AllanArgs {
    /// Test log (CSV).
    #[arg(long)]
    pub input: PathBuf,
    #[command(flatten)]
    pub log: LogArgs,
    /// Column to analyse, by its name in the file: the gyro column (default; also called
    /// gyro_dps, in °/s), the temperature or table column, or any numeric extra column.
    #[arg(long, default_value_t = AllanSettings::default().column)]
    pub column: String,
    /// Deviation.
    #[arg(long, default_value_t = allan_settings::DEFAULT_KIND,
          value_parser = choice::<DevKind>(KINDS.map(|k| (k.name(), k.help()))))]
    pub kind: DevKind,
    /// τ values: octave, decade, all, or seconds such as 1,10,100.
    #[arg(long, default_value_t = allan_settings::DEFAULT_TAUS,
          value_parser = |s: &str| s.parse::<TauSet>())]
    pub taus: TauSet,
    /// Noise exponent α (S(f) ∝ f^α) for the confidence intervals at every τ instead of the
    /// lag-1 autocorrelation noise identification.
    #[arg(long, allow_hyphen_values = true, value_parser = |s: &str| allan_settings::parse_alpha(s))]
    pub alpha: Option<i32>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also draw the curve with its 68.3 % bars and the noise-term slope lines (ADEV/OADEV)
    /// as FILE.png, with FILE.svg beside it.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Also write Kalibr's IMU noise file (gyroscope_noise_density, gyroscope_random_walk,
    /// update_rate, rostopic) as FILE, read from this Allan deviation curve (oadev or adev).
    #[arg(long, value_name = "FILE.yaml")]
    pub kalibr: Option<PathBuf>,
    /// The IMU topic the Kalibr file names.
    #[arg(long, default_value = kalibr_settings::DEFAULT_ROSTOPIC,
          value_parser = |s: &str| kalibr_settings::parse_rostopic(s))]
    pub rostopic: String,
}

/// The deviations in `--help` order (the library's name list).
const KINDS: [DevKind; 5] = [
    DevKind::Oadev,
    DevKind::Adev,
    DevKind::Mdev,
    DevKind::Hdev,
    DevKind::Ohdev,
];

impl AllanArgs {
    /// The library's settings.
    pub fn settings(&self) -> AllanSettings {
        AllanSettings {
            column: self.column.clone(),
            kind: self.kind,
            taus: self.taus.clone(),
            alpha: self.alpha,
        }
    }
}

/// A column read for `allan` and `evaluate`.
pub(crate) struct ReadColumn {
    /// The column's values (a mapped gyro column in °/s).
    pub values: Vec<f64>,
    /// Sample period, s.
    pub tau0_s: f64,
    /// The name the log holds it under (`gyro_dps` for the mapped gyro column): the one whose
    /// suffix gives its unit.
    pub log_name: String,
    /// The name in the file (the user's `--gyro-col`, not `gyro_dps`): what outputs call it.
    pub name: String,
}

/// Reads the log and picks a numeric column, named as in the file or by its standard name
/// (`gyro_dps` is the `--gyro-col` column, whatever its header).
pub(crate) fn read_column(
    input: &Path,
    column: &str,
    log_args: &LogArgs,
) -> anyhow::Result<ReadColumn> {
    let opts = log_args.read_options();
    let mut log = csvlog::read_log_columns(input, &opts, log_args.table_axis.as_deref())
        .with_context(|| format!("cannot use log {}", input.display()))?;
    for t in &log.told {
        tell(t);
    }
    let log_name = opts.log_column(column).to_owned();
    let name = opts.file_column(&log_name).to_owned();
    if log.gyro_cols.len() > 1 && name == opts.gyro_col {
        // A unit's log: its gyro columns are several, and the analysis is of one.
        bail!(
            "{}: the log holds several gyro columns ({}); allan analyses one: name it with \
             --column",
            input.display(),
            log.gyro_cols.join(", ")
        );
    }
    let values = log
        .take_numbers(&name)
        .with_context(|| input.display().to_string())?;
    let Some(tau0_s) = log.sample_period_s.filter(|t| *t > 0.0) else {
        bail!(
            "{}: cannot tell the sample period (need at least two samples with increasing time_s)",
            input.display()
        );
    };
    Ok(ReadColumn {
        values,
        tau0_s,
        log_name,
        name,
    })
}

/// The two names of the analysed column (see [`ReadColumn`]).
struct ReadColumnNames {
    log_name: String,
    name: String,
}

/// `--json`: the curve and the noise terms as the library computed them.
#[derive(Serialize)]
struct AllanJson<'a> {
    kind: &'static str,
    column: &'a str,
    samples: usize,
    tau0_s: f64,
    confidence: f64,
    points: &'a [AllanPoint],
    noise: Option<&'a NoiseTerms>,
    noise_from: Option<&'static str>,
}

/// Unit of a column for the plot's σ axis when it is not a rate (rates are drawn in °/h).
fn plain_unit(column: &str) -> String {
    if column.ends_with("_c") {
        "°C".to_owned()
    } else if column == "time_s" {
        "s".to_owned()
    } else {
        format!("unit of {column}")
    }
}

/// Unit of a column's values, read from its name as [`rate_column_to_dph`] reads it.
fn column_unit(column: &str) -> String {
    if column.ends_with("_dps") {
        "°/s".to_owned()
    } else if column.ends_with("_dph") {
        "°/h".to_owned()
    } else if column.ends_with("_rad_s") || column.ends_with("_rps") {
        "rad/s".to_owned()
    } else {
        plain_unit(column)
    }
}

/// `x` to 12 significant digits, printed in the shortest form that reads back as that: a
/// sample period from time stamps (0.20000000000000284 s) prints as 0.2 s.
fn short_num(x: f64) -> String {
    format!("{:.11e}", x)
        .parse::<f64>()
        .map_or_else(|_| x.to_string(), |r| r.to_string())
}

/// `--plot`: the curve in °/h for rate columns (else the column's unit), the noise terms as
/// slope lines when they were read from this curve (ADEV/OADEV); PNG and SVG, atomically.
fn plot(
    path: &Path,
    args: &AllanArgs,
    column: &ReadColumnNames,
    points: &[AllanPoint],
    noise: Option<&NoiseTerms>,
) -> anyhow::Result<()> {
    let (factor, unit) = match rate_column_to_dph(&column.log_name) {
        Some(f) => (f, "°/h".to_owned()),
        None => (1.0, plain_unit(&column.log_name)),
    };
    let kind = args.kind;
    let label = format!("{} of {}", kind.name().to_uppercase(), column.name);
    let curve = report::allan_curve(&label, points, factor);
    let lines = match (kind, noise) {
        (DevKind::Adev | DevKind::Oadev, Some(t)) => report::noise_lines(t, ""),
        _ => Vec::new(),
    };
    let files = report::allan_figure(path, &[curve], &lines, &unit)
        .with_context(|| format!("cannot write the plot {}", path.display()))?;
    eprintln!(
        "gyrotherm: wrote {} and {} ({}x{} px)",
        files.png.display(),
        files.svg.display(),
        files.width_px,
        files.height_px
    );
    Ok(())
}

/// `--kalibr`: the noise file, atomically, and its figures with their bounds on stderr.
fn write_kalibr(
    path: &Path,
    args: &AllanArgs,
    points: &[AllanPoint],
    noise: Option<&NoiseTerms>,
    tau0_s: f64,
) -> anyhow::Result<()> {
    let Some(terms) = noise else {
        bail!(
            "--kalibr needs a rate column (named *_dps, *_dph or *_rad_s), not {}",
            args.column
        );
    };
    let k = allan::kalibr::kalibr_noise(points, terms, tau0_s)
        .with_context(|| format!("cannot write the Kalibr file {}", path.display()))?;
    let text = allan::kalibr::kalibr_yaml(&k, &args.rostopic);
    gyrotherm::atomic_file::write_bytes_atomically(path, text.as_bytes())
        .with_context(|| format!("cannot write the Kalibr file {}", path.display()))?;
    for (key, unit, t) in [
        ("gyroscope_noise_density", "rad/s/√Hz", &k.noise_density),
        ("gyroscope_random_walk", "rad/s²/√Hz", &k.random_walk),
    ] {
        let bounds = if t.lo.is_finite() && t.hi.is_finite() {
            format!(
                "68.3 % bounds {:.4e} .. {:.4e}, EDF {:.1}",
                t.lo, t.hi, t.edf
            )
        } else {
            "no EDF for bounds".to_owned()
        };
        eprintln!(
            "gyrotherm: {key} {:.4e} {unit} (τ = {} s on the line fitted over τ {:.4} .. {:.4} s; {bounds})",
            t.value, t.tau_read_s, t.fit_tau_min_s, t.fit_tau_max_s
        );
    }
    eprintln!(
        "gyrotherm: wrote {} (update_rate {} Hz, rostopic {}; no accelerometer keys: not measured)",
        path.display(),
        k.update_rate_hz,
        args.rostopic
    );
    Ok(())
}

pub fn run(args: AllanArgs) -> anyhow::Result<ExitCode> {
    super::common::refuse_outputs_over_inputs(args.plot.as_deref(), [args.input.as_path()])?;
    let mut settings = args.settings();
    settings.validate()?;
    let kind = settings.kind;
    // Checked before the log is read: Kalibr's figures are defined on the Allan deviation.
    if args.kalibr.is_some() && !matches!(kind, DevKind::Oadev | DevKind::Adev) {
        bail!("--kalibr reads the Allan deviation: use --kind oadev (the default) or adev");
    }
    let mut w = std::io::stdout().lock();
    let ReadColumn {
        values,
        tau0_s,
        log_name,
        name,
        ..
    } = read_column(&args.input, &args.column, &args.log)?;
    // The unit (and so the noise terms) follows the name the log holds it under.
    settings.column = log_name.clone();
    let column = ReadColumnNames { log_name, name };
    let n_samples = values.len();
    let AllanAnalysis {
        points,
        noise,
        noise_from,
    } = settings
        .analyse(values, tau0_s)
        .with_context(|| format!("{} of column {}", kind.name(), column.name))?;
    if let Some(path) = &args.plot {
        plot(path, &args, &column, &points, noise.as_ref())?;
    }
    if let Some(path) = &args.kalibr {
        write_kalibr(path, &args, &points, noise.as_ref(), tau0_s)?;
    }
    if args.json {
        let out = AllanJson {
            kind: kind.name(),
            column: &column.name,
            samples: n_samples,
            tau0_s,
            confidence: allan::ONE_SIGMA_CI,
            points: &points,
            noise: noise.as_ref(),
            noise_from,
        };
        writeln!(w, "{}", serde_json::to_string_pretty(&out)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    writeln!(
        w,
        "{} of {} ({} samples, τ0 = {} s; 68.3 % bounds from Greenhall EDF)",
        kind.name().to_uppercase(),
        column.name,
        n_samples,
        short_num(tau0_s)
    )?;
    let unit = column_unit(&args.column);
    writeln!(
        w,
        "{:>12} {:>10} {:>10} {:>5} {:>13} {:>13} {:>13}",
        "tau (s)",
        "m",
        "n",
        "alpha",
        format!("lo ({unit})"),
        format!("dev ({unit})"),
        format!("hi ({unit})")
    )?;
    for p in &points {
        writeln!(
            w,
            "{:>12.6} {:>10} {:>10} {:>5} {:>13.6e} {:>13.6e} {:>13.6e}",
            p.tau_s, p.m, p.n, p.alpha, p.lo, p.dev, p.hi
        )?;
    }
    match noise {
        None => writeln!(
            w,
            "noise terms: column unit unknown (name it *_dps, *_dph or *_rad_s for noise terms)"
        )?,
        Some(t) => {
            writeln!(w, "noise terms (from {}):", noise_from.unwrap_or("oadev"))?;
            let rows = [
                ("angle random walk", "°/√h", t.arw_deg_rt_h),
                ("bias instability", "°/h", t.bias_instability_dph),
                ("rate random walk", "°/h/√h", t.rrw_deg_h_rt_h),
                ("quantization", "arcsec", t.quantization_arcsec),
                ("rate ramp", "°/h²", t.rate_ramp_deg_h2),
            ];
            for (label, unit, term) in rows {
                match term {
                    Some(x) => writeln!(
                        w,
                        "{label:<22} {:>13.6e} {unit:<10} (read at τ = {:.4} s; fit {:.4}..{:.4} s)",
                        x.value, x.tau_read_s, x.fit_tau_min_s, x.fit_tau_max_s
                    )?,
                    None => writeln!(
                        w,
                        "{label:<22} {:>13} {unit:<10} (no such region on the curve)",
                        "-"
                    )?,
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

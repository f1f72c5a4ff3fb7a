//! `gyrotherm allan`: Allan-family deviation of a rate column, with 68.3 % bounds and noise
//! terms. JSON: `{"kind", "points": [{"tau_s", "dev", "n", "lo", "hi", …}], "noise": {…}}`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use gyrotherm::allan::{self, AllanPoint, DevKind, NoiseModel, NoiseTerms, TauSet};
use gyrotherm::csvlog::TestLog;
use gyrotherm::report;

use super::common::{read_log_reporting, LogArgs};
use serde_json::{json, Value};

#[derive(Debug, clap::Args)]
pub struct AllanArgs {
    /// Test log (CSV).
    #[arg(long)]
    pub input: PathBuf,
    #[command(flatten)]
    pub log: LogArgs,
    /// Column to analyse: gyro_dps (default), temp_c, table_dps or any numeric extra column.
    #[arg(long, default_value = "gyro_dps")]
    pub column: String,
    /// Deviation: oadev, adev, mdev, hdev (non-overlapping Hadamard, as Stable32) or ohdev.
    #[arg(long, default_value = "oadev", value_parser = parse_kind)]
    pub kind: DevKind,
    /// τ values: octave, decade, all, or seconds such as 1,10,100.
    #[arg(long, default_value = "octave", value_parser = parse_taus)]
    pub taus: TauSet,
    /// Noise exponent α (S(f) ∝ f^α) for the confidence intervals at every τ instead of the
    /// lag-1 autocorrelation noise identification.
    #[arg(long, allow_hyphen_values = true)]
    pub alpha: Option<i32>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also draw the curve with its 68.3 % bars and the noise-term slope lines (ADEV/OADEV)
    /// as FILE.png, with FILE.svg beside it.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
}

fn parse_kind(s: &str) -> Result<DevKind, String> {
    s.parse().map_err(|e: allan::AllanError| e.to_string())
}

fn parse_taus(s: &str) -> Result<TauSet, String> {
    s.parse().map_err(|e: allan::AllanError| e.to_string())
}

/// Reads the log and picks a numeric column; returns (log, values, sample period s). The
/// chosen column is moved out of the log (left empty there) to keep one copy in memory.
pub(crate) fn read_column(
    input: &Path,
    column: &str,
    log_args: &LogArgs,
) -> anyhow::Result<(TestLog, Vec<f64>, f64)> {
    let mut log = read_log_reporting(input, log_args)?;
    let values = match column {
        "gyro_dps" => std::mem::take(&mut log.gyro_dps),
        "temp_c" => std::mem::take(&mut log.temp_c),
        "time_s" => log.time_s.clone(),
        "table_dps" => match &log.table_dps {
            Some(t) => t.clone(),
            None => bail!("{}: no table_dps column in this log", input.display()),
        },
        name => match log.extra_f64(name) {
            Some(v) => v,
            None => {
                let names: Vec<&str> = ["gyro_dps", "temp_c"]
                    .into_iter()
                    .chain(log.table_dps.as_ref().map(|_| "table_dps"))
                    .chain(log.extra.iter().map(|c| c.name.as_str()))
                    .collect();
                if log.extra.iter().any(|c| c.name == name) {
                    bail!("{}: column `{name}` is not all numeric", input.display());
                }
                bail!(
                    "{}: no column `{name}`; available: {}",
                    input.display(),
                    names.join(", ")
                );
            }
        },
    };
    let tau0_s = log.sample_period_s();
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        bail!(
            "{}: cannot tell the sample period (need at least two samples with increasing time_s)",
            input.display()
        );
    }
    Ok((log, values, tau0_s))
}

/// Factor from a column's unit (by its name suffix) to °/h, for rate columns.
pub(crate) fn to_dph_factor(column: &str) -> Option<f64> {
    if column.ends_with("_dps") {
        Some(3600.0)
    } else if column.ends_with("_dph") {
        Some(1.0)
    } else if column.ends_with("_rad_s") || column.ends_with("_rps") {
        Some(3600.0 * 180.0 / std::f64::consts::PI)
    } else {
        None
    }
}

fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

fn noise_json(t: &NoiseTerms) -> Value {
    let mut obj = serde_json::Map::new();
    let terms = [
        ("arw_deg_rt_h", t.arw_deg_rt_h),
        ("bias_instability_dph", t.bias_instability_dph),
        ("rrw_deg_h_rt_h", t.rrw_deg_h_rt_h),
        ("quantization_arcsec", t.quantization_arcsec),
        ("rate_ramp_deg_h2", t.rate_ramp_deg_h2),
    ];
    for (name, term) in terms {
        obj.insert(name.into(), term.map_or(Value::Null, |x| num(x.value)));
        let key = name.split('_').next().unwrap_or(name);
        let key = match name {
            "bias_instability_dph" => "bias_instability",
            "quantization_arcsec" => "quantization",
            "rate_ramp_deg_h2" => "rate_ramp",
            _ => key,
        };
        obj.insert(
            format!("{key}_tau_s"),
            term.map_or(Value::Null, |x| num(x.tau_read_s)),
        );
        obj.insert(
            format!("{key}_fit_tau_s"),
            term.map_or(Value::Null, |x| {
                json!([num(x.fit_tau_min_s), num(x.fit_tau_max_s)])
            }),
        );
    }
    Value::Object(obj)
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

/// `--plot`: the curve in °/h for rate columns (else the column's unit), the noise terms as
/// slope lines when they were read from this curve (ADEV/OADEV); PNG and SVG, atomically.
fn plot(
    path: &Path,
    args: &AllanArgs,
    points: &[AllanPoint],
    noise: Option<&NoiseTerms>,
) -> anyhow::Result<()> {
    let (factor, unit) = match to_dph_factor(&args.column) {
        Some(f) => (f, "°/h".to_owned()),
        None => (1.0, plain_unit(&args.column)),
    };
    let label = format!("{} of {}", args.kind.name().to_uppercase(), args.column);
    let curve = report::allan_curve(&label, points, factor);
    let lines = match (args.kind, noise) {
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

pub fn run(args: AllanArgs) -> anyhow::Result<ExitCode> {
    let mut w = std::io::stdout().lock();
    let (_log, values, tau0_s) = read_column(&args.input, &args.column, &args.log)?;
    let noise_model = args.alpha.map_or(NoiseModel::Identify, NoiseModel::Alpha);
    let points = allan::deviation(&values, tau0_s, args.kind, &args.taus, noise_model)
        .with_context(|| format!("{} of column {}", args.kind.name(), args.column))?;
    // Noise terms are defined on the Allan deviation: from this curve for adev/oadev, else
    // from an OADEV curve at the same τ.
    let to_dph = to_dph_factor(&args.column);
    let (noise, noise_from) = match to_dph {
        None => (None, None),
        Some(f) => {
            let curve: Vec<AllanPoint> = match args.kind {
                DevKind::Adev | DevKind::Oadev => points.clone(),
                _ => {
                    let taus = TauSet::Seconds(points.iter().map(|p| p.tau_s).collect());
                    allan::deviation(&values, tau0_s, DevKind::Oadev, &taus, noise_model)
                        .unwrap_or_default()
                }
            };
            let from = match args.kind {
                DevKind::Adev => "adev",
                _ => "oadev",
            };
            (Some(allan::noise_terms(&curve, f)), Some(from))
        }
    };
    if let Some(path) = &args.plot {
        plot(path, &args, &points, noise.as_ref())?;
    }
    if args.json {
        let pts: Vec<Value> = points
            .iter()
            .map(|p| {
                json!({
                    "tau_s": num(p.tau_s), "m": p.m, "dev": num(p.dev), "n": p.n,
                    "lo": num(p.lo), "hi": num(p.hi), "alpha": p.alpha, "edf": num(p.edf),
                })
            })
            .collect();
        let out = json!({
            "kind": args.kind.name(),
            "column": args.column,
            "samples": values.len(),
            "tau0_s": tau0_s,
            "confidence": allan::ONE_SIGMA_CI,
            "points": pts,
            "noise": noise.as_ref().map_or(Value::Null, noise_json),
            "noise_from": noise_from,
        });
        writeln!(w, "{}", serde_json::to_string_pretty(&out)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    writeln!(
        w,
        "{} of {} ({} samples, τ0 = {} s; 68.3 % bounds from Greenhall EDF)",
        args.kind.name().to_uppercase(),
        args.column,
        values.len(),
        tau0_s
    )?;
    writeln!(
        w,
        "{:>12} {:>10} {:>10} {:>5} {:>13} {:>13} {:>13}",
        "tau_s", "m", "n", "alpha", "lo", "dev", "hi"
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

//! `gyrotherm evaluate`: bias, bias stability and, for rate-table logs, the scale-factor
//! figures (IEEE Std 952 / GJB 2426A definitions).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context};
use gyrotherm::csvlog::rate_column_to_dph;
use gyrotherm::metrics::{self, EvaluationOptions};

use super::allan::read_column;

#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Test log (CSV).
    #[arg(long)]
    pub input: PathBuf,
    #[command(flatten)]
    pub log: super::common::LogArgs,
    /// Rate column to judge: gyro_dps (default) or a numeric extra column (*_dps, *_dph, *_rad_s).
    #[arg(long, default_value = "gyro_dps")]
    pub column: String,
    /// Smoothing time of the bias stability, s.
    #[arg(long, default_value_t = 100.0)]
    pub tau: f64,
    /// Time dropped at the start of each rate-table segment, s.
    #[arg(long, default_value_t = 10.0)]
    pub settle: f64,
    /// Room-temperature scale factor for the thermal error (default: first rate segment's).
    #[arg(long)]
    pub reference_scale: Option<f64>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    let mut w = std::io::stdout().lock();
    let (log, values, tau0_s) = read_column(&args.input, &args.column, &args.log)?;
    let Some(to_dph) = rate_column_to_dph(&args.column) else {
        bail!(
            "column `{}` has no rate unit in its name; name it *_dps, *_dph or *_rad_s",
            args.column
        );
    };
    let rate_dps: Vec<f64> = values.iter().map(|v| v * to_dph / 3600.0).collect();
    let opts = EvaluationOptions {
        tau_s: args.tau,
        settle_s: args.settle,
        reference_scale: args.reference_scale,
    };
    let e = metrics::evaluate(
        &args.column,
        &log.time_s,
        &rate_dps,
        tau0_s,
        log.table_dps.as_deref(),
        &opts,
    )
    .with_context(|| format!("column {}", args.column))?;
    if args.json {
        writeln!(w, "{}", serde_json::to_string_pretty(&e)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    writeln!(
        w,
        "{} ({} samples, τ0 = {} s)",
        e.column, e.samples, e.sample_period_s
    )?;
    writeln!(w, "bias                 {:>14.6} °/h", e.bias_dph)?;
    writeln!(
        w,
        "bias stability       {:>14.6} °/h (1σ of {} means of {} s{})",
        e.bias_stability_dph,
        e.means,
        e.tau_s,
        if e.stop_segments_only {
            ", stop segments only"
        } else {
            ""
        }
    )?;
    if let Some(r) = &e.scale {
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.3}"));
        writeln!(w, "scale factor         {:>14.9}", r.scale_factor)?;
        writeln!(w, "nonlinearity         {:>14.3} ppm", r.nonlinearity_ppm)?;
        writeln!(w, "asymmetry            {:>14} ppm", opt(r.asymmetry_ppm))?;
        writeln!(w,
            "SF thermal error     {:>14.3} ppm (max |K(t) − K_ref|, K_ref = {:.9}, {} rate segments)",
            r.sf_thermal_error_ppm,
            r.reference_scale,
            r.scale_over_time.len()
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

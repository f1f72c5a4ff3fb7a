//! `gyrotherm evaluate`: bias, bias stability and, for rate-table logs, the scale-factor
//! figures (IEEE Std 952 / GJB 2426A definitions).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context};
use gyrotherm::metrics::{self, ScaleFactorOptions};
use serde_json::{json, Value};

use super::allan::{read_column, to_dph_factor};

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

fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

pub fn run(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    let mut w = std::io::stdout().lock();
    let (log, values, tau0_s) = read_column(&args.input, &args.column, &args.log)?;
    let Some(to_dph) = to_dph_factor(&args.column) else {
        bail!(
            "column `{}` has no rate unit in its name; name it *_dps, *_dph or *_rad_s",
            args.column
        );
    };
    let rate_dps: Vec<f64> = values.iter().map(|v| v * to_dph / 3600.0).collect();
    // A rate-table log's bias comes from its stop segments only.
    let (bias, stab) = match &log.table_dps {
        Some(table) if table.iter().any(|w| *w != 0.0) => {
            metrics::stop_segment_bias_dph(&log.time_s, &rate_dps, table, args.settle, args.tau)
                .with_context(|| format!("bias of column {} over the stop segments", args.column))?
        }
        _ => (
            metrics::bias_dph(&rate_dps).with_context(|| format!("column {}", args.column))?,
            metrics::bias_stability_dph(&rate_dps, tau0_s, args.tau)
                .with_context(|| format!("bias stability of column {}", args.column))?,
        ),
    };
    let mut out = json!({
        "column": args.column,
        "samples": rate_dps.len(),
        "sample_period_s": tau0_s,
        "bias_dph": bias,
        "bias_stability_dph": stab.bias_stability_dph,
        "tau_s": stab.tau_s,
        "means": stab.means,
    });
    let mut sf_report = None;
    if let Some(table) = &log.table_dps {
        let opts = ScaleFactorOptions {
            settle_s: args.settle,
            reference_scale: args.reference_scale,
            ..Default::default()
        };
        let r = metrics::scale_factor(&log.time_s, &rate_dps, table, &opts)
            .context("scale factor from table_dps")?;
        let o = out.as_object_mut().expect("object");
        o.insert("scale_factor".into(), num(r.scale_factor));
        o.insert("intercept_dps".into(), num(r.intercept_dps));
        o.insert("nonlinearity_ppm".into(), num(r.nonlinearity_ppm));
        o.insert(
            "asymmetry_ppm".into(),
            r.asymmetry_ppm.map_or(Value::Null, num),
        );
        o.insert(
            "scale_positive".into(),
            r.scale_positive.map_or(Value::Null, num),
        );
        o.insert(
            "scale_negative".into(),
            r.scale_negative.map_or(Value::Null, num),
        );
        o.insert("sf_thermal_error_ppm".into(), num(r.sf_thermal_error_ppm));
        o.insert("reference_scale".into(), num(r.reference_scale));
        o.insert("settle_s".into(), num(args.settle));
        o.insert(
            "rate_points".into(),
            r.rate_points
                .iter()
                .map(|(w, f)| json!({"table_dps": num(*w), "mean_output_dps": num(*f)}))
                .collect(),
        );
        o.insert(
            "scale_over_time".into(),
            r.scale_over_time
                .iter()
                .map(|s| {
                    json!({"time_s": num(s.time_s), "table_dps": num(s.table_dps),
                           "scale": num(s.scale), "deviation_ppm": num(s.deviation_ppm)})
                })
                .collect(),
        );
        sf_report = Some(r);
    }
    if args.json {
        writeln!(w, "{}", serde_json::to_string_pretty(&out)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    writeln!(
        w,
        "{} ({} samples, τ0 = {} s)",
        args.column,
        rate_dps.len(),
        tau0_s
    )?;
    writeln!(w, "bias                 {:>14.6} °/h", bias)?;
    writeln!(
        w,
        "bias stability       {:>14.6} °/h (1σ of {} means of {} s{})",
        stab.bias_stability_dph,
        stab.means,
        stab.tau_s,
        if sf_report.is_some() {
            ", stop segments only"
        } else {
            ""
        }
    )?;
    if let Some(r) = sf_report {
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

//! `gyrotherm evaluate`: bias, bias stability and, for rate-table logs, the scale-factor
//! figures (IEEE Std 952 / GJB 2426A definitions).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use gyrotherm::settings::{EvaluateSettings, Rule};

use super::allan::{read_column, ReadColumn};
use super::common::seconds;

#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Test log (CSV).
    #[arg(long)]
    pub input: PathBuf,
    #[command(flatten)]
    pub log: super::common::LogArgs,
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
    /// Inertial-unit model (JSON from `train` with column lists): judge each axis's raw and
    /// compensated output (the log is read with the model's gyro and temperature columns).
    #[arg(long, value_name = "UNIT.json")]
    pub model: Option<PathBuf>,
    #[doc = "Spec sheet (TOML) to judge the figures against; exit 1 when a limit is missed."]
    #[arg(long, value_name = "SPEC.toml", long_help = super::verdict::SPEC_HELP)]
    pub spec: Option<std::path::PathBuf>,
}

pub fn run(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    if args.model.is_some() || args.log.read_options().is_multi_column() {
        return super::imu_judge::evaluate(args);
    }
    let mut w = std::io::stdout().lock();
    let spec = super::verdict::load(args.spec.as_deref())?;
    let ReadColumn {
        log,
        values,
        tau0_s,
        log_name,
        name,
    } = read_column(&args.input, &args.column, &args.log)?;
    let settings = EvaluateSettings {
        column: log_name,
        tau_s: args.tau_s,
        settle_s: args.settle_s,
        reference_scale: args.reference_scale,
    };
    let (mut e, tau) = settings.evaluate(&log, &values, tau0_s)?;
    // Named as in the file (the user's --gyro-col, not the standard `gyro_dps`).
    e.column = name;
    if let Some(note) = tau.note(tau0_s) {
        eprintln!("gyrotherm: {note}");
    }
    let verdict = match &spec {
        Some(s) => {
            let (rate_dps, opts, _) = settings.prepare(&values, tau0_s)?;
            Some(super::verdict::judge_log(
                s,
                &log,
                &rate_dps,
                &opts,
                &args.input,
            )?)
        }
        None => None,
    };
    let code = super::verdict::exit_code(verdict.as_ref().is_none_or(|v| v.pass));
    if args.json {
        let mut j = serde_json::to_value(&e)?;
        if let (Some(v), Some(o)) = (&verdict, j.as_object_mut()) {
            o.insert("verdict".into(), serde_json::to_value(v)?);
        }
        writeln!(w, "{}", serde_json::to_string_pretty(&j)?)?;
        return Ok(code);
    }
    print_evaluation(&mut w, &e)?;
    if let Some(v) = &verdict {
        writeln!(w)?;
        super::verdict::print(&mut w, v)?;
    }
    Ok(code)
}

/// The figures of one column as text (the single-axis output, and each axis's block of a
/// unit log).
pub fn print_evaluation(
    w: &mut dyn Write,
    e: &gyrotherm::metrics::Evaluation,
) -> std::io::Result<()> {
    writeln!(
        w,
        "{} ({} samples, τ0 = {} s)",
        e.column, e.samples, e.sample_period_s
    )?;
    writeln!(w, "bias                 {:>14} °/h", num(e.bias_dph, 6))?;
    writeln!(
        w,
        "bias stability       {:>14} °/h (1σ of {} means of {} s{})",
        num(e.bias_stability_dph, 6),
        e.means,
        e.tau_s,
        if e.stop_segments_only {
            ", stop segments only"
        } else {
            ""
        }
    )?;
    if let Some(r) = &e.scale {
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| num(x, 3));
        writeln!(w, "scale factor         {:>14}", num(r.scale_factor, 9))?;
        writeln!(
            w,
            "nonlinearity         {:>14} ppm",
            num(r.nonlinearity_ppm, 3)
        )?;
        writeln!(w, "asymmetry            {:>14} ppm", opt(r.asymmetry_ppm))?;
        writeln!(
            w,
            "SF thermal error     {:>14} ppm (max |K(t) − K_ref|, K_ref = {}, {} rate segments)",
            num(r.sf_thermal_error_ppm, 3),
            num(r.reference_scale, 9),
            r.scale_over_time.len()
        )?;
    }
    Ok(())
}

/// Fixed-point with `prec` decimals for ordinary magnitudes, scientific beyond (a figure of
/// 1e28 °/h is not printed as 29 digits).
fn num(x: f64, prec: usize) -> String {
    if x != 0.0 && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:.prec$e}")
    } else {
        format!("{x:.prec$}")
    }
}

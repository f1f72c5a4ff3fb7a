//! `gyrotherm simulate`: write a simulated thermal-chamber test log (see `gyrotherm::sim`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use gyrotherm::metrics;
use gyrotherm::sim::{self, FogUnit, Profile, SimConfig, BUILTIN_PROFILES};

#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// Built-in chamber profile (see --list-profiles).
    #[arg(long, default_value = "seed-shock", conflicts_with = "profile_file", value_parser = super::common::builtin_profile())]
    profile: String,
    /// User profile: text file of `duration_s,target_c` rows (set point starts at the first
    /// row's target; each later row ramps linearly to its target; `#` comments).
    #[arg(long, value_name = "FILE")]
    profile_file: Option<PathBuf>,
    /// Random seed (same seed, same bytes).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Rate-table test at this rate, °/s: +rate / stop / -rate / stop segments.
    #[arg(long, value_name = "DPS")]
    table_rate: Option<f64>,
    /// Length of each rate-table segment, s.
    #[arg(long, default_value_t = sim::DEFAULT_TABLE_SEGMENT_S, value_name = "S")]
    table_segment: f64,
    /// Add truth columns (true bias, true scale factor, noise-only part, node temperatures).
    #[arg(long)]
    truth: bool,
    /// Output sample rate, Hz.
    #[arg(long, default_value_t = 1.0, value_name = "HZ")]
    rate_hz: f64,
    /// Unit parameter file (JSON); fields given override the default unit's.
    #[arg(long, value_name = "FILE")]
    unit: Option<PathBuf>,
    /// Latitude, degrees north (Earth-rate component).
    #[arg(long, default_value_t = sim::DEFAULT_LATITUDE_DEG, allow_negative_numbers = true)]
    latitude: f64,
    /// Fault injection: mean dropouts (missing samples, a time gap) per hour.
    #[arg(long, default_value_t = 0.0, value_name = "N")]
    dropouts_per_hour: f64,
    /// Length of each dropout, s.
    #[arg(long, default_value_t = 5.0, value_name = "S")]
    dropout_s: f64,
    /// Fault injection: mean stuck-temperature episodes per hour.
    #[arg(long, default_value_t = 0.0, value_name = "N")]
    stuck_temp_per_hour: f64,
    /// Length of each stuck-temperature episode, s.
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    stuck_temp_s: f64,
    /// Fault injection: mean single-sample temperature spikes per hour (85.0, −127.0 and
    /// ±10–40 °C jumps in turn).
    #[arg(long, default_value_t = 0.0, value_name = "N")]
    spikes_per_hour: f64,
    /// Fault injection: mean NaN temperature bursts per hour.
    #[arg(long, default_value_t = 0.0, value_name = "N")]
    nan_bursts_per_hour: f64,
    /// Length of each NaN burst, s.
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    nan_burst_s: f64,
    /// Fault injection: mean episodes per hour of the temperature stuck at --stuck-value.
    #[arg(long, default_value_t = 0.0, value_name = "N")]
    stuck_value_per_hour: f64,
    /// Length of each stuck-value episode, s.
    #[arg(long, default_value_t = 120.0, value_name = "S")]
    stuck_value_s: f64,
    /// The reading of a stuck-value episode, °C (DS18B20 power-on value).
    #[arg(
        long,
        default_value_t = 85.0,
        value_name = "C",
        allow_negative_numbers = true
    )]
    stuck_value: f64,
    /// Output CSV file.
    #[arg(long, value_name = "FILE", required_unless_present_any = ["list_profiles", "print_unit"])]
    out: Option<PathBuf>,
    /// List the built-in profiles and exit.
    #[arg(long)]
    list_profiles: bool,
    /// Print the unit's parameters (default, or --unit applied) as JSON and exit.
    #[arg(long)]
    print_unit: bool,
}

pub fn run(args: SimulateArgs) -> anyhow::Result<ExitCode> {
    if args.list_profiles {
        for (name, what) in BUILTIN_PROFILES {
            println!("{name:<12} {what}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    let unit = match &args.unit {
        Some(path) => FogUnit::load(path)?,
        None => FogUnit::default(),
    };
    if args.print_unit {
        println!("{}", serde_json::to_string_pretty(&unit)?);
        return Ok(ExitCode::SUCCESS);
    }
    let profile = match &args.profile_file {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read profile file {}", path.display()))?;
            Profile::parse(&text, &path.display().to_string())?
        }
        None => Profile::builtin(&args.profile)?,
    };
    let cfg = SimConfig {
        seed: args.seed,
        sample_rate_hz: args.rate_hz,
        table_rate_dps: args.table_rate,
        table_segment_s: args.table_segment,
        truth: args.truth,
        unit,
        latitude_deg: args.latitude,
        faults: sim::FaultParams {
            dropouts_per_hour: args.dropouts_per_hour,
            dropout_s: args.dropout_s,
            stuck_temp_per_hour: args.stuck_temp_per_hour,
            stuck_temp_s: args.stuck_temp_s,
            spikes_per_hour: args.spikes_per_hour,
            nan_bursts_per_hour: args.nan_bursts_per_hour,
            nan_burst_s: args.nan_burst_s,
            stuck_value_per_hour: args.stuck_value_per_hour,
            stuck_value_s: args.stuck_value_s,
            stuck_value_c: Some(args.stuck_value),
        },
        ..SimConfig::new(profile)
    };
    let out = args.out.context("--out is required")?;
    let log = sim::simulate(&cfg)?;
    gyrotherm::sim::fault::write_log(&out, &log)?;

    let (tmin, tmax) = log
        .temp_c
        .iter()
        .filter(|t| t.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
            (a.min(t), b.max(t))
        });
    let stability = if cfg.table_rate_dps.is_none() {
        match metrics::bias_stability_dph(&log.gyro_dps, 1.0 / cfg.sample_rate_hz, 100.0) {
            Ok(b) => format!(
                "raw bias stability {:.5} °/h (1σ of 100 s means)",
                b.bias_stability_dph
            ),
            Err(e) => format!("no 100 s bias stability ({e})"),
        }
    } else {
        format!("rate table ±{} °/s", cfg.table_rate_dps.unwrap_or(0.0))
    };
    eprintln!(
        "simulated {} samples ({:.0} s at {} Hz) of `{}` with unit `{}`, seed {}: temperature \
         {tmin:.2} to {tmax:.2} °C (sensor), {stability}; wrote {}",
        log.len(),
        cfg.profile.duration_s(),
        cfg.sample_rate_hz,
        cfg.profile.name,
        cfg.unit.name,
        cfg.seed,
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}

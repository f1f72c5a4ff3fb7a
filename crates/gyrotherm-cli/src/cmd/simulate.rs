//! `gyrotherm simulate`: write a simulated thermal-chamber test log (see `gyrotherm::sim`).

use std::io::Write as _;
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
    /// Unit parameter file (JSON); fields given override the default unit's. `random` draws
    /// a unit from the documented family ranges (`gyrotherm::sim::family`) with --unit-seed;
    /// its parameters are written beside the log as `<out>.unit.json`.
    #[arg(long, value_name = "FILE|random")]
    unit: Option<PathBuf>,
    /// Seed of the random unit (`--unit random`; same seed, same unit).
    #[arg(long, value_name = "N")]
    unit_seed: Option<u64>,
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
    /// An inertial unit: three gyros in one housing, a sensor on the case and one beside each
    /// coil (`time_s,gyro_x_dps,gyro_y_dps,gyro_z_dps,temp_case_c,temp_x_c,temp_y_c,temp_z_c`);
    /// needs `--unit random --unit-seed N` (or no --unit: unit seed 0).
    #[arg(long)]
    imu: bool,
    /// With --imu and --table-rate: the axis the table turns.
    #[arg(long, default_value = "x", value_parser = ["x", "y", "z"], requires = "imu")]
    table_axis: String,
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
    // Errors returned, not `println!`: a closed pipe ends the command quietly.
    let mut w = std::io::stdout().lock();
    if args.list_profiles {
        for (name, what) in BUILTIN_PROFILES {
            writeln!(w, "{name:<12} {what}")?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let random = args.unit.as_deref() == Some(std::path::Path::new("random"));
    // The log, and the unit's parameters beside it (`--unit random`, `--imu`).
    let sidecar_of = args.out.as_ref().map(|o| {
        let mut p = o.clone().into_os_string();
        p.push(".unit.json");
        PathBuf::from(p)
    });
    super::common::refuse_outputs_over_inputs(
        args.out.iter().chain(&sidecar_of).map(PathBuf::as_path),
        args.profile_file
            .iter()
            .chain(args.unit.iter().filter(|_| !random))
            .map(PathBuf::as_path),
    )?;
    let unit = match (&args.unit, args.unit_seed) {
        (Some(_), Some(seed)) if random => sim::random_unit(seed),
        (Some(_), None) if random => {
            anyhow::bail!("--unit random needs --unit-seed N (the seed that names the unit)")
        }
        (_, Some(_)) => anyhow::bail!(
            "--unit-seed applies to --unit random only; give `--unit random --unit-seed N`"
        ),
        (Some(path), None) => FogUnit::load(path)?,
        (None, None) => FogUnit::default(),
    };
    if args.print_unit {
        writeln!(w, "{}", serde_json::to_string_pretty(&unit)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    let profile = match &args.profile_file {
        Some(path) => {
            let text = gyrotherm::input_file::read_capped_to_string(
                path,
                gyrotherm::input_file::InputKind::Profile,
            )
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
    let out = args.out.clone().context("--out is required")?;
    if args.imu {
        return run_imu(&args, cfg, &out);
    }
    let log = sim::simulate(&cfg)?;
    gyrotherm::sim::fault::write_log(&out, &log)?;
    let sidecar = random.then(|| {
        let mut p = out.clone().into_os_string();
        p.push(".unit.json");
        PathBuf::from(p)
    });
    if let Some(path) = &sidecar {
        let json = serde_json::to_string_pretty(&cfg.unit)? + "\n";
        gyrotherm::atomic_file::write_bytes_atomically(path, json.as_bytes())
            .with_context(|| format!("cannot write the unit's parameters to {}", path.display()))?;
    }

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
    if let Some(path) = sidecar {
        eprintln!("the drawn unit's parameters: {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// `simulate --imu`: the inertial unit of the unit seed (see `gyrotherm::sim::imu`).
fn run_imu(args: &SimulateArgs, run: SimConfig, out: &std::path::Path) -> anyhow::Result<ExitCode> {
    use gyrotherm::sim::imu;
    let random = args.unit.as_deref() == Some(std::path::Path::new("random"));
    anyhow::ensure!(
        args.unit.is_none() || random,
        "--imu draws its unit from the family: give `--unit random --unit-seed N`"
    );
    let unit_seed = args.unit_seed.unwrap_or(0);
    let cfg = imu::ImuConfig {
        unit: imu::imu_from_family(unit_seed),
        table_axis: imu::AXIS_NAMES
            .iter()
            .position(|a| *a == args.table_axis)
            .unwrap_or(0),
        run,
    };
    let log = imu::simulate_imu(&cfg)?;
    gyrotherm::csvlog::write_imu_log(out, &log)?;
    let mut sidecar = out.to_path_buf().into_os_string();
    sidecar.push(".unit.json");
    let sidecar = PathBuf::from(sidecar);
    let json = serde_json::to_string_pretty(&serde_json::json!({
        "gyros": cfg.unit.gyros,
        "case_sensor": {
            "tau_s": cfg.unit.case_sensor.tau_s,
            "offset_c": cfg.unit.case_sensor.offset_c,
            "noise_c": cfg.unit.case_sensor.noise_c,
            "resolution_c": cfg.unit.case_sensor.resolution_c,
        },
    }))? + "\n";
    gyrotherm::atomic_file::write_bytes_atomically(&sidecar, json.as_bytes()).with_context(
        || {
            format!(
                "cannot write the unit's parameters to {}",
                sidecar.display()
            )
        },
    )?;
    let table = match cfg.run.table_rate_dps {
        Some(r) => format!("rate table ±{r} °/s on axis {}", args.table_axis),
        None => "static".to_owned(),
    };
    eprintln!(
        "simulated {} samples ({:.0} s at {} Hz) of `{}` with inertial unit {unit_seed} (3 gyros, \
         4 sensors), seed {}, {table}; wrote {}; the unit's parameters: {}",
        log.len(),
        cfg.run.profile.duration_s(),
        cfg.run.sample_rate_hz,
        cfg.run.profile.name,
        cfg.run.seed,
        out.display(),
        sidecar.display()
    );
    Ok(ExitCode::SUCCESS)
}

//! `gyrotherm plan`: what the training logs cover of a flight's envelope and a chamber
//! profile that covers it (`gyrotherm::plan`; this file only translates).

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::plan::{
    propose, resolve_set_envelope, set_coverage, slowest_lag, CoverageSummary, Step,
};
use gyrotherm::settings::plan::{self as defaults, PlanSettings};

use super::common::{read_log_set, read_log_sets, LogArgs};

#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// Flight log (CSV): its sensor temperature's extremes and largest |dT| are the envelope.
    #[arg(long, value_name = "FLIGHT.csv")]
    pub flight: Option<PathBuf>,
    /// Envelope's coldest temperature, °C (instead of the flight log's).
    #[arg(long, value_name = "C", allow_hyphen_values = true)]
    pub temp_min_c: Option<f64>,
    /// Envelope's hottest temperature, °C (instead of the flight log's).
    #[arg(long, value_name = "C", allow_hyphen_values = true)]
    pub temp_max_c: Option<f64>,
    /// Envelope's largest |dT|, °C/min (instead of the flight log's).
    #[arg(long, value_name = "C_PER_MIN")]
    pub max_rate_c_per_min: Option<f64>,
    /// The chamber's coldest set point, °C.
    #[arg(long, value_name = "C", allow_hyphen_values = true, default_value_t = defaults::CHAMBER_MIN_C)]
    pub chamber_min_c: f64,
    /// The chamber's hottest set point, °C.
    #[arg(long, value_name = "C", allow_hyphen_values = true, default_value_t = defaults::CHAMBER_MAX_C)]
    pub chamber_max_c: f64,
    /// The chamber's fastest ramp, °C/min.
    #[arg(long, value_name = "C_PER_MIN", default_value_t = defaults::CHAMBER_MAX_RATE_C_PER_MIN)]
    pub chamber_max_rate_c_per_min: f64,
    /// Training log so far (CSV); repeat for several. Without one, only the profile.
    #[arg(long)]
    pub input: Vec<PathBuf>,
    /// Write the proposed profile here, as `simulate --profile-file` reads it.
    #[arg(long, value_name = "PROFILE.txt")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub log: LogArgs,
}

pub fn run(args: PlanArgs) -> anyhow::Result<ExitCode> {
    super::common::refuse_outputs_over_inputs(
        args.out.as_deref(),
        args.flight
            .as_deref()
            .into_iter()
            .chain(args.input.iter().map(PathBuf::as_path)),
    )?;
    // Written with errors returned, not `println!`: a closed pipe (`| head -1`) ends the
    // command quietly instead of a panic.
    let mut w = std::io::stdout().lock();
    let mut s = PlanSettings {
        temp_min_c: args.temp_min_c,
        temp_max_c: args.temp_max_c,
        max_rate_c_per_min: args.max_rate_c_per_min,
        chamber_min_c: args.chamber_min_c,
        chamber_max_c: args.chamber_max_c,
        chamber_max_rate_c_per_min: args.chamber_max_rate_c_per_min,
        slowest_lag_s: None,
    };
    // The flight and the training logs are read through the one entry, alike: a single
    // gyro's, or an inertial unit's when the columns are lists.
    let opts = args.log.read_options();
    let table_axis = args.log.table_axis.as_deref();
    let flight_paths: Vec<PathBuf> = args.flight.iter().cloned().collect();
    let (flight, train) = match (flight_paths.is_empty(), args.input.is_empty()) {
        (false, false) => {
            let [f, t] = read_log_sets([&flight_paths[..], &args.input[..]], &args.log)?;
            (Some(f), Some(t))
        }
        (false, true) => (Some(read_log_set(&flight_paths, &opts, table_axis)?), None),
        (true, false) => (None, Some(read_log_set(&args.input, &opts, table_axis)?)),
        (true, true) => (None, None),
    };
    let env = resolve_set_envelope(flight.as_ref(), &s)?;
    writeln!(
        w,
        "envelope: {:.1} to {:.1} °C, |dT| up to {:.2} °C/min{}",
        env.temp_min_c,
        env.temp_max_c,
        env.max_rate_c_per_min,
        if flight.is_some() {
            // Say which rate: the model's dT (what `compensate` warns with) is shorter and
            // reads faster on a shock.
            format!(
                " (flight log; rate of its {} s moving average)",
                gyrotherm::features::TEMP_RATE_SMOOTHING_S
            )
        } else {
            String::new()
        }
    )?;
    writeln!(
        w,
        "chamber: {} to {} °C, ramps up to {} °C/min",
        s.chamber_min_c, s.chamber_max_c, s.chamber_max_rate_c_per_min
    )?;
    if let Some(train) = &train {
        let pairs = set_coverage(train, flight.as_ref(), &env, &opts)?;
        for p in &pairs {
            // A unit's lines name the gyro and the sensor; a single gyro's are as they were.
            let pair = if pairs.len() > 1 {
                format!("{} on {}: ", p.gyro, p.temp)
            } else {
                String::new()
            };
            write_coverage(&mut w, &pair, &p.coverage)?;
        }
        if let Some((p, tau)) = slowest_lag(&pairs) {
            if pairs.len() > 1 {
                writeln!(
                    w,
                    "slowest thermal lag of the unit: {tau:.0} s ({} on {})",
                    p.gyro, p.temp
                )?;
            }
            s.slowest_lag_s = Some(tau);
        }
    }
    let plan = propose(&env, &s)?;
    for n in &plan.notes {
        eprintln!("gyrotherm: warning: {n}");
    }
    writeln!(
        w,
        "proposed profile: {:.1} to {:.1} °C; ramps at {}; {:.0} s ({:.1} h)",
        plan.temp_lo_c,
        plan.temp_hi_c,
        plan.rates_c_per_min
            .iter()
            .map(|(r, n)| format!("{r:.2} °C/min ×{n}"))
            .collect::<Vec<_>>()
            .join(", "),
        plan.duration_s(),
        plan.duration_s() / 3600.0
    )?;
    writeln!(
        w,
        "soaks: first at each extreme {:.0} s ({:.1} h): {}; the others {:.0} s",
        plan.soak.long_s,
        plan.soak.long_s / 3600.0,
        plan.soak.why,
        plan.soak.other_s
    )?;
    writeln!(
        w,
        "{:>4}  {:<5} {:>8} {:>8} {:>10} {:>10}",
        "#", "step", "from °C", "to °C", "°C/min", "s"
    )?;
    for (i, seg) in plan.segments.iter().enumerate() {
        let step = match seg.step {
            Step::Hold => "hold",
            Step::Ramp => "ramp",
            Step::Soak => "soak",
        };
        writeln!(
            w,
            "{:>4}  {:<5} {:>8.1} {:>8.1} {:>10.2} {:>10.0}",
            i + 1,
            step,
            seg.from_c,
            seg.to_c,
            seg.rate_c_per_min,
            seg.duration_s
        )?;
    }
    if let Some(out) = &args.out {
        gyrotherm::atomic_file::write_bytes_atomically(out, plan.profile_text().as_bytes())
            .with_context(|| format!("cannot write {}", out.display()))?;
        writeln!(w, "wrote {}", out.display())?;
    }
    Ok(ExitCode::SUCCESS)
}

/// What the training logs cover on one pair of columns, each line after `pair` (empty for a
/// single gyro).
fn write_coverage(
    w: &mut impl std::io::Write,
    pair: &str,
    coverage: &Result<CoverageSummary, String>,
) -> std::io::Result<()> {
    let c = match coverage {
        Err(why) => return writeln!(w, "{pair}training coverage: none: {why}"),
        Ok(c) => c,
    };
    writeln!(
        w,
        "{pair}training covers {} of {} (T, dT) cells: {:.1} to {:.1} °C, {:.2} to {:.2} \
         °C/min",
        c.covered_cells,
        c.cells,
        c.temp_span_c.0,
        c.temp_span_c.1,
        c.rate_span_c_per_min.0,
        c.rate_span_c_per_min.1
    )?;
    if let Some([inside, edge, outside]) = c.flight_shares {
        writeln!(
            w,
            "{pair}flight: {:.1} % of samples inside, {:.1} % at the edge, {:.1} % outside",
            100.0 * inside,
            100.0 * edge,
            100.0 * outside
        )?;
    }
    writeln!(
        w,
        "{pair}envelope (temperature × ±rate): {:.1} % outside",
        100.0 * c.envelope_outside
    )?;
    if let Some(tau) = c.slowest_lag_s {
        writeln!(
            w,
            "{pair}slowest thermal lag identified: {tau:.0} s{}",
            if c.lag_at_bound {
                " (at the lag search's upper bound: the true lag may be longer)"
            } else {
                ""
            }
        )?;
    }
    Ok(())
}

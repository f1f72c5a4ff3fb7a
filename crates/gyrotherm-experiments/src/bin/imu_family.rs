//! The inertial-unit family benchmark: does reading the coil sensors help the three axes of
//! a unit nobody tuned the method to?
//!
//! Draws units of the simulated family (`gyrotherm::sim::imu::imu_from_family`; design family:
//! unit seeds 1000.., confirmation family: 5000..), each three gyros in one housing with a
//! case sensor and a sensor beside each coil, and per unit:
//!
//! - training: `seed-shock` static + one ±20 °/s rate-table run per axis (a table turns one
//!   axis at a time; the table column of run k drives axis k, the other axes are static in
//!   that run);
//! - held out: `airborne` and `shock-5` (5 °C/min), static + one table run per axis each,
//!   other seeds.
//!
//! Settings (method `thermal`, the default): `case` (every axis reads the case sensor
//! alone), `chosen` (`fit_imu` with one sensor per axis, chosen by cross-validation among
//! the four), `all` (every axis may read every sensor; cross-validation decides which stay).
//!
//! Per setting and held-out profile it prints the median and worst, over units × axes, of
//! the bias stability (τ = 100 s) of the compensated static run as a multiple of the noise
//! floor (the bias stability of the axis's noise-only truth in the same run), and of the
//! scale-factor thermal error (ppm) on the axis's table run; per-case figures go to a TSV.
//!
//! `cargo run --release -p gyrotherm-experiments --bin imu_family -- [--family
//! design|confirm] [--units 30] [--first 0] [--settings case,chosen,all] [--threads 2]
//! [--min-gain 0.02] [--cases FILE]`; `bench/imu_family.sh` runs it as recorded in `docs/experiments/imu.md`.
//! Settings are chosen on the design family only; the confirmation family is run once.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use gyrotherm::csvlog::{ImuLog, NamedSeries};
use gyrotherm::fit::{FitConfig, RecipeKind, RecipeSettings};
use gyrotherm::imu_model::{compensate_imu, fit_imu_with, ImuFitSettings, ImuModel, ImuSensors};
use gyrotherm::metrics::bias_stability_dph;
use gyrotherm::metrics::scale_factor::{scale_factor, ScaleFactorOptions};
use gyrotherm::model::{Method, TempSensorDef};
use gyrotherm::sim::imu::{
    imu_from_family, simulate_imu, truth_col, ImuConfig, ImuUnit, AXIS_NAMES, CASE_SENSOR_COL,
};
use gyrotherm::sim::{Profile, SimConfig};

const TABLE_RATE_DPS: f64 = 20.0;
const TAU_S: f64 = 100.0;
const TEST_PROFILES: [&str; 2] = ["airborne", "shock-5"];
const SETTINGS: [&str; 3] = ["case", "chosen", "all"];
const DEFAULT_SETTINGS: &str = "case,chosen,all";
const DESIGN_BASE_SEED: u64 = 1000;
const CONFIRM_BASE_SEED: u64 = 5000;

fn sim(
    unit: &ImuUnit,
    profile: &str,
    seed: u64,
    table_axis: Option<usize>,
) -> Result<ImuLog, String> {
    let mut run = SimConfig::new(Profile::builtin(profile).map_err(|e| e.to_string())?);
    run.seed = seed;
    run.truth = true;
    run.table_rate_dps = table_axis.map(|_| TABLE_RATE_DPS);
    simulate_imu(&ImuConfig {
        run,
        unit: unit.clone(),
        table_axis: table_axis.unwrap_or(0),
    })
    .map_err(|e| e.to_string())
}

/// A pass-through truth column as numbers.
fn truth(log: &ImuLog, name: &str) -> Result<Vec<f64>, String> {
    let c = log
        .extra
        .iter()
        .find(|c| c.name == name)
        .ok_or_else(|| format!("no truth column {name}"))?;
    c.values
        .iter()
        .map(|v| v.parse::<f64>().map_err(|e| format!("{name}: {e}")))
        .collect()
}

/// The log with only the case sensor (the `case` setting reads nothing else).
fn case_only(log: &ImuLog) -> ImuLog {
    ImuLog {
        temp: log
            .temp
            .iter()
            .filter(|s| s.name == CASE_SENSOR_COL)
            .cloned()
            .collect::<Vec<NamedSeries>>(),
        extra: Vec::new(),
        ..log.clone()
    }
}

/// One axis's figures on one unit, one setting, one held-out profile.
#[derive(Debug, Clone)]
struct Case {
    unit_seed: u64,
    setting: String,
    axis: usize,
    profile: &'static str,
    x_floor: f64,
    sf_ppm: f64,
    fit_s: f64,
    temps: String,
}

struct Job<'a> {
    settings: &'a [String],
    min_gain: f64,
}

fn run_unit(unit_seed: u64, job: &Job) -> Result<Vec<Case>, String> {
    let settings = job.settings;
    let unit = imu_from_family(unit_seed);
    let s0 = unit_seed * 100;
    let mut train = vec![(
        "seed-shock-static".to_owned(),
        sim(&unit, "seed-shock", s0 + 1, None)?,
    )];
    for (k, axis) in AXIS_NAMES.iter().enumerate() {
        train.push((
            format!("seed-shock-table-{axis}"),
            sim(&unit, "seed-shock", s0 + 2 + k as u64, Some(k))?,
        ));
    }
    for (_, l) in &mut train {
        l.extra.clear();
    }
    let mut tests = Vec::new();
    for (p, profile) in TEST_PROFILES.iter().enumerate() {
        let seed = s0 + 50 + 10 * p as u64;
        let st = sim(&unit, profile, seed + 1, None)?;
        let tabs = (0..AXIS_NAMES.len())
            .map(|k| sim(&unit, profile, seed + 2 + k as u64, Some(k)))
            .collect::<Result<Vec<_>, _>>()?;
        let floors = AXIS_NAMES
            .iter()
            .map(|a| {
                let noise = truth(&st, &truth_col(gyrotherm::csvlog::NOISE_COL, a))?;
                bias_stability_dph(&noise, 1.0, TAU_S)
                    .map(|b| b.bias_stability_dph)
                    .map_err(|e| e.to_string())
            })
            .collect::<Result<Vec<_>, String>>()?;
        tests.push((*profile, st, tabs, floors));
    }
    let mut cfg = FitConfig::new(Method::Lstm);
    cfg.recipe = RecipeSettings::of_kind(RecipeKind::Thermal);
    cfg.seed = 1;
    let sensor = TempSensorDef::default();
    let one = ImuFitSettings {
        sensors: ImuSensors::ChooseOne,
        ..ImuFitSettings::default()
    };
    let all = ImuFitSettings {
        min_gain: job.min_gain,
        ..ImuFitSettings::default()
    };
    let mut out = Vec::new();
    for setting in settings {
        let t0 = Instant::now();
        let model: ImuModel = match setting.as_str() {
            "case" => {
                let logs: Vec<(String, ImuLog)> = train
                    .iter()
                    .map(|(n, l)| (n.clone(), case_only(l)))
                    .collect();
                fit_imu_with(&logs, &cfg, &one, &sensor, &|_, _, _, _, _| {})
            }
            "chosen" => fit_imu_with(&train, &cfg, &one, &sensor, &|_, _, _, _, _| {}),
            _ => fit_imu_with(&train, &cfg, &all, &sensor, &|_, _, _, _, _| {}),
        }
        .map_err(|e| {
            format!(
                "unit {unit_seed} {setting}: {e}: {:?}",
                std::error::Error::source(&e).map(|s| s.to_string())
            )
        })?;
        let fit_s = t0.elapsed().as_secs_f64();
        for (profile, st, tabs, floors) in &tests {
            let cs = compensate_imu(&model, st).map_err(|e| e.to_string())?;
            for (k, axis) in model.axes.iter().enumerate() {
                let b = bias_stability_dph(&cs[k].gyro_comp_dps, 1.0, TAU_S)
                    .map_err(|e| e.to_string())?
                    .bias_stability_dph;
                let tab = &tabs[k];
                let ct = compensate_imu(&model, tab).map_err(|e| e.to_string())?;
                let rep = scale_factor(
                    &tab.time_s,
                    &ct[k].gyro_comp_dps,
                    &tab.table.as_ref().ok_or("no table")?.values,
                    &ScaleFactorOptions::default(),
                )
                .map_err(|e| e.to_string())?;
                out.push(Case {
                    unit_seed,
                    setting: setting.clone(),
                    axis: k,
                    profile,
                    x_floor: b / floors[k],
                    sf_ppm: rep.sf_thermal_error_ppm,
                    fit_s,
                    temps: axis.temps.join("+"),
                });
            }
        }
    }
    Ok(out)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn worst(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

fn main() {
    if let Err(e) = run() {
        eprintln!("imu_family: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let get = |k: &str| gyrotherm_experiments::arg_value(&args, k);
    let family = get("--family").unwrap_or_else(|| "design".into());
    let base = match family.as_str() {
        "design" => DESIGN_BASE_SEED,
        "confirm" => CONFIRM_BASE_SEED,
        f => return Err(format!("--family {f:?}: use design or confirm")),
    };
    let units: u64 =
        get("--units").map_or(Ok(30), |v| v.parse().map_err(|e| format!("--units: {e}")))?;
    let first: u64 =
        get("--first").map_or(Ok(0), |v| v.parse().map_err(|e| format!("--first: {e}")))?;
    let threads: usize =
        get("--threads").map_or(Ok(2), |v| v.parse().map_err(|e| format!("--threads: {e}")))?;
    let settings: Vec<String> = get("--settings")
        .unwrap_or_else(|| DEFAULT_SETTINGS.into())
        .split(',')
        .map(str::to_owned)
        .collect();
    if let Some(s) = settings.iter().find(|s| !SETTINGS.contains(&s.as_str())) {
        return Err(format!(
            "--settings: unknown {s:?}; use {}",
            SETTINGS.join(", ")
        ));
    }
    let min_gain: f64 = get("--min-gain").map_or(Ok(ImuFitSettings::default().min_gain), |v| {
        v.parse().map_err(|e| format!("--min-gain: {e}"))
    })?;
    let job = Job {
        settings: &settings,
        min_gain,
    };
    let seeds: Vec<u64> = (first..first + units).map(|i| base + i).collect();
    eprintln!(
        "{family} family: {} units (seeds {}..{}), settings {settings:?}, {threads} threads",
        seeds.len(),
        seeds.first().copied().unwrap_or(0),
        seeds.last().copied().unwrap_or(0)
    );
    let t0 = Instant::now();
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let results: Mutex<Vec<Case>> = Mutex::new(Vec::new());
    let errors: Mutex<Vec<String>> = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(&seed) = seeds.get(i) else { break };
                match run_unit(seed, &job) {
                    Ok(c) => results.lock().unwrap_or_else(|p| p.into_inner()).extend(c),
                    Err(e) => errors.lock().unwrap_or_else(|p| p.into_inner()).push(e),
                }
                let d = done.fetch_add(1, Ordering::SeqCst) + 1;
                eprintln!(
                    "  unit {seed} done ({d}/{}), {:.0} s",
                    seeds.len(),
                    t0.elapsed().as_secs_f64()
                );
            });
        }
    });
    let errors = errors.into_inner().unwrap_or_else(|p| p.into_inner());
    let mut cases = results.into_inner().unwrap_or_else(|p| p.into_inner());
    cases.sort_by(|a, b| {
        (a.unit_seed, &a.setting, a.profile, a.axis).cmp(&(
            b.unit_seed,
            &b.setting,
            b.profile,
            b.axis,
        ))
    });
    if let Some(path) = get("--cases") {
        let mut text =
            String::from("unit_seed\tsetting\taxis\tprofile\tx_floor\tsf_ppm\tfit_s\ttemps\n");
        for c in &cases {
            text.push_str(&format!(
                "{}\t{}\t{}\t{}\t{:.4}\t{:.3}\t{:.2}\t{}\n",
                c.unit_seed,
                c.setting,
                AXIS_NAMES[c.axis],
                c.profile,
                c.x_floor,
                c.sf_ppm,
                c.fit_s,
                c.temps
            ));
        }
        gyrotherm::atomic_file::write_bytes_atomically(
            std::path::Path::new(&path),
            text.as_bytes(),
        )
        .map_err(|e| format!("{path}: {e}"))?;
    }
    println!();
    println!(
        "{family} family ({} units × 3 axes), trained on seed-shock static + one table run per axis",
        seeds.len()
    );
    println!("| setting | profile | ×floor median | ×floor worst | SF ppm median | SF ppm worst | fit s per unit |");
    println!("|---|---|---|---|---|---|---|");
    for setting in &settings {
        for profile in TEST_PROFILES.iter().map(Some).chain([None]) {
            let mine: Vec<&Case> = cases
                .iter()
                .filter(|c| &c.setting == setting && profile.is_none_or(|p| c.profile == *p))
                .collect();
            if mine.is_empty() {
                continue;
            }
            let mut x: Vec<f64> = mine.iter().map(|c| c.x_floor).collect();
            let mut sf: Vec<f64> = mine.iter().map(|c| c.sf_ppm).collect();
            let fit_s = mine.iter().map(|c| c.fit_s).sum::<f64>() / mine.len() as f64;
            println!(
                "| {setting} | {} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} |",
                profile.copied().unwrap_or("both"),
                median(&mut x),
                worst(&x),
                median(&mut sf),
                worst(&sf),
                fit_s
            );
        }
    }
    println!(
        "wall time {:.0} s ({} threads); {} units failed",
        t0.elapsed().as_secs_f64(),
        threads,
        errors.len()
    );
    for e in &errors {
        println!("  failed: {e}");
    }
    Ok(())
}

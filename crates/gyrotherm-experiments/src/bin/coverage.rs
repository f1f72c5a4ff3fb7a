//! The coverage benchmark: does the per-sample σ that `compensate` writes hold on held-out
//! runs, inside the training region and outside it?
//!
//! For each unit of a simulated family (`gyrotherm::sim::family`; design family: unit seeds
//! 1000.., confirmation family: 5000..; the wide family: seeds 7000.. drawn from ranges
//! widened past the design ranges, `gyrotherm_experiments::wide_ranges`, physics no setting was chosen on) the default `thermal` model is trained on `seed-shock`
//! static + ±20 °/s table runs (the seeds of the generalisation benchmark), and each held-out
//! static run (`slow-ramp`, `shock-5`, `airborne`) is compensated by the flight compensator.
//! Over non-overlapping 100 s windows it takes the mean of the compensated output (the true
//! rate is 0: the residual bias, noise included, °/h), the mean σ of the window and the window's
//! coverage (its worst sample: outside if one sample is outside, else edge if one is at the
//! edge, else inside), and prints the share of windows with |residual| ≤ σ per coverage class
//! for a grid of σ scales and growths per cell (the map's σ without scale and growth, times
//! `scale · (1 + growth · d)`), so both can be chosen on the design family and measured once
//! on the confirmation family.
//!
//! `cargo run --release -p gyrotherm-experiments --bin coverage -- [--family design|confirm|wide]
//! [--units 30] [--threads 2] [--scales 0.8,1,1.2] [--growths 0,0.25,0.5,1] [--method thermal]`
//! (`--method`: the method trained, `thermal` by default; the table is printed for every
//! model and again for the models whose bias holds an LSTM);
//! `bench/coverage.sh` runs it as recorded in `docs/experiments/coverage.md`.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use gyrotherm::compensate::compensator;
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::{fit_model, FitConfig, NamedLog, RecipeSettings};
use gyrotherm::model::Method;
use gyrotherm::sim::{random_unit, simulate_series, FogUnit, SimConfig, SimSeries};
use gyrotherm_core::coverage::Coverage;

const TABLE_RATE_DPS: f64 = 20.0;
const WINDOW_S: usize = 100;
const TEST_PROFILES: [&str; 3] = ["slow-ramp", "shock-5", "airborne"];
const DESIGN_BASE_SEED: u64 = 1000;
const CONFIRM_BASE_SEED: u64 = 5000;
const WIDE_BASE_SEED: u64 = 7000;

fn sim(unit: &FogUnit, profile: &str, seed: u64, table: bool) -> Result<SimSeries, String> {
    let mut c = SimConfig::builtin(profile).map_err(|e| e.to_string())?;
    c.unit = unit.clone();
    c.seed = seed;
    c.table_rate_dps = table.then_some(TABLE_RATE_DPS);
    simulate_series(&c).map_err(|e| e.to_string())
}

fn log_of(s: SimSeries) -> TestLog {
    TestLog {
        time_s: s.time_s,
        gyro_dps: s.gyro_dps,
        temp_c: s.temp_c,
        table_dps: s.table_dps,
        extra: Vec::new(),
    }
}

/// One 100 s window of a held-out run.
#[derive(Debug, Clone, Copy)]
struct Window {
    profile: usize,
    coverage: Coverage,
    /// Mean compensated output, °/h (the residual bias: the true rate is 0).
    resid_dph: f64,
    /// Mean σ of the unscaled map without growth, °/h.
    sigma0_dph: f64,
    /// Mean σ0 · d, °/h (so that σ = scale · (sigma0 + growth · sigma0_d)).
    sigma0_d_dph: f64,
    /// Whether the unit's bias model holds an LSTM.
    lstm: bool,
}

fn worse(a: Coverage, b: Coverage) -> Coverage {
    let rank = |c| match c {
        Coverage::Inside => 0,
        Coverage::Edge => 1,
        Coverage::Outside => 2,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

fn run_unit(unit_seed: u64, method: Method) -> Result<Vec<Window>, String> {
    let unit = if unit_seed >= WIDE_BASE_SEED {
        gyrotherm_experiments::wide_ranges().draw(unit_seed)
    } else {
        random_unit(unit_seed)
    };
    let s0 = unit_seed * 100;
    let train = [
        (
            "seed-shock-static",
            log_of(sim(&unit, "seed-shock", s0 + 1, false)?),
        ),
        (
            "seed-shock-table",
            log_of(sim(&unit, "seed-shock", s0 + 2, true)?),
        ),
    ];
    let named: Vec<NamedLog> = train
        .iter()
        .map(|(name, log)| NamedLog { name, log })
        .collect();
    let mut cfg = if method == Method::Thermal {
        // As recorded: the thermal recipe under the former method's name (the same fit).
        let mut c = FitConfig::new(Method::Lstm);
        c.recipe = RecipeSettings::of_kind(Method::Thermal);
        c
    } else {
        FitConfig::new(method)
    };
    cfg.seed = 1;
    let fit =
        fit_model(&named, &cfg, &|_, _, _| {}).map_err(|e| format!("unit {unit_seed}: {e}"))?;
    let def = fit.model.coverage.as_ref().ok_or_else(|| {
        format!(
            "unit {unit_seed}: no coverage map: {}",
            fit.coverage_note.clone().unwrap_or_default()
        )
    })?;
    // σ without growth; the harness applies scale and growth itself.
    let base = def
        .rescaled(1.0 / gyrotherm::settings::coverage::SIGMA_SCALE, 0.0)
        .to_core()
        .map_err(|e| e.to_string())?;
    let lstm = fit.model.bias.as_ref().is_some_and(|b| b.lstm().is_some());
    let mut out = Vec::new();
    for (k, p) in TEST_PROFILES.iter().enumerate() {
        let s = sim(&unit, p, s0 + 50 + 10 * k as u64 + 1, false)?;
        let mut comp = compensator(&fit.model).map_err(|e| e.to_string())?;
        let mut win: Option<(Coverage, f64, f64, f64, usize)> = None;
        for i in 0..s.time_s.len() {
            let c = comp.step(s.time_s[i], s.gyro_dps[i], s.temp_c[i]);
            let Some(v) = base.verdict_of(comp.features()) else {
                continue;
            };
            let r = c.rate().unwrap_or(f64::NAN) * 3600.0;
            let w = win.get_or_insert((Coverage::Inside, 0.0, 0.0, 0.0, 0));
            w.0 = worse(w.0, v.coverage);
            w.1 += r;
            w.2 += v.sigma_dph;
            w.3 += v.sigma_dph * v.distance_cells;
            w.4 += 1;
            if w.4 == WINDOW_S {
                let n = w.4 as f64;
                out.push(Window {
                    profile: k,
                    coverage: w.0,
                    resid_dph: w.1 / n,
                    sigma0_dph: w.2 / n,
                    sigma0_d_dph: w.3 / n,
                    lstm,
                });
                win = None;
            }
        }
    }
    Ok(out)
}

fn main() {
    if let Err(e) = run() {
        eprintln!("coverage: {e}");
        std::process::exit(2);
    }
}

fn list(v: Option<String>, default: &str) -> Result<Vec<f64>, String> {
    v.unwrap_or_else(|| default.into())
        .split(',')
        .map(|x| x.parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect()
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let get = |k: &str| gyrotherm_experiments::arg_value(&args, k);
    let family = get("--family").unwrap_or_else(|| "design".into());
    let base = match family.as_str() {
        "design" => DESIGN_BASE_SEED,
        "confirm" => CONFIRM_BASE_SEED,
        "wide" => WIDE_BASE_SEED,
        f => return Err(format!("--family {f:?}: use design, confirm or wide")),
    };
    let units: u64 =
        get("--units").map_or(Ok(30), |v| v.parse().map_err(|e| format!("--units: {e}")))?;
    let threads: usize =
        get("--threads").map_or(Ok(2), |v| v.parse().map_err(|e| format!("--threads: {e}")))?;
    // Defaults: the settings `train` uses.
    let scales = list(
        get("--scales"),
        &gyrotherm::settings::coverage::SIGMA_SCALE.to_string(),
    )?;
    let growths = list(
        get("--growths"),
        &gyrotherm::settings::coverage::GROWTH_PER_CELL.to_string(),
    )?;
    let method: Method = get("--method")
        .unwrap_or_else(|| "thermal".into())
        .parse()
        .map_err(|e| format!("--method: {e}"))?;
    let seeds: Vec<u64> = (0..units).map(|i| base + i).collect();
    let t0 = Instant::now();
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Window>> = Mutex::new(Vec::new());
    let errors: Mutex<Vec<String>> = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(&seed) = seeds.get(i) else { break };
                match run_unit(seed, method) {
                    Ok(w) => results.lock().unwrap_or_else(|p| p.into_inner()).extend(w),
                    Err(e) => errors.lock().unwrap_or_else(|p| p.into_inner()).push(e),
                }
            });
        }
    });
    let windows = results.into_inner().unwrap_or_else(|p| p.into_inner());
    let errors = errors.into_inner().unwrap_or_else(|p| p.into_inner());
    println!(
        "{family} family: {} units (seeds {}..{}), {} windows of {WINDOW_S} s",
        seeds.len(),
        base,
        base + units - 1,
        windows.len()
    );
    let classes = [Coverage::Inside, Coverage::Edge, Coverage::Outside];
    for (k, p) in TEST_PROFILES.iter().enumerate() {
        let n = |c| {
            windows
                .iter()
                .filter(|w| w.profile == k && w.coverage == c)
                .count()
        };
        println!(
            "  {p}: windows inside {}, edge {}, outside {}",
            n(Coverage::Inside),
            n(Coverage::Edge),
            n(Coverage::Outside)
        );
    }
    let with_lstm = windows.iter().filter(|w| w.lstm).count();
    println!(
        "method {}: {with_lstm} of {} windows from models holding an LSTM (rows `lstm` below)",
        method.as_str(),
        windows.len()
    );
    println!(
        "| models | σ scale | growth / cell | within ±1σ: inside | edge | outside | airborne outside |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (label, only_lstm) in [("all", false), ("lstm", true)] {
        for &sc in &scales {
            for &g in &growths {
                let share = |f: &dyn Fn(&Window) -> bool| {
                    let sel: Vec<&Window> = windows
                        .iter()
                        .filter(|w| (!only_lstm || w.lstm) && f(w))
                        .collect();
                    let hit = sel
                        .iter()
                        .filter(|w| w.resid_dph.abs() <= sc * (w.sigma0_dph + g * w.sigma0_d_dph))
                        .count();
                    format!(
                        "{:.1} % ({})",
                        100.0 * hit as f64 / sel.len().max(1) as f64,
                        sel.len()
                    )
                };
                let cells: Vec<String> = classes
                    .iter()
                    .map(|&c| share(&|w: &Window| w.coverage == c))
                    .collect();
                let air = share(&|w: &Window| w.coverage == Coverage::Outside && w.profile == 2);
                println!(
                    "| {label} | {sc} | {g} | {} | {} | {} | {air} |",
                    cells[0], cells[1], cells[2]
                );
            }
        }
    }
    println!(
        "wall time {:.0} s ({threads} threads); {} units failed",
        t0.elapsed().as_secs_f64(),
        errors.len()
    );
    for e in &errors {
        println!("  failed: {e}");
    }
    Ok(())
}

//! Held-out experiment for the LSTM recipes: simulate training runs (static +
//! rate-table) on some profiles and a held-out pair on another profile and seed, fit linear,
//! poly and lstm, compensate the held-out runs with the flight compensator and print
//! bias stability (°/h, τ = 100 s) raw / linear / poly / lstm / noise floor, the scale-factor
//! thermal error (ppm) and the compensated +20 °/s output range per method.
//!
//! `cargo run -p gyrotherm-experiments --release --bin heldout -- [--train seed-shock[,slow-ramp]]
//!  [--test slow-ramp] [--train-seed 7] [--test-seed 11] [--recipe residual|published]
//!  [--epochs N] [--scale-lstm] [--patience N] [--lr X] [--validation-every K]
//!  [--base B] [--scale-base B] [--bases B1,B2,...] [--no-lstm] [--base-input]
//!  [--run-gate]`
//!
//! `--base-input`: the residual LSTM reads the base prediction as one more input
//! (`RecipeSettings::base_input`). `--run-gate`: the leave-one-run-out check of the residual
//! LSTM (`RecipeSettings::validate_on_runs`).
//!
//! Bases `B`: `selected` (default), `tailored`, `linear`, `linear-t2`, `constant`,
//! `family:<set>` (one set of `fit::terms::ladder`, e.g. `family:T3+fast`). `--bases` adds a
//! row per base with its least-squares fit alone (bias and scale factor on that base);
//! `--no-lstm` leaves out the full recipe's row. Env `HELDOUT_UNIT=<unit json>` swaps the
//! simulated unit (`scripts/heldout_units/`); the scripts in `scripts/` run the sweeps
//! recorded in `docs/experiments/` (each record names its script and command).

use std::time::Instant;

use gyrotherm::compensate::compensate_log;
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::{fit_model, BaseTerms, FitConfig, NamedLog, RecipeSettings};
use gyrotherm::metrics::bias_stability_dph;
use gyrotherm::metrics::scale_factor::{scale_factor, ScaleFactorOptions};
use gyrotherm::model::Method;
use gyrotherm::sim::{simulate, SimConfig};

const TABLE_RATE_DPS: f64 = 20.0;

fn sim(profile: &str, seed: u64, table: bool) -> TestLog {
    let mut c = SimConfig::builtin(profile).expect("built-in profile");
    if let Ok(p) = std::env::var("HELDOUT_UNIT") {
        c.unit = gyrotherm::sim::FogUnit::load(std::path::Path::new(&p)).expect("unit file");
    }
    c.seed = seed;
    c.truth = true;
    c.table_rate_dps = table.then_some(TABLE_RATE_DPS);
    simulate(&c).expect("simulate")
}

fn extra(log: &TestLog, name: &str) -> Vec<f64> {
    log.extra
        .iter()
        .find(|c| c.name == name)
        .map(|c| c.values.iter().map(|v| v.parse().unwrap()).collect())
        .unwrap_or_else(|| panic!("no {name} column"))
}

/// Without the truth columns (training must not see them).
fn strip(log: &TestLog) -> TestLog {
    TestLog {
        extra: Vec::new(),
        ..log.clone()
    }
}

/// Process CPU time (user + system), s, from /proc/self/stat.
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 of the line are at 11 and 12 after the name.
    (tick(11) + tick(12)) / 100.0
}

struct Figures {
    bias_dph: f64,
    sf_ppm: f64,
    out20: (f64, f64),
}

fn figures(stat_out: &[f64], table_log: &TestLog, table_out: &[f64]) -> Figures {
    let bias_dph = bias_stability_dph(stat_out, 1.0, 100.0)
        .unwrap()
        .bias_stability_dph;
    let rep = scale_factor(
        &table_log.time_s,
        table_out,
        table_log.table_dps.as_ref().unwrap(),
        &ScaleFactorOptions::default(),
    )
    .unwrap();
    let out20 = rep
        .segments
        .iter()
        .filter(|s| (s.table_dps - TABLE_RATE_DPS).abs() < 1e-9)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
            (a.min(s.mean_output_dps), b.max(s.mean_output_dps))
        });
    Figures {
        bias_dph,
        sf_ppm: rep.sf_thermal_error_ppm,
        out20,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let get = |k: &str| gyrotherm_experiments::arg_value(&args, k);
    let train_profiles = get("--train").unwrap_or_else(|| "seed-shock".into());
    let test_profile = get("--test").unwrap_or_else(|| "slow-ramp".into());
    let train_seed: u64 = get("--train-seed").map_or(7, |v| v.parse().unwrap());
    let test_seed: u64 = get("--test-seed").map_or(11, |v| v.parse().unwrap());
    let mut recipe = RecipeSettings::of_kind(
        Method::parse_recipe(&get("--recipe").unwrap_or_else(|| "residual".into())).unwrap(),
    );
    if let Some(e) = get("--epochs") {
        recipe.epochs = e.parse().unwrap();
    }
    if let Some(v) = get("--lr") {
        recipe.lr = v.parse().unwrap();
    }
    if let Some(v) = get("--patience") {
        recipe.patience = Some(v.parse().unwrap());
    }
    if let Some(v) = get("--validation-every") {
        recipe.validation_every = v.parse().unwrap();
    }
    if let Some(v) = get("--batch") {
        recipe.batch = v.parse().unwrap();
    }
    if let Some(v) = get("--base") {
        recipe.base = BaseTerms::parse(&v).unwrap();
    }
    if let Some(v) = get("--scale-base") {
        recipe.scale_base = BaseTerms::parse(&v).unwrap();
    }
    if let Some(v) = get("--window") {
        recipe.window = v.parse().unwrap();
    }
    if let Some(v) = get("--burn-in") {
        recipe.burn_in = v.parse().unwrap();
    }
    if let Some(v) = get("--block") {
        recipe.block_steps = v.parse().unwrap();
    }
    if let Some(v) = get("--min-improvement") {
        recipe.min_val_improvement = v.parse().unwrap();
    }
    if let Some(v) = get("--smooth") {
        recipe.residual_smooth_steps = v.parse().unwrap();
    }
    let fit_seed: u64 = get("--fit-seed").map_or(1, |v| v.parse().unwrap());
    recipe.scale_lstm = args.iter().any(|a| a == "--scale-lstm");
    if args.iter().any(|a| a == "--base-input") {
        recipe.base_input = true;
    }
    if args.iter().any(|a| a == "--run-gate") {
        recipe.validate_on_runs = true;
    }

    let mut train_logs = Vec::new();
    let mut names = Vec::new();
    for (k, p) in train_profiles.split(',').enumerate() {
        let seed = train_seed + 1000 * k as u64;
        train_logs.push(strip(&sim(p, seed, false)));
        train_logs.push(strip(&sim(p, seed + 100, true)));
        names.push(format!("{p}-static-{seed}"));
        names.push(format!("{p}-table-{}", seed + 100));
    }
    let named: Vec<NamedLog> = train_logs
        .iter()
        .zip(&names)
        .map(|(log, name)| NamedLog { name, log })
        .collect();
    let test_static = sim(&test_profile, test_seed, false);
    let test_table = sim(&test_profile, test_seed + 100, true);
    let floor = bias_stability_dph(&extra(&test_static, "noise_dps"), 1.0, 100.0)
        .unwrap()
        .bias_stability_dph;
    let raw = figures(&test_static.gyro_dps, &test_table, &test_table.gyro_dps);

    println!(
        "train {train_profiles} (seed {train_seed}) -> test {test_profile} (seed {test_seed}); recipe {recipe:?}"
    );
    println!(
        "{:<8} {:>10} {:>8} {:>9} {:>22} {:>9} {:>9}",
        "method", "bias °/h", "×floor", "SF ppm", "+20 °/s output range", "wall s", "cpu s"
    );
    let row = |name: &str, f: &Figures, wall: f64, cpu: f64| {
        println!(
            "{:<8} {:>10.5} {:>8.2} {:>9.2} {:>10.6}..{:<10.6} {:>9.2} {:>9.2}",
            name,
            f.bias_dph,
            f.bias_dph / floor,
            f.sf_ppm,
            f.out20.0,
            f.out20.1,
            wall,
            cpu
        )
    };
    row("raw", &raw, 0.0, 0.0);
    let mut linear_bias = f64::NAN;
    let mut summary = vec![raw.bias_dph / floor];
    // `--bases a,b`: the residual recipe's least-squares base alone (no LSTM) for each named
    // base (bias and scale factor alike), for comparison; default: the recipe's own base.
    let bases: Vec<Option<BaseTerms>> = match get("--bases") {
        Some(v) => v
            .split(',')
            .map(|b| Some(BaseTerms::parse(b).unwrap()))
            .collect(),
        None => vec![None],
    };
    let mut runs: Vec<(String, Method, Option<Option<BaseTerms>>)> = vec![
        ("linear".into(), Method::Linear, None),
        ("poly".into(), Method::Poly, None),
    ];
    if recipe.kind != Method::Published {
        for b in &bases {
            let label = b.map_or("base".to_string(), |b| format!("b:{}", b.name()));
            runs.push((label, Method::Lstm, Some(*b)));
        }
    }
    if !args.iter().any(|a| a == "--no-lstm") {
        runs.push(("lstm".into(), Method::Lstm, None));
    }
    for (label, method, base) in runs {
        let label = label.as_str();
        let mut cfg = FitConfig::new(method);
        cfg.recipe = recipe.clone();
        if let Some(b) = base {
            cfg.recipe.epochs = 0;
            if let Some(b) = b {
                cfg.recipe.base = b;
                cfg.recipe.scale_base = b;
            }
        }
        cfg.seed = fit_seed;
        let (t0, c0) = (Instant::now(), cpu_s());
        let out = fit_model(&named, &cfg, &|_, _, _| {}).expect("fit");
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_s() - c0);
        let s = compensate_log(&out.model, &test_static).expect("compensate static");
        let t = compensate_log(&out.model, &test_table).expect("compensate table");
        let f = figures(&s.gyro_comp_dps, &test_table, &t.gyro_comp_dps);
        row(label, &f, wall, cpu);
        summary.push(f.bias_dph / floor);
        if method == Method::Linear {
            linear_bias = f.bias_dph;
        }
        if method == Method::Lstm {
            for (n, tr) in [("bias", &out.bias_training), ("scale", &out.scale_training)] {
                if let Some(tr) = tr {
                    println!(
                        "  {n}: epochs {} best {:?} final loss {:.4} val {:?} baseline rms {:?} gain {:?} val impr {:?} run gate {:?}",
                        tr.epochs,
                        tr.best_epoch,
                        tr.final_loss,
                        tr.best_epoch.and_then(|b| tr.val_loss_history.get(b)),
                        tr.baseline_rms,
                        tr.lstm_gain,
                        tr.val_improvement,
                        tr.run_gate
                    );
                    if let Some(sel) = &tr.selection {
                        println!("  {n} terms: {}", sel.describe());
                    }
                }
            }
        }
        if label == "lstm" {
            println!(
                "lstm vs linear: {:+.1} %   lstm / floor: {:.2}",
                (f.bias_dph / linear_bias - 1.0) * 100.0,
                f.bias_dph / floor
            );
        }
    }
    println!("floor    {floor:>10.5}");
    // One line for sweeps: case, then raw/linear/poly/base/lstm as multiples of the floor.
    println!(
        "SUMMARY {train_profiles}:{train_seed}->{test_profile}:{test_seed} floor {floor:.5} ×floor {}",
        summary
            .iter()
            .map(|v| format!("{v:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
}

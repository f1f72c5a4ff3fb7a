//! The inertial-unit family benchmark: does reading the coil sensors help the three axes of
//! a unit nobody tuned the method to?
//!
//! Draws units of the simulated family (`gyrotherm::sim::imu::imu_from_family`; design family:
//! unit seeds 1000.., confirmation family: 5000..; the wide family, 7000..: every gyro and the
//! case sensor drawn from `gyrotherm_experiments::wide_ranges`, physics past the design ranges), each three gyros in one housing with a
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
//! With method `auto` (docs/experiments/imu-auto.md): `all-auto` (each axis keeps its `all`
//! fit or `thermal-lstm` on that fit, whichever scores better on held-out validation of the
//! training runs; the TSV's `temps` column adds the choice and both scores, °/h) and
//! `all-lstm` (the `thermal-lstm` candidate kept on every axis, unscored); `all-tlstm`
//! (`--method thermal-lstm`: the same form, its fallback without an LSTM); `--lstm-hidden H`
//! and `--lstm-steps S` set that candidate's hidden units and Adam steps (default: `auto`'s).
//!
//! Per setting and held-out profile it prints the median and worst, over units × axes, of
//! the bias stability (τ = 100 s) of the compensated static run as a multiple of the noise
//! floor (the bias stability of the axis's noise-only truth in the same run), and of the
//! scale-factor thermal error (ppm) on the axis's table run; per-case figures go to a TSV.
//!
//! `cargo run --release -p gyrotherm-experiments --bin imu_family -- [--family
//! design|confirm|wide] [--units 30] [--first 0] [--settings case,chosen,all] [--threads 2]
//! [--min-gain 0.02] [--cases FILE] [--train seed-shock|planned|planned-soak|soak] [--hold none,lags,...]`;
//! `--train planned-soak`: `planned` with the first soak at each extreme sized from the slowest
//! lag a `thermal` fit of the training static run identifies, as `gyrotherm plan --train` does;
//! `--train soak` adds a static run with 6-hour soaks (docs/experiments/imu-soak.md); `--train planned` adds a
//! static run on the chamber profile `gyrotherm plan` proposes from the unit's own airborne
//! run (case sensor, a seed other than the held-out one's) to the training runs; `bench/imu_family.sh` runs it as recorded in `docs/experiments/imu.md`.
//! Settings are chosen on the design family only; the confirmation family is run once.
//!
//! `--hold` (experiment, docs/experiments/imu-extrapolation.md): each model is also applied
//! with its baseline inputs held within the range the training runs reached (per axis, per
//! sensor, the min and max of each feature over the training logs): `none` (as fitted),
//! `all` (every feature), `lags` (the lag differences `T − lag_j(T)`), `fast` (the fastest
//! lag difference only), `temp` (T only), `rate` (dT only), each feature on its own;
//! `shrink` / `shrink-fast`: every lag difference (the fastest) of all the axis's sensors
//! scaled toward 0 by one common factor (see `transform`); `k-<hold>`: that hold on the
//! scale factor's inputs only (the bias reads them as they are). Applied by a replica of
//! `compensate_imu` (checked bit-equal with `none`). One fit serves every hold.
//!
//! `--sigma FILE` (docs/experiments/coverage.md): per 100 s window of each held-out static
//! run and axis, the window's coverage (its worst sample's), the mean compensated output
//! (the residual bias, °/h) and the mean σ the model gives there, as `compensate` gives it
//! (axes without a map give none), then the same mean σ with the maps' growth per cell set
//! to 0 and to 1 (σ is linear in the growth, so any growth g gives σ0 + g·(σ1 − σ0): how
//! the growth is calibrated); one line a window.
//!
//! `--dump DIR` (experiment, docs/experiments/imu-worst-case.md): for setting `all`, per
//! axis, the 100 s means of the bias error and of each simulator bias term on the training
//! static run and each held-out static run ([`dump_run`]; `bench/imu_worst_case.py` reads
//! them). `--tau-max S`, `--max-tau-fraction F`, `--basis lean|linear|small|full`: the
//! thermal recipe's longest lag searched, its bound as a fraction of the longest run, and
//! the bias basis (defaults: the recipe's).
//!
//! Further fit overrides (experiment, docs/experiments/imu-worst-model.md): `--folds N`,
//! `--ridge-tolerance X`, `--n-lags N` (the recipe's), `--blend W` (the weight of each axis's
//! first-sensor one-sensor bias model averaged with the several-sensor one), `--multi-ridge
//! LO:HI` (the ridge strengths 10^LO..10^HI of the several-sensor fits and the selection),
//! `--multi-extra linear|temp|temp-fast|cubic|same` (the further sensors' terms; `same`:
//! the first sensor's basis), `--multi-first
//! single|combined|average` (the first sensor by its one-sensor score, by the score of the
//! model on every sensor with it first, or the bias model averaged over each sensor first),
//! `--select-folds N` (the folds of the sensor selection's cross-validation).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use gyrotherm::compensate::unit::{compensate_imu, imu_axis_compensators};
use gyrotherm::csvlog::{ImuLog, NamedSeries};
use gyrotherm::fit::unit::{fit_imu_with, ImuFitSettings, ImuSensors};
use gyrotherm::fit::{FitConfig, RecipeSettings};
use gyrotherm::metrics::bias_stability_dph;
use gyrotherm::metrics::scale_factor::{scale_factor, ScaleFactorOptions};
use gyrotherm::model::unit::ImuModel;
use gyrotherm::model::SubModel;
use gyrotherm::model::{Method, TempSensorDef};
use gyrotherm::sim::imu::{
    imu_from_family, simulate_imu, truth_col, ImuConfig, ImuUnit, AXIS_NAMES, CASE_SENSOR_COL,
};
use gyrotherm::sim::{Profile, SimConfig};
use gyrotherm::unit_model::{AxisCoverage, Model, NO_COVERAGE};
use gyrotherm_core::baseline::BaselineModel;
use gyrotherm_core::features::{FeatureKind, FeaturePipeline, FeatureSpec, MAX_FEATURES};

/// Per feature, lower and upper limits.
#[derive(Debug, Clone, Copy)]
struct FeatureBounds {
    lo: [f64; MAX_FEATURES],
    hi: [f64; MAX_FEATURES],
}

const TABLE_RATE_DPS: f64 = 20.0;
const TAU_S: f64 = 100.0;
const TEST_PROFILES: [&str; 2] = ["airborne", "shock-5"];
const SETTINGS: [&str; 6] = ["case", "chosen", "all", "all-auto", "all-lstm", "all-tlstm"];
const DEFAULT_SETTINGS: &str = "case,chosen,all";
const HOLDS: [&str; 14] = [
    "none",
    "all",
    "lags",
    "fast",
    "temp",
    "rate",
    "shrink",
    "shrink-fast",
    "shrink-x2",
    "shrink-x4",
    "k-lags",
    "k-fast",
    "k-shrink",
    "k-shrink-fast",
];
const DESIGN_BASE_SEED: u64 = 1000;
const CONFIRM_BASE_SEED: u64 = 5000;
/// The wide family: units drawn from `gyrotherm_experiments::wide_ranges`.
const WIDE_BASE_SEED: u64 = 7000;

fn sim(
    unit: &ImuUnit,
    profile: &str,
    seed: u64,
    table_axis: Option<usize>,
) -> Result<ImuLog, String> {
    sim_profile(
        unit,
        Profile::builtin(profile).map_err(|e| e.to_string())?,
        seed,
        table_axis,
    )
}

/// `seed-shock` with its soaks lengthened from 9,000 s to `hours` (`--soak-hours`, default
/// 6: 21,600 s, one and a half of the family's longest stress time constant; the run is then
/// 53,200 s), at the same 3 °C/min. Training data that holds each temperature long enough for
/// the coil's memory to settle, so that the slow lag is pinned by the data rather than traded
/// against the temperature polynomial (docs/experiments/imu-worst-case.md).
fn soak_profile(hours: f64) -> Profile {
    let soak = hours * 3600.0;
    let rows = [
        (3000.0, 22.0),
        (1240.0, -40.0),
        (soak, -40.0),
        (2000.0, 60.0),
        (soak, 60.0),
        (760.0, 22.0),
        (3000.0, 22.0),
    ];
    Profile {
        name: "soak-6h".to_owned(),
        start_c: 22.0,
        segments: rows
            .iter()
            .map(|&(duration_s, target_c)| gyrotherm::sim::Segment {
                duration_s,
                target_c,
            })
            .collect(),
    }
}

fn sim_profile(
    unit: &ImuUnit,
    profile: Profile,
    seed: u64,
    table_axis: Option<usize>,
) -> Result<ImuLog, String> {
    let mut run = SimConfig::new(profile);
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
    hold: String,
    axis: usize,
    profile: &'static str,
    x_floor: f64,
    sf_ppm: f64,
    fit_s: f64,
    temps: String,
    /// How far the static run leaves the training ranges.
    outside: Outside,
    /// `--sigma FILE`: the static run's 100 s windows ([`sigma_windows`]).
    windows: Vec<SigmaWindow>,
    /// Whether the axis's bias model holds an LSTM.
    lstm: bool,
}

/// One 100 s window of a held-out static run on one axis: its coverage (the worst sample's:
/// 0 inside, 1 edge, 2 outside), the mean compensated output (the residual bias, °/h: the true
/// rate is 0) and the mean σ the model gives there (°/h, as `compensate` writes it).
#[derive(Debug, Clone, Copy)]
struct SigmaWindow {
    coverage: u8,
    resid_dph: f64,
    sigma_dph: f64,
    /// The mean σ with the maps' growth per cell set to 0 and to 1.
    sigma_g0_dph: f64,
    sigma_g1_dph: f64,
}

/// The 100 s windows of an axis's compensated output `comp` on a static run, with the
/// verdicts `Model::coverage_log` gives that axis on the run (`cov`; a window with a sample
/// without a verdict gives none, so an axis without a map gives none).
fn sigma_windows(cov: &[&AxisCoverage; 3], comp: &[f64]) -> Vec<SigmaWindow> {
    let mut out = Vec::new();
    let mut w: Option<(u8, [f64; 4], usize)> = None;
    for (i, (out_dps, code)) in comp.iter().zip(&cov[0].codes).enumerate() {
        if *code == NO_COVERAGE {
            w = None;
            continue;
        }
        let x = w.get_or_insert((0, [0.0; 4], 0));
        x.0 = x.0.max(*code);
        x.1[0] += out_dps * 3600.0;
        for (sum, c) in x.1[1..].iter_mut().zip(cov) {
            *sum += c.sigma_dph[i];
        }
        x.2 += 1;
        if x.2 == 100 {
            let [r, s, s0, s1] = x.1.map(|v| v / 100.0);
            out.push(SigmaWindow {
                coverage: x.0,
                resid_dph: r,
                sigma_dph: s,
                sigma_g0_dph: s0,
                sigma_g1_dph: s1,
            });
            w = None;
        }
    }
    out
}

/// `model` with every map's growth per cell (each axis's and each fallback's) set to `growth`.
fn with_growth(model: &ImuModel, growth: f64) -> ImuModel {
    let mut m = model.clone();
    for a in &mut m.axes {
        for f in std::iter::once(&mut a.model).chain(a.fallback.as_mut()) {
            if let Some(c) = &mut f.coverage {
                *c = c.rescaled(1.0, growth);
            }
        }
    }
    m
}

struct Job<'a> {
    settings: &'a [String],
    min_gain: f64,
    /// Add a static run on the chamber profile `gyrotherm plan` proposes for the unit.
    planned: bool,
    /// `--train planned-soak`: the planned profile's first soak at each extreme sized from the
    /// training run's slowest identified lag, as `gyrotherm plan --train` sizes it.
    plan_soak: bool,
    /// Add a static run with soaks of `soak_h` hours at -40 and +60 °C ([`soak_profile`]).
    soak: bool,
    soak_h: f64,
    /// Input holds to apply each model with (see the module doc).
    holds: &'a [String],
    /// A hold other than `none` was asked for: apply every hold through the replica.
    replica: bool,
    /// `--dump DIR`: per-block bias error and simulator terms ([`dump_run`]).
    dump: Option<String>,
    /// Thermal-recipe overrides (experiment): longest lag searched, s; its bound as a
    /// fraction of the longest run; the bias basis.
    tau_max_s: Option<f64>,
    max_tau_fraction: Option<f64>,
    basis: Option<gyrotherm::fit::thermal::Basis>,
    /// Further overrides (experiment, docs/experiments/imu-worst-model.md): the recipe's
    /// folds, ridge tolerance, lag count; the unit's blend weight and several-sensor ridge
    /// decades.
    folds: Option<usize>,
    ridge_tolerance: Option<f64>,
    n_lags: Option<usize>,
    blend: Option<f64>,
    multi_ridge: Option<(i32, i32)>,
    multi_extra: Option<gyrotherm::fit::thermal::multi::ExtraTerms>,
    multi_first: Option<gyrotherm::fit::thermal::multi::FirstBy>,
    select_folds: Option<usize>,
    /// `auto`'s LSTM candidate: hidden units and Adam steps (None: the method's own).
    lstm_hidden: Option<usize>,
    lstm_steps: Option<usize>,
    /// `--sigma FILE`: collect the held-out static runs' σ windows.
    sigma: bool,
}

/// Per feature, the min and max a sensor's features reach over the training logs.
fn envelope(spec: &FeatureSpec, logs: &[&ImuLog], temp_col: &str) -> Result<FeatureBounds, String> {
    let mut b = FeatureBounds {
        lo: [f64::INFINITY; MAX_FEATURES],
        hi: [f64::NEG_INFINITY; MAX_FEATURES],
    };
    for log in logs {
        let t = &log
            .temp
            .iter()
            .find(|s| s.name == temp_col)
            .ok_or_else(|| format!("no temperature {temp_col}"))?
            .values;
        let mut p = FeaturePipeline::new(*spec).map_err(|e| e.to_string())?;
        for (&time, &temp) in log.time_s.iter().zip(t) {
            if let Ok(Some(step)) = p.push(time, temp) {
                for (i, &x) in step.features.as_slice().iter().enumerate() {
                    b.lo[i] = b.lo[i].min(x);
                    b.hi[i] = b.hi[i].max(x);
                }
            }
        }
    }
    Ok(b)
}

/// One sensor of an axis as the replica evaluates it: its pipeline, training envelope and
/// parts of B and K.
struct Part {
    col: usize,
    pipeline: FeaturePipeline,
    env: FeatureBounds,
    bias: Option<BaselineModel>,
    scale: Option<BaselineModel>,
}

/// Whether `hold` acts on feature kind `k`.
fn held_kind(hold: &str, k: Option<FeatureKind>) -> bool {
    matches!(
        (hold, k),
        ("all", _)
            | (
                "lags" | "shrink" | "shrink-x2" | "shrink-x4",
                Some(FeatureKind::LagDiff(_))
            )
            | ("fast" | "shrink-fast", Some(FeatureKind::LagDiff(0)))
            | ("temp", Some(FeatureKind::Temperature))
            | ("rate", Some(FeatureKind::Rate))
    )
}

/// The features of every sensor of an axis, transformed as `hold` says: `none` as they are;
/// `all`, `lags`, `fast`, `temp`, `rate` each chosen feature held at the edge of its training
/// range on its own; `shrink` (`shrink-fast`) every lag difference (the fastest one) of every
/// sensor scaled by one common factor s ≤ 1 toward 0 (the steady state, inside every
/// training range), the largest s that brings each of them within its range: the axis's
/// thermal state kept in its direction, so that differences between sensors keep their
/// sign and proportion, and held at the edge of what training saw; `shrink-x2`, `shrink-x4`:
/// `shrink` with each range widened 2 or 4 times about 0.
fn transform(parts: &[Part], feats: &mut [Vec<f64>], spec: &[FeatureSpec], hold: &str) {
    if hold == "none" {
        return;
    }
    if hold.starts_with("shrink") {
        let s = shrink_factor(parts, feats, spec, hold);
        if s < 1.0 {
            for (f, sp) in feats.iter_mut().zip(spec) {
                for (i, x) in f.iter_mut().enumerate() {
                    if held_kind(hold, sp.kind(i)) {
                        *x *= s;
                    }
                }
            }
        }
        return;
    }
    for ((p, f), sp) in parts.iter().zip(feats.iter_mut()).zip(spec) {
        for (i, x) in f.iter_mut().enumerate() {
            if held_kind(hold, sp.kind(i)) {
                *x = x.clamp(p.env.lo[i], p.env.hi[i]);
            }
        }
    }
}

/// The common factor of `shrink` holds (see [`transform`]); 1 inside every range.
fn shrink_factor(parts: &[Part], feats: &[Vec<f64>], spec: &[FeatureSpec], hold: &str) -> f64 {
    // `shrink-xN`: the ranges widened N times about 0 before the factor is found.
    let w = match hold {
        "shrink-x2" => 2.0,
        "shrink-x4" => 4.0,
        _ => 1.0,
    };
    let mut s = 1.0f64;
    for ((p, f), sp) in parts.iter().zip(feats).zip(spec) {
        for (i, &x) in f.iter().enumerate() {
            if held_kind(hold, sp.kind(i)) {
                let (lo, hi) = (w * p.env.lo[i].min(0.0), w * p.env.hi[i].max(0.0));
                if x > hi {
                    s = s.min(hi / x);
                } else if x < lo {
                    s = s.min(lo / x);
                }
            }
        }
    }
    s
}

/// How far a run leaves the training ranges of an axis's lag differences: the fraction of
/// steps outside them and the smallest `shrink` factor (1: never outside).
#[derive(Debug, Clone, Copy)]
struct Outside {
    frac: f64,
    min_s: f64,
}

/// A replica of `compensate_imu` for a log without sensor faults or time gaps (every sample
/// steps every pipeline), with each axis's features transformed as `hold` says
/// ([`transform`]) before its baselines read them: the compensated rate per axis. With
/// `none` it must equal `compensate_imu` bit for bit (checked by the caller).
fn compensate_held(
    model: &ImuModel,
    log: &ImuLog,
    envs: &[Vec<(FeatureSpec, FeatureBounds)>],
    hold: &str,
) -> Result<Vec<(Vec<f64>, Outside)>, String> {
    let comps = imu_axis_compensators(model).map_err(|e| e.to_string())?;
    let temps: Vec<&[f64]> = model
        .temp_cols
        .iter()
        .map(|t| {
            log.temp
                .iter()
                .find(|s| &s.name == t)
                .map(|s| s.values.as_slice())
                .ok_or_else(|| format!("no temperature {t}"))
        })
        .collect::<Result<_, _>>()?;
    let core = |sub: Option<&SubModel>| -> Result<Option<BaselineModel>, String> {
        match sub {
            None => Ok(None),
            Some(s) => match s.baseline_core() {
                Some(r) => r.map(Some).map_err(|e| e.to_string()),
                None => Err("the replica evaluates baselines only".into()),
            },
        }
    };
    let mut out = Vec::new();
    for ((a, comp), env) in model.axes.iter().zip(&comps).zip(envs) {
        let g = &log
            .gyro
            .iter()
            .find(|s| s.name == a.gyro)
            .ok_or("no gyro")?
            .values;
        let col = |t: &String| model.temp_cols.iter().position(|c| c == t).ok_or("column");
        let mut parts = vec![Part {
            col: col(&a.temps[0])?,
            pipeline: FeaturePipeline::new(*comp.first().spec()).map_err(|e| e.to_string())?,
            env: env[0].1,
            bias: core(a.model.bias.as_ref())?,
            scale: core(a.model.scale.as_ref())?,
        }];
        let first_scale_absent = a.model.scale.is_none();
        for ((t, (_, spec, bias, scale)), (_, e)) in
            a.temps.iter().skip(1).zip(comp.further()).zip(&env[1..])
        {
            parts.push(Part {
                col: col(t)?,
                pipeline: FeaturePipeline::new(*spec).map_err(|e| e.to_string())?,
                env: *e,
                bias: bias.copied(),
                scale: scale.copied(),
            });
        }
        let specs: Vec<FeatureSpec> = parts.iter().map(|p| *p.pipeline.spec()).collect();
        let mut held = (0.0, 1.0);
        let mut feats: Vec<Vec<f64>> = vec![Vec::new(); parts.len()];
        let mut kfeats: Vec<Vec<f64>> = Vec::new();
        let mut r = Vec::with_capacity(log.len());
        let (mut steps, mut outside, mut min_s) = (0usize, 0usize, 1.0f64);
        for i in 0..log.len() {
            let mut stepped = false;
            for (j, p) in parts.iter_mut().enumerate() {
                let step = p
                    .pipeline
                    .push(log.time_s[i], temps[p.col][i])
                    .map_err(|e| format!("sample {i}: {e}"))?;
                if j == 0 {
                    stepped = step.is_some();
                }
            }
            if stepped {
                for (f, p) in feats.iter_mut().zip(&parts) {
                    f.clear();
                    f.extend_from_slice(p.pipeline.current().ok_or("no step")?.as_slice());
                }
                let s = shrink_factor(&parts, &feats, &specs, "shrink");
                steps += 1;
                outside += usize::from(s < 1.0);
                min_s = min_s.min(s);
                // `k-<hold>`: the hold on the scale factor's inputs only.
                kfeats.clone_from(&feats);
                match hold.strip_prefix("k-") {
                    Some(h) => transform(&parts, &mut kfeats, &specs, h),
                    None => {
                        transform(&parts, &mut feats, &specs, hold);
                        kfeats.clone_from(&feats);
                    }
                }
                let ev = |m: &BaselineModel, f: &[f64]| m.eval(f).map_err(|e| e.to_string());
                let mut b = 0.0;
                if let Some(m) = &parts[0].bias {
                    b += ev(m, &feats[0])?;
                }
                let mut k = if first_scale_absent { 1.0 } else { 0.0 };
                if let Some(m) = &parts[0].scale {
                    k += ev(m, &kfeats[0])?;
                }
                for ((p, f), kf) in parts.iter().zip(&feats).zip(&kfeats).skip(1) {
                    if let Some(m) = &p.bias {
                        b += ev(m, f)?;
                    }
                    if let Some(m) = &p.scale {
                        k += ev(m, kf)?;
                    }
                }
                if k > 0.0 && b.is_finite() && k.is_finite() {
                    held = (b, k);
                }
            }
            r.push((g[i] - held.0) / held.1);
        }
        let frac = outside as f64 / steps.max(1) as f64;
        out.push((r, Outside { frac, min_s }));
    }
    Ok(out)
}

/// The flight's envelope as `gyrotherm plan` reads it: time and the case sensor.
fn case_log(log: &ImuLog) -> Result<gyrotherm::csvlog::TestLog, String> {
    let temp = log
        .temp
        .iter()
        .find(|s| s.name == CASE_SENSOR_COL)
        .ok_or("no case sensor")?;
    Ok(gyrotherm::csvlog::TestLog {
        time_s: log.time_s.clone(),
        gyro_dps: log.gyro[0].values.clone(),
        temp_c: temp.values.clone(),
        table_dps: None,
        extra: Vec::new(),
    })
}

/// `--dump DIR` (experiment, docs/experiments/imu-worst-case.md): for one static run with
/// truth, per axis, the 100 s means (the blocks `bias_stability_dph` takes) of the model's
/// bias error (estimate − true, °/h) and of each term of the simulator's bias computed from
/// the unit's parameters and the true node temperatures (°/h): the coil polynomial, the
/// Shupe term's linear part and its ΔT part, the stress term (stress state integrated from
/// the true coil temperature), the radial-gradient term (case rate by central difference),
/// the saturating term; `recon` is the true bias less their sum (a constant if the terms are
/// recomputed right). Also the coil rate, ΔT, and the axis's first sensor reading.
fn dump_run(
    dir: &str,
    tag: &str,
    unit_seed: u64,
    unit: &ImuUnit,
    model: &ImuModel,
    log: &ImuLog,
) -> Result<(), String> {
    let comp = compensate_imu(model, log).map_err(|e| e.to_string())?;
    let case = truth(log, gyrotherm::sim::CASE_TEMP_COL)?;
    let n = log.len();
    for (k, a) in AXIS_NAMES.iter().enumerate() {
        let g = &unit.gyros[k];
        let tb = truth(log, &truth_col(gyrotherm::csvlog::TRUE_BIAS_COL, a))?;
        let coil = truth(log, &truth_col(gyrotherm::sim::COIL_TEMP_COL, a))?;
        let first = &model.axes[k].temps[0];
        let sens = &log
            .temp
            .iter()
            .find(|s| &s.name == first)
            .ok_or("no sensor")?
            .values;
        let alpha = 1.0 - (-1.0 / g.stress_tau_s).exp();
        let mut stress_state = coil[0];
        const COLS: usize = 12;
        let mut rows: Vec<[f64; COLS]> = Vec::with_capacity(n);
        for i in 0..n {
            let dt = coil[i] - g.ref_temp_c;
            let r = (case[i] - coil[i]) / g.coil_tau_s;
            let case_rate = if i == 0 || i + 1 == n {
                0.0
            } else {
                (case[i + 1] - case[i - 1]) / (log.time_s[i + 1] - log.time_s[i - 1])
            };
            let poly = (g.bias_c1_dph_per_c
                + (g.bias_c2_dph_per_c2 + g.bias_c3_dph_per_c3 * dt) * dt)
                * dt;
            let shupe = g.shupe_dph_per_c_per_s * r;
            let shupe_tc = g.shupe_dph_per_c_per_s * g.shupe_tc_per_c * dt * r;
            let stress = g.stress_dph_per_c * (coil[i] - stress_state);
            let grad = g.shupe_grad_dph_per_c_per_s * (case_rate - r);
            let sat = g.rate_sat_dph * (r / g.rate_sat_c_per_s).tanh();
            let tb_dph = tb[i] * 3600.0;
            let e = (comp[k].bias_dps[i] - tb[i]) * 3600.0;
            let recon = tb_dph - (poly + shupe + shupe_tc + stress + grad + sat);
            rows.push([
                log.time_s[i],
                e,
                poly,
                shupe,
                shupe_tc,
                stress,
                grad,
                sat,
                recon,
                r,
                dt,
                sens[i],
            ]);
            // The stress state lags the coil, as `ThermalStep::advance` steps it.
            stress_state += (coil[i] - stress_state) * alpha;
        }
        let mut text = String::from(
            "t\te_dph\tpoly\tshupe\tshupe_tc\tstress\tgrad\tsat\trecon\tcoil_rate\tdT\tsensor\n",
        );
        let m = (TAU_S as usize).max(1);
        for block in rows.chunks_exact(m) {
            let mut mean = [0.0; COLS];
            for row in block {
                for (s, v) in mean.iter_mut().zip(row) {
                    *s += v / m as f64;
                }
            }
            let cells: Vec<String> = mean.iter().map(|v| format!("{v:.6e}")).collect();
            text.push_str(&cells.join("\t"));
            text.push('\n');
        }
        let path = format!("{dir}/{unit_seed}-{a}-{tag}.tsv");
        gyrotherm::atomic_file::write_bytes_atomically(
            std::path::Path::new(&path),
            text.as_bytes(),
        )
        .map_err(|e| format!("{path}: {e}"))?;

        // The sensors and lags the axis reads, for the record.
        let more: Vec<&Vec<f64>> = model.axes[k].more.iter().map(|m| &m.lags_s).collect();
        let info = format!(
            "temps {:?}\nfirst {:?}\nmore lags {:?}\ngyro {:?}\n",
            model.axes[k].temps, model.axes[k].model.features, more, unit.gyros[k]
        );
        let path = format!("{dir}/{unit_seed}-{a}-{tag}.model.txt");
        gyrotherm::atomic_file::write_bytes_atomically(
            std::path::Path::new(&path),
            info.as_bytes(),
        )
        .map_err(|e| format!("{path}: {e}"))?;
    }
    Ok(())
}

fn run_unit(unit_seed: u64, job: &Job) -> Result<Vec<Case>, String> {
    let settings = job.settings;
    let unit = if unit_seed >= WIDE_BASE_SEED {
        gyrotherm::sim::imu::imu_from_ranges(&gyrotherm_experiments::wide_ranges(), unit_seed)
    } else {
        imu_from_family(unit_seed)
    };
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
    if job.planned {
        // As in the single-axis benchmark: the flight input is an airborne run of this unit
        // with its own seed, never the held-out one; the profile depends on its envelope
        // and the chamber limits only.
        let flight = case_log(&sim(&unit, "airborne", s0 + 31, None)?)?;
        let env = gyrotherm::plan::envelope_of(&flight)
            .map_err(|e| format!("unit {unit_seed} plan: {e}"))?;
        let mut settings = gyrotherm::settings::plan::PlanSettings::default();
        if job.plan_soak {
            // As `gyrotherm plan --train` sizes the first soak at each extreme: from the
            // slowest lag a `thermal` fit of the training static run identifies (the x gyro
            // with the case sensor, a single gyro's log).
            let static_run = case_log(&train[0].1)?;
            let named = [gyrotherm::fit::NamedLog {
                name: "seed-shock-static",
                log: &static_run,
            }];
            if let Ok(c) = gyrotherm::plan::training_coverage(&named, None, &env)
                .map_err(|e| format!("unit {unit_seed} plan: {e}"))?
            {
                settings.slowest_lag_s = c.slowest_lag_s;
            }
        }
        let plan = gyrotherm::plan::propose(&env, &settings)
            .map_err(|e| format!("unit {unit_seed} plan: {e}"))?;
        train.push((
            "planned-static".to_owned(),
            sim_profile(&unit, plan.profile(), s0 + 41, None)?,
        ));
    }
    if job.soak {
        train.push((
            "soak-static".to_owned(),
            sim_profile(&unit, soak_profile(job.soak_h), s0 + 43, None)?,
        ));
    }
    let train_static_truth = job.dump.as_ref().map(|_| train[0].1.clone());
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
    cfg.recipe = RecipeSettings::of_kind(Method::Thermal);
    cfg.seed = 1;
    if let Some(t) = job.tau_max_s {
        cfg.thermal.tau_range_s.1 = t;
    }
    if let Some(f) = job.max_tau_fraction {
        cfg.thermal.max_tau_fraction = f;
    }
    if let Some(b) = job.basis {
        cfg.thermal.basis = b;
    }
    if let Some(f) = job.folds {
        cfg.thermal.folds = f;
    }
    if let Some(t) = job.ridge_tolerance {
        cfg.thermal.ridge_tolerance = t;
    }
    if let Some(n) = job.n_lags {
        cfg.thermal.n_lags = n;
    }
    let sensor = TempSensorDef::default();
    let one = ImuFitSettings {
        sensors: ImuSensors::ChooseOne,
        ..ImuFitSettings::default()
    };
    let mut all = ImuFitSettings {
        min_gain: job.min_gain,
        ..ImuFitSettings::default()
    };
    if let Some(w) = job.blend {
        all.blend = w;
    }
    if job.multi_ridge.is_some() {
        all.multi_ridge_decades = job.multi_ridge;
    }
    if let Some(e) = job.multi_extra {
        all.multi_extra = e;
    }
    if let Some(f) = job.multi_first {
        all.multi_first = f;
    }
    if let Some(f) = job.select_folds {
        all.multi_select_folds = f;
    }
    // `auto` (settings `all-auto`, `all-lstm`): the same thermal overrides, its own recipe.
    let mut auto_cfg = cfg.clone();
    auto_cfg.recipe = RecipeSettings::of_kind(Method::Auto);
    if let Some(h) = job.lstm_hidden {
        auto_cfg.recipe.hidden = h;
    }
    if let Some(e) = job.lstm_steps {
        auto_cfg.recipe.epochs = e;
    }
    // `thermal-lstm` by name (setting `all-tlstm`): the several-sensor fit with the residual
    // LSTM on it, at the same knobs.
    let mut tlstm_cfg = auto_cfg.clone();
    tlstm_cfg.recipe.kind = Method::ThermalLstm;
    let lstm_kept = ImuFitSettings {
        auto_keep: Some(Method::ThermalLstm),
        ..all
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
            "all-auto" => fit_imu_with(&train, &auto_cfg, &all, &sensor, &|_, _, _, _, _| {}),
            "all-lstm" => fit_imu_with(&train, &auto_cfg, &lstm_kept, &sensor, &|_, _, _, _, _| {}),
            "all-tlstm" => fit_imu_with(&train, &tlstm_cfg, &all, &sensor, &|_, _, _, _, _| {}),
            _ => fit_imu_with(&train, &cfg, &all, &sensor, &|_, _, _, _, _| {}),
        }
        .map_err(|e| {
            format!(
                "unit {unit_seed} {setting}: {e}: {:?}",
                std::error::Error::source(&e).map(|s| s.to_string())
            )
        })?;
        let fit_s = t0.elapsed().as_secs_f64();
        if let (Some(dir), "all") = (&job.dump, setting.as_str()) {
            if let Some(l) = &train_static_truth {
                dump_run(dir, "seed-shock", unit_seed, &unit, &model, l)?;
            }
            for (profile, st, _, _) in &tests {
                dump_run(dir, profile, unit_seed, &unit, &model, st)?;
            }
        }
        // Each axis's training envelope, per sensor it reads (first sensor first).
        let train_logs: Vec<&ImuLog> = train.iter().map(|(_, l)| l).collect();
        let comps = imu_axis_compensators(&model).map_err(|e| e.to_string())?;
        let mut envs = Vec::new();
        for (a, comp) in model.axes.iter().zip(&comps).filter(|_| job.replica) {
            let mut specs = vec![*comp.first().spec()];
            specs.extend(comp.further().into_iter().map(|(_, s, _, _)| *s));
            envs.push(
                specs
                    .iter()
                    .zip(&a.temps)
                    .map(|(s, t)| envelope(s, &train_logs, t).map(|e| (*s, e)))
                    .collect::<Result<Vec<_>, _>>()?,
            );
        }
        for hold in job.holds {
            // Without a hold asked for, compensate_imu itself (the recorded runs unchanged);
            // with one, the replica for every hold, checked against compensate_imu.
            let apply = |log: &ImuLog| -> Result<Vec<(Vec<f64>, Outside)>, String> {
                if job.replica {
                    return compensate_held(&model, log, &envs, hold);
                }
                let unknown = Outside {
                    frac: f64::NAN,
                    min_s: f64::NAN,
                };
                Ok(compensate_imu(&model, log)
                    .map_err(|e| e.to_string())?
                    .into_iter()
                    .map(|c| (c.gyro_comp_dps, unknown))
                    .collect())
            };
            for (profile, st, tabs, floors) in &tests {
                let cs = apply(st)?;
                let coverage = if job.sigma && hold == "none" {
                    let log = |m: ImuModel| {
                        Model::from_unit(m)
                            .coverage_log(st)
                            .map(|c| c.0)
                            .map_err(|e| e.to_string())
                    };
                    vec![
                        log(model.clone())?,
                        log(with_growth(&model, 0.0))?,
                        log(with_growth(&model, 1.0))?,
                    ]
                } else {
                    Vec::new()
                };
                if job.replica && hold == "none" {
                    // The replica must be compensate_imu exactly.
                    let reference = compensate_imu(&model, st).map_err(|e| e.to_string())?;
                    for ((c, _), r) in cs.iter().zip(&reference) {
                        if c.iter()
                            .map(|x| x.to_bits())
                            .ne(r.gyro_comp_dps.iter().map(|x| x.to_bits()))
                        {
                            return Err(format!("unit {unit_seed}: held replica differs"));
                        }
                    }
                }
                for (k, axis) in model.axes.iter().enumerate() {
                    let b = bias_stability_dph(&cs[k].0, 1.0, TAU_S)
                        .map_err(|e| e.to_string())?
                        .bias_stability_dph;
                    let tab = &tabs[k];
                    let ct = apply(tab)?;
                    let rep = scale_factor(
                        &tab.time_s,
                        &ct[k].0,
                        &tab.table.as_ref().ok_or("no table")?.values,
                        &ScaleFactorOptions::default(),
                    )
                    .map_err(|e| e.to_string())?;
                    out.push(Case {
                        unit_seed,
                        setting: setting.clone(),
                        hold: hold.clone(),
                        axis: k,
                        profile,
                        x_floor: b / floors[k],
                        sf_ppm: rep.sf_thermal_error_ppm,
                        fit_s,
                        temps: match &axis.model.method_choice {
                            None => axis.temps.join("+"),
                            Some(c) => format!(
                                "{} {}={}",
                                axis.temps.join("+"),
                                c.chosen,
                                c.candidates
                                    .iter()
                                    .map(|s| format!("{}:{:.5}", s.method, s.bias_rms_dps * 3600.0))
                                    .collect::<Vec<_>>()
                                    .join(",")
                            ),
                        },
                        outside: cs[k].1,
                        lstm: axis.model.bias.as_ref().is_some_and(|b| b.lstm().is_some()),
                        windows: match coverage.as_slice() {
                            [a, b, c] => match (a.get(k), b.get(k), c.get(k)) {
                                (Some(a), Some(b), Some(c)) => sigma_windows(&[a, b, c], &cs[k].0),
                                _ => Vec::new(),
                            },
                            _ => Vec::new(),
                        },
                    });
                }
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
        "wide" => WIDE_BASE_SEED,
        f => return Err(format!("--family {f:?}: use design, confirm or wide")),
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
    let plan_soak = get("--train").as_deref() == Some("planned-soak");
    let (planned, soak) = match get("--train").as_deref() {
        None | Some("seed-shock") => (false, false),
        Some("planned") | Some("planned-soak") => (true, false),
        Some("soak") => (false, true),
        Some(v) => {
            return Err(format!(
                "--train {v:?}: use seed-shock, planned, planned-soak or soak"
            ))
        }
    };
    let holds: Vec<String> = get("--hold")
        .unwrap_or_else(|| "none".into())
        .split(',')
        .map(str::to_owned)
        .collect();
    if let Some(h) = holds.iter().find(|h| !HOLDS.contains(&h.as_str())) {
        return Err(format!("--hold: unknown {h:?}; use {}", HOLDS.join(", ")));
    }
    let job = Job {
        settings: &settings,
        min_gain,
        planned,
        plan_soak,
        soak,
        soak_h: get("--soak-hours").map_or(Ok(6.0), |v| {
            v.parse().map_err(|e| format!("--soak-hours: {e}"))
        })?,
        holds: &holds,
        replica: holds.iter().any(|h| h != "none"),
        dump: get("--dump"),
        tau_max_s: get("--tau-max")
            .map(|v| v.parse().map_err(|e| format!("--tau-max: {e}")))
            .transpose()?,
        max_tau_fraction: get("--max-tau-fraction")
            .map(|v| v.parse().map_err(|e| format!("--max-tau-fraction: {e}")))
            .transpose()?,
        basis: match get("--basis").as_deref() {
            None => None,
            Some("lean") => Some(gyrotherm::fit::thermal::Basis::Lean),
            Some("linear") => Some(gyrotherm::fit::thermal::Basis::Linear),
            Some("small") => Some(gyrotherm::fit::thermal::Basis::Small),
            Some("full") => Some(gyrotherm::fit::thermal::Basis::Full),
            Some("minimal") => Some(gyrotherm::fit::thermal::Basis::Minimal),
            Some(v) => {
                return Err(format!(
                    "--basis {v:?}: use minimal, lean, linear, small or full"
                ))
            }
        },
        folds: get("--folds")
            .map(|v| v.parse().map_err(|e| format!("--folds: {e}")))
            .transpose()?,
        ridge_tolerance: get("--ridge-tolerance")
            .map(|v| v.parse().map_err(|e| format!("--ridge-tolerance: {e}")))
            .transpose()?,
        n_lags: get("--n-lags")
            .map(|v| v.parse().map_err(|e| format!("--n-lags: {e}")))
            .transpose()?,
        blend: get("--blend")
            .map(|v| v.parse().map_err(|e| format!("--blend: {e}")))
            .transpose()?,
        multi_extra: match get("--multi-extra").as_deref() {
            None => None,
            Some("linear") => Some(gyrotherm::fit::thermal::multi::ExtraTerms::Linear),
            Some("temp") => Some(gyrotherm::fit::thermal::multi::ExtraTerms::Temp),
            Some("temp-fast") => Some(gyrotherm::fit::thermal::multi::ExtraTerms::TempFast),
            Some("cubic") => Some(gyrotherm::fit::thermal::multi::ExtraTerms::Cubic),
            Some("same") => Some(gyrotherm::fit::thermal::multi::ExtraTerms::Same),
            Some(v) => {
                return Err(format!(
                    "--multi-extra {v:?}: use linear, temp, temp-fast, cubic or same"
                ))
            }
        },
        multi_first: match get("--multi-first").as_deref() {
            None => None,
            Some("single") => Some(gyrotherm::fit::thermal::multi::FirstBy::Single),
            Some("combined") => Some(gyrotherm::fit::thermal::multi::FirstBy::Combined),
            Some("average") => Some(gyrotherm::fit::thermal::multi::FirstBy::Average),
            Some(v) => {
                return Err(format!(
                    "--multi-first {v:?}: use single, combined or average"
                ))
            }
        },
        lstm_hidden: get("--lstm-hidden")
            .map(|v| v.parse().map_err(|e| format!("--lstm-hidden: {e}")))
            .transpose()?,
        lstm_steps: get("--lstm-steps")
            .map(|v| v.parse().map_err(|e| format!("--lstm-steps: {e}")))
            .transpose()?,
        sigma: get("--sigma").is_some(),
        select_folds: get("--select-folds")
            .map(|v| v.parse().map_err(|e| format!("--select-folds: {e}")))
            .transpose()?,
        multi_ridge: get("--multi-ridge")
            .map(|v| {
                let (a, b) = v
                    .split_once(':')
                    .ok_or_else(|| format!("--multi-ridge {v:?}: give LO:HI (powers of ten)"))?;
                Ok::<_, String>((
                    a.parse().map_err(|e| format!("--multi-ridge: {e}"))?,
                    b.parse().map_err(|e| format!("--multi-ridge: {e}"))?,
                ))
            })
            .transpose()?,
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
        (a.unit_seed, &a.setting, &a.hold, a.profile, a.axis).cmp(&(
            b.unit_seed,
            &b.setting,
            &b.hold,
            b.profile,
            b.axis,
        ))
    });
    if let Some(path) = get("--cases") {
        // The hold column only when a hold was asked for (the recorded files keep their form).
        let with_hold = job.replica;
        let mut text = String::from(if with_hold {
            "unit_seed\tsetting\thold\taxis\tprofile\tx_floor\tsf_ppm\tfit_s\ttemps\tout_frac\tmin_s\n"
        } else {
            "unit_seed\tsetting\taxis\tprofile\tx_floor\tsf_ppm\tfit_s\ttemps\n"
        });
        for c in &cases {
            let setting = if with_hold {
                format!("{}\t{}", c.setting, c.hold)
            } else {
                c.setting.clone()
            };
            text.push_str(&format!(
                "{}\t{}\t{}\t{}\t{:.4}\t{:.3}\t{:.2}\t{}\n",
                c.unit_seed,
                setting,
                AXIS_NAMES[c.axis],
                c.profile,
                c.x_floor,
                c.sf_ppm,
                c.fit_s,
                c.temps
            ));
            if with_hold {
                text.pop();
                text.push_str(&format!(
                    "\t{:.4}\t{:.4}\n",
                    c.outside.frac, c.outside.min_s
                ));
            }
        }
        gyrotherm::atomic_file::write_bytes_atomically(
            std::path::Path::new(&path),
            text.as_bytes(),
        )
        .map_err(|e| format!("{path}: {e}"))?;
    }
    if let Some(path) = get("--sigma") {
        // One line per 100 s window of each held-out static run and axis.
        let mut text = String::from(
            "unit_seed\tsetting\taxis\tprofile\tsensors\tlstm\tcoverage\tresid_dph\tsigma_dph\t\
             sigma_g0_dph\tsigma_g1_dph\n",
        );
        for c in &cases {
            let sensors = c.temps.split(' ').next().unwrap_or("").split('+').count();
            for w in &c.windows {
                text.push_str(&format!(
                    "{}\t{}\t{}\t{}\t{}\t{}\t{}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\n",
                    c.unit_seed,
                    c.setting,
                    AXIS_NAMES[c.axis],
                    c.profile,
                    sensors,
                    u8::from(c.lstm),
                    w.coverage,
                    w.resid_dph,
                    w.sigma_dph,
                    w.sigma_g0_dph,
                    w.sigma_g1_dph
                ));
            }
        }
        gyrotherm::atomic_file::write_bytes_atomically(
            std::path::Path::new(&path),
            text.as_bytes(),
        )
        .map_err(|e| format!("{path}: {e}"))?;
    }
    println!();
    println!(
        "{family} family ({} units × 3 axes), trained on seed-shock static + one table run per axis{}",
        seeds.len(),
        if planned {
            " + a static run on the planned profile"
        } else if soak {
            " + a static run with long soaks at -40 and +60 °C (--soak-hours)"
        } else {
            ""
        }
    );
    // The hold column only when a hold was asked for (the recorded tables keep their form).
    let hold_head = if job.replica { " hold |" } else { "" };
    println!("| setting |{hold_head} profile | ×floor median | ×floor worst | SF ppm median | SF ppm worst | fit s per unit |");
    println!(
        "|---|---|---|---|---|---|---|{}",
        if job.replica { "---|" } else { "" }
    );
    for setting in &settings {
        for hold in &holds {
            for profile in TEST_PROFILES.iter().map(Some).chain([None]) {
                let mine: Vec<&Case> = cases
                    .iter()
                    .filter(|c| {
                        &c.setting == setting
                            && &c.hold == hold
                            && profile.is_none_or(|p| c.profile == *p)
                    })
                    .collect();
                if mine.is_empty() {
                    continue;
                }
                let mut x: Vec<f64> = mine.iter().map(|c| c.x_floor).collect();
                let mut sf: Vec<f64> = mine.iter().map(|c| c.sf_ppm).collect();
                let fit_s = mine.iter().map(|c| c.fit_s).sum::<f64>() / mine.len() as f64;
                let hold_cell = if job.replica {
                    format!(" {hold} |")
                } else {
                    String::new()
                };
                println!(
                    "| {setting} |{hold_cell} {} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} |",
                    profile.copied().unwrap_or("both"),
                    median(&mut x),
                    worst(&x),
                    median(&mut sf),
                    worst(&sf),
                    fit_s
                );
            }
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

//! The thermal-state recipe: thermal time constants identified from the training data, and a
//! ridge fit whose strength is chosen by blocked cross-validation in time.
//!
//! A gyro's bias and scale factor follow the temperatures of nodes the log does not see (the
//! coil, a mounting plate, a slow stress state); with one sensor they are first-order lags of
//! the logged temperature (a chain of lags is a sum of parallel ones with the same time
//! constants). Fixed lags of 300, 1000 and 3000 s fit the units they were chosen on; here the
//! lags are identified by **variable projection** (Golub & Pereyra 1973, SIAM J. Numer. Anal.
//! 10(2), DOI 10.1137/0710036): for given time constants the model is linear in its
//! coefficients, which are projected out by (ridge) least squares, leaving a search over the
//! time constants alone — a grid over triples in log τ, then a coordinate search refining the
//! best. Each candidate is scored by blocked cross-validation (each run cut into contiguous
//! folds, a gap either side of the left-out one, the residual's per-run mean removed: Roberts
//! et al. 2017, DOI 10.1111/ecog.02881), so a lag that only fits the noise does not win.
//!
//! The terms are one generous polynomial over `x = (T, dT, D1, D2, D3)`, `Dj = T - lag_τj(T)`
//! ([`basis`]), not a subset picked by name; **ridge** regression (Hoerl & Kennard 1970,
//! Technometrics 12(1)) on RMS-scaled, per-run-centred columns keeps the redundant ones small,
//! its strength chosen from `ThermalConfig::ridge_grid` by the same cross-validation. Each
//! training run keeps its own offset (turn-on repeatability); the model keeps their mean. The
//! result is a least-squares sub-model the flight compensator evaluates as it is (no LSTM).
//!
//! Short or coarse logs (80 minutes at one sample per 15 s, one heating ramp): the recipe
//! degrades rather than refuse — fewer folds, lags bounded by the run length, fewer lags,
//! fewer terms, a fixed ridge strength without cross-validation — and says each step in
//! [`ThermalReport::notes`]. It refuses only data no method could fit (fewer labelled steps
//! than a linear fit needs, a constant temperature).

use std::fmt;

use nalgebra::{DMatrix, DVector};

use crate::baseline::Terms;
use crate::csvlog::TestLog;
use crate::features::{extract_series, FeatureSpec, FeatureTable, LagOutputs};
use crate::model::SubModel;
use crate::targets::{self, TargetSet};

mod allowance;
mod config;
pub mod multi;
mod ridge;
mod search;

use allowance::*;
// The recipe's settings are experiment knobs: public only with the `experiments` feature.
#[cfg(feature = "experiments")]
pub use config::ThermalConfig;
#[cfg(not(feature = "experiments"))]
pub(crate) use config::ThermalConfig;
use ridge::*;

/// The term sets of the recipe (over `T, dT, D1..Dn`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// `1, T, T², T³, Dj, T·Dj (j ≤ 2), D1², D1·D2, D2², D1³`.
    Full,
    /// `1, T, T², T³, Dj, T·D1, D1²` (fewer second-order terms).
    Small,
    /// `1, T, T², T³, Dj, T·Dj`: a cubic in T, every lag difference linear with a
    /// temperature-dependent slope; nothing of higher order in the lag differences, so a
    /// faster temperature change than in training extrapolates linearly.
    Linear,
    /// `1, T, T², T³, Dj, T·D1`: as `Linear`, the temperature-dependent slope on the fastest
    /// lag only (the Shupe term's temperature coefficient).
    Lean,
    /// `1, T, T², Dj` (short runs).
    Minimal,
}

impl Basis {
    /// Name as in the benchmark and the report.
    pub fn name(&self) -> &'static str {
        match self {
            Basis::Full => "full",
            Basis::Small => "small",
            Basis::Linear => "linear",
            Basis::Lean => "lean",
            Basis::Minimal => "minimal",
        }
    }
}

/// Monomial powers over `n` features from (feature, power) pairs.
fn term(n: usize, parts: &[(usize, u8)]) -> Vec<u8> {
    let mut p = vec![0u8; n];
    for &(i, q) in parts {
        p[i] += q;
    }
    p
}

/// The terms over `x = (T, dT, D1, …, D_lags)` (feature 0 is T, 1 is dT, 2.. the lag
/// differences, fastest lag first). The 20 s rate dT is no term: the fastest lag difference
/// carries the rate, smoothed, where dT carries the sensor's 0.0625 °C steps.
pub fn basis(kind: Basis, lags: usize) -> Terms {
    let n = 2 + lags;
    let d = |j: usize| 2 + j;
    let mut p = vec![term(n, &[]), term(n, &[(0, 1)]), term(n, &[(0, 2)])];
    if kind != Basis::Minimal {
        p.push(term(n, &[(0, 3)]));
    }
    for j in 0..lags {
        p.push(term(n, &[(d(j), 1)]));
    }
    match kind {
        Basis::Minimal => {}
        Basis::Lean => {
            if lags >= 1 {
                p.push(term(n, &[(0, 1), (d(0), 1)]));
            }
        }
        Basis::Linear => {
            for j in 0..lags {
                p.push(term(n, &[(0, 1), (d(j), 1)]));
            }
        }
        Basis::Small => {
            if lags >= 1 {
                p.push(term(n, &[(0, 1), (d(0), 1)]));
                p.push(term(n, &[(d(0), 2)]));
            }
        }
        Basis::Full => {
            for j in 0..lags.min(2) {
                p.push(term(n, &[(0, 1), (d(j), 1)]));
            }
            if lags >= 1 {
                p.push(term(n, &[(d(0), 2)]));
            }
            if lags >= 2 {
                p.push(term(n, &[(d(0), 1), (d(1), 1)]));
                p.push(term(n, &[(d(1), 2)]));
            }
            if lags >= 1 {
                p.push(term(n, &[(d(0), 3)]));
            }
        }
    }
    Terms {
        n_features: n,
        powers: p,
    }
}

/// Why the recipe could not fit.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ThermalError {
    /// No static and no rate-table run gave labelled steps.
    NoTargets,
    /// The targets of run `run` could not be computed.
    Targets { run: String, message: String },
    /// Fewer labelled steps than even a linear fit with per-run offsets needs.
    TooFewSteps { steps: usize, needed: usize },
    /// The logged temperature does not vary in the training runs.
    ConstantTemperature,
    /// The feature pipeline refused the identified spec (a bug if it happens).
    Features(String),
    /// The least-squares system could not be solved.
    Singular,
}

impl fmt::Display for ThermalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThermalError::NoTargets => write!(
                f,
                "no training run has labelled steps: give a static run (bias) or a rate-table \
                 run with stop segments between the rates (scale factor)"
            ),
            ThermalError::Targets { run, message } => write!(f, "{run}: {message}"),
            ThermalError::TooFewSteps { steps, needed } => write!(
                f,
                "{steps} labelled steps, fewer than the {needed} a linear fit needs: log longer \
                 runs (at least a temperature ramp and a soak)"
            ),
            ThermalError::ConstantTemperature => write!(
                f,
                "the temperature does not vary in the training runs: no thermal model can be \
                 fitted; log a run through a temperature change"
            ),
            ThermalError::Features(m) => write!(f, "features: {m}"),
            ThermalError::Singular => write!(
                f,
                "the least-squares system is singular even with the ridge penalty: the runs \
                 carry too little variation"
            ),
        }
    }
}

impl std::error::Error for ThermalError {}

/// What the recipe identified and how, for the user and the model's record.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ThermalReport {
    /// Identified time constants, s, fastest first.
    pub lags_s: Vec<f64>,
    /// Which target identified them (`bias`, `scale factor`, or both).
    pub identified_on: String,
    /// Cross-validated RMS residual at the identified lags, target units (None without
    /// cross-validation).
    pub cv_rms: Option<f64>,
    /// Candidate lag sets scored.
    pub candidates: usize,
    /// Ridge strength chosen for this target.
    pub ridge: f64,
    /// Folds of the cross-validation (0: none).
    pub folds: usize,
    /// Terms of this target's fit.
    pub basis: String,
    /// Each degradation taken, in words (empty: none).
    pub notes: Vec<String>,
}

impl ThermalReport {
    /// One paragraph for the user: the lags, how they and the ridge strength were chosen, and
    /// every degradation taken.
    pub fn describe(&self) -> String {
        let lags: Vec<String> = self.lags_s.iter().map(|t| format!("{t:.0}")).collect();
        let mut out = format!(
            "thermal lags {} s identified on the {} ({} candidates); terms `{}`, ridge \
             strength {:.0e} ",
            lags.join(", "),
            self.identified_on,
            self.candidates,
            self.basis,
            self.ridge
        );
        match (self.folds, self.cv_rms) {
            (0, _) => out.push_str("(fixed: no cross-validation)"),
            (f, Some(rms)) => out.push_str(&format!(
                "by {f}-fold time-segment cross-validation (RMS {rms:.3e})"
            )),
            (f, None) => out.push_str(&format!("by {f}-fold time-segment cross-validation")),
        }
        for n in &self.notes {
            out.push_str("; ");
            out.push_str(n);
        }
        out
    }
}

/// The identification: the feature spec the model reads, and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct Identified {
    pub spec: FeatureSpec,
    pub report: ThermalReport,
    /// The basis and folds the data allow (used for both targets).
    pub basis: Basis,
    pub folds: usize,
    pub gap_steps: usize,
}

/// One run's labelled steps for the search: temperature and time per step, target, mask.
struct RunData<'a> {
    log: &'a TestLog,
    target: Vec<f64>,
    mask: Vec<bool>,
    /// The run's features without lags (the search's temperature steps), when made ahead.
    base: Option<&'a FeatureTable>,
}

/// Per-run design matrices (labelled rows only) for given lags and a term set.
struct Design {
    /// Row-major, `terms.len() - 1` columns (no constant), per run.
    x: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    /// Row index (step) of each labelled row, per run (for the folds).
    step: Vec<Vec<usize>>,
    /// Steps per run (for the fold boundaries).
    n_steps: Vec<usize>,
}

fn spec_with(lags: &[f64]) -> Result<FeatureSpec, ThermalError> {
    FeatureSpec::THERMAL_STATE
        .with_lags(lags, LagOutputs::DiffFromT)
        .map_err(|e| ThermalError::Features(e.to_string()))
}

fn design(runs: &[RunData], lags: &[f64], terms: &Terms) -> Result<Design, ThermalError> {
    let spec = spec_with(lags)?;
    let nc = terms.len() - 1;
    let mut d = Design {
        x: Vec::new(),
        y: Vec::new(),
        step: Vec::new(),
        n_steps: Vec::new(),
    };
    let sparse = terms.sparse();
    for r in runs {
        let table = extract_series(&r.log.time_s, &r.log.temp_c, &spec)
            .map_err(|e| ThermalError::Features(e.to_string()))?;
        let n = table.n_rows().min(r.mask.len());
        // Sized ahead: a design grown row by row copies itself over and over.
        let rows = r.mask[..n].iter().filter(|&&m| m).count();
        let mut x = Vec::with_capacity(rows * nc);
        let mut y = Vec::with_capacity(rows);
        let mut step = Vec::with_capacity(rows);
        for k in 0..n {
            if r.mask[k] {
                sparse.extend_design_row(table.row(k), 1, &mut x);
                debug_assert_eq!(x.len() % nc.max(1), 0);
                y.push(r.target[k]);
                step.push(k);
            }
        }
        d.x.push(x);
        d.y.push(y);
        d.step.push(step);
        d.n_steps.push(table.n_rows());
    }
    Ok(d)
}

fn run_data<'a>(
    logs: &[(&'a str, &'a TestLog)],
    bias: bool,
    bias_window_s: f64,
    settle_s: f64,
    scale_window_s: f64,
) -> Result<Vec<RunData<'a>>, ThermalError> {
    let spec = FeatureSpec::PUBLISHED;
    let mut out = Vec::new();
    for (name, log) in logs {
        if targets::is_static(log) != bias {
            continue;
        }
        let t = if bias {
            targets::bias_targets(log, &spec, bias_window_s)
        } else {
            targets::scale_targets(log, &spec, settle_s, scale_window_s)
        }
        .map_err(|message| ThermalError::Targets {
            run: (*name).to_owned(),
            message: message.to_string(),
        })?;
        if t.labelled() > 0 {
            out.push(RunData {
                log,
                target: t.target,
                mask: t.mask,
                base: None,
            });
        }
    }
    Ok(out)
}

/// Identify the lags from the training logs (the static runs' bias, or without static runs
/// the rate-table runs' scale factor) and return the feature spec the model will read.
pub(crate) fn identify(
    logs: &[(&str, &TestLog)],
    cfg: &ThermalConfig,
    bias_window_s: f64,
    settle_s: f64,
    scale_window_s: f64,
) -> Result<Identified, ThermalError> {
    identify_every(logs, cfg, bias_window_s, settle_s, scale_window_s, 1)
}

/// [`identify`] with the lag search's statistics kept on every `every`-th labelled step (1:
/// every step, as [`identify`]); the allowance (basis, folds) still comes from every step,
/// the returned score and ridge strength from the thinned search (the final fits choose
/// their own on every step). An inertial unit's fit searches this way
/// ([`crate::settings::fit::IMU_IDENTIFY_EVERY`]).
pub(crate) fn identify_every(
    logs: &[(&str, &TestLog)],
    cfg: &ThermalConfig,
    bias_window_s: f64,
    settle_s: f64,
    scale_window_s: f64,
    every: usize,
) -> Result<Identified, ThermalError> {
    let bias_runs = run_data(logs, true, bias_window_s, settle_s, scale_window_s)?;
    let scale_runs = run_data(logs, false, bias_window_s, settle_s, scale_window_s)?;
    identify_runs(bias_runs, scale_runs, cfg, every)
}

/// What [`identify_shared`] takes of one run made ahead: the per-sample targets of its gyro
/// column, and the features of its temperature column at the published spec and without
/// lags (the same for every gyro column that reads this temperature column).
pub(crate) struct Prepared<'a> {
    pub samples: &'a targets::GyroSamples,
    pub published: &'a FeatureTable,
    pub base: &'a FeatureTable,
}

/// The features [`identify_shared`] takes of a temperature column, in its order (published
/// spec, no lags); None when either cannot be made ([`identify_every`] then reports why).
pub(crate) fn shared_tables(
    time_s: &[f64],
    temp_c: &[f64],
) -> Option<(FeatureTable, FeatureTable)> {
    Some((
        extract_series(time_s, temp_c, &FeatureSpec::PUBLISHED).ok()?,
        extract_series(time_s, temp_c, &search::base_spec().ok()?).ok()?,
    ))
}

/// [`identify_every`] with each run's targets and temperature features made ahead
/// (`prepared`, one per log, all made without error): the same result.
pub(crate) fn identify_shared(
    logs: &[(&str, &TestLog)],
    prepared: &[Prepared<'_>],
    cfg: &ThermalConfig,
    every: usize,
) -> Result<Identified, ThermalError> {
    let runs = |bias: bool| {
        let mut out = Vec::new();
        for ((_, log), p) in logs.iter().zip(prepared) {
            if targets::is_static(log) != bias {
                continue;
            }
            let (target, mask) = p.samples.pick(&p.published.sample_index);
            if mask.iter().any(|m| *m) {
                out.push(RunData {
                    log,
                    target,
                    mask,
                    base: Some(p.base),
                });
            }
        }
        out
    };
    identify_runs(runs(true), runs(false), cfg, every)
}

fn identify_runs(
    bias_runs: Vec<RunData<'_>>,
    scale_runs: Vec<RunData<'_>>,
    cfg: &ThermalConfig,
    every: usize,
) -> Result<Identified, ThermalError> {
    let (runs, on) = if bias_runs.is_empty() {
        (&scale_runs, "scale factor")
    } else {
        (&bias_runs, "bias")
    };
    if runs.is_empty() {
        return Err(ThermalError::NoTargets);
    }
    let al = allowance(runs, cfg)?;
    // The scale factor joins the identification when it can be cross-validated too.
    let joint = (cfg.joint && !bias_runs.is_empty() && !scale_runs.is_empty())
        .then(|| allowance(&scale_runs, cfg).ok())
        .flatten()
        .filter(|a| a.folds > 0 && al.folds > 0);
    let on = if joint.is_some() {
        "bias and scale factor"
    } else {
        on
    };
    let tau_min = cfg.tau_range_s.0.max(
        3.0 * runs
            .iter()
            .map(|r| r.log.sample_period_s())
            .fold(0.0f64, f64::max),
    );
    let terms = basis(al.basis, al.n_lags);
    let nc = terms.len() - 1;
    let scale_terms = basis(cfg.scale_basis, al.n_lags);
    let lambdas: Vec<f64> = if al.folds == 0 {
        vec![cfg.fallback_ridge]
    } else {
        cfg.ridge_grid.clone()
    };
    // Each target's score relative to its own spread, so that the two can be added.
    let spread = |rs: &[RunData]| {
        let (mut ss, mut n) = (0.0, 0usize);
        for r in rs {
            let v: Vec<f64> = r
                .target
                .iter()
                .zip(&r.mask)
                .filter(|(t, m)| **m && t.is_finite())
                .map(|(t, _)| *t)
                .collect();
            if v.is_empty() {
                continue;
            }
            let m = v.iter().sum::<f64>() / v.len() as f64;
            ss += v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
            n += v.len();
        }
        (ss / n.max(1) as f64).sqrt().max(f64::MIN_POSITIVE)
    };
    let (ref_main, ref_scale) = (spread(runs), spread(&scale_runs));
    let g = cfg.tau_grid.max(al.n_lags + 1);
    let (lo, hi) = (tau_min.ln(), al.tau_max_s.max(tau_min * 1.01).ln());
    let grid: Vec<f64> = (0..g)
        .map(|i| (lo + (hi - lo) * i as f64 / (g - 1) as f64).exp())
        .collect();
    // The candidates' scores from statistics kept between them (`search`); a term set the
    // scorer does not take is scored from its design.
    let mut main_scorer = match al.folds {
        0 => None,
        _ => search::Scorer::new(runs, &terms, al.folds, al.gap_steps, every)?,
    };
    let mut scale_scorer = match &joint {
        Some(ak) => search::Scorer::new(&scale_runs, &scale_terms, ak.folds, ak.gap_steps, every)?,
        None => None,
    };
    for sc in [&mut main_scorer, &mut scale_scorer].into_iter().flatten() {
        sc.make_lags(&grid)?;
    }
    let mut score = |lags: &[f64]| -> Result<(f64, f64), ThermalError> {
        if al.folds == 0 {
            // No cross-validation: the in-sample RMS at the fixed ridge strength.
            let d = design(runs, lags, &terms)?;
            return Ok((
                in_sample_rms(&d, nc, cfg.fallback_ridge),
                cfg.fallback_ridge,
            ));
        }
        let (s, l) = match &mut main_scorer {
            Some(sc) => choose_ridge(sc.scores(lags, &lambdas)?, &lambdas, cfg.ridge_tolerance),
            None => best_ridge(
                &design(runs, lags, &terms)?,
                nc,
                al.folds,
                al.gap_steps,
                &lambdas,
                cfg.ridge_tolerance,
            ),
        };
        let Some(ak) = &joint else {
            return Ok((s, l));
        };
        let (sk, _) = match &mut scale_scorer {
            Some(sc) => choose_ridge(sc.scores(lags, &lambdas)?, &lambdas, cfg.ridge_tolerance),
            None => best_ridge(
                &design(&scale_runs, lags, &scale_terms)?,
                scale_terms.len() - 1,
                ak.folds,
                ak.gap_steps,
                &lambdas,
                cfg.ridge_tolerance,
            ),
        };
        Ok((s / ref_main + sk / ref_scale, l))
    };
    // 1. Grid over increasing lag tuples, neighbours at least one grid step apart.
    let mut tuples: Vec<Vec<usize>> = vec![vec![]];
    for _ in 0..al.n_lags {
        let mut next = Vec::new();
        for t in &tuples {
            let start = t.last().map_or(0, |v| v + 1);
            for i in start..g {
                if let Some(&p) = t.last() {
                    if grid[i] < grid[p] * cfg.min_lag_ratio * 0.999 {
                        continue;
                    }
                }
                let mut u = t.clone();
                u.push(i);
                next.push(u);
            }
        }
        tuples = next;
    }
    let mut candidates = 0;
    let mut best = (f64::INFINITY, f64::NAN, Vec::new());
    for t in &tuples {
        let lags: Vec<f64> = t.iter().map(|&i| grid[i]).collect();
        let (s, l) = score(&lags)?;
        candidates += 1;
        if s < best.0 {
            best = (s, l, lags);
        }
    }
    if best.2.is_empty() {
        return Err(ThermalError::Singular);
    }
    // 2. Coordinate search in log τ around the best, step factor halving in log.
    let mut step = ((hi - lo) / (g - 1) as f64 / 2.0).exp();
    for _ in 0..3 {
        let mut improved = true;
        while improved {
            improved = false;
            for j in 0..best.2.len() {
                for f in [step, 1.0 / step] {
                    let mut lags = best.2.clone();
                    lags[j] = (lags[j] * f).clamp(tau_min, al.tau_max_s);
                    let ok = lags.windows(2).all(|w| w[1] >= w[0] * cfg.min_lag_ratio);
                    if !ok || lags == best.2 {
                        continue;
                    }
                    let (s, l) = score(&lags)?;
                    candidates += 1;
                    if s < best.0 * (1.0 - 1e-4) {
                        best = (s, l, lags);
                        improved = true;
                    }
                }
            }
        }
        step = step.sqrt();
    }
    let lags = best.2;
    let spec = spec_with(&lags)?;
    Ok(Identified {
        spec,
        report: ThermalReport {
            lags_s: lags,
            identified_on: on.to_owned(),
            cv_rms: (al.folds > 0 && joint.is_none()).then_some(best.0),
            candidates,
            ridge: best.1,
            folds: al.folds,
            basis: al.basis.name().to_owned(),
            notes: al.notes,
        },
        basis: al.basis,
        folds: al.folds,
        gap_steps: al.gap_steps,
    })
}

/// The basis [`fit_target`] fits a target with: the configured one (the scale basis, or the
/// bias basis identified), degraded one step at a time while the training runs hold fewer
/// than 100 labelled steps per term.
pub(crate) fn target_basis(
    sets: &[TargetSet],
    cfg: &ThermalConfig,
    id: &Identified,
    scale: bool,
) -> Basis {
    let lags = id.report.lags_s.len();
    let mut kind = if scale { cfg.scale_basis } else { id.basis };
    let labelled: usize = sets.iter().map(|s| s.labelled()).sum();
    while kind != Basis::Minimal && labelled < 100 * basis(kind, lags).len() {
        kind = match kind {
            Basis::Full => Basis::Small,
            Basis::Small => Basis::Linear,
            Basis::Linear => Basis::Lean,
            _ => Basis::Minimal,
        };
    }
    kind
}

/// Fit one target on training sets whose features are the identified spec's: ridge over
/// [`basis`], strength by blocked cross-validation (or the fallback), per-run offsets
/// averaged into the constant.
pub fn fit_target(
    sets: &[TargetSet],
    cfg: &ThermalConfig,
    id: &Identified,
    scale: bool,
) -> Result<(SubModel, ThermalReport), ThermalError> {
    let lags = id.report.lags_s.len();
    let kind = target_basis(sets, cfg, id, scale);
    let terms = basis(kind, lags);
    let nc = terms.len() - 1;
    let mut d = Design {
        x: Vec::new(),
        y: Vec::new(),
        step: Vec::new(),
        n_steps: Vec::new(),
    };
    let sparse = terms.sparse();
    for s in sets {
        let used = |k: usize| s.mask[k] && s.target[k].is_finite();
        // Sized ahead: a design grown row by row copies itself over and over.
        let rows = (0..s.table.n_rows()).filter(|&k| used(k)).count();
        let mut x = Vec::with_capacity(rows * nc);
        let mut y = Vec::with_capacity(rows);
        let mut step = Vec::with_capacity(rows);
        for k in 0..s.table.n_rows() {
            if used(k) {
                sparse.extend_design_row(s.table.row(k), 1, &mut x);
                y.push(s.target[k]);
                step.push(k);
            }
        }
        d.x.push(x);
        d.y.push(y);
        d.step.push(step);
        d.n_steps.push(s.table.n_rows());
    }
    let needed = nc + 1 + sets.len();
    let labelled: usize = sets.iter().map(|s| s.labelled()).sum();
    if labelled < needed {
        return Err(ThermalError::TooFewSteps {
            steps: labelled,
            needed,
        });
    }
    let per_run_min = d.y.iter().map(Vec::len).min().unwrap_or(0);
    let folds = if id.folds == 0 || per_run_min / id.folds.max(1) < 20 {
        0
    } else {
        id.folds
    };
    let mut notes = id.report.notes.clone();
    if folds == 0 && id.folds > 0 {
        notes.push(format!(
            "no cross-validation for this target ({per_run_min} labelled steps); ridge \
             strength fixed at {:.0e}",
            cfg.fallback_ridge
        ));
    }
    let RidgeFit {
        cv,
        lambda,
        beta,
        constant,
    } = ridge_fit(&d, nc, folds, id.gap_steps, cfg)?;
    let mut coefficients = vec![constant];
    coefficients.extend_from_slice(&beta);
    let report = ThermalReport {
        cv_rms: cv,
        ridge: lambda,
        folds,
        basis: kind.name().to_owned(),
        notes,
        ..id.report.clone()
    };
    Ok((
        SubModel::Baseline {
            terms,
            coefficients,
        },
        report,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every entry of `s`, as bits (for comparisons to the bit).
    fn bits(s: &Stats) -> Vec<u64> {
        let mut v = vec![s.n.to_bits(), s.sy.to_bits(), s.syy.to_bits()];
        v.extend(s.sx.iter().chain(&s.sxx).chain(&s.sxy).map(|f| f.to_bits()));
        v
    }

    /// `Stats::of_rows` is `Stats::add` of each row in turn, to the bit (the reference: the
    /// row-at-a-time update), for column counts around its block of eight and with zero,
    /// negative-zero and wide-ranging values.
    #[test]
    fn stats_of_rows_is_add_row_by_row_to_the_bit() {
        for nc in [0, 1, 3, 7, 8, 9, 16, 17, 30] {
            for n in [0, 1, 5, 257] {
                let x: Vec<f64> = (0..n * nc)
                    .map(|k| match k % 11 {
                        0 => 0.0,
                        1 => -0.0,
                        _ => (k as f64 * 0.731).sin() * 10f64.powi((k % 7) as i32 - 3),
                    })
                    .collect();
                let y: Vec<f64> = (0..n).map(|k| (k as f64 * 1.3).cos() * 1e-5).collect();
                let mut want = Stats::new(nc);
                for k in 0..n {
                    want.add(&x[k * nc..(k + 1) * nc], y[k], 1.0);
                }
                let got = Stats::of_rows(&x, &y, nc);
                assert_eq!(bits(&got), bits(&want), "{nc} columns, {n} rows");
            }
        }
    }

    /// Ridge with λ = 0 is ordinary least squares: on y = 2 + 3·x1 − x2 exactly, the centred
    /// normal equations give the coefficients back (independent: the generating formula).
    #[test]
    fn ridge_without_penalty_recovers_exact_coefficients() {
        let nc = 2;
        let mut s = Stats::new(nc);
        for k in 0..50 {
            let x1 = (k as f64 * 0.37).sin();
            let x2 = (k as f64 * 0.11).cos() + 0.1 * k as f64;
            s.add(&[x1, x2], 2.0 + 3.0 * x1 - x2, 1.0);
        }
        let (g, b, _) = centred_normal(&[s], nc);
        let beta = ridge_solve(&g, &b, nc, 0.0).unwrap();
        assert!(
            (beta[0] - 3.0).abs() < 1e-9 && (beta[1] + 1.0).abs() < 1e-9,
            "{beta:?}"
        );
        // A strong penalty shrinks the coefficients towards zero.
        let shrunk = ridge_solve(&g, &b, nc, 1e3).unwrap();
        assert!(shrunk[0].abs() < 0.1 && shrunk[1].abs() < 0.1, "{shrunk:?}");
    }

    /// The statistics of some columns taken from a wider design's ([`Stats::columns`]) are
    /// those of a design of these columns alone, to the bit: per segment (centred on the run's
    /// means) and per run, and so the cross-validated scores and the fit from them
    /// (independent: the narrower design built and scored on its own).
    #[test]
    fn column_subsets_of_statistics_equal_the_narrow_design_s_own() {
        let (nc, keep) = (6, [0usize, 1, 3, 5]);
        let mut wide = Design {
            x: Vec::new(),
            y: Vec::new(),
            step: Vec::new(),
            n_steps: Vec::new(),
        };
        let mut narrow = Design {
            x: Vec::new(),
            y: Vec::new(),
            step: Vec::new(),
            n_steps: Vec::new(),
        };
        for r in 0..2 {
            let (mut xw, mut xn, mut y, mut step) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for k in 0..400 {
                if k % 7 == 3 {
                    continue;
                }
                let row: Vec<f64> = (0..nc)
                    .map(|c| ((k * (c + 2) + 31 * r) as f64 * 0.013).sin() * (c + 1) as f64 + 10.0)
                    .collect();
                y.push(0.3 * row[0] - 0.7 * row[3] + (k as f64 * 0.29).cos());
                xn.extend(keep.iter().map(|&c| row[c]));
                xw.extend(row);
                step.push(k);
            }
            for d in [&mut wide, &mut narrow] {
                d.y.push(y.clone());
                d.step.push(step.clone());
                d.n_steps.push(400);
            }
            wide.x.push(xw);
            narrow.x.push(xn);
        }
        let (folds, gap, lambdas) = (5, 12, [1e-6, 1e-3, 1e-1]);
        let layouts: Vec<Layout> = (0..2)
            .map(|r| layout(&wide.step[r], wide.n_steps[r], folds, gap))
            .collect();
        let seg_w = segment_stats(&wide, nc, &layouts);
        let seg_n = segment_stats(&narrow, keep.len(), &layouts);
        let sub: Vec<Vec<Stats>> = seg_w
            .iter()
            .map(|run| run.iter().map(|s| s.columns(&keep)).collect())
            .collect();
        for (a, b) in sub.iter().flatten().zip(seg_n.iter().flatten()) {
            assert_eq!(bits(a), bits(b));
        }
        let runs: Vec<(&[Stats], &Layout)> = sub.iter().map(Vec::as_slice).zip(&layouts).collect();
        let scores = segment_scores(&runs, keep.len(), folds, &lambdas);
        let own = cv_scores(&narrow, keep.len(), folds, gap, &lambdas);
        assert_eq!(
            scores.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            own.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        for (a, b) in run_stats(&wide, nc)
            .iter()
            .zip(&run_stats(&narrow, keep.len()))
        {
            assert_eq!(bits(&a.columns(&keep)), bits(b));
        }
    }

    /// Every basis stays within the flight crate's 16 terms, and starts with the constant.
    #[test]
    fn bases_fit_the_flight_crate() {
        for kind in [
            Basis::Full,
            Basis::Small,
            Basis::Linear,
            Basis::Lean,
            Basis::Minimal,
        ] {
            for lags in 1..=3 {
                let t = basis(kind, lags);
                t.validate().unwrap();
                assert!(t.powers[0].iter().all(|p| *p == 0));
            }
        }
    }
}

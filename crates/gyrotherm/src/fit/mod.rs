//! Fit a compensation model from test logs: targets, features, the chosen method, the file.
//!
//! Static logs train the bias model, rate-table logs the scale-factor model (He et al. 2024,
//! DOI 10.19452/j.issn1007-5453.2024.02.004, §2: two separate networks, because the
//! magnitudes differ). Methods: `linear` (bias = c0 + c1·T + c2·dT, the paper's comparison),
//! `poly` (degree n in T, m in dT, optional T·dT), and the recipe methods `thermal`,
//! `residual`, `generic`, `direct`, `published` (each a [`RecipeSettings`]).
//!
//! Modules, each one concept, imports running one way (down this list):
//! - [`recipe`]: which LSTM recipe, its knobs, and what training reports ([`TrainSummary`]).
//! - `methods`: how each method is fitted, one row per method (its recipe's default knobs,
//!   its features, the function that fits one target); the methods' names are
//!   [`crate::settings::method`]'s registry.
//! - [`published`], [`residual`], [`generic`], [`direct`]: one recipe each.
//! - [`thermal`]: the thermal-state recipe (lags identified from the data, ridge by
//!   cross-validation; no LSTM).
//! - [`select`]: choosing a residual recipe's least-squares terms by blocked cross-validation.
//! - [`terms`]: the term sets (tailored, generic, the ladder) the bases are built from.
//! - [`error`]: why a fit was refused ([`FitError`]).
//!
//! Least squares itself (with or without per-run offsets) is [`crate::baseline`]; LSTM
//! training is [`crate::nn`].

pub mod auto;
pub mod direct;
pub mod error;
pub mod generic;
mod methods;
pub mod published;
pub mod recipe;
pub mod residual;
pub mod select;
pub mod terms;
pub mod thermal;
pub(crate) mod thermal_lstm;
pub mod unit;

use crate::baseline::{self, PolyDegrees, Terms};
use crate::csvlog::TestLog;
use crate::features::{FeatureSpec, FeatureTable};
use crate::model::{self, FeatureDef, ModelFile, SubModel, TrainingInfo};
use crate::settings::fit::FitSettings;
use crate::settings::method::Method;
use crate::settings::rule::SettingError;
use crate::targets::{self, TargetSet};

pub use crate::model::Target;
pub use error::FitError;
use methods::TargetFit;
pub use recipe::{LstmVerdict, RecipeSettings, TrainSummary};
pub use select::TermSelection;
pub use terms::BaseTerms;

/// A training log and the name it is reported under (its file name).
#[derive(Debug, Clone, Copy)]
pub struct NamedLog<'a> {
    pub name: &'a str,
    pub log: &'a TestLog,
}

/// How to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitConfig {
    pub method: Method,
    /// The recipe (recipe methods only; for them its kind names the model's method).
    pub recipe: RecipeSettings,
    /// Degrees of the `poly` method's bias model.
    pub poly: PolyDegrees,
    /// Bias target smoothing window, s (100 s as published).
    pub bias_window_s: f64,
    /// Settle time excluded at each table segment start, s.
    pub settle_s: f64,
    /// Output smoothing inside a rate segment for the scale-factor target, s.
    pub scale_window_s: f64,
    /// Random seed (LSTM initialisation and window order).
    pub seed: u64,
    /// Settings of the thermal recipe ([`thermal`]).
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub thermal: thermal::ThermalConfig,
    #[cfg(not(feature = "experiments"))]
    pub(crate) thermal: thermal::ThermalConfig,
}

impl FitConfig {
    /// The defaults for `method` (a recipe method gets its recipe's knobs).
    pub fn new(method: Method) -> Self {
        FitConfig {
            method,
            recipe: RecipeSettings::of_kind(method),
            poly: PolyDegrees::default(),
            bias_window_s: targets::BIAS_WINDOW_S,
            settle_s: targets::SETTLE_S,
            scale_window_s: targets::SCALE_WINDOW_S,
            seed: 0,
            thermal: thermal::ThermalConfig::default(),
        }
    }
}

/// The fit's side of the user's settings: the settings sit below the fit and know nothing of
/// it, so the fit builds its configuration from them here.
impl FitSettings {
    /// The recipe settings a recipe method trains with here (`epochs` and
    /// `validate_on_runs` applied to the method's own).
    pub(crate) fn recipe_for(&self, kind: Method) -> RecipeSettings {
        let mut r = RecipeSettings::of_kind(kind);
        if let Some(e) = self.epochs {
            r.epochs = e;
        }
        r.validate_on_runs = self.validate_on_runs;
        // Each method keeps its own size (8 as published, 32 for `thermal-lstm`) unless
        // a size is asked for.
        if let Some(h) = self.hidden {
            r.hidden = h;
        }
        // Only a recipe that draws windows at random takes a batch of them per Adam step.
        if let (Some(w), true) = (self.windows, r.sampled_windows) {
            r.batch = w;
        }
        r
    }

    /// The library's fit configuration, the settings checked first.
    pub fn fit_config(&self) -> Result<FitConfig, SettingError> {
        self.validate()?;
        let method = self.method;
        let mut cfg = FitConfig::new(method);
        // linear and poly fit no recipe; theirs stays the default, unused.
        cfg.recipe = self.recipe_for(method);
        cfg.seed = self.seed;
        cfg.bias_window_s = self.bias_window_s;
        cfg.settle_s = self.settle_s;
        cfg.poly = PolyDegrees {
            temp: self.poly_temp_degree,
            rate: self.poly_rate_degree,
            cross: self.cross,
        };
        Ok(cfg)
    }
}

impl FitConfig {
    /// The method a fit with this configuration writes: for a recipe method, its recipe's
    /// (the recipe may be swapped in whole, as a comparison column does).
    pub fn model_method(&self) -> Method {
        if self.method.is_recipe() {
            self.recipe.kind
        } else {
            self.method
        }
    }
}

/// A fitted model and how training went.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    pub model: ModelFile,
    /// LSTM training summaries (None for least-squares fits or an absent target).
    pub bias_training: Option<TrainSummary>,
    pub scale_training: Option<TrainSummary>,
    /// Why the model carries no coverage map (None when it does).
    pub coverage_note: Option<String>,
}

impl FitOutcome {
    /// What the fit did, one line each (indented as `gyrotherm train` prints them after the
    /// file it wrote; Python's `Model.summary()` prints the same): the training range, then
    /// per fitted target its model kind, the identified thermal lags and their
    /// cross-validated RMS, the least-squares term choice, and LSTM epochs and loss only
    /// where an LSTM was trained; last, the coverage map or why there is none. `logs` are the
    /// training logs as given to [`fit_model`] (a run's figure names it).
    pub fn describe(&self, logs: &[NamedLog], cfg: &FitConfig) -> Vec<String> {
        let m = &self.model;
        let mut out = vec![format!(
            "  training range: temperature {:.2} to {:.2} °C, rate {:.3} to {:.3} °C/min",
            m.training.temp_range_c.min,
            m.training.temp_range_c.max,
            m.training.rate_range_c_per_s.min * 60.0,
            m.training.rate_range_c_per_s.max * 60.0
        )];
        if let Some(c) = &m.method_choice {
            out.push(format!("  {}", c.describe()));
        }
        // The training runs of each target, in the order the fit saw them.
        let (static_names, table_names): (Vec<&NamedLog>, Vec<&NamedLog>) =
            logs.iter().partition(|l| l.log.is_static());
        for (name, sub, t, runs) in [
            ("bias", &m.bias, &self.bias_training, &static_names),
            ("scale factor", &m.scale, &self.scale_training, &table_names),
        ] {
            let Some(sub) = sub else { continue };
            out.push(format!("  {name} model: {}", sub.kind()));
            let Some(t) = t else { continue };
            if let Some(r) = &t.thermal {
                out.push(format!("    {}", r.describe()));
            }
            if let Some(sel) = &t.selection {
                out.push(format!(
                    "    least-squares terms by time-segment cross-validation (RMS, * chosen): {}",
                    sel.describe()
                ));
            }
            if let Some(verdict) = t.lstm_verdict {
                out.push(format!(
                    "    LSTM: {} epochs, final loss {:.4e} (normalised MSE); {}",
                    t.epochs,
                    t.final_loss,
                    verdict.text()
                ));
                if let Some(gate) = &t.run_gate {
                    let each: Vec<String> = gate
                        .iter()
                        .zip(runs.iter())
                        .map(|(g, l)| format!("{} {:.1} %", l.name, 100.0 * g))
                        .collect();
                    out.push(format!(
                        "    LSTM trained without each run, loss reduction on that run (needs {:.0} %): {}",
                        100.0 * cfg.recipe.min_val_improvement,
                        each.join(", ")
                    ));
                }
            }
        }
        match (&m.coverage, &self.coverage_note) {
            (Some(c), _) => out.push(format!(
                "  coverage: {} of {} (T, dT) cells covered ({:.2} °C × {:.3} °C/min cells), \
                 cross-validated bias residual {:.4} °/h RMS over {} folds",
                c.covered_cells(),
                c.n_temp * c.n_rate,
                c.temp_cell_c,
                c.rate_cell_c_per_s * 60.0,
                c.pooled_rms_dph(),
                c.folds
            )),
            (None, Some(note)) => out.push(format!("  coverage: none: {note}")),
            (None, None) => {}
        }
        out
    }
}

/// The feature specification a method reads.
pub fn feature_spec(cfg: &FitConfig) -> FeatureSpec {
    if cfg.method.is_recipe() {
        cfg.recipe.feature_spec()
    } else {
        methods::fitting(cfg.method).features
    }
}

/// Least-squares terms of a baseline method for one target.
fn baseline_terms(cfg: &FitConfig, target: Target, n_features: usize) -> Terms {
    match (cfg.method, target) {
        (Method::Poly, Target::Bias) => Terms::poly(n_features, cfg.poly),
        (Method::Poly, Target::Scale) => Terms::poly(
            n_features,
            PolyDegrees {
                temp: 2,
                rate: 1,
                cross: false,
            },
        ),
        _ => Terms::linear(n_features),
    }
}

/// Fit a baseline on the labelled steps of all runs.
fn fit_baseline(sets: &[TargetSet], terms: &Terms) -> Result<SubModel, FitError> {
    let first = &sets[0].table;
    let mut rows = Vec::new();
    let mut target = Vec::new();
    let mut mask = Vec::new();
    for s in sets {
        rows.extend_from_slice(&s.table.rows);
        target.extend_from_slice(&s.target);
        mask.extend_from_slice(&s.mask);
    }
    let fit = baseline::fit_rows(
        &rows,
        first.n_features,
        &first.names,
        &first.units,
        &target,
        Some(&mask),
        terms,
    )?;
    Ok(SubModel::from_fit(&fit))
}

/// Whether `cfg` trains an LSTM on the thermal recipe's bias residual (`thermal-lstm`, or the
/// thermal recipe's experiment knob), with training steps to take.
pub(crate) fn wants_residual_lstm(cfg: &FitConfig) -> bool {
    (cfg.thermal.residual_lstm || methods::residual_lstm(cfg.recipe.kind)) && cfg.recipe.epochs > 0
}

/// Fit one target with the configured method.
fn fit_one(
    sets: &[TargetSet],
    cfg: &FitConfig,
    target: Target,
    identified: Option<&thermal::Identified>,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, Option<TrainSummary>), FitError> {
    if let Some(id) = identified {
        let (sub, report) = thermal::fit_target(sets, &cfg.thermal, id, target == Target::Scale)?;
        let want_lstm =
            wants_residual_lstm(cfg) && (target == Target::Bias || cfg.recipe.scale_lstm);
        if let (
            true,
            SubModel::Baseline {
                terms,
                coefficients,
            },
        ) = (want_lstm, &sub)
        {
            let base = thermal_base(sets, terms, coefficients);
            let seed = cfg.seed.wrapping_add(match target {
                Target::Bias => 0,
                Target::Scale => 1,
            });
            let n_in = sets[0].table.n_features;
            let (sub, mut summary) =
                residual::fit_lstm_on_base(sets, base, &cfg.recipe, n_in, seed, progress)?;
            summary.thermal = Some(report);
            return Ok((sub, Some(summary)));
        }
        let summary = TrainSummary {
            thermal: Some(report),
            ..TrainSummary::default()
        };
        return Ok((sub, Some(summary)));
    }
    match cfg.method {
        Method::Linear | Method::Poly => {
            let terms = baseline_terms(cfg, target, sets[0].table.n_features);
            Ok((fit_baseline(sets, &terms)?, None))
        }
        _ => {
            let seed = cfg.seed.wrapping_add(match target {
                Target::Bias => 0,
                Target::Scale => 1,
            });
            let (sub, summary) = fit_target(sets, &cfg.recipe, target, seed, progress)?;
            Ok((sub, Some(summary)))
        }
    }
}

/// The thermal recipe's fitted model as a base for a residual LSTM: each run's offset is its
/// mean residual against the model (the model's constant is their labelled-step mean).
fn thermal_base(
    sets: &[TargetSet],
    terms: &Terms,
    coefficients: &[f64],
) -> baseline::FixedEffectsFit {
    let mut run_offset = Vec::with_capacity(sets.len());
    let (mut ss, mut n) = (0.0, 0usize);
    for s in sets {
        let resid: Vec<f64> = (0..s.table.n_rows())
            .filter(|r| s.mask[*r] && s.target[*r].is_finite())
            .map(|r| s.target[r] - baseline::evaluate(terms, coefficients, s.table.row(r)))
            .collect();
        let off = if resid.is_empty() {
            0.0
        } else {
            resid.iter().sum::<f64>() / resid.len() as f64
        };
        ss += resid.iter().map(|e| (e - off) * (e - off)).sum::<f64>();
        n += resid.len();
        run_offset.push(off);
    }
    baseline::FixedEffectsFit {
        terms: terms.clone(),
        coefficients: coefficients.to_vec(),
        run_offset,
        rms: (ss / n.max(1) as f64).sqrt(),
    }
}

/// Fit bias (from static logs) and scale factor (from rate-table logs). The two targets train
/// on two threads. `progress(target, epoch, loss)` is called from both threads.
pub fn fit_model(
    logs: &[NamedLog],
    cfg: &FitConfig,
    progress: &(dyn Fn(Target, usize, f64) + Sync),
) -> Result<FitOutcome, FitError> {
    if logs.is_empty() {
        return Err(FitError::NoLogs);
    }
    if chooses_method(cfg) {
        return auto::fit(logs, cfg, progress);
    }
    let identified = if uses_identification(cfg) {
        Some(identify(logs, cfg)?)
    } else {
        None
    };
    fit_model_identified(logs, cfg, identified, progress)
}

/// Whether the method chooses among candidates by held-out validation (`auto`).
pub(crate) fn chooses_method(cfg: &FitConfig) -> bool {
    cfg.method.is_recipe() && matches!(methods::fitting(cfg.recipe.kind).fit, TargetFit::Chosen)
}

/// Whether the method identifies lags from the data (the `thermal` recipe).
pub(crate) fn uses_identification(cfg: &FitConfig) -> bool {
    cfg.method.is_recipe()
        && matches!(
            methods::fitting(cfg.recipe.kind).fit,
            TargetFit::Identified { .. }
        )
}

/// Widest span a static run's gyro output may have, °/s, from its 1st to its 99th
/// percentile: 5 °/s (18,000 °/h). A gyro's thermal bias stays far inside it (a navigation
/// FOG drifts below 1 °/h over −40…+85 °C, a consumer MEMS gyro about 1 °/s), while a rate
/// table turns at ±1 to ±400 °/s: a wider span is a rate-table run read without its table
/// column, whose rates a bias model would fit as bias.
pub(crate) const MAX_STATIC_SPAN_DPS: f64 = 5.0;

/// Refuses training logs the models cannot learn from: one sampled more sparsely than the
/// models step ([`crate::features::max_sample_period_s`]), and a static one whose gyro output
/// spans more than [`MAX_STATIC_SPAN_DPS`].
pub(crate) fn check_logs(logs: &[NamedLog], spec: &FeatureSpec) -> Result<(), FitError> {
    let max_s = crate::features::max_sample_period_s(spec);
    for l in logs {
        let period_s = l.log.sample_period_s();
        if period_s > max_s {
            return Err(FitError::SampledTooSparsely {
                run: l.name.to_owned(),
                period_s,
                max_s,
            });
        }
        if targets::is_static(l.log) {
            if let Some(span_dps) = percentile_span(&l.log.gyro_dps) {
                if span_dps > MAX_STATIC_SPAN_DPS {
                    return Err(FitError::StaticRunTurns {
                        run: l.name.to_owned(),
                        span_dps,
                        has_table: l.log.table_dps.is_some(),
                    });
                }
            }
        }
    }
    Ok(())
}

/// The 1st to 99th percentile span of the finite values (None: fewer than two).
fn percentile_span(v: &[f64]) -> Option<f64> {
    let mut x: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if x.len() < 2 {
        return None;
    }
    let n = x.len() - 1;
    let hi = *x.select_nth_unstable_by(n * 99 / 100, f64::total_cmp).1;
    let lo = *x.select_nth_unstable_by(n / 100, f64::total_cmp).1;
    Some(hi - lo)
}

/// The `thermal` recipe's identification on the training logs (the first part of
/// [`fit_model`]).
pub(crate) fn identify(
    logs: &[NamedLog],
    cfg: &FitConfig,
) -> Result<thermal::Identified, FitError> {
    check_logs(logs, &feature_spec(cfg))?;
    let named: Vec<(&str, &TestLog)> = logs.iter().map(|l| (l.name, l.log)).collect();
    Ok(thermal::identify(
        &named,
        &cfg.thermal,
        cfg.bias_window_s,
        cfg.settle_s,
        cfg.scale_window_s,
    )?)
}

/// [`identify`] with the lag search on every `every`-th labelled step
/// ([`thermal::identify_every`]).
pub(crate) fn identify_every(
    logs: &[NamedLog],
    cfg: &FitConfig,
    every: usize,
) -> Result<thermal::Identified, FitError> {
    check_logs(logs, &feature_spec(cfg))?;
    let named: Vec<(&str, &TestLog)> = logs.iter().map(|l| (l.name, l.log)).collect();
    Ok(thermal::identify_every(
        &named,
        &cfg.thermal,
        cfg.bias_window_s,
        cfg.settle_s,
        cfg.scale_window_s,
        every,
    )?)
}

/// [`fit_model`] with the identification already made ([`identify`] on the same logs and
/// settings; None for methods without one).
pub(crate) fn fit_model_identified(
    logs: &[NamedLog],
    cfg: &FitConfig,
    identified: Option<thermal::Identified>,
    progress: &(dyn Fn(Target, usize, f64) + Sync),
) -> Result<FitOutcome, FitError> {
    fit_model_with(logs, cfg, identified, true, None, progress)
}

/// [`fit_model_identified`]; with `own_bias` false, for a caller that replaces the bias model,
/// no bias model is fitted (unless an LSTM on it would tell the training summary), no coverage
/// map made, and the model is left unchecked: the caller completes and checks it. `made`: the
/// bias and scale-factor target sets of the static and the table logs, in log order, when the
/// caller has them already (made as here, at the identification's spec).
pub(crate) fn fit_model_with(
    logs: &[NamedLog],
    cfg: &FitConfig,
    identified: Option<thermal::Identified>,
    own_bias: bool,
    made: Option<(&[TargetSet], &[TargetSet])>,
    progress: &(dyn Fn(Target, usize, f64) + Sync),
) -> Result<FitOutcome, FitError> {
    let coverage = own_bias;
    // A residual LSTM's summary goes into the model's training record: fitted as before.
    let fit_bias = own_bias
        || ((cfg.thermal.residual_lstm || methods::residual_lstm(cfg.recipe.kind))
            && cfg.recipe.epochs > 0);
    if logs.is_empty() {
        return Err(FitError::NoLogs);
    }
    let spec = identified
        .as_ref()
        .map_or_else(|| feature_spec(cfg), |id| id.spec);
    check_logs(logs, &spec)?;
    let statics = logs.iter().filter(|l| targets::is_static(l.log)).count();
    let made = made.filter(|(b, s)| b.len() == statics && s.len() == logs.len() - statics);
    if let Some((_, scale)) = made {
        // What making them here would refuse: a table log without a labelled step.
        let tables = logs.iter().filter(|l| !targets::is_static(l.log));
        if let Some((l, _)) = tables.zip(scale).find(|(_, s)| s.labelled() == 0) {
            return Err(FitError::NoScaleSegments {
                run: l.name.to_owned(),
            });
        }
    }
    let mut bias_sets = Vec::new();
    let mut scale_sets = Vec::new();
    for l in logs.iter().filter(|_| made.is_none()) {
        if targets::is_static(l.log) {
            bias_sets.push(
                targets::bias_targets(l.log, &spec, cfg.bias_window_s).map_err(|source| {
                    FitError::Targets {
                        run: l.name.to_owned(),
                        source,
                    }
                })?,
            );
        } else {
            let s = targets::scale_targets(l.log, &spec, cfg.settle_s, cfg.scale_window_s)
                .map_err(|source| FitError::Targets {
                    run: l.name.to_owned(),
                    source,
                })?;
            if s.labelled() == 0 {
                return Err(FitError::NoScaleSegments {
                    run: l.name.to_owned(),
                });
            }
            scale_sets.push(s);
        }
    }
    let (bias_sets, scale_sets): (&[TargetSet], &[TargetSet]) =
        made.unwrap_or((&bias_sets, &scale_sets));
    if bias_sets.is_empty() && scale_sets.is_empty() {
        return Err(FitError::NoUsableLogs);
    }
    let (bias, scale) = std::thread::scope(|s| {
        let bias = s.spawn(|| {
            (!bias_sets.is_empty() && fit_bias)
                .then(|| {
                    fit_one(
                        bias_sets,
                        cfg,
                        Target::Bias,
                        identified.as_ref(),
                        &mut |e, l| progress(Target::Bias, e, l),
                    )
                })
                .transpose()
        });
        let scale = (!scale_sets.is_empty())
            .then(|| {
                fit_one(
                    scale_sets,
                    cfg,
                    Target::Scale,
                    identified.as_ref(),
                    &mut |e, l| progress(Target::Scale, e, l),
                )
            })
            .transpose();
        let bias = bias.join().unwrap_or(Err(FitError::ThreadPanicked {
            target: Target::Bias,
        }));
        (bias, scale)
    });
    let in_target = |target: Target| {
        move |e: FitError| FitError::Target {
            target,
            source: Box::new(e),
        }
    };
    let bias = bias.map_err(in_target(Target::Bias))?;
    let scale = scale.map_err(in_target(Target::Scale))?;
    let tables: Vec<&FeatureTable> = bias_sets
        .iter()
        .chain(scale_sets)
        .map(|s| &s.table)
        .collect();
    let (temp_range_c, rate_range_c_per_s) =
        model::training_ranges(&tables).ok_or(FitError::NoFeatureSteps)?;
    // A bias left to the caller would have told the thermal recipe's summary without an LSTM
    // (no epochs, no loss): the training record says the same as when it is fitted here.
    let unfitted = TrainSummary::default();
    let lstm_summary = bias
        .as_ref()
        .and_then(|b| b.1.as_ref())
        .or((identified.is_some() && !fit_bias && !bias_sets.is_empty()).then_some(&unfitted))
        .or(scale.as_ref().and_then(|s| s.1.as_ref()));
    let all_logs: Vec<&TestLog> = logs.iter().map(|l| l.log).collect();
    let training = TrainingInfo {
        temp_range_c,
        rate_range_c_per_s,
        data_digest_sha256: model::data_digest(&all_logs),
        epochs: lstm_summary.map(|s| s.epochs as u64),
        final_loss: lstm_summary.map(|s| s.final_loss),
        seed: cfg.method.is_recipe().then_some(cfg.seed),
        created_by: model::created_by(),
        inputs: logs.iter().map(|l| l.name.to_owned()).collect(),
    };
    let (bias_model, bias_training) = match bias {
        Some((m, t)) => (Some(m), t),
        None => (None, None),
    };
    let (scale_model, scale_training) = match scale {
        Some((m, t)) => (Some(m), t),
        None => (None, None),
    };
    let method = thermal_lstm::label(
        cfg.model_method(),
        bias_model.as_ref(),
        scale_model.as_ref(),
    );
    let model = ModelFile {
        format_version: model::FORMAT_VERSION,
        method,
        features: FeatureDef::from_spec(&spec),
        bias: bias_model,
        scale: scale_model,
        training,
        coverage: None,
        columns: None,
        coverage_note: None,
        method_choice: None,
    };
    // What training covered, and the bias model's cross-validated error there.
    let coverage = model.bias.as_ref().filter(|_| coverage).map(|b| {
        crate::coverage::cross_validated(
            b,
            bias_sets,
            &crate::coverage::CoverageSettings::default(),
        )
    });
    // The map's σ is the least-squares base's cross-validated error. A residual LSTM, where
    // kept, took out part of that error on the blocks held out of its training: σ shrinks by
    // the same ratio (on-sample it would be too wide for the model as it flies).
    let shrink = lstm_sigma_ratio(cfg, model.bias.as_ref(), bias_training.as_ref());
    let (coverage, coverage_note) = match coverage {
        Some(Ok(c)) => match shrink {
            Some(r) => (Some(c.rescaled(r, c.growth_per_cell)), None),
            None => (Some(c), None),
        },
        Some(Err(e)) => (None, Some(crate::error_chain::error_chain(&e))),
        None => (None, Some("no bias model: no coverage map".to_owned())),
    };
    let model = ModelFile {
        coverage,
        coverage_note: coverage_note.clone(),
        ..model
    };
    if own_bias {
        model.validate()?;
    }
    Ok(FitOutcome {
        model,
        bias_training,
        scale_training,
        coverage_note,
    })
}

/// The ratio of the held-out blocks' bias RMS with the residual LSTM to without it, where the
/// bias model holds one on a least-squares thermal base (`thermal-lstm`, `residual`,
/// `generic`; None otherwise, or where it did not help). `direct`'s base is a constant, whose
/// map is no σ of the LSTM's error to shrink: shrunk, it was too narrow everywhere (47 %
/// within ±1σ outside coverage on the design family).
fn lstm_sigma_ratio(
    cfg: &FitConfig,
    bias: Option<&SubModel>,
    training: Option<&TrainSummary>,
) -> Option<f64> {
    if !matches!(
        cfg.recipe.kind,
        Method::ThermalLstm | Method::Residual | Method::Generic
    ) {
        return None;
    }
    held_out_ratio(bias?, training?)
}

/// The ratio of the held-out blocks' bias RMS with `bias`'s residual LSTM to without it, as
/// `training` measured it; None where `bias` holds no LSTM or it did not help there.
pub(crate) fn held_out_ratio(bias: &SubModel, training: &TrainSummary) -> Option<f64> {
    bias.lstm()?;
    let (base, kept) = training.held_out_rms?;
    (base.is_finite() && kept > 0.0 && kept < base).then(|| kept / base)
}

/// Fit one target (bias or scale factor) on the training runs with an LSTM recipe.
pub fn fit_target(
    train: &[TargetSet],
    recipe: &RecipeSettings,
    target: Target,
    seed: u64,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, TrainSummary), FitError> {
    let n_in = train
        .first()
        .map(|t| t.table.n_features)
        .ok_or(FitError::NoUsableLogs)?;
    if let Some(t) = train.iter().find(|t| t.table.n_features != n_in) {
        return Err(FitError::MixedFeatures {
            first: n_in,
            other: t.table.n_features,
        });
    }
    match methods::fitting(recipe.kind).fit {
        TargetFit::Recipe(fit) => fit(train, recipe, target, n_in, seed, progress),
        // Its features come from the logs: `fit_model` identifies them and fits it; its
        // candidates likewise.
        TargetFit::Identified { .. } | TargetFit::Chosen => Err(FitError::NeedsLogs),
        // Least squares on all runs at once (`fit_model`); `lstm` is read only.
        TargetFit::LeastSquares | TargetFit::None => Err(FitError::NotARecipe {
            method: recipe.kind,
        }),
    }
}

#[cfg(test)]
mod tests {
    use crate::settings::fit::{FitSettings, DEFAULT_HIDDEN, THERMAL_LSTM_HIDDEN};
    use crate::settings::Method;

    /// Each method keeps its own LSTM size (the published 8, `thermal-lstm`'s 32) unless a
    /// size is asked for; then that size, even the published one (a `--hidden 8` once left
    /// `thermal-lstm` at 32).
    #[test]
    fn a_given_hidden_size_overrides_each_method_s_own() {
        let size = |method, hidden| {
            FitSettings {
                method,
                hidden,
                ..FitSettings::default()
            }
            .fit_config()
            .unwrap()
            .recipe
            .hidden
        };
        assert_eq!(size(Method::Published, None), DEFAULT_HIDDEN);
        assert_eq!(size(Method::ThermalLstm, None), THERMAL_LSTM_HIDDEN);
        assert_eq!(size(Method::ThermalLstm, Some(8)), 8);
        assert_eq!(size(Method::ThermalLstm, Some(64)), 64);
        assert_eq!(size(Method::Published, Some(16)), 16);
    }

    /// The windows per Adam step reach the LSTM of the methods that draw windows at random
    /// (`thermal-lstm`, `auto`'s candidate), whose own is 32; the others train on every
    /// window in turn and keep theirs.
    #[test]
    fn given_windows_reach_the_minibatch_methods_only() {
        let recipe = |method, windows| {
            FitSettings {
                method,
                windows,
                ..FitSettings::default()
            }
            .fit_config()
            .unwrap()
            .recipe
        };
        // The methods' own: `thermal-lstm`'s recipe, which `auto`'s candidate trains with.
        let own_sampled = super::RecipeSettings::thermal_lstm().batch;
        for m in [Method::ThermalLstm, Method::Auto] {
            assert_eq!(recipe(m, None).batch, own_sampled, "{m:?}");
            assert_eq!(recipe(m, Some(128)).batch, 128, "{m:?}");
        }
        let own = recipe(Method::Residual, None).batch;
        assert!(!recipe(Method::Residual, None).sampled_windows);
        assert_eq!(recipe(Method::Residual, Some(128)).batch, own);
    }
}

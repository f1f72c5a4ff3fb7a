//! The thermal recipe on several temperature sensors of one axis.
//!
//! Each sensor's lags are identified on its own (`identify`, as for a one-sensor fit). The
//! axis model is the first sensor's terms ([`basis`], with its constant) plus, for each
//! further sensor, its temperature and its lag differences, linearly (`T_s, D_s1, …`): a
//! difference between sensors (a gradient) is a linear combination of these columns. One
//! ridge fit over all columns, strength chosen by the same blocked cross-validation.
//!
//! Which sensors stay: the sensor whose one-sensor fit has the lowest cross-validated RMS
//! comes first; each other sensor, best first, joins when the cross-validated RMS of the
//! bias (of the scale factor when the axis has no static run) drops below
//! `(1 − min_gain)` times the best so far ([`MultiConfig::min_gain`]). The scale-factor model
//! reads the further sensors only when its own cross-validated RMS passes the same test.
//!
//! The default `min_gain` is −1: a sensor joins unless it doubles the cross-validated RMS.
//! On the design family the blocked cross-validation within the chamber runs scored further
//! sensors up to 20 % worse (unit 1000), while on held-out profiles they lower the error (median 1.41 →
//! 1.26 × the noise floor, worst 7.85 → 5.91; docs/experiments/imu.md): the chamber runs do
//! not move the gradients independently enough for the folds to see what they carry, so the
//! test is kept as a guard against a sensor that ruins the fit, not as a filter.
//!
//! Experiments ([`MultiConfig`]): other terms of the further sensors ([`ExtraTerms`]), the
//! first sensor chosen by the score of the model on every sensor ([`FirstBy::Combined`]) or
//! the bias model averaged over each sensor first ([`FirstBy::Average`]), separate folds for
//! the selection; docs/experiments/imu-worst-model.md has what each gave.

use super::*;
use crate::settings::fit::{DEFAULT_IMU_EXTRA_TERMS, DEFAULT_IMU_FIRST, DEFAULT_IMU_MIN_GAIN};
use crate::targets::TargetSet;

/// Settings of the multi-sensor selection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiConfig {
    /// Least relative drop of the cross-validated RMS for a sensor to join.
    pub min_gain: f64,
    /// The further sensors' terms.
    pub extra: ExtraTerms,
    /// How the first sensor is chosen.
    pub first: FirstBy,
    /// Folds of the selection's cross-validation (0: the identification's).
    pub select_folds: usize,
}

impl Default for MultiConfig {
    fn default() -> Self {
        MultiConfig {
            min_gain: DEFAULT_IMU_MIN_GAIN,
            extra: DEFAULT_IMU_EXTRA_TERMS,
            first: DEFAULT_IMU_FIRST,
            select_folds: 0,
        }
    }
}

pub use crate::settings::fit::{ExtraTerms, FirstBy};

/// One sensor's data for one axis: its identification and its training sets (features of
/// this sensor's spec; targets and rows are the same for every sensor of the axis).
pub struct SensorData<'a> {
    pub id: &'a Identified,
    pub bias: &'a [TargetSet],
    pub scale: &'a [TargetSet],
}

/// The further sensor's terms: `T` and each lag difference, linearly, no constant (other
/// sets as `kind` says).
pub(crate) fn extra_terms(lags: usize, kind: ExtraTerms) -> Terms {
    let n = 2 + lags;
    let mut powers = vec![term(n, &[(0, 1)])];
    if kind == ExtraTerms::Cubic {
        powers.push(term(n, &[(0, 2)]));
        powers.push(term(n, &[(0, 3)]));
    }
    let used = match kind {
        ExtraTerms::Temp => 0,
        ExtraTerms::TempFast => lags.min(1),
        _ => lags,
    };
    for j in 0..used {
        powers.push(term(n, &[(2 + j, 1)]));
    }
    Terms {
        n_features: n,
        powers,
    }
}

/// The first sensor's terms for a target, degraded on few labelled steps exactly as
/// [`fit_target`] does ([`target_basis`]).
pub(crate) fn first_terms(
    sets: &[TargetSet],
    cfg: &ThermalConfig,
    id: &Identified,
    scale: bool,
) -> Terms {
    basis(target_basis(sets, cfg, id, scale), id.report.lags_s.len())
}

/// The terms of one target on the sensors `order`: the first sensor's (its constant first)
/// and each further sensor's ([`extra_terms`], or with [`ExtraTerms::Same`] the further
/// sensor's own first-sensor terms without the constant). A further sensor's terms depend
/// on that sensor alone, never on its place in the order.
fn order_terms(
    sensors: &[SensorData],
    order: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
) -> (Terms, Vec<Terms>) {
    let first = &sensors[order[0]];
    let t0 = first_terms(target_sets(first, scale), cfg, first.id, scale);
    let extra = order[1..]
        .iter()
        .map(|&j| {
            let s = &sensors[j];
            if multi.extra == ExtraTerms::Same {
                let mut t = first_terms(target_sets(s, scale), cfg, s.id, scale);
                t.powers.remove(0);
                t
            } else {
                extra_terms(s.id.report.lags_s.len(), multi.extra)
            }
        })
        .collect();
    (t0, extra)
}

/// The parts of the design of one target on the sensors `order` with their terms
/// ([`order_terms`]), for [`combined`].
fn order_parts<'s, 't>(
    sensors: &[SensorData<'s>],
    order: &[usize],
    scale: bool,
    t0: &'t Terms,
    extra: &'t [Terms],
) -> Vec<(&'s [TargetSet], &'t Terms)> {
    std::iter::once((target_sets(&sensors[order[0]], scale), t0))
        .chain(
            order[1..]
                .iter()
                .zip(extra)
                .map(|(&j, t)| (target_sets(&sensors[j], scale), t)),
        )
        .collect()
}

/// The design over the first sensor's terms (no constant) and each further sensor's.
fn combined(parts: &[(&[TargetSet], &Terms)]) -> (Design, usize) {
    let nc: usize = parts
        .iter()
        .enumerate()
        .map(|(i, (_, t))| t.len() - usize::from(i == 0))
        .sum();
    let mut d = Design {
        x: Vec::new(),
        y: Vec::new(),
        step: Vec::new(),
        n_steps: Vec::new(),
    };
    let Some((first, _)) = parts.first() else {
        return (d, 0);
    };
    let sparse: Vec<_> = parts.iter().map(|(_, t)| t.sparse()).collect();
    for (r, s) in first.iter().enumerate() {
        let n_rows = parts
            .iter()
            .map(|(sets, _)| sets[r].table.n_rows())
            .min()
            .unwrap_or(0);
        let used = |k: usize| s.mask[k] && s.target[k].is_finite();
        // Sized ahead: a design grown row by row copies itself over and over.
        let rows = (0..n_rows).filter(|&k| used(k)).count();
        let mut x = Vec::with_capacity(rows * nc);
        let mut y = Vec::with_capacity(rows);
        let mut step = Vec::with_capacity(rows);
        for k in 0..n_rows {
            if used(k) {
                for (i, ((sets, _), terms)) in parts.iter().zip(&sparse).enumerate() {
                    terms.extend_design_row(sets[r].table.row(k), usize::from(i == 0), &mut x);
                }
                y.push(s.target[k]);
                step.push(k);
            }
        }
        d.x.push(x);
        d.y.push(y);
        d.step.push(step);
        d.n_steps.push(n_rows);
    }
    (d, nc)
}

fn target_sets<'a>(s: &SensorData<'a>, scale: bool) -> &'a [TargetSet] {
    if scale {
        s.scale
    } else {
        s.bias
    }
}

fn folds_for(d: &Design, id: &Identified) -> usize {
    let per_run_min = d.y.iter().map(Vec::len).min().unwrap_or(0);
    if id.folds == 0 || per_run_min / id.folds.max(1) < 20 {
        0
    } else {
        id.folds
    }
}

/// Cross-validated RMS of one target on the sensors `order` (first sensor first); None
/// when the runs are too short to cross-validate.
pub fn cv_rms<'a>(
    sensors: &[SensorData<'a>],
    order: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
) -> Option<f64> {
    let first = &sensors[order[0]];
    let (t0, extra) = order_terms(sensors, order, cfg, multi, scale);
    let parts = order_parts(sensors, order, scale, &t0, &extra);
    if target_sets(first, scale).is_empty() {
        return None;
    }
    let (d, nc) = combined(&parts);
    let mut folds = folds_for(&d, first.id);
    if folds == 0 {
        return None;
    }
    if multi.select_folds > 0 {
        folds = multi.select_folds;
    }
    let (s, _) = best_ridge(
        &d,
        nc,
        folds,
        first.id.gap_steps,
        &cfg.ridge_grid,
        cfg.ridge_tolerance,
    );
    s.is_finite().then_some(s)
}

/// One target's design over a first sensor's terms and further sensors' columns, in a fixed
/// order, with its per-segment statistics: the cross-validation (and fit) of the first sensor
/// with any further sensors taken in that order comes from these, to the bit, instead of from
/// a design of its own. Every trial of `select_shared` and the fits after it read the same rows
/// and the same values in each column; only which columns differs, and each entry of the
/// statistics is a sum over rows of its own columns alone.
pub struct Shared {
    first: usize,
    scale: bool,
    /// The further sensors, in column order.
    rest: Vec<usize>,
    /// First column of each part (the first sensor's terms without the constant, then each
    /// further sensor's), and the end.
    starts: Vec<usize>,
    design: Design,
    folds: usize,
    layouts: Vec<Layout>,
    segs: Vec<Vec<Stats>>,
    runs: std::cell::OnceCell<Vec<Stats>>,
}

/// [`Shared`] statistics of one target for the sensor `first` followed by `rest`; None where
/// a trial's design could differ in its rows (the sensors' feature tables not all of the
/// same length in every run), the first sensor has no training set or the selection's folds
/// are set apart from the fit's ([`MultiConfig::select_folds`], an experiment): the callers
/// then build each design on its own.
pub fn shared<'a>(
    sensors: &[SensorData<'a>],
    first: usize,
    rest: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
) -> Option<Shared> {
    let sets = |s: &SensorData<'a>| target_sets(s, scale);
    let f = &sensors[first];
    let first_sets = sets(f);
    if first_sets.is_empty() || multi.select_folds > 0 {
        return None;
    }
    let same_rows = rest.iter().all(|&j| {
        let other = sets(&sensors[j]);
        other.len() == first_sets.len()
            && other
                .iter()
                .zip(first_sets)
                .all(|(o, s)| o.table.n_rows() == s.table.n_rows())
    });
    if !same_rows {
        return None;
    }
    let mut order = vec![first];
    order.extend_from_slice(rest);
    // Each further sensor's terms depend on that sensor alone, never on its place in the
    // order: a trial's columns are a subset of this design's.
    let (t0, extra) = order_terms(sensors, &order, cfg, multi, scale);
    let parts = order_parts(sensors, &order, scale, &t0, &extra);
    let (design, nc) = combined(&parts);
    let mut starts = vec![0, t0.len() - 1];
    for t in &extra {
        starts.push(starts[starts.len() - 1] + t.len());
    }
    debug_assert_eq!(starts.last(), Some(&nc));
    let folds = folds_for(&design, f.id);
    let gap = f.id.gap_steps;
    let layouts: Vec<Layout> = if folds == 0 {
        Vec::new()
    } else {
        (0..design.x.len())
            .map(|r| layout(&design.step[r], design.n_steps[r], folds, gap))
            .collect()
    };
    let segs = if folds == 0 {
        Vec::new()
    } else {
        segment_stats(&design, nc, &layouts)
    };
    Some(Shared {
        first,
        scale,
        rest: rest.to_vec(),
        starts,
        design,
        folds,
        layouts,
        segs,
        runs: std::cell::OnceCell::new(),
    })
}

impl Shared {
    /// The columns of `order` (the first sensor, then further sensors in this design's
    /// order), or None when `order` is not such a trial of this design.
    fn columns(&self, order: &[usize], scale: bool) -> Option<Vec<usize>> {
        if scale != self.scale || order.first() != Some(&self.first) {
            return None;
        }
        let mut cols: Vec<usize> = (self.starts[0]..self.starts[1]).collect();
        let mut from = 0;
        for &j in &order[1..] {
            let at = from + self.rest[from..].iter().position(|&r| r == j)?;
            cols.extend(self.starts[at + 1]..self.starts[at + 2]);
            from = at + 1;
        }
        Some(cols)
    }

    /// The cross-validated scores over `lambdas` of the columns `cols` (None without folds).
    fn scores(&self, cols: &[usize], lambdas: &[f64]) -> Option<Vec<f64>> {
        if self.folds == 0 {
            return None;
        }
        let segs: Vec<Vec<Stats>> = self
            .segs
            .iter()
            .map(|run| run.iter().map(|s| s.columns(cols)).collect())
            .collect();
        let runs: Vec<(&[Stats], &Layout)> =
            segs.iter().map(Vec::as_slice).zip(&self.layouts).collect();
        Some(segment_scores(&runs, cols.len(), self.folds, lambdas))
    }
}

/// [`cv_rms`], from `shared` when `order` is one of its trials.
pub(crate) fn cv_rms_with<'a>(
    sensors: &[SensorData<'a>],
    order: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
    shared: Option<&Shared>,
) -> Option<f64> {
    let Some((sh, cols)) = shared.and_then(|sh| Some((sh, sh.columns(order, scale)?))) else {
        return cv_rms(sensors, order, cfg, multi, scale);
    };
    let (s, _) = choose_ridge(
        sh.scores(&cols, &cfg.ridge_grid)?,
        &cfg.ridge_grid,
        cfg.ridge_tolerance,
    );
    s.is_finite().then_some(s)
}

/// The sensors an axis keeps, first sensor first (see the module doc), and each one-sensor
/// score; the trials' cross-validation comes from one [`Shared`] design over the best sensor
/// and every other in ranked order, which it also returns (for `fit_multi_with` and
/// `cv_rms_with`; None where there was nothing to try or it could not be made).
pub(crate) fn select_shared(
    sensors: &[SensorData],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
) -> (Vec<usize>, Vec<Option<f64>>, Option<Shared>) {
    let scale = sensors.iter().all(|s| s.bias.is_empty());
    let single: Vec<Option<f64>> = (0..sensors.len())
        .map(|j| cv_rms(sensors, &[j], cfg, multi, scale))
        .collect();
    let mut ranked: Vec<usize> = (0..sensors.len()).collect();
    ranked.sort_by(|&a, &b| {
        let key = |j: usize| single[j].unwrap_or(f64::INFINITY);
        key(a).total_cmp(&key(b)).then(a.cmp(&b))
    });
    if multi.first == FirstBy::Combined && ranked.len() > 1 {
        // Each sensor first, the others after it in their ranking: the lowest score of the
        // model on every sensor decides which comes first.
        let n = ranked.len().min(gyrotherm_core::multi::MAX_SENSORS);
        let mut best: Option<(f64, usize)> = None;
        for (i, &j) in ranked.iter().enumerate() {
            let mut trial = vec![j];
            trial.extend(ranked.iter().copied().filter(|&o| o != j).take(n - 1));
            if let Some(s) = cv_rms(sensors, &trial, cfg, multi, scale) {
                if best.is_none_or(|(b, _)| s < b) {
                    best = Some((s, i));
                }
            }
        }
        if let Some((_, i)) = best {
            let j = ranked.remove(i);
            ranked.insert(0, j);
        }
    }
    let mut order = vec![ranked[0]];
    let Some(mut best) = single[ranked[0]] else {
        return (order, single, None);
    };
    let sh = if ranked.len() > 1 {
        shared(sensors, ranked[0], &ranked[1..], cfg, multi, scale)
    } else {
        None
    };
    for &j in &ranked[1..] {
        if order.len() >= gyrotherm_core::multi::MAX_SENSORS {
            break;
        }
        let mut trial = order.clone();
        trial.push(j);
        if let Some(s) = cv_rms_with(sensors, &trial, cfg, multi, scale, sh.as_ref()) {
            if s < best * (1.0 - multi.min_gain) {
                best = s;
                order = trial;
            }
        }
    }
    (order, single, sh)
}

/// A fitted target on several sensors: the first sensor's model (constant first, its
/// terms) and each further sensor's coefficients over `extra_terms`.
pub(crate) struct MultiFit {
    pub first: SubModel,
    pub extra: Vec<SubModel>,
    pub cv_rms: Option<f64>,
    pub ridge: f64,
}

/// Fit one target on the sensors `order` (ridge strength by cross-validation, or the
/// fallback), per-run offsets averaged into the constant as [`fit_target`] does.
pub(crate) fn fit_multi<'a>(
    sensors: &[SensorData<'a>],
    order: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
) -> Result<MultiFit, ThermalError> {
    fit_multi_with(sensors, order, cfg, multi, scale, None)
}

/// [`fit_multi`], from `shared` when `order` is one of its trials.
pub(crate) fn fit_multi_with<'a>(
    sensors: &[SensorData<'a>],
    order: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
    shared: Option<&Shared>,
) -> Result<MultiFit, ThermalError> {
    let first = &sensors[order[0]];
    let (t0, extra) = order_terms(sensors, order, cfg, multi, scale);
    let parts = order_parts(sensors, order, scale, &t0, &extra);
    let from_shared = shared.and_then(|sh| Some((sh, sh.columns(order, scale)?)));
    let own;
    let (d, nc) = match &from_shared {
        Some((sh, cols)) => (&sh.design, cols.len()),
        None => {
            own = combined(&parts);
            (&own.0, own.1)
        }
    };
    let labelled: usize = d.y.iter().map(Vec::len).sum();
    let needed = nc + 1 + d.y.len();
    if labelled < needed {
        return Err(ThermalError::TooFewSteps {
            steps: labelled,
            needed,
        });
    }
    let RidgeFit {
        cv,
        lambda,
        beta,
        constant,
    } = match &from_shared {
        Some((sh, cols)) => {
            let runs = sh
                .runs
                .get_or_init(|| run_stats(&sh.design, sh.starts[sh.starts.len() - 1]));
            let stats: Vec<Stats> = runs.iter().map(|s| s.columns(cols)).collect();
            ridge_fit_from(sh.scores(cols, &cfg.ridge_grid), &stats, nc, cfg)?
        }
        None => ridge_fit(d, nc, folds_for(d, first.id), first.id.gap_steps, cfg)?,
    };
    let n0 = t0.len() - 1;
    let mut coefficients = vec![constant];
    coefficients.extend_from_slice(&beta[..n0]);
    let mut at = n0;
    let mut extra_models = Vec::new();
    for t in extra {
        let c = beta[at..at + t.len()].to_vec();
        at += t.len();
        extra_models.push(SubModel::Baseline {
            terms: t,
            coefficients: c,
        });
    }
    Ok(MultiFit {
        first: SubModel::Baseline {
            terms: t0,
            coefficients,
        },
        extra: extra_models,
        cv_rms: cv,
        ridge: lambda,
    })
}

/// The average of `fit_multi` over each sensor of `order` first (the others after it in
/// their order): every sensor's terms are its first-sensor terms (the constant on the first
/// sensor of `order`), each coefficient the mean of the fits'. A model averaged over which
/// sensor gets the nonlinear terms, instead of one chosen by a cross-validation that cannot
/// tell them apart on chamber runs. Its `cv_rms` is the mean of the fits' (an upper bound of
/// the average's own on the same folds), `ridge` the first fit's.
pub(crate) fn fit_multi_averaged<'a>(
    sensors: &[SensorData<'a>],
    order: &[usize],
    cfg: &ThermalConfig,
    multi: &MultiConfig,
    scale: bool,
) -> Result<MultiFit, ThermalError> {
    if order.len() < 2 {
        return fit_multi(sensors, order, cfg, multi, scale);
    }
    // Per sensor of `order`: its terms in the average and their coefficients.
    let mut terms: Vec<Terms> = order
        .iter()
        .map(|&j| {
            let s = &sensors[j];
            first_terms(target_sets(s, scale), cfg, s.id, scale)
        })
        .collect();
    for t in terms.iter_mut().skip(1) {
        // The further sensors carry no constant.
        t.powers.remove(0);
    }
    let mut coef: Vec<Vec<f64>> = terms.iter().map(|t| vec![0.0; t.len()]).collect();
    let (mut cv, mut ridge) = (Some(0.0), f64::NAN);
    let m = order.len() as f64;
    for i in 0..order.len() {
        let mut rot = vec![order[i]];
        rot.extend(
            order
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != i)
                .map(|(_, &j)| j),
        );
        let fit = fit_multi(sensors, &rot, cfg, multi, scale)?;
        if i == 0 {
            ridge = fit.ridge;
        }
        cv = cv.zip(fit.cv_rms).map(|(a, b)| a + b / m);
        for (pos, sub) in std::iter::once(&fit.first).chain(&fit.extra).enumerate() {
            let SubModel::Baseline {
                terms: t,
                coefficients: c,
            } = sub
            else {
                return fit_multi(sensors, order, cfg, multi, scale);
            };
            let k = order.iter().position(|&j| j == rot[pos]).unwrap_or(0);
            for (p, v) in t.powers.iter().zip(c) {
                if p.iter().all(|&q| q == 0) {
                    // The constant: the first sensor of `order` carries it.
                    coef[0][0] += v / m;
                    continue;
                }
                match terms[k].powers.iter().position(|q| q == p) {
                    Some(at) => coef[k][at] += v / m,
                    None => return fit_multi(sensors, order, cfg, multi, scale),
                }
            }
        }
    }
    let mut parts = terms
        .into_iter()
        .zip(coef)
        .map(|(t, c)| SubModel::Baseline {
            terms: t,
            coefficients: c,
        });
    let first = parts.next().ok_or(ThermalError::NoTargets)?;
    Ok(MultiFit {
        first,
        extra: parts.collect(),
        cv_rms: cv,
        ridge,
    })
}

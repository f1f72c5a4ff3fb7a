//! The ridge machinery of the thermal fit: sufficient statistics per run, per-run-centred
//! normal equations, the ridge solve and its blocked cross-validation.

use super::*;

/// Sufficient statistics of a set of rows: n, Σx, Σy, Σxxᵀ (upper), Σxy, Σy².
#[derive(Clone)]
pub(super) struct Stats {
    pub(super) n: f64,
    pub(super) sx: Vec<f64>,
    pub(super) sy: f64,
    pub(super) sxx: Vec<f64>,
    pub(super) sxy: Vec<f64>,
    pub(super) syy: f64,
}

impl Stats {
    pub(super) fn new(nc: usize) -> Self {
        Stats {
            n: 0.0,
            sx: vec![0.0; nc],
            sy: 0.0,
            sxx: vec![0.0; nc * nc],
            sxy: vec![0.0; nc],
            syy: 0.0,
        }
    }
    pub(super) fn add(&mut self, x: &[f64], y: f64, sign: f64) {
        let nc = self.sx.len();
        self.n += sign;
        self.sy += sign * y;
        self.syy += sign * y * y;
        let x = &x[..nc];
        for i in 0..nc {
            let xi = sign * x[i];
            self.sx[i] += xi;
            self.sxy[i] += xi * y;
            // The same sums in the same order as an indexed loop, without bounds checks.
            let row = &mut self.sxx[i * nc + i..(i + 1) * nc];
            row.iter_mut()
                .zip(&x[i..])
                .for_each(|(r, xj)| *r += xi * xj);
        }
    }
    /// The statistics of the rows `x` (`nc` columns each, row after row) with targets `y`:
    /// [`Stats::add`] of each row in turn (sign 1), to the bit. Every entry is still its own
    /// sum in row order; the rows are taken eight entries of Σxxᵀ at a time, which keeps
    /// those sums in registers instead of reading and writing them at every row.
    pub(super) fn of_rows(x: &[f64], y: &[f64], nc: usize) -> Stats {
        let mut s = Stats::new(nc);
        if nc == 0 {
            s.n = y.len() as f64;
            for &v in y {
                s.sy += v;
                s.syy += v * v;
            }
            return s;
        }
        let rows = || x.chunks_exact(nc).zip(y);
        for _ in rows() {
            s.n += 1.0;
        }
        for (_, &v) in rows() {
            s.sy += v;
            s.syy += v * v;
        }
        for i in 0..nc {
            let (mut sx, mut sxy) = (0.0, 0.0);
            for (r, &v) in rows() {
                sx += r[i];
                sxy += r[i] * v;
            }
            s.sx[i] = sx;
            s.sxy[i] = sxy;
            let mut j = i;
            while j + 8 <= nc {
                let mut acc = [0.0; 8];
                for (r, _) in rows() {
                    let (xi, xj) = (r[i], &r[j..j + 8]);
                    for (a, v) in acc.iter_mut().zip(xj) {
                        *a += xi * v;
                    }
                }
                s.sxx[i * nc + j..i * nc + j + 8].copy_from_slice(&acc);
                j += 8;
            }
            let rest = nc - j;
            if rest > 0 {
                let mut acc = [0.0; 8];
                for (r, _) in rows() {
                    let (xi, xj) = (r[i], &r[j..nc]);
                    for (a, v) in acc.iter_mut().zip(xj) {
                        *a += xi * v;
                    }
                }
                s.sxx[i * nc + j..(i + 1) * nc].copy_from_slice(&acc[..rest]);
            }
        }
        s
    }
    #[cfg(test)]
    pub(super) fn minus(&self, o: &Stats) -> Stats {
        let sub = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p - q).collect();
        Stats {
            n: self.n - o.n,
            sx: sub(&self.sx, &o.sx),
            sy: self.sy - o.sy,
            sxx: sub(&self.sxx, &o.sxx),
            sxy: sub(&self.sxy, &o.sxy),
            syy: self.syy - o.syy,
        }
    }
    /// The statistics of the columns `cols` (increasing indices): each entry is the sum it
    /// would be over those columns alone, to the bit (every entry is summed on its own, in
    /// row order); the lower triangle of Σxxᵀ left zero as [`Stats::add`] leaves it.
    pub(super) fn columns(&self, cols: &[usize]) -> Stats {
        let nc = self.sx.len();
        let m = cols.len();
        let mut sxx = vec![0.0; m * m];
        for (a, &i) in cols.iter().enumerate() {
            for (b, &j) in cols.iter().enumerate().skip(a) {
                sxx[a * m + b] = self.sxx[i * nc + j];
            }
        }
        Stats {
            n: self.n,
            sx: cols.iter().map(|&i| self.sx[i]).collect(),
            sy: self.sy,
            sxx,
            sxy: cols.iter().map(|&i| self.sxy[i]).collect(),
            syy: self.syy,
        }
    }
    /// Add the statistics of a disjoint set of rows.
    pub(super) fn merge(&mut self, o: &Stats) {
        let add = |a: &mut [f64], b: &[f64]| a.iter_mut().zip(b).for_each(|(p, q)| *p += q);
        self.n += o.n;
        add(&mut self.sx, &o.sx);
        self.sy += o.sy;
        add(&mut self.sxx, &o.sxx);
        add(&mut self.sxy, &o.sxy);
        self.syy += o.syy;
    }
}

/// Per-run-centred normal equations from per-run statistics: G = Σ_r (Sxx − n x̄x̄ᵀ),
/// g = Σ_r (Sxy − n x̄ ȳ).
pub(super) fn centred_normal(stats: &[Stats], nc: usize) -> (Vec<f64>, Vec<f64>, f64) {
    let mut g = vec![0.0; nc * nc];
    let mut b = vec![0.0; nc];
    let mut n = 0.0;
    for s in stats {
        if s.n < 1.0 {
            continue;
        }
        n += s.n;
        for i in 0..nc {
            b[i] += s.sxy[i] - s.sx[i] * s.sy / s.n;
            for j in i..nc {
                let v = s.sxx[i * nc + j] - s.sx[i] * s.sx[j] / s.n;
                g[i * nc + j] += v;
            }
        }
    }
    for i in 0..nc {
        for j in 0..i {
            g[i * nc + j] = g[j * nc + i];
        }
    }
    (g, b, n)
}

/// Ridge solution on RMS-scaled columns: (G + λ·n·diag(G)/n… ) — the penalty is
/// λ·Σ_j G_jj·β_j², i.e. λ·n·Σ (s_j β_j)² with s_j the column's centred RMS.
pub(super) fn ridge_solve(g: &[f64], b: &[f64], nc: usize, lambda: f64) -> Option<Vec<f64>> {
    if nc == 0 {
        return Some(Vec::new());
    }
    // Scale to unit diagonal for conditioning, solve, scale back.
    let s: Vec<f64> = (0..nc).map(|i| g[i * nc + i].max(0.0).sqrt()).collect();
    if s.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return None;
    }
    let a = DMatrix::from_fn(nc, nc, |i, j| {
        g[i * nc + j] / (s[i] * s[j]) + if i == j { lambda } else { 0.0 }
    });
    let rhs = DVector::from_fn(nc, |i, _| b[i] / s[i]);
    let sol = match a.clone().cholesky() {
        Some(ch) => ch.solve(&rhs),
        None => a.svd(true, true).solve(&rhs, 1e-14).ok()?,
    };
    let beta: Vec<f64> = (0..nc).map(|i| sol[i] / s[i]).collect();
    beta.iter().all(|v| v.is_finite()).then_some(beta)
}

/// Contiguous fold `f` of `folds` over `n` steps: `[a, b)`.
pub(super) fn fold_range(n: usize, f: usize, folds: usize) -> (usize, usize) {
    (n * f / folds, n * (f + 1) / folds)
}

/// A run's steps cut so that every fold's held-out range and its training set are unions of
/// whole segments: the cuts are each fold's ends and its ends moved out by the gap.
pub(super) struct Layout {
    /// Labelled-row range `[a, b)` of each segment, in step order.
    pub(super) rows: Vec<(usize, usize)>,
    /// Per fold, the segments held out `[a, b)`.
    held: Vec<(usize, usize)>,
    /// Per fold, the segments left out of training (held out and the gap either side).
    left_out: Vec<(usize, usize)>,
}

/// The [`Layout`] of a run of `n_steps` steps whose labelled rows are at `steps` (increasing).
pub(super) fn layout(steps: &[usize], n_steps: usize, folds: usize, gap: usize) -> Layout {
    let mut cuts = vec![0, n_steps];
    for f in 0..folds {
        let (a, b) = fold_range(n_steps, f, folds);
        cuts.extend([a, b, a.saturating_sub(gap), (b + gap).min(n_steps)]);
    }
    cuts.sort_unstable();
    cuts.dedup();
    let row = |step: usize| steps.partition_point(|&s| s < step);
    let rows = cuts.windows(2).map(|w| (row(w[0]), row(w[1]))).collect();
    let seg = |step: usize| cuts.partition_point(|&c| c < step);
    let (mut held, mut left_out) = (Vec::new(), Vec::new());
    for f in 0..folds {
        let (a, b) = fold_range(n_steps, f, folds);
        held.push((seg(a), seg(b)));
        left_out.push((seg(a.saturating_sub(gap)), seg((b + gap).min(n_steps))));
    }
    Layout {
        rows,
        held,
        left_out,
    }
}

/// Per-segment statistics of each run of a design, its columns and target centred on the
/// run's means (so that the residual sums taken from them lose no digits to the offsets).
pub(super) fn segment_stats(d: &Design, nc: usize, layouts: &[Layout]) -> Vec<Vec<Stats>> {
    let mut xc = Vec::new();
    let mut yc = Vec::new();
    (0..d.x.len())
        .map(|r| {
            let (x, y) = (&d.x[r], &d.y[r]);
            let n = y.len().max(1) as f64;
            let mut mx = vec![0.0; nc];
            for row in x.chunks_exact(nc.max(1)) {
                mx.iter_mut().zip(row).for_each(|(m, v)| *m += v);
            }
            mx.iter_mut().for_each(|m| *m /= n);
            let my = y.iter().sum::<f64>() / n;
            layouts[r]
                .rows
                .iter()
                .map(|&(a, b)| {
                    xc.clear();
                    for row in x[a * nc..b * nc].chunks_exact(nc.max(1)) {
                        xc.extend(row.iter().zip(&mx).map(|(v, m)| v - m));
                    }
                    yc.clear();
                    yc.extend(y[a..b].iter().map(|v| v - my));
                    Stats::of_rows(&xc, &yc, nc)
                })
                .collect()
        })
        .collect()
}

/// Blocked cross-validated RMS residual (per-run means removed) for each ridge strength, from
/// each run's per-segment statistics ([`segment_stats`]): for each fold a ridge fit on the
/// segments not left out, each run keeping its own offset, scored on the held-out segments by
/// the residual's sum and sum of squares per run, which is all the pooled within-run RMS
/// ([`crate::fit::select::pooled_within_run_rms`]) needs.
pub(super) fn segment_scores(
    runs: &[(&[Stats], &Layout)],
    nc: usize,
    folds: usize,
    lambdas: &[f64],
) -> Vec<f64> {
    let nr = runs.len();
    let nl = lambdas.len();
    // Per λ and run: Σr, Σr², count of the held-out residuals.
    let (mut s1, mut s2, mut cnt) = (vec![0.0; nl * nr], vec![0.0; nl * nr], vec![0.0; nr]);
    let mut failed = vec![false; nl];
    for f in 0..folds {
        let mut train = Vec::with_capacity(nr);
        let mut held = Vec::with_capacity(nr);
        for (segs, lay) in runs {
            let (la, lb) = lay.left_out[f];
            let mut t = Stats::new(nc);
            for s in segs[..la].iter().chain(&segs[lb..]) {
                t.merge(s);
            }
            let (ha, hb) = lay.held[f];
            let mut h = Stats::new(nc);
            for s in &segs[ha..hb] {
                h.merge(s);
            }
            train.push(t);
            held.push(h);
        }
        let any_held = held.iter().any(|h| h.n >= 1.0);
        held.iter()
            .zip(&mut cnt)
            .for_each(|(h, c)| *c += h.n.max(0.0));
        let (g, b, _) = centred_normal(&train, nc);
        for (li, &lam) in lambdas.iter().enumerate() {
            let Some(beta) = ridge_solve(&g, &b, nc, lam) else {
                // Every held-out step of the fold is left without a residual.
                failed[li] |= any_held;
                continue;
            };
            let dot = |a: &[f64]| a.iter().zip(&beta).map(|(p, q)| p * q).sum::<f64>();
            for r in 0..nr {
                let (t, h) = (&train[r], &held[r]);
                if h.n < 1.0 {
                    continue;
                }
                if t.n < 1.0 {
                    failed[li] = true;
                    continue;
                }
                let offset = (t.sy - dot(&t.sx)) / t.n;
                let xb = dot(&h.sx);
                let mut quad = 0.0;
                for i in 0..nc {
                    let row = &h.sxx[i * nc..];
                    let mut acc = 0.5 * row[i] * beta[i];
                    for j in i + 1..nc {
                        acc += row[j] * beta[j];
                    }
                    quad += 2.0 * beta[i] * acc;
                }
                // r = y − x·β − offset over the held-out rows.
                let sum = h.sy - xb - h.n * offset;
                let sum2 = h.syy - 2.0 * dot(&h.sxy) + quad - 2.0 * offset * (h.sy - xb)
                    + h.n * offset * offset;
                s1[li * nr + r] += sum;
                s2[li * nr + r] += sum2;
            }
        }
    }
    (0..nl)
        .map(|li| {
            if failed[li] {
                return f64::INFINITY;
            }
            let (mut ss, mut n) = (0.0, 0.0);
            for r in 0..nr {
                if cnt[r] >= 1.0 {
                    let (a, b) = (s1[li * nr + r], s2[li * nr + r]);
                    ss += b - a * a / cnt[r];
                    n += cnt[r];
                }
            }
            let rms = (ss.max(0.0) / n).sqrt();
            if n >= 1.0 && rms.is_finite() {
                rms
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

/// Blocked cross-validated RMS residual (per-run means removed) for each ridge strength.
pub(super) fn cv_scores(
    d: &Design,
    nc: usize,
    folds: usize,
    gap: usize,
    lambdas: &[f64],
) -> Vec<f64> {
    let layouts: Vec<Layout> = (0..d.x.len())
        .map(|r| layout(&d.step[r], d.n_steps[r], folds, gap))
        .collect();
    let segs = segment_stats(d, nc, &layouts);
    let runs: Vec<(&[Stats], &Layout)> = segs.iter().map(Vec::as_slice).zip(&layouts).collect();
    segment_scores(&runs, nc, folds, lambdas)
}

/// [`cv_scores`] the direct way: every held-out residual computed row by row (the reference
/// the statistics-based one is checked against).
#[cfg(test)]
pub(super) fn cv_scores_rows(
    d: &Design,
    nc: usize,
    folds: usize,
    gap: usize,
    lambdas: &[f64],
) -> Vec<f64> {
    let nr = d.x.len();
    let total = run_stats(d, nc);
    // Out-of-fold residuals per λ, per run.
    let mut resid: Vec<Vec<Vec<f64>>> = lambdas
        .iter()
        .map(|_| d.y.iter().map(|y| vec![f64::NAN; y.len()]).collect())
        .collect();
    for f in 0..folds {
        let mut train = Vec::with_capacity(nr);
        for (r, tot) in total.iter().enumerate() {
            let (a, b) = fold_range(d.n_steps[r], f, folds);
            let (ga, gb) = (a.saturating_sub(gap), b + gap);
            let mut out = Stats::new(nc);
            for (k, &st) in d.step[r].iter().enumerate() {
                if st >= ga && st < gb {
                    out.add(&d.x[r][k * nc..(k + 1) * nc], d.y[r][k], 1.0);
                }
            }
            train.push(tot.minus(&out));
        }
        let (g, b, _) = centred_normal(&train, nc);
        for (li, &lam) in lambdas.iter().enumerate() {
            let Some(beta) = ridge_solve(&g, &b, nc, lam) else {
                continue;
            };
            for r in 0..nr {
                let t = &train[r];
                if t.n < 1.0 {
                    continue;
                }
                let offset = (t.sy - t.sx.iter().zip(&beta).map(|(p, q)| p * q).sum::<f64>()) / t.n;
                let (a, b) = fold_range(d.n_steps[r], f, folds);
                for (k, &st) in d.step[r].iter().enumerate() {
                    if st >= a && st < b {
                        let x = &d.x[r][k * nc..(k + 1) * nc];
                        let p: f64 = x.iter().zip(&beta).map(|(u, v)| u * v).sum::<f64>() + offset;
                        resid[li][r][k] = d.y[r][k] - p;
                    }
                }
            }
        }
    }
    resid
        .iter()
        .map(|runs| {
            // Every held-out step has a residual here: a non-finite one is a failed fit.
            if runs.iter().flatten().any(|x| !x.is_finite()) {
                f64::INFINITY
            } else {
                crate::fit::select::pooled_within_run_rms(runs)
            }
        })
        .collect()
}

/// Best (score, λ) for a design: the strongest λ within `tol` of the least score.
pub(super) fn best_ridge(
    d: &Design,
    nc: usize,
    folds: usize,
    gap: usize,
    lambdas: &[f64],
    tol: f64,
) -> (f64, f64) {
    choose_ridge(cv_scores(d, nc, folds, gap, lambdas), lambdas, tol)
}

/// The strongest λ whose score is within `tol` of the least, with its score.
pub(super) fn choose_ridge(scores: Vec<f64>, lambdas: &[f64], tol: f64) -> (f64, f64) {
    let least = scores.iter().copied().fold(f64::INFINITY, f64::min);
    scores
        .into_iter()
        .zip(lambdas.iter().copied())
        .filter(|(s, _)| s.is_finite() && *s <= least * (1.0 + tol))
        .fold((f64::INFINITY, f64::NAN), |best, (s, l)| {
            if best.1.is_nan() || l > best.1 {
                (s, l)
            } else {
                best
            }
        })
}

/// Sufficient statistics of each run's labelled steps (`nc` columns).
pub(super) fn run_stats(d: &Design, nc: usize) -> Vec<Stats> {
    (0..d.x.len())
        .map(|r| {
            let mut s = Stats::new(nc);
            for (k, y) in d.y[r].iter().enumerate() {
                s.add(&d.x[r][k * nc..(k + 1) * nc], *y, 1.0);
            }
            s
        })
        .collect()
}

pub(super) fn in_sample_rms(d: &Design, nc: usize, lambda: f64) -> f64 {
    let stats = run_stats(d, nc);
    let (g, b, n) = centred_normal(&stats, nc);
    let Some(beta) = ridge_solve(&g, &b, nc, lambda) else {
        return f64::INFINITY;
    };
    let mut ss = 0.0;
    for (r, s) in stats.iter().enumerate() {
        if s.n < 1.0 {
            continue;
        }
        let off = (s.sy - s.sx.iter().zip(&beta).map(|(p, q)| p * q).sum::<f64>()) / s.n;
        for (k, y) in d.y[r].iter().enumerate() {
            let x = &d.x[r][k * nc..(k + 1) * nc];
            let p: f64 = x.iter().zip(&beta).map(|(u, v)| u * v).sum::<f64>() + off;
            ss += (y - p) * (y - p);
        }
    }
    (ss / n.max(1.0)).sqrt()
}

/// A ridge fit of a design: its cross-validated RMS (None without folds), the strength used,
/// the coefficients of the columns and the constant.
pub(super) struct RidgeFit {
    pub cv: Option<f64>,
    pub lambda: f64,
    pub beta: Vec<f64>,
    /// The labelled-step-weighted mean of the per-run offsets.
    pub constant: f64,
}

/// Fit `d` with the strength [`best_ridge`] chooses over `folds` blocked folds (`fallback`
/// when there are none or the cross-validation gives no finite score).
pub(super) fn ridge_fit(
    d: &Design,
    nc: usize,
    folds: usize,
    gap_steps: usize,
    cfg: &ThermalConfig,
) -> Result<RidgeFit, ThermalError> {
    let scores = (folds > 0).then(|| cv_scores(d, nc, folds, gap_steps, &cfg.ridge_grid));
    ridge_fit_from(scores, &run_stats(d, nc), nc, cfg)
}

/// [`ridge_fit`] from a design's cross-validated scores over `cfg.ridge_grid` ([`cv_scores`];
/// None without folds) and its runs' statistics ([`run_stats`]).
pub(super) fn ridge_fit_from(
    scores: Option<Vec<f64>>,
    stats: &[Stats],
    nc: usize,
    cfg: &ThermalConfig,
) -> Result<RidgeFit, ThermalError> {
    let (cv, lambda) = match scores {
        None => (None, cfg.fallback_ridge),
        Some(scores) => {
            let (s, l) = choose_ridge(scores, &cfg.ridge_grid, cfg.ridge_tolerance);
            (
                s.is_finite().then_some(s),
                if s.is_finite() { l } else { cfg.fallback_ridge },
            )
        }
    };
    let (g, b, _) = centred_normal(stats, nc);
    let beta = ridge_solve(&g, &b, nc, lambda).ok_or(ThermalError::Singular)?;
    let (mut c0, mut n) = (0.0, 0.0);
    for s in stats {
        if s.n >= 1.0 {
            c0 += s.sy - s.sx.iter().zip(&beta).map(|(p, q)| p * q).sum::<f64>();
            n += s.n;
        }
    }
    Ok(RidgeFit {
        cv,
        lambda,
        beta,
        constant: c0 / n,
    })
}

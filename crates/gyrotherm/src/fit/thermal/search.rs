//! The lag search's scorer: the blocked cross-validated score of a candidate lag set from
//! statistics kept between candidates, instead of a design built and passed over per
//! candidate.
//!
//! A column of the design is `T^a · Π D(τ_j)^p_j`; each lag difference depends on its own
//! time constant only (the lags are parallel first-order filters), so a run's `D(τ)` series
//! is made once per τ, and the per-segment sums the cross-validation needs (Σx, Σx·y and
//! Σx_i·x_j over the segments of [`Layout`]) once per column and pair of columns: the
//! candidates of the search share most of them (the fixed powers of T, each lag's own
//! columns, each pair of lags). The columns and the target are centred on their run's mean
//! first, as [`segment_stats`] does. The score is [`segment_scores`]' from these
//! statistics, equal to the one from the design's rows up to rounding.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use super::ridge::{layout, segment_scores, Layout, Stats};
use super::*;
use gyrotherm_core::features::MAX_LAGS;

/// The search's maps' hasher: their keys are a few integers made here (τ's bits, exponents),
/// never outside input, so a multiply-and-rotate hash (rustc's `FxHash`) serves, at a fraction
/// of the default hasher's cost, which a profile put at 2–3 % of a unit's training. Only
/// lookups use the maps, never their order.
#[derive(Default, Clone, Copy)]
struct KeyHasher(u64);

impl KeyHasher {
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        bytes.iter().for_each(|&b| self.add(u64::from(b)));
    }
    fn write_u8(&mut self, v: u8) {
        self.add(u64::from(v));
    }
    fn write_u64(&mut self, v: u64) {
        self.add(v);
    }
    fn write_usize(&mut self, v: usize) {
        self.add(v as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

type KeyMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;

/// A design column: `T^t · Π D(τ)^p` over `(τ bits, p)`, sorted, unused entries `(0, 0)`
/// last.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
struct Col {
    t: u8,
    d: [(u64, u8); MAX_LAGS],
}

impl Col {
    /// The column of term `powers` (over `T, dT, D1..`) at `lags`; None for a term in dT,
    /// which the search's bases do not have.
    fn of(powers: &[u8], lags: &[f64]) -> Option<Col> {
        if powers.get(1).copied().unwrap_or(0) != 0 || lags.len() > MAX_LAGS {
            return None;
        }
        let mut d: Vec<(u64, u8)> = Vec::new();
        for (j, &tau) in lags.iter().enumerate() {
            let p = powers.get(2 + j).copied().unwrap_or(0);
            if p == 0 {
                continue;
            }
            match d.iter_mut().find(|e| e.0 == tau.to_bits()) {
                Some(e) => e.1 += p,
                None => d.push((tau.to_bits(), p)),
            }
        }
        d.sort_unstable();
        let mut col = Col {
            t: powers.first().copied().unwrap_or(0),
            d: [(0, 0); MAX_LAGS],
        };
        col.d[..d.len()].copy_from_slice(&d);
        Some(col)
    }
}

/// A column's mean over the run, and the per-segment sums of the centred column: Σx and
/// Σx·y.
struct ColSums {
    mean: f64,
    sx: Vec<f64>,
    sxy: Vec<f64>,
}

/// One run's labelled steps and what the candidates so far left behind.
struct Run {
    /// `T` at every step, and the steps since the previous one (0 for the first).
    t_all: Vec<f64>,
    gaps: Vec<u64>,
    /// `T` at the labelled steps.
    t: Vec<f64>,
    /// Labelled steps.
    steps: Vec<usize>,
    /// Target at the labelled steps, centred on its mean.
    y: Vec<f64>,
    layout: Layout,
    /// Per segment: labelled steps, Σy, Σy².
    seg: Vec<(f64, f64, f64)>,
    /// `D(τ)` at the labelled steps, by τ's bits.
    lag: KeyMap<u64, Vec<f64>>,
    cols: KeyMap<Col, ColSums>,
    /// Buffers of the centred columns, kept from one candidate to the next.
    pool: Vec<Vec<f64>>,
    /// Per-segment Σx_i·x_j of centred columns, by the pair (in order).
    cross: KeyMap<(Col, Col), Vec<f64>>,
}

/// The spec of the search's temperature steps: the published spec without lags.
pub(super) fn base_spec() -> Result<FeatureSpec, ThermalError> {
    spec_with(&[])
}

/// The scorer of one target's runs for one term set.
pub(super) struct Scorer<'a> {
    runs: Vec<Run>,
    terms: &'a Terms,
    folds: usize,
}

impl<'a> Scorer<'a> {
    /// A scorer of `runs` (each with labelled steps, of which it scores every `every`-th)
    /// over `terms` with `folds` folds and `gap` steps either side; None when the terms are
    /// not the search's (a term in dT).
    pub(super) fn new(
        runs: &[RunData<'a>],
        terms: &'a Terms,
        folds: usize,
        gap: usize,
        every: usize,
    ) -> Result<Option<Scorer<'a>>, ThermalError> {
        if terms
            .powers
            .iter()
            .any(|p| p.get(1).copied().unwrap_or(0) != 0)
        {
            return Ok(None);
        }
        let spec = base_spec()?;
        let mut out = Vec::with_capacity(runs.len());
        for r in runs {
            let made;
            let table = match r.base {
                Some(t) => t,
                None => {
                    made = extract_series(&r.log.time_s, &r.log.temp_c, &spec)
                        .map_err(|e| ThermalError::Features(e.to_string()))?;
                    &made
                }
            };
            let n_steps = table.n_rows();
            let every = every.max(1);
            let steps: Vec<usize> = (0..n_steps.min(r.mask.len()))
                .filter(|&k| r.mask[k])
                .enumerate()
                .filter(|(i, _)| i % every == 0)
                .map(|(_, k)| k)
                .collect();
            let t_all: Vec<f64> = (0..n_steps).map(|k| table.row(k)[0]).collect();
            let t: Vec<f64> = steps.iter().map(|&k| t_all[k]).collect();
            let p = spec.step_period_s;
            let at = |k: usize| table.step_time_s[k] - table.step_time_s[0];
            let gaps = (0..n_steps)
                .map(|k| match k {
                    0 => 0,
                    _ => ((at(k) - at(k - 1)) / p).round() as u64,
                })
                .collect();
            let mut y: Vec<f64> = steps.iter().map(|&k| r.target[k]).collect();
            let my = y.iter().sum::<f64>() / y.len().max(1) as f64;
            y.iter_mut().for_each(|v| *v -= my);
            let layout = layout(&steps, n_steps, folds, gap);
            let seg = layout
                .rows
                .iter()
                .map(|&(a, b)| {
                    let v = &y[a..b];
                    (
                        (b - a) as f64,
                        v.iter().sum(),
                        v.iter().map(|x| x * x).sum(),
                    )
                })
                .collect();
            out.push(Run {
                t_all,
                gaps,
                t,
                steps,
                y,
                layout,
                seg,
                lag: KeyMap::default(),
                cols: KeyMap::default(),
                pool: Vec::new(),
                cross: KeyMap::default(),
            });
        }
        Ok(Some(Scorer {
            runs: out,
            terms,
            folds,
        }))
    }

    /// Make the lag differences of `taus` ahead of the candidates that use them (one pass
    /// over each run for all of them).
    pub(super) fn make_lags(&mut self, taus: &[f64]) -> Result<(), ThermalError> {
        self.runs.iter_mut().try_for_each(|r| r.make_lags(taus))
    }

    /// The cross-validated score of each ridge strength at `lags` (as [`cv_scores`] of the
    /// design at these lags).
    pub(super) fn scores(
        &mut self,
        lags: &[f64],
        lambdas: &[f64],
    ) -> Result<Vec<f64>, ThermalError> {
        let cols: Vec<Col> = self.terms.powers[1..]
            .iter()
            .map(|p| Col::of(p, lags))
            .collect::<Option<_>>()
            .ok_or_else(|| ThermalError::Features("a term in dT in the lag search".into()))?;
        let nc = cols.len();
        let mut segs = Vec::with_capacity(self.runs.len());
        for run in &mut self.runs {
            run.prepare(lags, &cols)?;
            segs.push(run.segment_stats(&cols));
        }
        let runs: Vec<(&[Stats], &Layout)> = segs
            .iter()
            .map(Vec::as_slice)
            .zip(self.runs.iter().map(|r| &r.layout))
            .collect();
        Ok(segment_scores(&runs, nc, self.folds, lambdas))
    }
}

/// `T − lag_τ(T)` at every step of a run for each τ of `taus` (`t` per step, `gaps` steps
/// since the previous one, `p` the step period): the feature pipeline's lag difference, the
/// same arithmetic (`gyrotherm_core::features`), without its other features. Eight lags go
/// through the run together: each is a chain of dependent steps, and eight chains keep the
/// processor busy where one waits on each step.
#[cfg(test)]
fn lag_differences(t: &[f64], gaps: &[u64], p: f64, taus: &[f64]) -> Vec<Vec<f64>> {
    let every: Vec<usize> = (0..t.len()).collect();
    lag_differences_at(t, gaps, p, taus, &every)
}

/// [`lag_differences`] kept only at the steps `keep` (increasing): the lags still run through
/// every step, but a search that reads a few steps stores only those.
fn lag_differences_at(
    t: &[f64],
    gaps: &[u64],
    p: f64,
    taus: &[f64],
    keep: &[usize],
) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = taus.iter().map(|_| vec![0.0; keep.len()]).collect();
    for (tau, dst) in taus.chunks(8).zip(out.chunks_mut(8)) {
        match tau.len() {
            1 => lag_lanes::<1>(t, gaps, p, tau, keep, dst),
            2 => lag_lanes::<2>(t, gaps, p, tau, keep, dst),
            3 | 4 => lag_lanes::<4>(t, gaps, p, tau, keep, dst),
            _ => lag_lanes::<8>(t, gaps, p, tau, keep, dst),
        }
    }
    out
}

/// [`lag_differences_at`] of up to `W` lags (`dst` one output per lag), in `W` lanes; unused
/// lanes run a τ of 1 s and are dropped.
fn lag_lanes<const W: usize>(
    t: &[f64],
    gaps: &[u64],
    p: f64,
    tau: &[f64],
    keep: &[usize],
    dst: &mut [Vec<f64>],
) {
    let mut lane = [1.0; W];
    lane[..tau.len()].copy_from_slice(tau);
    let g1 = lane.map(|tau| -libm::expm1(-p / tau));
    let mut c = [t.first().copied().unwrap_or(0.0); W];
    let mut next = 0;
    for (k, (&v, &n)) in t.iter().zip(gaps).enumerate() {
        if n == 1 {
            for i in 0..W {
                c[i] += g1[i] * (v - c[i]);
            }
        } else {
            for i in 0..W {
                let gain = match n {
                    0 => 0.0,
                    _ => -libm::expm1(-(n as f64) * p / lane[i]),
                };
                c[i] += gain * (v - c[i]);
            }
        }
        if keep.get(next) == Some(&k) {
            for (o, ci) in dst.iter_mut().zip(c) {
                o[next] = v - ci;
            }
            next += 1;
        }
    }
}

impl Run {
    /// Make the lag differences of `taus` this run does not hold yet (all in one pass).
    fn make_lags(&mut self, taus: &[f64]) -> Result<(), ThermalError> {
        let mut new: Vec<f64> = Vec::new();
        for &tau in taus {
            if !self.lag.contains_key(&tau.to_bits()) && !new.contains(&tau) {
                // The spec's checks on the lag (finite, > 0), as the pipeline makes them.
                spec_with(&[tau])?;
                new.push(tau);
            }
        }
        let p = FeatureSpec::THERMAL_STATE.step_period_s;
        for (tau, d) in new.iter().zip(lag_differences_at(
            &self.t_all,
            &self.gaps,
            p,
            &new,
            &self.steps,
        )) {
            self.lag.insert(tau.to_bits(), d);
        }
        Ok(())
    }

    /// Make every sum the columns `cols` at `lags` need and this run does not hold yet.
    fn prepare(&mut self, lags: &[f64], cols: &[Col]) -> Result<(), ThermalError> {
        self.make_lags(lags)?;
        // Centred values of the columns some missing sum needs, for this candidate only.
        let mut values: KeyMap<Col, Vec<f64>> = KeyMap::default();
        let mut missing = Vec::new();
        for (i, &a) in cols.iter().enumerate() {
            for &b in &cols[i..] {
                let key = if a <= b { (a, b) } else { (b, a) };
                if !self.cross.contains_key(&key) && !missing.contains(&key) {
                    missing.push(key);
                }
            }
        }
        for &c in cols {
            if !self.cols.contains_key(&c) || missing.iter().any(|&(a, b)| a == c || b == c) {
                let buf = self.pool.pop().unwrap_or_default();
                let v = self.centred(c, buf);
                if !self.cols.contains_key(&c) {
                    let sums = ColSums {
                        mean: v.1,
                        sx: self.per_segment(&v.0, None),
                        sxy: self.per_segment(&v.0, Some(&self.y)),
                    };
                    self.cols.insert(c, sums);
                }
                values.insert(c, v.0);
            }
        }
        for (a, b) in missing {
            let (va, vb) = (&values[&a], &values[&b]);
            let sums = self.per_segment(va, Some(vb));
            self.cross.insert((a, b), sums);
        }
        self.pool.extend(values.into_values());
        Ok(())
    }

    /// Column `c` at the labelled steps, centred on its mean, and the mean.
    fn centred(&self, c: Col, mut v: Vec<f64>) -> (Vec<f64>, f64) {
        let lags = c.d.iter().filter(|e| e.1 > 0);
        let lags = lags.map(|&(bits, p)| (&self.lag[&bits], p));
        let mut factors = std::iter::once((&self.t, c.t))
            .chain(lags)
            .flat_map(|(f, p)| std::iter::repeat_n(f, usize::from(p)));
        v.clear();
        match factors.next() {
            Some(f) => v.extend_from_slice(f),
            None => v.resize(self.t.len(), 1.0),
        }
        for f in factors {
            v.iter_mut().zip(f).for_each(|(x, fv)| *x *= fv);
        }
        let m = match self.cols.get(&c) {
            Some(s) => s.mean,
            None => sum(&v) / v.len().max(1) as f64,
        };
        v.iter_mut().for_each(|x| *x -= m);
        (v, m)
    }

    /// Σv (`w` None) or Σv·w over each segment's labelled steps.
    fn per_segment(&self, v: &[f64], w: Option<&[f64]>) -> Vec<f64> {
        self.layout
            .rows
            .iter()
            .map(|&(a, b)| match w {
                None => sum(&v[a..b]),
                Some(w) => dot(&v[a..b], &w[a..b]),
            })
            .collect()
    }

    /// Per-segment statistics of the columns `cols` (all prepared).
    fn segment_stats(&self, cols: &[Col]) -> Vec<Stats> {
        let nc = cols.len();
        let sums: Vec<&ColSums> = cols.iter().map(|c| &self.cols[c]).collect();
        let cross: Vec<&Vec<f64>> = (0..nc * nc)
            .map(|ij| {
                let (a, b) = (cols[ij / nc], cols[ij % nc]);
                &self.cross[&if a <= b { (a, b) } else { (b, a) }]
            })
            .collect();
        self.seg
            .iter()
            .enumerate()
            .map(|(s, &(n, sy, syy))| {
                let mut st = Stats::new(nc);
                st.n = n;
                st.sy = sy;
                st.syy = syy;
                for i in 0..nc {
                    st.sx[i] = sums[i].sx[s];
                    st.sxy[i] = sums[i].sxy[s];
                    for j in i..nc {
                        st.sxx[i * nc + j] = cross[i * nc + j][s];
                    }
                }
                st
            })
            .collect()
    }
}

/// Σ a_k·b_k, in four running sums (the compiler keeps them in vector registers).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(p, q)| p * q)
        .sum();
    for (p, q) in ca.zip(cb) {
        for i in 0..4 {
            acc[i] += p[i] * q[i];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Σ a_k, in four running sums.
fn sum(a: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let c = a.chunks_exact(4);
    let tail: f64 = c.remainder().iter().sum();
    for p in c {
        for i in 0..4 {
            acc[i] += p[i];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A static log of `n` samples about 1 s apart with two dropouts (gaps of 7 and 30 s), a
    /// temperature cycle quantised to the sensor's 0.0625 °C, and a gyro output that follows
    /// the temperature and a lag of it (deterministic, no random draws).
    fn log(n: usize) -> TestLog {
        let mut time_s = Vec::new();
        let mut t = 0.0;
        for k in 0..n {
            time_s.push(t);
            t += match k {
                400 => 7.0,
                1700 => 30.0,
                _ => 1.0 + 1e-4 * ((k % 7) as f64),
            };
        }
        let temp_c: Vec<f64> = time_s
            .iter()
            .map(|&s| {
                let v = 20.0 + 30.0 * (s / 900.0).sin() + 5.0 * (s / 170.0).cos();
                (v / 0.0625).round() * 0.0625
            })
            .collect();
        let mut slow = temp_c[0];
        let gyro_dps = temp_c
            .iter()
            .enumerate()
            .map(|(k, &c)| {
                slow += (c - slow) / 400.0;
                1e-3 + 2e-5 * c + 3e-7 * c * c + 4e-5 * (c - slow) + 1e-6 * ((k * 7919) % 13) as f64
            })
            .collect();
        TestLog {
            time_s,
            gyro_dps,
            temp_c,
            table_dps: None,
            extra: Vec::new(),
        }
    }

    /// The lag difference made here is the feature pipeline's to the last bit, gaps included
    /// (reference: `extract_series` with the one lag).
    #[test]
    fn lag_difference_is_the_pipelines() {
        let l = log(3000);
        let base = extract_series(&l.time_s, &l.temp_c, &spec_with(&[]).unwrap()).unwrap();
        let t: Vec<f64> = (0..base.n_rows()).map(|k| base.row(k)[0]).collect();
        let at = |k: usize| base.step_time_s[k] - base.step_time_s[0];
        let gaps: Vec<u64> = (0..base.n_rows())
            .map(|k| {
                if k == 0 {
                    0
                } else {
                    (at(k) - at(k - 1)).round() as u64
                }
            })
            .collect();
        assert!(gaps.iter().any(|&g| g > 1), "the log must have gaps");
        for tau in [60.0, 311.7, 12000.0] {
            let table = extract_series(&l.time_s, &l.temp_c, &spec_with(&[tau]).unwrap()).unwrap();
            let want: Vec<u64> = (0..table.n_rows())
                .map(|k| table.row(k)[2].to_bits())
                .collect();
            for taus in [
                vec![tau],
                vec![5.0, tau, 77.0, 1e4, 3.0, 9.0, 11.0, 13.0, 600.0],
            ] {
                let i = taus.iter().position(|&x| x == tau).unwrap();
                let got: Vec<u64> = lag_differences(&t, &gaps, 1.0, &taus)[i]
                    .iter()
                    .map(|v| v.to_bits())
                    .collect();
                assert_eq!(got, want, "τ = {tau} among {taus:?}");
            }
        }
    }

    /// A scorer on every third labelled step scores as one on runs whose mask keeps only
    /// those steps (the independent computation: the thinning done on the mask instead), to
    /// the bit, and differs from the scorer on every step.
    #[test]
    fn thinned_scorer_is_the_thinned_masks() {
        let logs = [log(4000), log(3000)];
        let named: Vec<(&str, &TestLog)> = vec![("a", &logs[0]), ("b", &logs[1])];
        let runs = run_data(&named, true, 100.0, 10.0, 60.0).unwrap();
        let thinned: Vec<RunData> = runs
            .iter()
            .map(|r| {
                let mut seen = 0usize;
                let mask = r
                    .mask
                    .iter()
                    .map(|&m| {
                        let keep = m && seen % 3 == 0;
                        seen += usize::from(m);
                        keep
                    })
                    .collect();
                RunData {
                    log: r.log,
                    target: r.target.clone(),
                    mask,
                    base: r.base,
                }
            })
            .collect();
        let lambdas: Vec<f64> = (0..=9).map(|k| 10f64.powi(-9 + k)).collect();
        let terms = basis(Basis::Lean, 2);
        let mut every3 = Scorer::new(&runs, &terms, 5, 200, 3).unwrap().unwrap();
        let mut masked = Scorer::new(&thinned, &terms, 5, 200, 1).unwrap().unwrap();
        let mut all = Scorer::new(&runs, &terms, 5, 200, 1).unwrap().unwrap();
        for lags in [[100.0, 700.0], [80.0, 2500.0]] {
            let got = every3.scores(&lags, &lambdas).unwrap();
            let want = masked.scores(&lags, &lambdas).unwrap();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "{lags:?}");
            assert_ne!(bits(&got), bits(&all.scores(&lags, &lambdas).unwrap()));
        }
    }

    /// The scorer's scores, and those from the design's per-segment statistics
    /// ([`cv_scores`]), are those from the design's rows (`cv_scores_rows`, the direct
    /// computation) to rounding: the same ridge strength wins.
    #[test]
    fn scorer_scores_are_the_designs() {
        let logs = [log(4000), log(3000)];
        let named: Vec<(&str, &TestLog)> = vec![("a", &logs[0]), ("b", &logs[1])];
        let runs = run_data(&named, true, 100.0, 10.0, 60.0).unwrap();
        let lambdas: Vec<f64> = (0..=9).map(|k| 10f64.powi(-9 + k)).collect();
        for kind in [Basis::Lean, Basis::Full] {
            let terms = basis(kind, 3);
            let nc = terms.len() - 1;
            let mut scorer = Scorer::new(&runs, &terms, 5, 200, 1).unwrap().unwrap();
            for lags in [
                [100.0, 400.0, 1500.0],
                [100.0, 700.0, 2500.0],
                [80.0, 400.0, 2500.0],
            ] {
                let d = design(&runs, &lags, &terms).unwrap();
                let want = cv_scores_rows(&d, nc, 5, 200, &lambdas);
                for got in [
                    scorer.scores(&lags, &lambdas).unwrap(),
                    cv_scores(&d, nc, 5, 200, &lambdas),
                ] {
                    // The two differ by rounding only, which the solve amplifies by its condition
                    // number: 1e-8 relative from λ = 1e-4 up, up to 1e-5 at the weakest ridges
                    // of this nearly collinear design.
                    for ((g, w), l) in got.iter().zip(&want).zip(&lambdas) {
                        let tol = if *l >= 1e-4 { 1e-8 } else { 1e-5 };
                        assert!(
                            (g - w).abs() <= tol * w,
                            "{kind:?} {lags:?}: {got:?} vs {want:?}"
                        );
                    }
                    assert_eq!(
                        choose_ridge(got, &lambdas, 0.0).1,
                        choose_ridge(want.clone(), &lambdas, 0.0).1
                    );
                }
            }
        }
    }
}

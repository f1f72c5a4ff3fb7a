//! Streaming overlapping Allan deviation: samples arrive in chunks (a log larger than memory),
//! memory is O(m_max) for the largest averaging factor, work O(number of τ) per sample.
//!
//! Same estimator as [`super::deviation`] with [`super::DevKind::Oadev`]; the phase is the
//! running sum of (Ω − Ω_first) (an offset leaves OADEV unchanged and keeps the sum small).
//! Samples are divided by a power of two near the first non-zero one (exact: only exponents
//! move), so that logs in any unit, however large or small, neither overflow nor underflow.

use super::{confidence, AllanError, AllanPoint, DevKind};

/// Accumulates OADEV sums for a fixed set of averaging factors.
#[derive(Debug, Clone)]
pub struct StreamingOadev {
    ms: Vec<usize>,
    tau0_s: f64,
    /// Last `ring.len()` phase values; phase index k lives at k % ring.len().
    ring: Vec<f64>,
    /// Phase points seen so far (N + 1 once N samples were pushed).
    phase_points: usize,
    offset: Option<f64>,
    /// Power of two the samples are divided by (fixed by the first non-zero sample).
    scale: Option<f64>,
    sum: f64,
    comp: f64,
    sums: Vec<f64>,
}

impl StreamingOadev {
    /// For averaging factors `ms` (each ≥ 1) at sample period `tau0_s`. Memory: 2·max(ms) + 1
    /// f64 values.
    pub fn new(ms: &[usize], tau0_s: f64) -> Result<Self, AllanError> {
        if !(tau0_s.is_finite() && tau0_s > 0.0) {
            return Err(AllanError::BadSamplePeriod(tau0_s));
        }
        let mut ms = ms.to_vec();
        ms.sort_unstable();
        ms.dedup();
        if ms.first() == Some(&0) || ms.is_empty() {
            return Err(AllanError::BadTauList(
                "averaging factors must be integers ≥ 1 (and at least one)".into(),
            ));
        }
        let len = 2 * ms[ms.len() - 1] + 1;
        let mut ring = vec![0.0; len];
        ring[0] = 0.0;
        Ok(StreamingOadev {
            sums: vec![0.0; ms.len()],
            ms,
            tau0_s,
            ring,
            phase_points: 1,
            offset: None,
            scale: None,
            sum: 0.0,
            comp: 0.0,
        })
    }

    /// Octave averaging factors 1, 2, 4, … ≤ `max_m`.
    pub fn octave(max_m: usize, tau0_s: f64) -> Result<Self, AllanError> {
        let ms: Vec<usize> = std::iter::successors(Some(1usize), |m| m.checked_mul(2))
            .take_while(|&m| m <= max_m.max(1))
            .collect();
        Self::new(&ms, tau0_s)
    }

    /// Adds samples. A non-finite sample is an error naming its index in the whole stream;
    /// the samples before it in this chunk are kept. A finite sample so large that the sums
    /// overflow is an error too ([`AllanError::TooLarge`]); the state is then spent.
    pub fn push(&mut self, samples: &[f64]) -> Result<(), AllanError> {
        let len = self.ring.len();
        for &v in samples {
            if !v.is_finite() {
                return Err(AllanError::NonFinite {
                    index: self.phase_points - 1,
                });
            }
            let raw = v;
            if self.scale.is_none() && v != 0.0 {
                self.scale = Some(power_of_two_below(v.abs()));
            }
            let scale = self.scale.unwrap_or(1.0);
            let v = v / scale;
            let off = *self.offset.get_or_insert(v);
            let v = v - off;
            let t = self.sum + v;
            if self.sum.abs() >= v.abs() {
                self.comp += (self.sum - t) + v;
            } else {
                self.comp += (v - t) + self.sum;
            }
            self.sum = t;
            let k_new = self.phase_points; // index of the new phase point
            let x_new = self.sum + self.comp;
            self.ring[k_new % len] = x_new;
            self.phase_points += 1;
            for (s, &m) in self.sums.iter_mut().zip(&self.ms) {
                if k_new < 2 * m {
                    break; // ms ascending: larger m cannot have a term yet
                }
                let x_mid = self.ring[(k_new - m) % len];
                let x_old = self.ring[(k_new - 2 * m) % len];
                let d = x_new - 2.0 * x_mid + x_old;
                *s += d * d;
            }
            // A deviation is at most √sum and its upper bound a few times that: refuse
            // before any of them would be beyond f64 in the samples' unit.
            let fits = |s: &f64| (s.sqrt() * scale * 8.0).is_finite();
            if !(x_new.is_finite() && self.sums.iter().all(fits)) {
                return Err(AllanError::TooLarge {
                    index: k_new - 1,
                    value: raw,
                });
            }
        }
        Ok(())
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> usize {
        self.phase_points - 1
    }

    /// The curve so far, for the τ with at least one term. Bounds from Greenhall's EDF with
    /// the given α (the stream is not kept, so α cannot be identified here); NaN without α.
    pub fn points(&self, alpha: Option<i32>) -> Vec<AllanPoint> {
        let n_samples = self.samples();
        self.ms
            .iter()
            .zip(&self.sums)
            .filter_map(|(&m, &s)| {
                let n = DevKind::Oadev.terms(n_samples, m);
                if n == 0 {
                    return None;
                }
                let mf = m as f64;
                let dev =
                    (s / (2.0 * mf * mf * n as f64)).max(0.0).sqrt() * self.scale.unwrap_or(1.0);
                let (edf, lo, hi) = match alpha {
                    Some(a) => confidence(DevKind::Oadev, dev, a, m, n_samples),
                    None => (f64::NAN, f64::NAN, f64::NAN),
                };
                Some(AllanPoint {
                    m,
                    tau_s: mf * self.tau0_s,
                    dev,
                    n,
                    alpha: alpha.unwrap_or(0),
                    edf,
                    lo,
                    hi,
                })
            })
            .collect()
    }
}

/// 2^⌊log2 v⌋ for finite v > 0 (the smallest normal power of two for subnormal v).
fn power_of_two_below(v: f64) -> f64 {
    f64::from_bits(v.to_bits() & 0x7ff0_0000_0000_0000).max(f64::MIN_POSITIVE)
}

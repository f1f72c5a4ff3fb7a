//! Allan-family deviations of rate (or fractional-frequency) data, with confidence intervals
//! and noise-term identification (IEEE Std 952-1997 Annex C; NIST SP 1065 §5.2).
//!
//! Rate data Ω (any unit) sampled every τ0 is integrated to the "phase"
//! θ_k = Σ_{i<k} Ω_i·τ0 (leading 0, N+1 points). With τ = m·τ0 (m the averaging factor):
//!
//! - ADEV (non-overlapping): σ² = Σ_{k=0,m,2m,…} (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ²·n),
//!   n = ⌊N/m⌋ − 1 terms.
//! - OADEV (overlapping): the same sum over every k, n = N + 1 − 2m terms (docs/method.md).
//! - MDEV: σ² = Σ_j (Σ_{i=j}^{j+m−1} θ_{i+2m} − 2θ_{i+m} + θ_i)² / (2m²τ²·n), n = N + 2 − 3m.
//! - HDEV: non-overlapping Hadamard, σ² = Σ_{k=0,m,…} (θ_{k+3m} − 3θ_{k+2m} + 3θ_{k+m} − θ_k)²
//!   / (6τ²·n), n = ⌊N/m⌋ − 2. This is what Stable32 calls "Hadamard" and what NIST SP 1065's
//!   table lists as HDEV (both reference sets in docs/method.md are this estimator).
//! - OHDEV: the overlapping Hadamard deviation, n = N + 1 − 3m.
//!
//! Frequency data y is the same math as rate data Ω (τ0 cancels: θ is kept in units of
//! Ω·τ0 internally). The mean is removed before integrating, which leaves every deviation
//! unchanged in exact arithmetic and keeps θ small for precision on long logs.
//!
//! Memory: one extra f64 array (θ) of N + 1 values. OADEV for a set of τ runs in one blocked
//! pass over θ (O(N) per τ, cache-friendly for octave sets). [`StreamingOadev`] computes OADEV
//! over a stream of chunks (a log larger than memory) in O(m_max) memory.

mod edf;
pub mod kalibr;
pub mod noise_id;
mod phase;
mod streaming;
mod terms;

pub use edf::{chi2_inv, edf_greenhall, edf_simple, ONE_SIGMA_CI};
use noise_id::lag1_noise_id_from_phase;
pub use noise_id::{lag1_noise_id, NoiseId};
pub use phase::{deviation_from_phase, phase_from_rate, phase_from_rate_in_place};
use phase::{mean_of, overlapping_second_diff_sums, phase_in_place};
pub use streaming::StreamingOadev;
pub use terms::{noise_terms, NoiseTerm, NoiseTerms};

use std::fmt;

/// Which deviation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DevKind {
    /// Non-overlapping Allan deviation.
    Adev,
    /// Overlapping Allan deviation.
    Oadev,
    /// Modified Allan deviation.
    Mdev,
    /// Non-overlapping Hadamard deviation (Stable32 "Hadamard").
    Hdev,
    /// Overlapping Hadamard deviation.
    Ohdev,
}

impl DevKind {
    /// Lower-case name as used on the command line and in JSON (`"oadev"`).
    pub fn name(self) -> &'static str {
        match self {
            DevKind::Adev => "adev",
            DevKind::Oadev => "oadev",
            DevKind::Mdev => "mdev",
            DevKind::Hdev => "hdev",
            DevKind::Ohdev => "ohdev",
        }
    }

    /// Number of terms in the sum for N rate samples and averaging factor m (0 if none).
    pub fn terms(self, n_samples: usize, m: usize) -> usize {
        if m == 0 {
            return 0;
        }
        let n = n_samples;
        match self {
            DevKind::Adev => (n / m).saturating_sub(1),
            DevKind::Oadev => (n + 1).saturating_sub(2 * m),
            DevKind::Mdev => (n + 2).saturating_sub(3 * m),
            DevKind::Hdev => (n / m).saturating_sub(2),
            DevKind::Ohdev => (n + 1).saturating_sub(3 * m),
        }
    }

    /// Largest m that leaves at least one term (0 if none).
    pub fn max_m(self, n_samples: usize) -> usize {
        let n = n_samples;
        match self {
            DevKind::Adev | DevKind::Oadev => n / 2,
            DevKind::Mdev => (n + 1) / 3,
            DevKind::Hdev | DevKind::Ohdev => n / 3,
        }
    }

    /// Largest m used by the automatic τ sets (`octave`, `decade`, `all`): ⌊N/5⌋ for the
    /// non-overlapping estimators, ⌊N/4⌋ otherwise — the limits Stable32 uses (they reproduce
    /// the τ lists of the reference files in docs/method.md).
    pub(crate) fn auto_max_m(self, n_samples: usize) -> usize {
        match self {
            DevKind::Adev | DevKind::Hdev => n_samples / 5,
            _ => n_samples / 4,
        }
    }

    /// Order of the difference (2: Allan, 3: Hadamard) for EDF and noise identification.
    fn diff_order(self) -> u32 {
        match self {
            DevKind::Hdev | DevKind::Ohdev => 3,
            _ => 2,
        }
    }
}

impl std::str::FromStr for DevKind {
    type Err = AllanError;
    fn from_str(s: &str) -> Result<Self, AllanError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "adev" => Ok(DevKind::Adev),
            "oadev" => Ok(DevKind::Oadev),
            "mdev" => Ok(DevKind::Mdev),
            "hdev" => Ok(DevKind::Hdev),
            "ohdev" => Ok(DevKind::Ohdev),
            other => Err(AllanError::BadKind(other.to_string())),
        }
    }
}

/// Which τ values to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub enum TauSet {
    /// m = 1, 2, 4, 8, … up to `DevKind::auto_max_m`.
    Octave,
    /// m = 1, 2, 5, 10, 20, 50, … up to `DevKind::auto_max_m`.
    Decade,
    /// Every m from 1 to `DevKind::auto_max_m` (O(N) work per τ: for short logs).
    All,
    /// Explicit τ values in seconds; each must be an integer multiple of τ0.
    Seconds(Vec<f64>),
}

impl std::str::FromStr for TauSet {
    type Err = AllanError;
    /// `octave`, `decade`, `all`, or a comma-separated list of seconds (`1,10,100`).
    fn from_str(s: &str) -> Result<Self, AllanError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "octave" => Ok(TauSet::Octave),
            "decade" => Ok(TauSet::Decade),
            "all" => Ok(TauSet::All),
            list => {
                let taus = list
                    .split(',')
                    .map(|t| {
                        t.trim().parse::<f64>().map_err(|_| {
                            AllanError::BadTauList(format!(
                                "`{t}` is not a number; give octave, decade, all or seconds like 1,10,100"
                            ))
                        })
                    })
                    .collect::<Result<Vec<f64>, _>>()?;
                Ok(TauSet::Seconds(taus))
            }
        }
    }
}

/// Why a deviation could not be computed.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum AllanError {
    /// Unknown kind name.
    BadKind(String),
    /// A τ list that does not parse.
    BadTauList(String),
    /// τ0 not finite and positive.
    BadSamplePeriod(f64),
    /// A sample is NaN or infinite.
    NonFinite { index: usize },
    /// τ is not an integer multiple of τ0.
    TauNotMultiple { tau_s: f64, tau0_s: f64 },
    /// τ leaves no term in the sum (too long for the log, or not positive).
    TauOutOfRange { tau_s: f64, max_tau_s: f64 },
    /// Too few samples for any τ.
    TooShort { samples: usize, need: usize },
    /// Finite samples so large that the deviation or its bounds exceed the range of f64;
    /// `index` is the sample of largest magnitude (or, streaming, the one that overflowed).
    TooLarge { index: usize, value: f64 },
}

impl fmt::Display for AllanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AllanError::BadKind(k) => {
                write!(f, "unknown deviation kind `{k}`; use adev, oadev, mdev, hdev or ohdev")
            }
            AllanError::BadTauList(m) => write!(f, "bad τ list: {m}"),
            AllanError::BadSamplePeriod(t) => {
                write!(f, "sample period {t} s is not a positive finite number; check the time column")
            }
            AllanError::NonFinite { index } => {
                write!(f, "sample {index} is NaN or infinite; clean or fill the log first")
            }
            AllanError::TauNotMultiple { tau_s, tau0_s } => write!(
                f,
                "τ = {tau_s} s is not an integer multiple of the sample period {tau0_s} s; pick a multiple"
            ),
            AllanError::TauOutOfRange { tau_s, max_tau_s } => write!(
                f,
                "τ = {tau_s} s is out of range for this log (allowed: τ0 ≤ τ ≤ {max_tau_s} s)"
            ),
            AllanError::TooShort { samples, need } => write!(
                f,
                "{samples} samples is too short for this deviation (need at least {need})"
            ),
            AllanError::TooLarge { index, value } => write!(
                f,
                "sample {index} is {value:e}: too large for its deviation to be represented; \
                 check the column's unit or remove the outlier"
            ),
        }
    }
}

impl std::error::Error for AllanError {}

/// One point of a deviation curve.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AllanPoint {
    /// Averaging factor m (τ = m·τ0).
    pub m: usize,
    /// τ, s.
    pub tau_s: f64,
    /// The deviation, in the unit of the input samples.
    pub dev: f64,
    /// Number of terms in the sum.
    pub n: usize,
    /// Noise exponent α (S(f) ∝ f^α) used for the EDF.
    pub alpha: i32,
    /// Equivalent degrees of freedom (Greenhall & Riley 2003), NaN when not defined.
    pub edf: f64,
    /// Lower 68.3 % bound: σ·√(edf/χ²(0.8413, edf)).
    pub lo: f64,
    /// Upper 68.3 % bound: σ·√(edf/χ²(0.1587, edf)).
    pub hi: f64,
}

/// Checks τ0 and the samples (finite).
fn check_input(samples: &[f64], tau0_s: f64) -> Result<(), AllanError> {
    // Every τ = m·τ0 (m ≤ N) must be finite too.
    if !(tau0_s.is_finite() && tau0_s > 0.0 && (tau0_s * samples.len() as f64).is_finite()) {
        return Err(AllanError::BadSamplePeriod(tau0_s));
    }
    if let Some(index) = samples.iter().position(|v| !v.is_finite()) {
        return Err(AllanError::NonFinite { index });
    }
    Ok(())
}

/// Averaging factors for a τ set, ascending and unique. Explicit τ must be positive integer
/// multiples of τ0 (to 1e-9 relative) that leave at least one term.
pub fn averaging_factors(
    set: &TauSet,
    kind: DevKind,
    n_samples: usize,
    tau0_s: f64,
) -> Result<Vec<usize>, AllanError> {
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(AllanError::BadSamplePeriod(tau0_s));
    }
    let max_auto = kind.auto_max_m(n_samples).max(1);
    let mut ms: Vec<usize> = match set {
        TauSet::Octave => std::iter::successors(Some(1usize), |m| m.checked_mul(2))
            .take_while(|&m| m <= max_auto)
            .collect(),
        TauSet::Decade => {
            let mut v = Vec::new();
            let mut dec = 1usize;
            'outer: loop {
                for k in [1, 2, 5] {
                    let m = dec.saturating_mul(k);
                    if m > max_auto {
                        break 'outer;
                    }
                    v.push(m);
                }
                dec = match dec.checked_mul(10) {
                    Some(d) => d,
                    None => break,
                };
            }
            v
        }
        TauSet::All => (1..=max_auto).collect(),
        TauSet::Seconds(taus) => {
            let mut v = Vec::with_capacity(taus.len());
            let max_m = kind.max_m(n_samples);
            let max_tau_s = max_m as f64 * tau0_s;
            for &tau_s in taus {
                if !(tau_s.is_finite() && tau_s > 0.0) {
                    return Err(AllanError::TauOutOfRange { tau_s, max_tau_s });
                }
                let ratio = tau_s / tau0_s;
                let m = ratio.round();
                if (ratio - m).abs() > 1e-9 * ratio.max(1.0) {
                    return Err(AllanError::TauNotMultiple { tau_s, tau0_s });
                }
                if m < 1.0 || m > max_m as f64 {
                    return Err(AllanError::TauOutOfRange { tau_s, max_tau_s });
                }
                v.push(m as usize);
            }
            v
        }
    };
    ms.retain(|&m| kind.terms(n_samples, m) > 0);
    ms.sort_unstable();
    ms.dedup();
    if ms.is_empty() {
        return Err(AllanError::TooShort {
            samples: n_samples,
            need: match kind.diff_order() {
                3 => 3,
                _ => 2,
            },
        });
    }
    Ok(ms)
}

/// Largest |sample| past which (or, non-zero, below which) [`deviation`] works on rescaled
/// samples. Below it nothing can overflow: with N ≤ 1e9 samples of magnitude ≤ 1e100 the
/// phase stays below 2e109 and the sums of squared differences below 1e230; nor underflow
/// (the squares of differences of magnitude ≥ 1e-100 are ≥ 1e-200).
const RESCALE_ABOVE: f64 = 1e100;
const RESCALE_BELOW: f64 = 1e-100;

/// A power of two to divide the samples by when their magnitude is out of the safe range
/// (None otherwise: the usual case, computed as is). Dividing by a power of two only moves
/// exponents, so the rescaled deviation times the scale is the deviation of the samples.
pub(crate) fn rescale_for_range(samples: &[f64]) -> Option<f64> {
    let max = samples.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if (max > 0.0 && max < RESCALE_BELOW) || max > RESCALE_ABOVE {
        // 2^⌊log2 max⌋ from the exponent bits; the smallest normal power of two for a
        // subnormal max (whose exponent bits are 0).
        Some(f64::from_bits(max.to_bits() & 0x7ff0_0000_0000_0000).max(f64::MIN_POSITIVE))
    } else {
        None
    }
}

/// Index and value of the sample of largest magnitude (the one an overflow is blamed on).
fn largest_sample(samples: &[f64]) -> (usize, f64) {
    samples
        .iter()
        .copied()
        .enumerate()
        .fold(
            (0, 0.0f64),
            |(i, m), (j, v)| {
                if v.abs() > m.abs() {
                    (j, v)
                } else {
                    (i, m)
                }
            },
        )
}

/// Points of rescaled samples back in the samples' unit; refused when a deviation or bound
/// is beyond f64 (the error names the largest sample, `largest` = (index, value)).
fn scale_points(
    mut points: Vec<AllanPoint>,
    scale: f64,
    largest: (usize, f64),
) -> Result<Vec<AllanPoint>, AllanError> {
    for p in &mut points {
        p.dev *= scale;
        p.lo *= scale;
        p.hi *= scale;
        let bounds_ok = !p.edf.is_finite() || (p.lo.is_finite() && p.hi.is_finite());
        if !(p.dev.is_finite() && bounds_ok) {
            let (index, value) = largest;
            return Err(AllanError::TooLarge { index, value });
        }
    }
    Ok(points)
}

/// How to compute the confidence intervals.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum NoiseModel {
    /// Identify α at every τ by the lag-1 autocorrelation method (Riley & Greenhall 2004);
    /// for τ with fewer than 30 averages by the B1 ratio and R(n) (as Stable32 does), and
    /// with fewer than 4 the α of the previous τ is kept.
    #[default]
    Identify,
    /// Use this α at every τ.
    Alpha(i32),
}

/// Deviation curve of rate (or fractional-frequency) samples taken every `tau0_s` seconds,
/// with terms, α, Greenhall EDF and 68.3 % bounds at every τ of the set.
pub fn deviation(
    samples: &[f64],
    tau0_s: f64,
    kind: DevKind,
    taus: &TauSet,
    noise: NoiseModel,
) -> Result<Vec<AllanPoint>, AllanError> {
    check_input(samples, tau0_s)?;
    if let Some(scale) = rescale_for_range(samples) {
        let scaled: Vec<f64> = samples.iter().map(|v| v / scale).collect();
        let points = deviation(&scaled, tau0_s, kind, taus, noise)?;
        return scale_points(points, scale, largest_sample(samples));
    }
    let ms = averaging_factors(taus, kind, samples.len(), tau0_s)?;
    let x = phase_from_rate(samples);
    Ok(deviation_of_phase(&x, tau0_s, kind, &ms, noise))
}

/// [`deviation`] of samples the caller hands over: the phase is built in their buffer
/// ([`phase_from_rate_in_place`]), so the peak memory is the samples plus O(number of τ)
/// (about 0.8 GB for 1e8 samples instead of 1.6 GB). Same results as [`deviation`].
pub fn deviation_owned(
    samples: Vec<f64>,
    tau0_s: f64,
    kind: DevKind,
    taus: &TauSet,
    noise: NoiseModel,
) -> Result<Vec<AllanPoint>, AllanError> {
    // One pass for the mean and the finiteness check: a sum of finite values that is not
    // finite means a NaN or ∞ (or an overflow, which check_input lets through as before).
    let mean = mean_of(&samples);
    if !mean.is_finite() {
        check_input(&samples, tau0_s)?;
    }
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(AllanError::BadSamplePeriod(tau0_s));
    }
    // Samples of extreme magnitude are worked on divided by a power of two (exact), as in
    // `deviation`; their sum above may also have overflowed, so the mean is taken again.
    if let Some(scale) = rescale_for_range(&samples) {
        let largest = largest_sample(&samples);
        let mut samples = samples;
        for v in &mut samples {
            *v /= scale;
        }
        let points = deviation_owned(samples, tau0_s, kind, taus, noise)?;
        return scale_points(points, scale, largest);
    }
    let ms = averaging_factors(taus, kind, samples.len(), tau0_s)?;
    let x = phase_in_place(samples, mean);
    Ok(deviation_of_phase(&x, tau0_s, kind, &ms, noise))
}

/// The curve from θ (N + 1 points) at averaging factors `ms` (checked, ascending).
fn deviation_of_phase(
    x: &[f64],
    tau0_s: f64,
    kind: DevKind,
    ms: &[usize],
    noise: NoiseModel,
) -> Vec<AllanPoint> {
    let n_samples = x.len().saturating_sub(1);
    let devs: Vec<(f64, usize)> = if kind == DevKind::Oadev {
        let sums = overlapping_second_diff_sums(x, ms);
        ms.iter()
            .zip(sums)
            .map(|(&m, s)| {
                let n = kind.terms(n_samples, m);
                let mf = m as f64;
                ((s / (2.0 * mf * mf * n as f64)).max(0.0).sqrt(), n)
            })
            .collect()
    } else {
        ms.iter()
            .map(|&m| deviation_from_phase(x, kind, m).unwrap_or((f64::NAN, 0)))
            .collect()
    };
    let alphas: Vec<i32> = match noise {
        NoiseModel::Alpha(a) => vec![a; ms.len()],
        NoiseModel::Identify => identify_alphas(x, kind, ms, &devs),
    };
    ms.iter()
        .zip(devs)
        .zip(alphas)
        .map(|((&m, (dev, n)), alpha)| {
            let (edf, lo, hi) = confidence(kind, dev, alpha, m, n_samples);
            AllanPoint {
                m,
                tau_s: m as f64 * tau0_s,
                dev,
                n,
                alpha,
                edf,
                lo,
                hi,
            }
        })
        .collect()
}

/// α at every m: the lag-1 method where there are enough averages, else the B1 ratio (with
/// R(n) = MVAR/AVAR for α ≥ 1), else the α of the previous τ (0 before the first).
/// R(n) needs an O(N) MDEV per such τ; those run side by side on the available cores, and
/// for OADEV the ADEV of R(n) is the one already in `devs` (the same computation).
fn identify_alphas(x: &[f64], kind: DevKind, ms: &[usize], devs: &[(f64, usize)]) -> Vec<i32> {
    enum Found {
        Alpha(i32),
        NeedsRn,
        Nothing,
    }
    let found: Vec<Found> = ms
        .iter()
        .map(|&m| {
            if let Some(id) = lag1_noise_id_from_phase(x, m, kind.diff_order()) {
                Found::Alpha(id.alpha)
            } else {
                match noise_id::b1_stage(x, m) {
                    Some(noise_id::B1::Alpha(a)) => Found::Alpha(a),
                    Some(noise_id::B1::NeedsRn) => Found::NeedsRn,
                    None => Found::Nothing,
                }
            }
        })
        .collect();
    let rn_alpha_at = |i: usize, m: usize| -> Option<i32> {
        let mdev = deviation_from_phase(x, DevKind::Mdev, m)?.0;
        let adev = match (kind, devs.get(i)) {
            (DevKind::Oadev, Some(&(dev, n))) if n > 0 => dev,
            _ => deviation_from_phase(x, DevKind::Oadev, m)?.0,
        };
        Some(noise_id::rn_alpha(m, mdev, adev))
    };
    // (index, m) of the τ that need R(n), split over the cores for long logs.
    let need: Vec<(usize, usize)> = found
        .iter()
        .zip(ms)
        .enumerate()
        .filter(|(_, (f, _))| matches!(f, Found::NeedsRn))
        .map(|(i, (_, &m))| (i, m))
        .collect();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(need.len())
        .max(1);
    let results: Vec<Option<i32>> = if threads == 1 || x.len() < 1_000_000 {
        need.iter().map(|&(i, m)| rn_alpha_at(i, m)).collect()
    } else {
        let per = need.len().div_ceil(threads);
        std::thread::scope(|s| {
            let handles: Vec<_> = need
                .chunks(per)
                .map(|chunk| {
                    s.spawn(move || {
                        chunk
                            .iter()
                            .map(|&(i, m)| rn_alpha_at(i, m))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
        })
    };
    let mut rn: Vec<Option<i32>> = vec![None; ms.len()];
    for (&(i, _), r) in need.iter().zip(results) {
        if let Some(slot) = rn.get_mut(i) {
            *slot = r;
        }
    }
    let mut last_alpha = 0i32;
    found
        .iter()
        .zip(rn)
        .map(|(f, rn)| {
            match (f, rn) {
                (Found::Alpha(a), _) => last_alpha = *a,
                (Found::NeedsRn, Some(a)) => last_alpha = a,
                _ => {}
            }
            last_alpha
        })
        .collect()
}

/// EDF and 68.3 % bounds of one deviation: Greenhall's EDF for α clamped to the range the
/// estimator converges for (α + 2d > 1, α ≤ 2); NaN bounds when no EDF is defined.
pub fn confidence(
    kind: DevKind,
    dev: f64,
    alpha: i32,
    m: usize,
    n_samples: usize,
) -> (f64, f64, f64) {
    let d = kind.diff_order();
    let alpha = alpha.clamp(2 - 2 * d as i32, 2);
    let (overlapping, modified) = match kind {
        DevKind::Adev | DevKind::Hdev => (false, false),
        DevKind::Oadev | DevKind::Ohdev => (true, false),
        DevKind::Mdev => (true, true),
    };
    // Greenhall counts phase points: N + 1 for N rate samples.
    let edf = edf_greenhall(alpha, d, m, n_samples + 1, overlapping, modified);
    match edf {
        Some(edf) if edf.is_finite() && edf > 0.0 => {
            let lo_q = (1.0 - ONE_SIGMA_CI) / 2.0;
            let hi_q = 1.0 - lo_q;
            let lo = dev * (edf / chi2_inv(hi_q, edf)).sqrt();
            let hi = dev * (edf / chi2_inv(lo_q, edf)).sqrt();
            (edf, lo, hi)
        }
        _ => (f64::NAN, f64::NAN, f64::NAN),
    }
}

#[cfg(test)]
mod tests {
    use super::noise_id::b1_noise_id_from_phase;
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// White phase noise as rate samples (differences of white noise): α = 2, so the long τ
    /// go through the B1 ratio and R(n), the path that runs MDEV on several threads.
    fn white_pm(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let e: Vec<f64> = (0..=n).map(|_| rng.gen::<f64>() - 0.5).collect();
        e.windows(2).map(|w| 3.0 + w[1] - w[0]).collect()
    }

    #[test]
    fn phase_in_place_equals_phase_bit_for_bit() {
        for n in [0usize, 1, 2, 7, 10_000] {
            let y = white_pm(n, n as u64);
            let want = phase_from_rate(&y);
            let got = phase_from_rate_in_place(y);
            assert_eq!(got.len(), n + 1);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "n = {n}");
        }
    }

    /// α by the sequential rule, from the public per-τ functions (the way `deviation` chose
    /// α before the R(n) work was split over threads).
    fn alphas_one_by_one(x: &[f64], kind: DevKind, ms: &[usize]) -> Vec<i32> {
        let mut last = 0;
        ms.iter()
            .map(|&m| {
                if let Some(id) = lag1_noise_id_from_phase(x, m, kind.diff_order()) {
                    last = id.alpha;
                } else if let Some(a) = b1_noise_id_from_phase(x, m) {
                    last = a;
                }
                last
            })
            .collect()
    }

    /// `deviation_owned` equals `deviation` bit for bit, and on a log long enough for the
    /// threaded R(n) path (≥ 1e6 samples) the α equal the one-τ-at-a-time rule.
    #[test]
    fn owned_equals_borrowed_and_threaded_alpha_equals_sequential() {
        let y = white_pm(1_200_000, 5);
        for kind in [DevKind::Oadev, DevKind::Mdev] {
            let a = deviation(&y, 1.0, kind, &TauSet::Octave, NoiseModel::Identify).unwrap();
            let b = deviation_owned(y.clone(), 1.0, kind, &TauSet::Octave, NoiseModel::Identify)
                .unwrap();
            assert_eq!(a.len(), b.len());
            for (p, q) in a.iter().zip(&b) {
                assert_eq!(
                    (p.dev.to_bits(), p.alpha, p.lo.to_bits(), p.hi.to_bits()),
                    (q.dev.to_bits(), q.alpha, q.lo.to_bits(), q.hi.to_bits()),
                    "{kind:?} m = {}",
                    p.m
                );
            }
            let x = phase_from_rate(&y);
            let ms: Vec<usize> = a.iter().map(|p| p.m).collect();
            let want = alphas_one_by_one(&x, kind, &ms);
            let got: Vec<i32> = a.iter().map(|p| p.alpha).collect();
            assert_eq!(got, want, "{kind:?}");
            // The data are white PM: some τ with too few averages for the lag-1 method (so
            // decided by B1, and α = 2 only through R(n)) must have come out as α = 2.
            let via_b1: Vec<i32> = a
                .iter()
                .filter(|p| y.len() / p.m < noise_id::MIN_AVERAGES)
                .map(|p| p.alpha)
                .collect();
            assert!(via_b1.contains(&2), "{kind:?}: {got:?}");
        }
    }

    /// The owned path checks its input as the borrowed one does (it folds the check into the
    /// mean's pass).
    #[test]
    fn owned_refuses_what_borrowed_refuses() {
        let mut y = white_pm(100, 1);
        y[5] = f64::NAN;
        y[9] = f64::INFINITY;
        let want = Err(AllanError::NonFinite { index: 5 });
        let run = |y: Vec<f64>, tau0: f64| {
            (
                deviation(
                    &y,
                    tau0,
                    DevKind::Oadev,
                    &TauSet::Octave,
                    NoiseModel::Identify,
                ),
                deviation_owned(
                    y,
                    tau0,
                    DevKind::Oadev,
                    &TauSet::Octave,
                    NoiseModel::Identify,
                ),
            )
        };
        let (a, b) = run(y, 1.0);
        assert_eq!((&a, &b), (&want, &want));
        let (a, b) = run(white_pm(100, 1), 0.0);
        let want = Err(AllanError::BadSamplePeriod(0.0));
        assert_eq!((&a, &b), (&want, &want));
    }
}

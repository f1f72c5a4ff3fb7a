//! Noise-type identification by the lag-1 autocorrelation (W. J. Riley and C. A. Greenhall,
//! "Power law noise identification using the lag 1 autocorrelation", 18th EFTF, 2004).
//!
//! For rate/frequency data at averaging factor m: average non-overlapping groups of m,
//! remove a linear trend, then difference d times until ρ = r1/(1 + r1) < 0.25 (r1 the lag-1
//! autocorrelation) or d reaches dmax; α = −round(2ρ) − 2d, i.e. S_y(f) ∝ f^α
//! (2 white PM, 1 flicker PM, 0 white FM / ARW, −1 flicker FM / bias instability,
//! −2 random-walk FM / RRW).

/// Result of one identification.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseId {
    /// Integer noise exponent α, in −2..=2.
    pub alpha: i32,
    /// Unrounded estimate −2(ρ + d).
    pub alpha_est: f64,
    /// Differences taken.
    pub d: u32,
    /// ρ of the last step.
    pub rho: f64,
}

/// Fewest averages the method is used on (Riley & Greenhall recommend ≥ 30).
pub const MIN_AVERAGES: usize = 30;
/// At most this many averages (the first ones) are used, to bound time and memory on long
/// logs (the lag-1 autocorrelation of 1e5 points has a standard error of about 0.003, far
/// below the 0.25 steps between noise types).
pub(crate) const MAX_AVERAGES: usize = 100_000;

fn lag1_acf(x: &[f64]) -> f64 {
    let mu = x.iter().sum::<f64>() / x.len() as f64;
    let num: f64 = x.windows(2).map(|w| (w[0] - mu) * (w[1] - mu)).sum();
    let den: f64 = x.iter().map(|v| (v - mu) * (v - mu)).sum();
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

fn detrend_linear(x: &mut [f64]) {
    let n = x.len() as f64;
    let t_mean = (n - 1.0) / 2.0;
    let x_mean = x.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let dt = i as f64 - t_mean;
        sxy += dt * (v - x_mean);
        sxx += dt * dt;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    for (i, v) in x.iter_mut().enumerate() {
        *v -= x_mean + slope * (i as f64 - t_mean);
    }
}

/// Identify α of rate/frequency samples at averaging factor m; `dmax` = 2 for Allan-type,
/// 3 for Hadamard-type deviations. None with fewer than [`MIN_AVERAGES`] averages.
pub fn lag1_noise_id(samples: &[f64], m: usize, dmax: u32) -> Option<NoiseId> {
    if m == 0 {
        return None;
    }
    let groups = (samples.len() / m).min(MAX_AVERAGES);
    if groups < MIN_AVERAGES {
        return None;
    }
    let x: Vec<f64> = samples[..groups * m]
        .chunks_exact(m)
        .map(|c| c.iter().sum::<f64>() / m as f64)
        .collect();
    identify(x, dmax)
}

/// As [`lag1_noise_id`], from the integrated samples θ (N + 1 points, leading 0, as made by
/// [`super::phase_from_rate`]): the m-sample means are (θ_{(j+1)m} − θ_{jm})/m, O(1) each, so
/// identification costs O(N/m) instead of O(N) per τ. (A constant offset of the means, such as
/// the mean removed by `phase_from_rate`, goes away with the linear detrend.)
pub(crate) fn lag1_noise_id_from_phase(phase: &[f64], m: usize, dmax: u32) -> Option<NoiseId> {
    if m == 0 || phase.is_empty() {
        return None;
    }
    let groups = ((phase.len() - 1) / m).min(MAX_AVERAGES);
    if groups < MIN_AVERAGES {
        return None;
    }
    let x: Vec<f64> = (0..groups)
        .map(|j| (phase[(j + 1) * m] - phase[j * m]) / m as f64)
        .collect();
    identify(x, dmax)
}

fn identify(mut x: Vec<f64>, dmax: u32) -> Option<NoiseId> {
    detrend_linear(&mut x);
    let mut d = 0u32;
    loop {
        let r1 = lag1_acf(&x);
        let rho = r1 / (1.0 + r1);
        if rho < 0.25 || d >= dmax || x.len() < 3 {
            let alpha_est = -2.0 * (rho + f64::from(d));
            // ρ below −1 (r1 < −1/2, an alternating sequence) would give α > 2, outside the
            // power-law range the method identifies (−2..=2): clamp to it.
            let alpha = ((-(2.0 * rho).round()) as i32 - 2 * d as i32).clamp(-2, 2);
            return Some(NoiseId {
                alpha,
                alpha_est,
                d,
                rho,
            });
        }
        for i in 0..x.len() - 1 {
            x[i] = x[i + 1] - x[i];
        }
        x.pop();
        d += 1;
    }
}

/// Expected B1 ratio (standard variance of N averages / Allan variance) for the power-law
/// exponent μ of σ²(τ) ∝ τ^μ (Barnes' bias function; Riley, Handbook of Frequency Stability
/// Analysis, NIST SP 1065 §5.5.3).
fn b1_theory(n: f64, mu: i32) -> f64 {
    match mu {
        1 => n / 2.0,
        0 => n * n.ln() / (2.0 * (n - 1.0) * std::f64::consts::LN_2),
        -1 => 1.0,
        _ => (n * n - 1.0) / (1.5 * n * (n - 1.0)),
    }
}

/// Fewest averages for the B1 method.
pub(crate) const B1_MIN_AVERAGES: usize = 4;

/// Noise identification for τ with too few averages for the lag-1 method (Stable32's
/// fallback): the B1 ratio picks α ∈ {−2, −1, 0, ≥1} by the geometric-mean boundaries of
/// [`b1_theory`]; for α ≥ 1 the ratio R(n) = MVAR/AVAR separates flicker PM (α = 1) from
/// white PM (α = 2) (R(n) = 1/m for white PM; IEEE Std 1139 table for flicker PM with
/// f_h = 1/(2τ0)). `phase` as made by [`super::phase_from_rate`].
///
/// `deviation` runs the same steps, with the O(N) R(n) work of several τ in parallel; this
/// one-τ form is its reference in the tests.
#[cfg(test)]
pub(crate) fn b1_noise_id_from_phase(phase: &[f64], m: usize) -> Option<i32> {
    match b1_stage(phase, m)? {
        B1::Alpha(alpha) => Some(alpha),
        B1::NeedsRn => {
            let mdev = super::deviation_from_phase(phase, super::DevKind::Mdev, m)?.0;
            let adev = super::deviation_from_phase(phase, super::DevKind::Oadev, m)?.0;
            Some(rn_alpha(m, mdev, adev))
        }
    }
}

/// What the B1 ratio alone decides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum B1 {
    /// α ∈ {−2, −1, 0}.
    Alpha(i32),
    /// α ≥ 1: flicker or white PM, to be told apart by R(n) = MVAR/AVAR ([`rn_alpha`]).
    NeedsRn,
}

/// The B1 part of `b1_noise_id_from_phase`: O(N/m); None with fewer than
/// [`B1_MIN_AVERAGES`] averages or a degenerate ratio.
pub(crate) fn b1_stage(phase: &[f64], m: usize) -> Option<B1> {
    if m == 0 || phase.is_empty() {
        return None;
    }
    let groups = (phase.len() - 1) / m;
    if groups < B1_MIN_AVERAGES {
        return None;
    }
    let y: Vec<f64> = (0..groups)
        .map(|j| (phase[(j + 1) * m] - phase[j * m]) / m as f64)
        .collect();
    let n = groups as f64;
    let mean = y.iter().sum::<f64>() / n;
    let var = y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let avar = y.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (2.0 * (n - 1.0));
    if !(avar > 0.0 && var.is_finite()) {
        return None;
    }
    let b1 = var / avar;
    let bound = |mu_hi: i32, mu_lo: i32| (b1_theory(n, mu_hi) * b1_theory(n, mu_lo)).sqrt();
    Some(if b1 < bound(-2, -1) {
        B1::NeedsRn
    } else if b1 < bound(-1, 0) {
        B1::Alpha(0)
    } else if b1 < bound(0, 1) {
        B1::Alpha(-1)
    } else {
        B1::Alpha(-2)
    })
}

/// α = 1 or 2 from R(n) = (MDEV/ADEV)² at averaging factor m.
pub(crate) fn rn_alpha(m: usize, mdev: f64, adev: f64) -> i32 {
    let rn = (mdev / adev).powi(2);
    let pi2 = std::f64::consts::PI.powi(2);
    let rn_white_pm = 1.0 / m as f64;
    let avar_fpm = (1.038 + 3.0 * (std::f64::consts::PI * m as f64).ln()) / (4.0 * pi2);
    let mvar_fpm = 3.0 * (256.0f64 / 27.0).ln() / (8.0 * pi2);
    let rn_flicker_pm = mvar_fpm / avar_fpm;
    if rn < (rn_white_pm * rn_flicker_pm).sqrt() {
        2
    } else {
        1
    }
}

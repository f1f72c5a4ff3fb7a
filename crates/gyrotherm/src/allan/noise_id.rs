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
    /// Integer noise exponent α.
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
pub const MAX_AVERAGES: usize = 100_000;

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
pub fn lag1_noise_id_from_phase(phase: &[f64], m: usize, dmax: u32) -> Option<NoiseId> {
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
            let alpha = (-(2.0 * rho).round()) as i32 - 2 * d as i32;
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

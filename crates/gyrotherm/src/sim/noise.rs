//! Gyro noise terms (IEEE Std 952-1997 annex C; NIST SP 1065): angle random walk, bias
//! instability (flicker approximated by first-order Gauss-Markov processes), rate random walk
//! and angle quantization. All random numbers come from ChaCha8 streams and are turned into
//! Gaussians with Box-Muller over `libm`, so the same seed gives the same bits on every
//! platform (no platform maths library is involved).

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Gaussian source: ChaCha8 (one stream per noise term) + Box-Muller with `libm`.
#[derive(Debug, Clone)]
pub(crate) struct Gauss {
    rng: ChaCha8Rng,
    spare: Option<f64>,
}

impl Gauss {
    /// Stream `stream` of `seed`: independent streams so that adding a noise term never
    /// changes the numbers of another.
    pub(crate) fn new(seed: u64, stream: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Gauss { rng, spare: None }
    }

    /// Uniform in (0, 1), from 53 random bits.
    pub(crate) fn uniform(&mut self) -> f64 {
        ((self.rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal sample (Box-Muller, Box & Muller 1958).
    pub(crate) fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1 = self.uniform();
        let u2 = self.uniform();
        let r = libm::sqrt(-2.0 * libm::log(u1));
        let (s, c) = libm::sincos(2.0 * core::f64::consts::PI * u2);
        self.spare = Some(r * s);
        r * c
    }
}

/// A first-order Gauss-Markov process x' = -x/τ + w, stationary standard deviation `sigma`,
/// sampled exactly: x_{k+1} = a·x_k + σ·√(1-a²)·n_k, a = exp(-Δt/τ).
#[derive(Debug, Clone)]
pub(crate) struct GaussMarkov {
    a: f64,
    drive: f64,
    x: f64,
}

impl GaussMarkov {
    /// Starts in its stationary distribution (one draw from `g`).
    pub(crate) fn new(sigma: f64, tau_s: f64, dt_s: f64, g: &mut Gauss) -> Self {
        let a = libm::exp(-dt_s / tau_s);
        GaussMarkov {
            a,
            drive: sigma * libm::sqrt(1.0 - a * a),
            x: sigma * g.normal(),
        }
    }
    pub(crate) fn value(&self) -> f64 {
        self.x
    }
    pub(crate) fn step(&mut self, g: &mut Gauss) -> f64 {
        self.x = self.a * self.x + self.drive * g.normal();
        self.x
    }
}

/// Correlation times of the Gauss-Markov terms that approximate flicker (1/f) rate noise, s:
/// half-decade spacing from 10 s to 10^4 s, equal variances, so their summed spectrum is close
/// to 1/f between about 1/(2π·10^4) and 1/(2π·10) Hz (the usual sum-of-GM approximation of
/// flicker noise, e.g. Kasdin 1995, Proc. IEEE 83(5) sec. V).
pub(crate) const FLICKER_TAUS_S: [f64; 7] = [
    10.0, 31.6227766, 100.0, 316.227766, 1000.0, 3162.27766, 10000.0,
];

/// Flicker floor of the Allan deviation for bias instability B: σ_min = 0.6643·B
/// (IEEE Std 952-1997 C.1.3: σ = √(2 ln2 / π)·B).
pub(crate) const FLICKER_FLOOR_FACTOR: f64 = 0.6643;

/// Allan variance of a continuous first-order Gauss-Markov process with variance σ² and
/// correlation time T at averaging time τ (x = τ/T):
/// AVAR = (2σ²T/τ)·[1 - (T/(2τ))·(3 - 4e^{-x} + e^{-2x})]
/// (IEEE Std 952-1997 C.1.6, with q_c = 2σ²/T).
pub(crate) fn gauss_markov_avar(sigma: f64, tau_c_s: f64, tau_s: f64) -> f64 {
    let x = tau_s / tau_c_s;
    if x < 1e-4 {
        // Series of the bracket: 2σ²x/3·(1 - 3x/4), avoids cancellation.
        return 2.0 * sigma * sigma * x / 3.0 * (1.0 - 0.75 * x);
    }
    let br = 1.0 - (3.0 - 4.0 * libm::exp(-x) + libm::exp(-2.0 * x)) / (2.0 * x);
    2.0 * sigma * sigma / x * br
}

/// Per-term standard deviation (same unit as `bias_instability`) of the [`FLICKER_TAUS_S`]
/// sum such that the flat part of its Allan deviation equals 0.6643·`bias_instability`.
/// The summed curve rises below 30 s and falls above 10^4 s (where the slowest term turns
/// white); its flat part is its maximum, flat within ±4 % from 60 s to 3000 s, so the
/// maximum over a 401-point log grid of τ in [1 s, 10^5 s] is used.
pub(crate) fn flicker_term_sigma(bias_instability: f64) -> f64 {
    if bias_instability <= 0.0 {
        return 0.0;
    }
    let mut plateau_unit = 0.0_f64;
    for k in 0..=400 {
        let tau = libm::pow(10.0, k as f64 / 80.0);
        let avar: f64 = FLICKER_TAUS_S
            .iter()
            .map(|&tc| gauss_markov_avar(1.0, tc, tau))
            .sum();
        plateau_unit = plateau_unit.max(libm::sqrt(avar));
    }
    FLICKER_FLOOR_FACTOR * bias_instability / plateau_unit
}

/// Noise parameters of the rate output (see [`super::FogUnit`] for units and defaults).
#[derive(Debug, Clone, Copy)]
pub(crate) struct NoiseParams {
    pub arw_deg_rt_h: f64,
    pub bias_instability_dph: f64,
    pub rrw_dph_rt_h: f64,
}

/// The summed rate noise, °/h, one value per sample.
#[derive(Debug, Clone)]
pub(crate) struct RateNoise {
    white_dph: f64,
    rrw_step_dph: f64,
    rrw_dph: f64,
    flicker: Vec<GaussMarkov>,
    g_white: Gauss,
    g_flicker: Gauss,
    g_rrw: Gauss,
}

impl RateNoise {
    pub(crate) fn new(p: NoiseParams, dt_s: f64, seed: u64) -> Self {
        let mut g_flicker = Gauss::new(seed, 2);
        let sigma = flicker_term_sigma(p.bias_instability_dph);
        let flicker = FLICKER_TAUS_S
            .iter()
            .map(|&tc| GaussMarkov::new(sigma, tc, dt_s, &mut g_flicker))
            .collect();
        RateNoise {
            // ARW N (°/√h): σ(τ) = N/√τ[h] = 60·N/√τ[s] °/h, so a white sample over Δt has
            // σ = 60·N/√Δt °/h (IEEE Std 952-1997 C.1.1).
            white_dph: 60.0 * p.arw_deg_rt_h / libm::sqrt(dt_s),
            // RRW K (°/h/√h): rate random walk with increments K·√(Δt[h]) = K·√Δt/60 °/h
            // (IEEE Std 952-1997 C.1.4, σ(τ) = K·√(τ/3)).
            rrw_step_dph: p.rrw_dph_rt_h * libm::sqrt(dt_s) / 60.0,
            rrw_dph: 0.0,
            flicker,
            g_white: Gauss::new(seed, 1),
            g_flicker,
            g_rrw: Gauss::new(seed, 3),
        }
    }

    /// Noise of the current sample, °/h; then advances the coloured terms.
    pub(crate) fn next_dph(&mut self) -> f64 {
        let white = self.white_dph * self.g_white.normal();
        let flick: f64 = self.flicker.iter().map(GaussMarkov::value).sum();
        let total = white + flick + self.rrw_dph;
        for f in &mut self.flicker {
            f.step(&mut self.g_flicker);
        }
        self.rrw_dph += self.rrw_step_dph * self.g_rrw.normal();
        total
    }
}

/// Angle quantization of a pulse-counting (digital) FOG output: the integrated angle is
/// counted in pulses of `pulse_arcsec`, and each sample outputs (pulses this period)·q/Δt.
/// The error is white in angle, which gives the -1 Allan slope of quantization noise,
/// Q = q/√12 (IEEE Std 952-1997 C.1.2), as long as the other noise randomises the pulse phase
/// (with a noiseless constant rate the error is a deterministic pattern instead).
/// `pulse_arcsec = 0` switches it off.
#[derive(Debug, Clone)]
pub(crate) struct Quantizer {
    q_deg: f64,
    angle_deg: f64,
    last_count: f64,
}

impl Quantizer {
    /// Starts with a random sub-pulse phase (from `g`).
    pub(crate) fn new(pulse_arcsec: f64, g: &mut Gauss) -> Self {
        let q_deg = pulse_arcsec / 3600.0;
        let angle_deg = g.uniform() * q_deg;
        Quantizer {
            q_deg,
            angle_deg,
            last_count: 0.0,
        }
    }

    /// Output rate, °/s, for a sample period `dt_s` with true mean rate `rate_dps`.
    pub(crate) fn output_dps(&mut self, rate_dps: f64, dt_s: f64) -> f64 {
        if self.q_deg <= 0.0 {
            return rate_dps;
        }
        self.angle_deg += rate_dps * dt_s;
        let count = libm::floor(self.angle_deg / self.q_deg);
        let out = (count - self.last_count) * self.q_deg / dt_s;
        self.last_count = count;
        out
    }
}

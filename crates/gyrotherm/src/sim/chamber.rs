//! Thermal-chamber air temperature: a second-order response to the set point, plus ripple.
//!
//! Air temperature x follows the set point s as a damped second-order system
//! x'' = ωn²·(s - x) - 2ζωn·x' (a PID-controlled chamber seen from outside), which lags a
//! ramp by 2ζ/ωn·rate and overshoots when the ramp stops. With the defaults
//! (ωn = 0.02 rad/s, ζ = 0.6) a 3 °C/min ramp lags by 3 °C and overshoots by about 1 °C, in
//! line with chamber data sheets (±0.5-1 °C overshoot, ±0.3 °C fluctuation). On top: ripple =
//! a sinusoid (compressor / heater cycling) and a Gauss-Markov fluctuation.

use serde::{Deserialize, Serialize};

use super::noise::{Gauss, GaussMarkov};

/// Chamber parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChamberParams {
    /// Natural frequency ωn of the air-temperature loop, rad/s.
    pub natural_freq_rad_s: f64,
    /// Damping ratio ζ (dimensionless; < 1 overshoots).
    pub damping: f64,
    /// Ripple sinusoid amplitude, °C.
    pub ripple_amp_c: f64,
    /// Ripple sinusoid period, s.
    pub ripple_period_s: f64,
    /// Standard deviation of the random air fluctuation, °C.
    pub fluct_sigma_c: f64,
    /// Correlation time of the random air fluctuation, s.
    pub fluct_tau_s: f64,
}

impl Default for ChamberParams {
    fn default() -> Self {
        ChamberParams {
            natural_freq_rad_s: 0.02,
            damping: 0.6,
            ripple_amp_c: 0.15,
            ripple_period_s: 240.0,
            fluct_sigma_c: 0.05,
            fluct_tau_s: 60.0,
        }
    }
}

impl ChamberParams {
    pub(crate) fn validate(&self) -> Result<(), String> {
        let pos = [
            ("natural_freq_rad_s", self.natural_freq_rad_s),
            ("damping", self.damping),
            ("ripple_period_s", self.ripple_period_s),
            ("fluct_tau_s", self.fluct_tau_s),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("chamber {name} = {v} must be finite and > 0"));
            }
        }
        for (name, v) in [
            ("ripple_amp_c", self.ripple_amp_c),
            ("fluct_sigma_c", self.fluct_sigma_c),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("chamber {name} = {v} must be finite and >= 0"));
            }
        }
        if self.natural_freq_rad_s > 1.0 {
            return Err(format!(
                "chamber natural_freq_rad_s = {} is faster than any chamber (at most 1 rad/s)",
                self.natural_freq_rad_s
            ));
        }
        Ok(())
    }
}

/// Chamber state.
#[derive(Debug, Clone)]
pub(crate) struct Chamber {
    p: ChamberParams,
    x_c: f64,
    v_c_per_s: f64,
    fluct: GaussMarkov,
    g: Gauss,
    phase: f64,
}

impl Chamber {
    /// At rest at `start_c`; `substep_s` is the integration step used by [`Chamber::advance`].
    pub(crate) fn new(p: ChamberParams, start_c: f64, substep_s: f64, seed: u64) -> Self {
        let mut g = Gauss::new(seed, 10);
        let fluct = GaussMarkov::new(p.fluct_sigma_c, p.fluct_tau_s, substep_s, &mut g);
        let phase = g.uniform() * 2.0 * core::f64::consts::PI;
        Chamber {
            p,
            x_c: start_c,
            v_c_per_s: 0.0,
            fluct,
            g,
            phase,
        }
    }

    /// Advance the loop by `h_s` towards set point `sp_c` (semi-implicit Euler; stable for
    /// ωn·h < 1, we use h ≤ 0.5 s).
    pub(crate) fn advance(&mut self, sp_c: f64, h_s: f64) {
        let wn = self.p.natural_freq_rad_s;
        let acc = wn * wn * (sp_c - self.x_c) - 2.0 * self.p.damping * wn * self.v_c_per_s;
        self.v_c_per_s += h_s * acc;
        self.x_c += h_s * self.v_c_per_s;
        self.fluct.step(&mut self.g);
    }

    /// Air temperature at time `t_s`, °C (loop output + ripple + fluctuation).
    pub(crate) fn air_c(&self, t_s: f64) -> f64 {
        let w = 2.0 * core::f64::consts::PI / self.p.ripple_period_s;
        self.x_c + self.p.ripple_amp_c * libm::sin(w * t_s + self.phase) + self.fluct.value()
    }
}

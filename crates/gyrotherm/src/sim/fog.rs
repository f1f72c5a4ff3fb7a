//! The FOG unit: thermal nodes, bias and scale-factor physics, temperature sensor.
//!
//! Thermal nodes (first-order lags, sampled exactly: y += (u - y)·(1 - e^{-h/τ})):
//! - mount T_mount (optional, `mount_tau_s > 0`): lag of the chamber air (mounting plate or
//!   fixture between chamber and housing);
//! - case  T_case: lag of the mounting node, or of the chamber air without one,
//!   τ = `case_tau_s`;
//! - coil  T_coil: lag of the case, τ = `coil_tau_s` (the fiber coil sits inside, potted);
//! - stress state S: lag of the coil, τ = `stress_tau_s` (slow relaxation of the potting and
//!   fiber jacket; makes the output depend on temperature history — hysteresis);
//! - sensor T_sens: lag of the node named by `sensor_node` (mount, case — the default, as in
//!   He et al. 2024 — or coil), τ = `sensor_tau_s`.
//!
//! Bias, °/h, with ΔT = T_coil - `ref_temp_c` (He et al. 2024 eq. (3): B = B0 - Be):
//! ```text
//! B = bias0_dph + Ω_e·sin φ                        constant + Earth rate (Ω_e = 15.041 °/h,
//!                                                   input axis up, latitude φ)
//!   + c1·ΔT + c2·ΔT² + c3·ΔT³                        stress-induced, static in T (°/h/°C^k)
//!   + shupe_dph_per_c_per_s·(1 + shupe_tc_per_c·ΔT)·dT_coil/dt
//!                                                    Shupe term (Shupe 1980, Appl. Opt. 19(5)):
//!                                                    ∝ the coil temperature rate, zero when
//!                                                    steady; the ΔT factor models the
//!                                                    potting's temperature-dependent stiffness
//!                                                    (elasto-optic part, Mohr 1996)
//!   + stress_dph_per_c·(T_coil - S)                  stress relaxation / hysteresis (°/h/°C)
//!   + shupe_grad_dph_per_c_per_s·d(T_case - T_coil)/dt
//!                                                    radial-gradient Shupe term: the rate of
//!                                                    change of the gradient across the coil
//!                                                    (Mohr 1996, transient thermal gradients)
//!   + rate_sat_dph·tanh(dT_coil/dt / rate_sat_c_per_s)
//!                                                    saturating rate term (potting that stops
//!                                                    following the rate: tanh-like)
//! ```
//! For a first-order coil node dT_coil/dt = (T_case - T_coil)/τ_coil, so the Shupe term is
//! also the case-to-coil gradient term; it is evaluated from that formula (no numerical
//! differentiation).
//!
//! Scale factor (dimensionless, Ĝ = B + K·G, He et al. eq. (1),(2)): with ΔT on the coil,
//! K = 1 + 1e-6·(`sf_offset_ppm` + `sf_c1_ppm_per_c`·ΔT + `sf_c2_ppm_per_c2`·ΔT² +
//! `sf_c3_ppm_per_c3`·ΔT³ + `sf_rate_ppm_per_c_per_s`·dT_coil/dt +
//! `sf_stress_ppm_per_c`·(T_coil - S)) (fiber length and refractive index, source
//! wavelength; the lag comes from the coil node). The rate derivatives are evaluated from the
//! node equations (d T/dt = (drive - T)/τ), not by numerical differentiation. The terms after
//! the stress term are zero for the default unit; [`super::family`] draws units that use them.
//!
//! Temperature sensor reading (the logged `temp_c`, DS18B20 class, He et al. sec. 3: ±0.5 °C
//! accuracy, 0.0625 °C resolution): round((T_sens + offset + noise) / res)·res.

use serde::{Deserialize, Serialize};

use super::SimError;

/// Earth's rotation rate relative to the stars, °/h (15.041 °/h; IERS: 7.292115e-5 rad/s).
pub const EARTH_RATE_DPH: f64 = 15.041067;

/// Parameters of one simulated FOG. Every field has the built-in default unit's value, so a
/// JSON parameter file may give only the fields it changes (unknown names are an error).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FogUnit {
    /// Free-text name.
    pub name: String,
    /// Case thermal time constant (chamber air → case), s.
    pub case_tau_s: f64,
    /// Coil thermal time constant (case → coil), s.
    pub coil_tau_s: f64,
    /// Stress-relaxation time constant (coil → stress state), s.
    pub stress_tau_s: f64,
    /// Reference (room) temperature of the polynomial coefficients, °C.
    pub ref_temp_c: f64,
    /// Constant bias B0 at `ref_temp_c`, °/h (Earth rate excluded).
    pub bias0_dph: f64,
    /// Linear bias coefficient on the coil temperature, °/h/°C.
    pub bias_c1_dph_per_c: f64,
    /// Quadratic bias coefficient, °/h/°C².
    pub bias_c2_dph_per_c2: f64,
    /// Cubic bias coefficient, °/h/°C³.
    pub bias_c3_dph_per_c3: f64,
    /// Shupe coefficient: bias per coil temperature rate, °/h per °C/s.
    pub shupe_dph_per_c_per_s: f64,
    /// Relative change of the Shupe coefficient per °C of ΔT, 1/°C.
    pub shupe_tc_per_c: f64,
    /// Stress / hysteresis coefficient on T_coil - S, °/h/°C.
    pub stress_dph_per_c: f64,
    /// Scale-factor error at `ref_temp_c`, ppm.
    pub sf_offset_ppm: f64,
    /// Linear scale-factor coefficient on the coil temperature, ppm/°C.
    pub sf_c1_ppm_per_c: f64,
    /// Quadratic scale-factor coefficient, ppm/°C².
    pub sf_c2_ppm_per_c2: f64,
    /// Angle random walk N, °/√h.
    pub arw_deg_rt_h: f64,
    /// Bias instability B, °/h (Allan floor 0.6643·B).
    pub bias_instability_dph: f64,
    /// Rate random walk K, °/h/√h.
    pub rrw_dph_rt_h: f64,
    /// Output pulse weight (angle quantum), arcsec; 0 = no quantization.
    pub pulse_arcsec: f64,
    /// Temperature sensor offset (calibration error), °C.
    pub sensor_offset_c: f64,
    /// Temperature sensor white noise, °C (1σ per reading).
    pub sensor_noise_c: f64,
    /// Temperature sensor resolution, °C (DS18B20 at 12 bits: 0.0625 °C); 0 = none.
    pub sensor_resolution_c: f64,
    /// Temperature sensor thermal lag behind the node it sits on, s.
    pub sensor_tau_s: f64,
    /// Mounting-node time constant (chamber air → mounting plate → case), s; 0: no mounting
    /// node, the case follows the chamber air directly.
    pub mount_tau_s: f64,
    /// The node the temperature sensor sits on.
    pub sensor_node: SensorNode,
    /// Radial-gradient Shupe coefficient: bias per rate of change of T_case - T_coil,
    /// °/h per °C/s.
    pub shupe_grad_dph_per_c_per_s: f64,
    /// Saturating rate term: amplitude A, °/h, of A·tanh(dT_coil/dt / r_s).
    pub rate_sat_dph: f64,
    /// Saturating rate term: the coil rate r_s at which it reaches tanh(1) of its amplitude,
    /// °C/s (> 0).
    pub rate_sat_c_per_s: f64,
    /// Cubic scale-factor coefficient on the coil temperature, ppm/°C³.
    pub sf_c3_ppm_per_c3: f64,
    /// Scale factor per coil temperature rate, ppm per °C/s.
    pub sf_rate_ppm_per_c_per_s: f64,
    /// Scale factor per stress lag T_coil - S, ppm/°C.
    pub sf_stress_ppm_per_c: f64,
}

/// Where the temperature sensor sits (the logged `temp_c` follows this node through the
/// sensor's own lag).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SensorNode {
    /// On the mounting plate (the case when the unit has no mounting node).
    Mount,
    /// On the housing (case), as in He et al. 2024's test set-up.
    #[default]
    Case,
    /// On the fiber coil.
    Coil,
}

impl Default for FogUnit {
    /// The built-in unit, tuned so that its raw figures on `seed-shock` at 1 Hz match He et al.
    /// 2024 (static bias stability 0.13861 °/h over 100 s means; ~20.009 °/s at +20 °/s), and
    /// the held-out fits recorded in docs/experiments/. Measured (seed 7, 1 Hz): raw bias stability 0.137 °/h,
    /// noise-only floor 0.0078 °/h, +20 °/s output 20.0103 °/s cold / 20.0092 °/s hot; a
    /// (T, dT) linear fit trained on `seed-shock` leaves 0.031 °/h on another `seed-shock`
    /// run, 0.016 on `slow-ramp`, 0.047 on `fast-cycle`. Checked in `tests/sim_calibration.rs`.
    fn default() -> Self {
        FogUnit {
            name: "default (navigation-grade FOG, no thermostat)".into(),
            case_tau_s: 180.0,
            coil_tau_s: 300.0,
            stress_tau_s: 2500.0,
            ref_temp_c: 20.0,
            bias0_dph: 0.5,
            bias_c1_dph_per_c: 0.003,
            bias_c2_dph_per_c2: 8e-6,
            bias_c3_dph_per_c3: 0.0,
            shupe_dph_per_c_per_s: 1.0,
            shupe_tc_per_c: 0.012,
            stress_dph_per_c: 0.0015,
            sf_offset_ppm: 150.0,
            sf_c1_ppm_per_c: 1.0,
            sf_c2_ppm_per_c2: 0.08,
            arw_deg_rt_h: 0.0008,
            bias_instability_dph: 0.0055,
            rrw_dph_rt_h: 0.001,
            pulse_arcsec: 0.02,
            sensor_offset_c: 0.3,
            sensor_noise_c: 0.01,
            sensor_resolution_c: 0.0625,
            sensor_tau_s: 20.0,
            mount_tau_s: 0.0,
            sensor_node: SensorNode::Case,
            shupe_grad_dph_per_c_per_s: 0.0,
            rate_sat_dph: 0.0,
            rate_sat_c_per_s: 0.01,
            sf_c3_ppm_per_c3: 0.0,
            sf_rate_ppm_per_c_per_s: 0.0,
            sf_stress_ppm_per_c: 0.0,
        }
    }
}

/// A field of [`FogUnit`] that is a quantum: name, getter, its range when not 0, unit, what.
type Quantum = (
    &'static str,
    fn(&FogUnit) -> f64,
    (f64, f64),
    &'static str,
    &'static str,
);

/// The quanta a unit may have. Temperature sensors resolve 0.0001 °C (a 24-bit RTD
/// converter) to 1 °C (a coarse thermistor); 1e-6 to 10 °C spans them with room. FOG pulse
/// weights are about 0.01 to 10 arcsec; 1e-6 to 3600 arcsec spans them with room.
const QUANTA: [Quantum; 2] = [
    (
        "sensor_resolution_c",
        |u| u.sensor_resolution_c,
        (1e-6, 10.0),
        "°C",
        "temperature sensor resolution",
    ),
    (
        "pulse_arcsec",
        |u| u.pulse_arcsec,
        (1e-6, 3600.0),
        "arcsec",
        "pulse weight",
    ),
];

/// Largest temperature-sensor offset or noise (1σ) a unit may have, °C: beyond it the
/// logged temperature no longer follows the unit's (chamber set points span −80 to 180 °C).
pub(crate) const MAX_SENSOR_ERROR_C: f64 = 100.0;

impl FogUnit {
    /// Parse a JSON parameter file's text: the given fields override the default unit's.
    pub fn from_json_str(text: &str, source: &str) -> Result<FogUnit, SimError> {
        let unit: FogUnit = serde_json::from_str(text).map_err(|e| SimError::Unit {
            field: source.to_owned(),
            message: format!(
                "{e} (fields are those of FogUnit; see `gyrotherm simulate --print-unit`)"
            ),
        })?;
        unit.validate()?;
        Ok(unit)
    }

    /// Read a JSON parameter file (partial override of the default unit).
    pub fn load(path: &std::path::Path) -> Result<FogUnit, SimError> {
        let text =
            crate::input_file::read_capped_to_string(path, crate::input_file::InputKind::SimUnit)
                .map_err(|e| SimError::Io {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        FogUnit::from_json_str(&text, &path.display().to_string())
    }

    /// Checks every field: finite; time constants > 0; noise terms and resolution ≥ 0; the
    /// quanta 0 or within a real part's range; the sensor's offset and noise at most
    /// `MAX_SENSOR_ERROR_C`.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |field: &str, message: String| {
            Err(SimError::Unit {
                field: field.to_owned(),
                message,
            })
        };
        let finite = [
            ("ref_temp_c", self.ref_temp_c),
            ("bias0_dph", self.bias0_dph),
            ("bias_c1_dph_per_c", self.bias_c1_dph_per_c),
            ("bias_c2_dph_per_c2", self.bias_c2_dph_per_c2),
            ("bias_c3_dph_per_c3", self.bias_c3_dph_per_c3),
            ("shupe_dph_per_c_per_s", self.shupe_dph_per_c_per_s),
            ("shupe_tc_per_c", self.shupe_tc_per_c),
            ("stress_dph_per_c", self.stress_dph_per_c),
            ("sf_offset_ppm", self.sf_offset_ppm),
            ("sf_c1_ppm_per_c", self.sf_c1_ppm_per_c),
            ("sf_c2_ppm_per_c2", self.sf_c2_ppm_per_c2),
            ("sensor_offset_c", self.sensor_offset_c),
            (
                "shupe_grad_dph_per_c_per_s",
                self.shupe_grad_dph_per_c_per_s,
            ),
            ("rate_sat_dph", self.rate_sat_dph),
            ("sf_c3_ppm_per_c3", self.sf_c3_ppm_per_c3),
            ("sf_rate_ppm_per_c_per_s", self.sf_rate_ppm_per_c_per_s),
            ("sf_stress_ppm_per_c", self.sf_stress_ppm_per_c),
        ];
        for (f, v) in finite {
            if !v.is_finite() {
                return bad(f, format!("{v} is not finite"));
            }
        }
        let positive = [
            ("case_tau_s", self.case_tau_s),
            ("coil_tau_s", self.coil_tau_s),
            ("stress_tau_s", self.stress_tau_s),
            ("sensor_tau_s", self.sensor_tau_s),
            ("rate_sat_c_per_s", self.rate_sat_c_per_s),
        ];
        for (f, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(f, format!("{v} must be a finite time constant > 0 s"));
            }
        }
        let non_negative = [
            ("arw_deg_rt_h", self.arw_deg_rt_h),
            ("bias_instability_dph", self.bias_instability_dph),
            ("rrw_dph_rt_h", self.rrw_dph_rt_h),
            ("pulse_arcsec", self.pulse_arcsec),
            ("sensor_noise_c", self.sensor_noise_c),
            ("sensor_resolution_c", self.sensor_resolution_c),
            ("mount_tau_s", self.mount_tau_s),
        ];
        for (f, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(f, format!("{v} must be finite and >= 0"));
            }
        }
        // A quantum is 0 (none) or within what a real part has: a reading divided by a
        // quantum far below it overflows (1e-320 °C makes every temperature infinite), and
        // one far above it leaves nothing of the signal.
        for (f, v, (lo, hi), unit, what) in QUANTA {
            let v = v(self);
            if v != 0.0 && !(lo..=hi).contains(&v) {
                return bad(
                    f,
                    format!(
                        "{} {unit} is not a {what}: give 0 (none) or {lo:e} to {hi} {unit}",
                        crate::csvlog::short_f64(v)
                    ),
                );
            }
        }
        let sensor = [
            ("sensor_offset_c", self.sensor_offset_c.abs()),
            ("sensor_noise_c", self.sensor_noise_c),
        ];
        for (f, v) in sensor {
            if v > MAX_SENSOR_ERROR_C {
                return bad(
                    f,
                    format!(
                        "{v} °C is beyond {MAX_SENSOR_ERROR_C} °C, more than a working \
                         temperature sensor's error"
                    ),
                );
            }
        }
        Ok(())
    }

    /// Thermal part of the bias (everything but b0, Earth rate and noise), °/h, from the coil
    /// temperature, its rate and the stress state.
    pub fn thermal_bias_dph(&self, coil_c: f64, coil_rate_c_per_s: f64, stress_c: f64) -> f64 {
        let dt = coil_c - self.ref_temp_c;
        (self.bias_c1_dph_per_c + (self.bias_c2_dph_per_c2 + self.bias_c3_dph_per_c3 * dt) * dt)
            * dt
            + self.shupe_dph_per_c_per_s * (1.0 + self.shupe_tc_per_c * dt) * coil_rate_c_per_s
            + self.stress_dph_per_c * (coil_c - stress_c)
    }

    /// Scale factor K (dimensionless, ≈ 1) at coil temperature `coil_c`, the rest of the
    /// state at rest (no coil rate, stress state at the coil temperature).
    pub fn scale(&self, coil_c: f64) -> f64 {
        self.scale_ppm_terms(coil_c, 0.0, coil_c)
    }

    /// Scale factor K of a thermal state: the coil polynomial plus the coil-rate and stress
    /// terms.
    pub(crate) fn scale_of_state(&self, s: &ThermalState) -> f64 {
        self.scale_ppm_terms(s.coil_c, s.coil_rate_c_per_s(self), s.stress_c)
    }

    fn scale_ppm_terms(&self, coil_c: f64, coil_rate_c_per_s: f64, stress_c: f64) -> f64 {
        let dt = coil_c - self.ref_temp_c;
        1.0 + 1e-6
            * (self.sf_offset_ppm
                + (self.sf_c1_ppm_per_c
                    + (self.sf_c2_ppm_per_c2 + self.sf_c3_ppm_per_c3 * dt) * dt)
                    * dt
                + self.sf_rate_ppm_per_c_per_s * coil_rate_c_per_s
                + self.sf_stress_ppm_per_c * (coil_c - stress_c))
    }

    /// The bias terms beyond [`FogUnit::thermal_bias_dph`], °/h: the radial-gradient Shupe
    /// term on d(T_case - T_coil)/dt and the saturating rate term A·tanh(dT_coil/dt / r_s),
    /// for the state `s` with chamber air at `air_c`.
    pub(crate) fn gradient_and_saturation_bias_dph(&self, s: &ThermalState, air_c: f64) -> f64 {
        let coil_rate = s.coil_rate_c_per_s(self);
        let grad_rate = s.case_rate_c_per_s(self, air_c) - coil_rate;
        self.shupe_grad_dph_per_c_per_s * grad_rate
            + self.rate_sat_dph * libm::tanh(coil_rate / self.rate_sat_c_per_s)
    }

    /// Whether the unit has a mounting node between the chamber air and the case.
    pub(crate) fn has_mount(&self) -> bool {
        self.mount_tau_s > 0.0
    }
}

/// Exact one-step factor of a first-order lag: 1 - e^{-h/τ}.
pub(crate) fn lag_alpha(h_s: f64, tau_s: f64) -> f64 {
    1.0 - libm::exp(-h_s / tau_s)
}

/// Thermal state of the unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ThermalState {
    /// Mounting-node temperature, °C (follows the chamber air when the unit has none).
    pub mount_c: f64,
    /// Case temperature, °C.
    pub case_c: f64,
    /// Coil temperature, °C.
    pub coil_c: f64,
    /// Stress state, °C.
    pub stress_c: f64,
    /// Temperature at the sensor element, °C (before offset, noise, resolution).
    pub sensor_c: f64,
}

impl ThermalState {
    /// Everything in equilibrium at `temp_c`.
    pub fn steady(temp_c: f64) -> Self {
        ThermalState {
            mount_c: temp_c,
            case_c: temp_c,
            coil_c: temp_c,
            stress_c: temp_c,
            sensor_c: temp_c,
        }
    }

    /// Coil temperature rate, °C/s (= (T_case - T_coil)/τ_coil for the first-order node).
    pub(crate) fn coil_rate_c_per_s(&self, unit: &FogUnit) -> f64 {
        (self.case_c - self.coil_c) / unit.coil_tau_s
    }

    /// Case temperature rate, °C/s, with chamber air at `air_c`: (drive - T_case)/τ_case, the
    /// drive being the mounting node, or the air when the unit has none.
    pub(crate) fn case_rate_c_per_s(&self, unit: &FogUnit, air_c: f64) -> f64 {
        let drive = if unit.has_mount() {
            self.mount_c
        } else {
            air_c
        };
        (drive - self.case_c) / unit.case_tau_s
    }
}

/// Precomputed lag factors for one integration step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ThermalStep {
    /// Mounting-node factor; None: no mounting node.
    mount: Option<f64>,
    sensor_node: SensorNode,
    case: f64,
    coil: f64,
    stress: f64,
    sensor: f64,
}

impl ThermalStep {
    pub(crate) fn new(unit: &FogUnit, h_s: f64) -> Self {
        ThermalStep {
            mount: unit.has_mount().then(|| lag_alpha(h_s, unit.mount_tau_s)),
            sensor_node: unit.sensor_node,
            case: lag_alpha(h_s, unit.case_tau_s),
            coil: lag_alpha(h_s, unit.coil_tau_s),
            stress: lag_alpha(h_s, unit.stress_tau_s),
            sensor: lag_alpha(h_s, unit.sensor_tau_s),
        }
    }

    /// One step with chamber air at `air_c` (each node driven by its upstream node's value at
    /// the start of the step).
    pub(crate) fn advance(&self, s: &mut ThermalState, air_c: f64) {
        let (mount, case, coil) = (s.mount_c, s.case_c, s.coil_c);
        let case_drive = match self.mount {
            Some(a) => {
                s.mount_c += (air_c - mount) * a;
                mount
            }
            None => {
                s.mount_c = air_c;
                air_c
            }
        };
        let sensed = match (self.sensor_node, self.mount) {
            (SensorNode::Mount, Some(_)) => mount,
            (SensorNode::Mount, None) | (SensorNode::Case, _) => case,
            (SensorNode::Coil, _) => coil,
        };
        s.case_c += (case_drive - case) * self.case;
        s.coil_c += (case - coil) * self.coil;
        s.stress_c += (coil - s.stress_c) * self.stress;
        s.sensor_c += (sensed - s.sensor_c) * self.sensor;
    }
}

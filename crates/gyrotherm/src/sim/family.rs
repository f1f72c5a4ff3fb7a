//! A family of simulated units: [`UnitRanges::draw`] picks one physically plausible FOG from
//! documented ranges, so that a method can be judged on gyros nobody tuned it to.
//!
//! Every drawn unit uses the whole physics of [`super::fog`]: two or three chained thermal
//! nodes (an optional mounting plate, the housing, the coil), the sensor on one of them, a
//! bias up to cubic in the coil temperature, the coil-rate Shupe term with a temperature
//! coefficient, the radial-gradient Shupe term, a stress memory of hours, a saturating rate
//! term, and a scale factor on the same states; noise at the default unit's class.
//!
//! Ranges ([`UnitRanges::default`]; `±a–b` means a magnitude uniform in `[a, b]` with a random
//! sign, `log a–b` log-uniform):
//!
//! | parameter | range | why |
//! |---|---|---|
//! | mounting node | present with probability ½; τ log 100–5000 s | fixture between chamber and housing |
//! | case, coil τ | log 100–5000 s | potted coils in housings: minutes to over an hour |
//! | stress τ | log 3600–14400 s | relaxation memory of hours |
//! | sensor node | uniform over the nodes present | housing, plate or coil-mounted sensors |
//! | sensor τ, offset, noise | log 5–60 s, ±0–0.5 °C, 0.005–0.02 °C; 0.0625 °C steps | DS18B20 (He et al. 2024 §3: ±0.5 °C, 12 bits) |
//! | reference temperature | 18–26 °C | |
//! | B0 | 0–1 °/h | turn-on bias |
//! | c1, c2, c3 | ±0.001–0.006 °/h/°C, ±2e-6–2e-5 °/h/°C², ±0–3e-7 °/h/°C³ | default unit: 0.003, 8e-6, 0 |
//! | Shupe, its temperature coefficient | ±0.3–2 °/h per °C/s, ±0–0.03 /°C | default unit: 1.0, 0.012 |
//! | gradient Shupe | ±0–3 °/h per °C/s | |
//! | stress | ±0.0005–0.004 °/h/°C | default unit: 0.0015 |
//! | saturating rate term | ±0.005–0.04 °/h, saturating at log 0.002–0.02 °C/s | |
//! | SF offset, c1, c2, c3 | 0–300 ppm, ±0.3–2 ppm/°C, ±0.02–0.12 ppm/°C², ±0–5e-4 ppm/°C³ | default unit: 150, 1, 0.08, 0 |
//! | SF rate, stress | ±0–200 ppm per °C/s, ±0–0.5 ppm/°C | |
//! | ARW, bias instability, RRW | 0.0005–0.0012 °/√h, 0.003–0.008 °/h, 0.0005–0.002 °/h/√h | default unit: 0.0008, 0.0055, 0.001 |
//!
//! Draws come from a ChaCha8 stream of the unit seed (stream 40, apart from the run's noise
//! streams), in a fixed order, so a seed names one unit on every platform.

use super::fog::{FogUnit, SensorNode};
use super::noise::Gauss;

/// The ChaCha8 stream a unit is drawn from (apart from the run's noise streams, 1 to 31).
pub(crate) const UNIT_STREAM: u64 = 40;

/// A closed interval `(lo, hi)`.
pub(crate) type Interval = (f64, f64);

/// The ranges a unit is drawn from (see the module doc for the defaults and their reasons).
/// Signed entries give the magnitude; the sign is drawn separately.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitRanges {
    /// Probability that the unit has a mounting node (three nodes instead of two).
    pub mount_probability: f64,
    /// Mounting, case and coil time constants, s (log-uniform).
    pub node_tau_s: Interval,
    /// Stress-relaxation time constant, s (log-uniform).
    pub stress_tau_s: Interval,
    /// Sensor lag, s (log-uniform).
    pub sensor_tau_s: Interval,
    /// Sensor offset magnitude, °C (signed).
    pub sensor_offset_c: Interval,
    /// Sensor white noise, °C.
    pub sensor_noise_c: Interval,
    /// Sensor resolution, °C (fixed: the DS18B20's 12-bit step).
    pub sensor_resolution_c: f64,
    /// Reference temperature, °C.
    pub ref_temp_c: Interval,
    /// Constant bias, °/h.
    pub bias0_dph: Interval,
    /// Linear, quadratic, cubic bias coefficients (signed magnitudes).
    pub bias_c1_dph_per_c: Interval,
    pub bias_c2_dph_per_c2: Interval,
    pub bias_c3_dph_per_c3: Interval,
    /// Shupe coefficient and its temperature coefficient (signed).
    pub shupe_dph_per_c_per_s: Interval,
    pub shupe_tc_per_c: Interval,
    /// Radial-gradient Shupe coefficient (signed).
    pub shupe_grad_dph_per_c_per_s: Interval,
    /// Stress coefficient (signed).
    pub stress_dph_per_c: Interval,
    /// Saturating rate term amplitude (signed) and saturation rate (log-uniform).
    pub rate_sat_dph: Interval,
    pub rate_sat_c_per_s: Interval,
    /// Scale-factor offset, ppm.
    pub sf_offset_ppm: Interval,
    /// Scale-factor coefficients (signed).
    pub sf_c1_ppm_per_c: Interval,
    pub sf_c2_ppm_per_c2: Interval,
    pub sf_c3_ppm_per_c3: Interval,
    pub sf_rate_ppm_per_c_per_s: Interval,
    pub sf_stress_ppm_per_c: Interval,
    /// Noise: ARW °/√h, bias instability °/h, RRW °/h/√h.
    pub arw_deg_rt_h: Interval,
    pub bias_instability_dph: Interval,
    pub rrw_dph_rt_h: Interval,
}

impl Default for UnitRanges {
    fn default() -> Self {
        UnitRanges {
            mount_probability: 0.5,
            node_tau_s: (100.0, 5000.0),
            stress_tau_s: (3600.0, 14400.0),
            sensor_tau_s: (5.0, 60.0),
            sensor_offset_c: (0.0, 0.5),
            sensor_noise_c: (0.005, 0.02),
            sensor_resolution_c: 0.0625,
            ref_temp_c: (18.0, 26.0),
            bias0_dph: (0.0, 1.0),
            bias_c1_dph_per_c: (0.001, 0.006),
            bias_c2_dph_per_c2: (2e-6, 2e-5),
            bias_c3_dph_per_c3: (0.0, 3e-7),
            shupe_dph_per_c_per_s: (0.3, 2.0),
            shupe_tc_per_c: (0.0, 0.03),
            shupe_grad_dph_per_c_per_s: (0.0, 3.0),
            stress_dph_per_c: (0.0005, 0.004),
            rate_sat_dph: (0.005, 0.04),
            rate_sat_c_per_s: (0.002, 0.02),
            sf_offset_ppm: (0.0, 300.0),
            sf_c1_ppm_per_c: (0.3, 2.0),
            sf_c2_ppm_per_c2: (0.02, 0.12),
            sf_c3_ppm_per_c3: (0.0, 5e-4),
            sf_rate_ppm_per_c_per_s: (0.0, 200.0),
            sf_stress_ppm_per_c: (0.0, 0.5),
            arw_deg_rt_h: (0.0005, 0.0012),
            bias_instability_dph: (0.003, 0.008),
            rrw_dph_rt_h: (0.0005, 0.002),
        }
    }
}

/// Draws in a fixed order from one stream.
struct Draw(Gauss);

impl Draw {
    fn uniform(&mut self, (lo, hi): Interval) -> f64 {
        lo + (hi - lo) * self.0.uniform()
    }
    fn log_uniform(&mut self, (lo, hi): Interval) -> f64 {
        libm::exp(self.uniform((libm::log(lo), libm::log(hi))))
    }
    fn signed(&mut self, r: Interval) -> f64 {
        let sign = if self.0.uniform() < 0.5 { -1.0 } else { 1.0 };
        sign * self.uniform(r)
    }
}

impl UnitRanges {
    /// The unit of seed `unit_seed` (same seed, same unit), named `random unit <seed>`.
    pub fn draw(&self, unit_seed: u64) -> FogUnit {
        self.draw_on_stream(unit_seed, UNIT_STREAM)
    }

    /// [`UnitRanges::draw`] from another ChaCha8 stream of the same seed: the further gyros of
    /// an inertial unit ([`super::imu`]) are drawn from streams after [`UNIT_STREAM`], so the
    /// first gyro of unit N is single-axis unit N's gyro.
    pub(crate) fn draw_on_stream(&self, unit_seed: u64, stream: u64) -> FogUnit {
        let mut d = Draw(Gauss::new(unit_seed, stream));
        let has_mount = d.0.uniform() < self.mount_probability;
        let mount_tau_s = d.log_uniform(self.node_tau_s);
        let case_tau_s = d.log_uniform(self.node_tau_s);
        let coil_tau_s = d.log_uniform(self.node_tau_s);
        let nodes: &[SensorNode] = if has_mount {
            &[SensorNode::Mount, SensorNode::Case, SensorNode::Coil]
        } else {
            &[SensorNode::Case, SensorNode::Coil]
        };
        let pick = ((d.0.uniform() * nodes.len() as f64) as usize).min(nodes.len() - 1);
        FogUnit {
            name: format!("random unit {unit_seed}"),
            mount_tau_s: if has_mount { mount_tau_s } else { 0.0 },
            case_tau_s,
            coil_tau_s,
            sensor_node: nodes[pick],
            stress_tau_s: d.log_uniform(self.stress_tau_s),
            sensor_tau_s: d.log_uniform(self.sensor_tau_s),
            sensor_offset_c: d.signed(self.sensor_offset_c),
            sensor_noise_c: d.uniform(self.sensor_noise_c),
            sensor_resolution_c: self.sensor_resolution_c,
            ref_temp_c: d.uniform(self.ref_temp_c),
            bias0_dph: d.uniform(self.bias0_dph),
            bias_c1_dph_per_c: d.signed(self.bias_c1_dph_per_c),
            bias_c2_dph_per_c2: d.signed(self.bias_c2_dph_per_c2),
            bias_c3_dph_per_c3: d.signed(self.bias_c3_dph_per_c3),
            shupe_dph_per_c_per_s: d.signed(self.shupe_dph_per_c_per_s),
            shupe_tc_per_c: d.signed(self.shupe_tc_per_c),
            shupe_grad_dph_per_c_per_s: d.signed(self.shupe_grad_dph_per_c_per_s),
            stress_dph_per_c: d.signed(self.stress_dph_per_c),
            rate_sat_dph: d.signed(self.rate_sat_dph),
            rate_sat_c_per_s: d.log_uniform(self.rate_sat_c_per_s),
            sf_offset_ppm: d.uniform(self.sf_offset_ppm),
            sf_c1_ppm_per_c: d.signed(self.sf_c1_ppm_per_c),
            sf_c2_ppm_per_c2: d.signed(self.sf_c2_ppm_per_c2),
            sf_c3_ppm_per_c3: d.signed(self.sf_c3_ppm_per_c3),
            sf_rate_ppm_per_c_per_s: d.signed(self.sf_rate_ppm_per_c_per_s),
            sf_stress_ppm_per_c: d.signed(self.sf_stress_ppm_per_c),
            arw_deg_rt_h: d.uniform(self.arw_deg_rt_h),
            bias_instability_dph: d.uniform(self.bias_instability_dph),
            rrw_dph_rt_h: d.uniform(self.rrw_dph_rt_h),
            ..FogUnit::default()
        }
    }
}

/// The unit of seed `unit_seed` drawn from the default [`UnitRanges`]
/// (`gyrotherm simulate --unit random --unit-seed N`).
pub fn random_unit(unit_seed: u64) -> FogUnit {
    UnitRanges::default().draw(unit_seed)
}

//! Thermal-chamber + FOG simulator: realistic temperature-shock test logs with known truth.
//!
//! No real thermal-chamber FOG logs are public, so gyrotherm makes its own. A run is
//! chamber set point ([`profile`]) → chamber air ([`chamber`]: second-order loop, overshoot,
//! ripple) → case, coil, stress and sensor nodes ([`fog`]: first-order lags) → bias and scale
//! factor ([`fog`]) → rate output with noise ([`noise`]) and, optionally, a rate table
//! ([`table`]). The output is a [`TestLog`] in the project's CSV format.
//!
//! ```text
//! gyro_dps = Q( B(t)/3600 + K(t)·Ω_table(t) + n(t)/3600 )      Q: angle quantization
//! ```
//! with B in °/h (He et al. 2024 eq. (1)-(3), DOI 10.19452/j.issn1007-5453.2024.02.004).
//! `truth` adds [`TRUE_BIAS_COL`] (B, °/s), [`TRUE_SCALE_COL`] (K), [`NOISE_COL`]
//! (gyro_dps - B - K·Ω, °/s, i.e. noise plus quantization) and the node temperatures
//! `CHAMBER_TEMP_COL`, [`CASE_TEMP_COL`], [`COIL_TEMP_COL`] (°C).
//!
//! Determinism: every random number comes from ChaCha8 streams of `seed` and every
//! transcendental function from `libm`, so the same config gives the same bytes on every
//! platform.
//!
//! Optional faults ([`fault`]): dropouts (time gaps) and stuck temperature readings.
//!
//! Not modelled: table acceleration and wobble,
//! magnetic sensitivity, vibration, temperature-dependent noise levels, the sensor's
//! conversion time, and non-vertical mounting (the Earth-rate term assumes the input axis up).

pub mod chamber;
pub mod family;
pub mod fault;
pub mod fog;
pub mod imu;
pub mod noise;
pub mod profile;
pub mod table;

use std::path::PathBuf;

pub use chamber::ChamberParams;
pub use family::{random_unit, UnitRanges};
pub use fault::FaultParams;
pub(crate) use fog::ThermalState;
pub use fog::{FogUnit, SensorNode, EARTH_RATE_DPH};
pub use profile::{Profile, Segment, BUILTIN_PROFILES};

use crate::csvlog::{ExtraColumn, TestLog, NOISE_COL, TRUE_BIAS_COL, TRUE_SCALE_COL};

/// Truth column: chamber air temperature, °C.
pub(crate) const CHAMBER_TEMP_COL: &str = "chamber_temp_c";
/// Truth column: case temperature, °C.
pub const CASE_TEMP_COL: &str = "case_temp_c";
/// Truth column: coil temperature, °C.
pub const COIL_TEMP_COL: &str = "coil_temp_c";

/// Default latitude, degrees (He et al. 2024's test site; 39.1° N).
pub const DEFAULT_LATITUDE_DEG: f64 = 39.1;
/// Default rate-table segment length, s (He et al. 2024 dynamic test: 300 s per segment).
pub const DEFAULT_TABLE_SEGMENT_S: f64 = 300.0;
/// Most samples one run may make (memory bound: about 100 bytes per sample with truth).
pub const MAX_SAMPLES: usize = 40_000_000;
/// Sample-rate range, Hz (1 Hz as published, up to 1 kHz).
pub(crate) const SAMPLE_RATE_RANGE_HZ: (f64, f64) = (0.01, 1000.0);
/// Longest internal integration step of the chamber and thermal nodes, s.
const MAX_SUBSTEP_S: f64 = 0.5;

/// Everything that defines a simulated run.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Chamber set-point profile.
    pub profile: Profile,
    /// Random seed (same seed, same bytes).
    pub seed: u64,
    /// Output sample rate, Hz (default 1).
    pub sample_rate_hz: f64,
    /// Rate-table rate, °/s (None: static test).
    pub table_rate_dps: Option<f64>,
    /// Length of each +Ω / stop / -Ω / stop table segment, s (default 300).
    pub table_segment_s: f64,
    /// Add the truth columns.
    pub truth: bool,
    /// The gyro.
    pub unit: FogUnit,
    /// The chamber.
    pub chamber: ChamberParams,
    /// Latitude, degrees north (default 39.1); sets the Earth-rate component Ω_e·sin φ.
    pub latitude_deg: f64,
    /// Fault injection (default: none).
    pub faults: FaultParams,
}

impl Default for SimConfig {
    /// `seed-shock`, seed 0, 1 Hz, static, no truth, default unit and chamber, 39.1° N.
    fn default() -> Self {
        SimConfig::new(Profile::builtin("seed-shock").expect("built-in profile exists"))
    }
}

impl SimConfig {
    /// A static 1 Hz run of the default unit on `profile`, seed 0, no truth columns.
    pub fn new(profile: Profile) -> Self {
        SimConfig {
            profile,
            seed: 0,
            sample_rate_hz: 1.0,
            table_rate_dps: None,
            table_segment_s: DEFAULT_TABLE_SEGMENT_S,
            truth: false,
            unit: FogUnit::default(),
            chamber: ChamberParams::default(),
            latitude_deg: DEFAULT_LATITUDE_DEG,
            faults: FaultParams::default(),
        }
    }

    /// [`SimConfig::new`] on a built-in profile (see [`BUILTIN_PROFILES`]).
    pub fn builtin(profile_name: &str) -> Result<Self, SimError> {
        Ok(SimConfig::new(Profile::builtin(profile_name)?))
    }

    /// Number of samples the run will make: round(duration · rate).
    pub(crate) fn sample_count(&self) -> usize {
        let n = (self.profile.duration_s() * self.sample_rate_hz).round();
        if n.is_finite() && n >= 0.0 {
            n as usize
        } else {
            usize::MAX
        }
    }

    /// Checks the whole config (profile, unit, chamber, rates, size).
    pub fn validate(&self) -> Result<(), SimError> {
        self.profile.validate()?;
        self.unit.validate()?;
        self.chamber.validate().map_err(SimError::Config)?;
        self.faults.validate().map_err(SimError::Config)?;
        let (lo, hi) = SAMPLE_RATE_RANGE_HZ;
        if !(self.sample_rate_hz >= lo && self.sample_rate_hz <= hi) {
            return Err(SimError::Config(format!(
                "sample rate {} Hz is outside {lo} to {hi} Hz",
                self.sample_rate_hz
            )));
        }
        if !(self.latitude_deg.is_finite() && self.latitude_deg.abs() <= 90.0) {
            return Err(SimError::Config(format!(
                "latitude {} ° must be between -90 and 90",
                self.latitude_deg
            )));
        }
        if let Some(r) = self.table_rate_dps {
            if !(r.is_finite() && r.abs() <= 1000.0) {
                return Err(SimError::Config(format!(
                    "table rate {r} °/s must be finite and at most 1000 °/s in magnitude"
                )));
            }
            if !(self.table_segment_s.is_finite() && self.table_segment_s > 0.0) {
                return Err(SimError::Config(format!(
                    "table segment length {} s must be finite and > 0",
                    self.table_segment_s
                )));
            }
        }
        let n = self.sample_count();
        if n < 2 {
            return Err(SimError::Config(format!(
                "the run would have {n} samples; lengthen the profile or raise the rate"
            )));
        }
        if n > MAX_SAMPLES {
            return Err(SimError::Config(format!(
                "the run would have {n} samples, more than {MAX_SAMPLES}; lower the sample rate \
                 or shorten the profile"
            )));
        }
        Ok(())
    }
}

/// Why a run cannot be made.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SimError {
    /// A user profile file is malformed (`line` is 1-based; 0 for the whole file).
    Profile {
        source: String,
        line: usize,
        message: String,
    },
    /// A unit parameter is invalid (`field` names it, or the file for a JSON syntax error).
    Unit { field: String, message: String },
    /// Any other bad setting.
    Config(String),
    /// A file could not be read.
    Io { path: PathBuf, message: String },
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SimError::Profile {
                source,
                line: 0,
                message,
            } => write!(f, "profile {source}: {message}"),
            SimError::Profile {
                source,
                line,
                message,
            } => write!(f, "profile {source}:{line}: {message}"),
            SimError::Unit { field, message } => write!(f, "unit parameter {field}: {message}"),
            SimError::Config(m) => write!(f, "{m}"),
            SimError::Io { path, message } => write!(f, "{}: {message}", path.display()),
        }
    }
}

impl std::error::Error for SimError {}

/// A simulated run as numbers (what [`simulate`] writes into a [`TestLog`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimSeries {
    /// Time, s (i / rate).
    pub time_s: Vec<f64>,
    /// Gyro output, °/s.
    pub gyro_dps: Vec<f64>,
    /// Logged temperature (sensor reading), °C.
    pub temp_c: Vec<f64>,
    /// Table rate, °/s (None: static).
    pub table_dps: Option<Vec<f64>>,
    /// True bias B, °/s.
    pub true_bias_dps: Vec<f64>,
    /// True scale factor K (dimensionless).
    pub true_scale: Vec<f64>,
    /// Noise-only part of the output (gyro - B - K·Ω), °/s.
    pub noise_dps: Vec<f64>,
    /// Chamber set point, °C.
    pub setpoint_c: Vec<f64>,
    /// Chamber air temperature, °C.
    pub chamber_c: Vec<f64>,
    /// Case temperature, °C.
    pub case_c: Vec<f64>,
    /// Coil temperature, °C.
    pub coil_c: Vec<f64>,
    /// Stress state, °C.
    pub stress_c: Vec<f64>,
}

impl SimSeries {
    /// Every per-sample column except the optional table rate, for operations that must treat
    /// them alike (reserving, dropping samples).
    pub(crate) fn sample_columns_mut(&mut self) -> [&mut Vec<f64>; 11] {
        [
            &mut self.time_s,
            &mut self.gyro_dps,
            &mut self.temp_c,
            &mut self.true_bias_dps,
            &mut self.true_scale,
            &mut self.noise_dps,
            &mut self.setpoint_c,
            &mut self.chamber_c,
            &mut self.case_c,
            &mut self.coil_c,
            &mut self.stress_c,
        ]
    }
}

/// Simulate a run and return every series as numbers (truth included, whatever
/// `cfg.truth` says).
pub fn simulate_series(cfg: &SimConfig) -> Result<SimSeries, SimError> {
    cfg.validate()?;
    let n = cfg.sample_count();
    let dt_s = 1.0 / cfg.sample_rate_hz;
    let substeps = (dt_s / MAX_SUBSTEP_S).ceil().max(1.0) as usize;
    let h_s = dt_s / substeps as f64;
    let unit = &cfg.unit;

    let mut setpoint = profile::SetpointCursor::new(&cfg.profile);
    let mut chamber = chamber::Chamber::new(cfg.chamber, cfg.profile.start_c, h_s, cfg.seed);
    let mut thermal = ThermalState::steady(cfg.profile.start_c);
    let step = fog::ThermalStep::new(unit, h_s);
    let mut rate_noise = noise::RateNoise::new(
        noise::NoiseParams {
            arw_deg_rt_h: unit.arw_deg_rt_h,
            bias_instability_dph: unit.bias_instability_dph,
            rrw_dph_rt_h: unit.rrw_dph_rt_h,
        },
        dt_s,
        cfg.seed,
    );
    let mut g_sensor = noise::Gauss::new(cfg.seed, 20);
    let mut g_quant = noise::Gauss::new(cfg.seed, 21);
    let mut quant = noise::Quantizer::new(unit.pulse_arcsec, &mut g_quant);
    let earth_dph = EARTH_RATE_DPH * libm::sin(cfg.latitude_deg.to_radians());

    let mut s = SimSeries {
        table_dps: cfg.table_rate_dps.map(|_| Vec::with_capacity(n)),
        ..SimSeries::default()
    };
    for v in s.sample_columns_mut() {
        v.reserve_exact(n);
    }

    for i in 0..n {
        let t_s = i as f64 / cfg.sample_rate_hz;
        let sp_c = setpoint.at(t_s);
        let air_c = chamber.air_c(t_s);
        let bias_dph = unit.bias0_dph
            + earth_dph
            + unit.thermal_bias_dph(
                thermal.coil_c,
                thermal.coil_rate_c_per_s(unit),
                thermal.stress_c,
            )
            + unit.gradient_and_saturation_bias_dph(&thermal, air_c);
        let bias_dps = bias_dph / 3600.0;
        let k = unit.scale_of_state(&thermal);
        let omega_dps = cfg
            .table_rate_dps
            .map_or(0.0, |r| table::table_rate_dps(r, cfg.table_segment_s, t_s));
        let signal_dps = bias_dps + k * omega_dps;
        let rate_dps = signal_dps + rate_noise.next_dph() / 3600.0;
        let gyro_dps = quant.output_dps(rate_dps, dt_s);

        let mut reading_c =
            thermal.sensor_c + unit.sensor_offset_c + unit.sensor_noise_c * g_sensor.normal();
        if unit.sensor_resolution_c > 0.0 {
            reading_c =
                libm::round(reading_c / unit.sensor_resolution_c) * unit.sensor_resolution_c;
        }

        s.time_s.push(t_s);
        s.gyro_dps.push(gyro_dps);
        s.temp_c.push(reading_c);
        if let Some(tab) = &mut s.table_dps {
            tab.push(omega_dps);
        }
        s.true_bias_dps.push(bias_dps);
        s.true_scale.push(k);
        s.noise_dps.push(gyro_dps - signal_dps);
        s.setpoint_c.push(sp_c);
        s.chamber_c.push(air_c);
        s.case_c.push(thermal.case_c);
        s.coil_c.push(thermal.coil_c);
        s.stress_c.push(thermal.stress_c);

        for j in 0..substeps {
            let tj = t_s + j as f64 * h_s;
            let air = chamber.air_c(tj);
            step.advance(&mut thermal, air);
            chamber.advance(setpoint.at(tj), h_s);
        }
    }
    fault::apply(&mut s, &cfg.faults, dt_s, cfg.seed);
    Ok(s)
}

/// Simulate a run as a [`TestLog`]: `time_s, gyro_dps, temp_c[, table_dps]` and, with
/// `cfg.truth`, the truth columns (in this order: [`TRUE_BIAS_COL`], [`TRUE_SCALE_COL`],
/// [`NOISE_COL`], `CHAMBER_TEMP_COL`, [`CASE_TEMP_COL`], [`COIL_TEMP_COL`]).
pub fn simulate(cfg: &SimConfig) -> Result<TestLog, SimError> {
    let s = simulate_series(cfg)?;
    let mut extra = Vec::new();
    if cfg.truth {
        let col = |name: &str, v: &[f64]| ExtraColumn {
            name: name.to_owned(),
            values: v.iter().map(|x| format!("{x}")).collect(),
        };
        extra = vec![
            col(TRUE_BIAS_COL, &s.true_bias_dps),
            col(TRUE_SCALE_COL, &s.true_scale),
            col(NOISE_COL, &s.noise_dps),
            col(CHAMBER_TEMP_COL, &s.chamber_c),
            col(CASE_TEMP_COL, &s.case_c),
            col(COIL_TEMP_COL, &s.coil_c),
        ];
    }
    Ok(TestLog {
        time_s: s.time_s,
        gyro_dps: s.gyro_dps,
        temp_c: s.temp_c,
        table_dps: s.table_dps,
        extra,
    })
}

//! An inertial unit: three gyros in one housing, a temperature sensor on the case and one
//! beside each coil, logged in one file (`gyrotherm simulate --imu`).
//!
//! Thermal nodes (first-order lags, as in [`super::fog`]): the chamber air drives an optional
//! mounting node and the **housing (case) node, shared by the three gyros**; each gyro's coil
//! node lags the case with its own time constant, and its stress state lags its coil. Each
//! gyro's bias and scale factor are [`FogUnit`]'s physics on its own coil (so the
//! radial-gradient Shupe term reads the shared case and that gyro's coil).
//!
//! Sensors (each DS18B20 class: own lag, offset and white noise, 0.0625 °C steps; He et al.
//! 2024 §3, DOI 10.19452/j.issn1007-5453.2024.02.004): [`CASE_SENSOR_COL`] on the case node,
//! and `temp_<axis>_c` on each gyro's coil node. A housing-only sensor sees neither the coil
//! temperature nor the case-to-coil gradient; the coil sensors do.
//!
//! A unit of the family ([`imu_from_family`]): gyro x has single-axis unit N's parameters
//! ([`UnitRanges::draw`]; its sensor moved to the coil), gyros y and z are drawn from the next ChaCha8 streams of the same
//! seed, with the mounting and case time constants of gyro x (one housing); the case sensor's
//! lag, offset and noise come from one more stream. Each gyro's coil sensor takes its drawn
//! sensor's lag, offset and noise.
//!
//! The rate table ([`ImuConfig::table_axis`]) turns one axis at a time, as a single-axis
//! table does: that gyro sees K·Ω, the others only their bias and noise (the Earth-rate
//! component is the same for all: input axes assumed at the same latitude projection, as the
//! single-axis simulator assumes input axis up). Not modelled besides what
//! [`super`] leaves out: cross-axis coupling, misalignment, heat from one gyro into another,
//! sensor faults (inject them by editing the log).
//!
//! Determinism: the chamber uses the run's seed as a single-axis run does; gyro `k`'s noise
//! and its coil sensor use the seed `axis_seed``(seed, k)`, the case sensor stream
//! `CASE_SENSOR_STREAM` of the run's seed.

use super::fog::{lag_alpha, FogUnit, SensorNode, ThermalState, ThermalStep};
use super::noise::{Gauss, NoiseParams, Quantizer, RateNoise};
use super::{
    chamber, profile, table, SimConfig, SimError, UnitRanges, CASE_TEMP_COL, CHAMBER_TEMP_COL,
    COIL_TEMP_COL, EARTH_RATE_DPH,
};
use crate::csvlog::{
    ExtraColumn, ImuLog, NamedSeries, DEFAULT_TABLE_COL, NOISE_COL, TRUE_BIAS_COL, TRUE_SCALE_COL,
};
use crate::sim::family::UNIT_STREAM;

/// Names of the simulated axes, in column order.
pub const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];
/// The case (housing) sensor's column.
pub const CASE_SENSOR_COL: &str = "temp_case_c";
/// Gauss stream of the run's seed for the case sensor's noise (after the fault streams 30, 31).
pub(crate) const CASE_SENSOR_STREAM: u64 = 32;
/// Stream of the unit seed the case sensor's lag, offset and noise are drawn from (after gyro
/// z's unit stream).
pub(crate) const CASE_SENSOR_UNIT_STREAM: u64 = UNIT_STREAM + 3;

/// Gyro column of axis `a` (`gyro_x_dps`).
pub fn gyro_col(axis: &str) -> String {
    format!("gyro_{axis}_dps")
}

/// Coil-sensor column of axis `a` (`temp_x_c`).
pub(crate) fn coil_sensor_col(axis: &str) -> String {
    format!("temp_{axis}_c")
}

/// A per-axis truth column: the single-axis name with the axis appended (`true_bias_dps_x`).
pub fn truth_col(base: &str, axis: &str) -> String {
    format!("{base}_{axis}")
}

/// The axis a simulated gyro column names (`gyro_y_dps` → `y`), so a tool can find that
/// axis's truth columns ([`truth_col`]); None for any other name.
pub(crate) fn axis_of_gyro_col(col: &str) -> Option<&'static str> {
    AXIS_NAMES.into_iter().find(|a| gyro_col(a) == col)
}

/// The seed of gyro `k`'s noise and coil sensor: the run's seed mixed with the axis
/// (a golden-ratio multiple, so nearby seeds and axes never share a ChaCha8 key).
pub(crate) fn axis_seed(seed: u64, k: usize) -> u64 {
    seed ^ 0x9E37_79B9_7F4A_7C15u64.wrapping_mul(k as u64 + 1)
}

/// The case sensor: lag, offset, noise and resolution (the [`FogUnit`] sensor fields).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CaseSensor {
    pub tau_s: f64,
    pub offset_c: f64,
    pub noise_c: f64,
    pub resolution_c: f64,
}

/// An inertial unit: three gyros sharing a housing, and a case sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuUnit {
    /// The gyros x, y, z. Their mounting and case time constants must be equal (one housing);
    /// each one's sensor fields describe its coil sensor.
    pub gyros: [FogUnit; 3],
    pub case_sensor: CaseSensor,
}

/// The inertial unit of seed `unit_seed` (see the module doc).
pub fn imu_from_family(unit_seed: u64) -> ImuUnit {
    imu_from_ranges(&UnitRanges::default(), unit_seed)
}

/// [`imu_from_family`] with every gyro and the case sensor drawn from `ranges` instead of the
/// design ranges (a family whose physics ranges are widened, for example).
pub fn imu_from_ranges(ranges: &UnitRanges, unit_seed: u64) -> ImuUnit {
    let x = ranges.draw(unit_seed);
    let (mount_tau_s, case_tau_s) = (x.mount_tau_s, x.case_tau_s);
    let housing = |mut u: FogUnit, axis: &str| {
        u.mount_tau_s = mount_tau_s;
        u.case_tau_s = case_tau_s;
        u.sensor_node = SensorNode::Coil;
        u.name = format!("random unit {unit_seed}, gyro {axis}");
        u
    };
    let y = ranges.draw_on_stream(unit_seed, UNIT_STREAM + 1);
    let z = ranges.draw_on_stream(unit_seed, UNIT_STREAM + 2);
    let s = ranges.draw_on_stream(unit_seed, CASE_SENSOR_UNIT_STREAM);
    ImuUnit {
        case_sensor: CaseSensor {
            tau_s: s.sensor_tau_s,
            offset_c: s.sensor_offset_c,
            noise_c: s.sensor_noise_c,
            resolution_c: s.sensor_resolution_c,
        },
        gyros: [housing(x, "x"), housing(y, "y"), housing(z, "z")],
    }
}

impl ImuUnit {
    /// Checks each gyro and the shared housing.
    pub fn validate(&self) -> Result<(), SimError> {
        for g in &self.gyros {
            g.validate()?;
        }
        let g0 = &self.gyros[0];
        if self
            .gyros
            .iter()
            .any(|g| g.mount_tau_s != g0.mount_tau_s || g.case_tau_s != g0.case_tau_s)
        {
            return Err(SimError::Unit {
                field: "case_tau_s".into(),
                message: "the gyros of one inertial unit share the housing: give them the same \
                          mount_tau_s and case_tau_s"
                    .into(),
            });
        }
        let c = &self.case_sensor;
        let ok = c.tau_s.is_finite()
            && c.tau_s > 0.0
            && c.offset_c.is_finite()
            && c.noise_c.is_finite()
            && c.noise_c >= 0.0
            && c.resolution_c.is_finite()
            && c.resolution_c >= 0.0;
        if !ok {
            return Err(SimError::Unit {
                field: "case_sensor".into(),
                message: format!("{c:?}: the lag must be > 0 s, noise and resolution >= 0"),
            });
        }
        Ok(())
    }
}

/// A simulated inertial-unit run: the single-axis settings (profile, seed, rate, table rate
/// and segment, truth, chamber, latitude; its `unit` and `faults` are not used), the unit,
/// and the axis the table turns.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuConfig {
    pub run: SimConfig,
    pub unit: ImuUnit,
    /// Index of the gyro the table turns (0 = x); with no table rate, ignored.
    pub table_axis: usize,
}

fn quantize(v: f64, res: f64) -> f64 {
    if res > 0.0 {
        libm::round(v / res) * res
    } else {
        v
    }
}

/// Simulate an inertial-unit run: `time_s, gyro_x_dps, gyro_y_dps, gyro_z_dps, temp_case_c,
/// temp_x_c, temp_y_c, temp_z_c[, table_dps]` and with `truth` per axis `true_bias_dps_<a>`,
/// `true_scale_<a>`, `noise_dps_<a>`, `coil_temp_c_<a>`, then the shared `chamber_temp_c`,
/// `case_temp_c`.
pub fn simulate_imu(cfg: &ImuConfig) -> Result<ImuLog, SimError> {
    let run = &cfg.run;
    run.validate()?;
    cfg.unit.validate()?;
    if !run.faults.is_off() {
        return Err(SimError::Config(
            "fault injection is not simulated for an inertial unit; edit the log to inject \
             sensor faults"
                .into(),
        ));
    }
    if cfg.table_axis >= AXIS_NAMES.len() {
        return Err(SimError::Config(format!(
            "table axis {} does not exist (0 to 2: x, y, z)",
            cfg.table_axis
        )));
    }
    let n = run.sample_count();
    let dt_s = 1.0 / run.sample_rate_hz;
    let substeps = (dt_s / 0.5).ceil().max(1.0) as usize;
    let h_s = dt_s / substeps as f64;
    let earth_dph = EARTH_RATE_DPH * libm::sin(run.latitude_deg.to_radians());

    let mut setpoint = profile::SetpointCursor::new(&run.profile);
    let mut chamber = chamber::Chamber::new(run.chamber, run.profile.start_c, h_s, run.seed);
    struct Axis<'a> {
        unit: &'a FogUnit,
        state: ThermalState,
        step: ThermalStep,
        noise: RateNoise,
        sensor_noise: Gauss,
        quant: Quantizer,
    }
    let mut axes: Vec<Axis> = cfg
        .unit
        .gyros
        .iter()
        .enumerate()
        .map(|(k, unit)| {
            let seed = axis_seed(run.seed, k);
            let mut g_quant = Gauss::new(seed, 21);
            Axis {
                unit,
                state: ThermalState::steady(run.profile.start_c),
                step: ThermalStep::new(unit, h_s),
                noise: RateNoise::new(
                    NoiseParams {
                        arw_deg_rt_h: unit.arw_deg_rt_h,
                        bias_instability_dph: unit.bias_instability_dph,
                        rrw_dph_rt_h: unit.rrw_dph_rt_h,
                    },
                    dt_s,
                    seed,
                ),
                sensor_noise: Gauss::new(seed, 20),
                quant: Quantizer::new(unit.pulse_arcsec, &mut g_quant),
            }
        })
        .collect();
    let cs = cfg.unit.case_sensor;
    let case_alpha = lag_alpha(h_s, cs.tau_s);
    let mut case_sensor_c = run.profile.start_c;
    let mut case_noise = Gauss::new(run.seed, CASE_SENSOR_STREAM);

    let series = |name: String| NamedSeries {
        name,
        values: Vec::with_capacity(n),
    };
    let mut time_s = Vec::with_capacity(n);
    let mut gyro: Vec<NamedSeries> = AXIS_NAMES.iter().map(|a| series(gyro_col(a))).collect();
    let mut temp: Vec<NamedSeries> = std::iter::once(CASE_SENSOR_COL.to_owned())
        .chain(AXIS_NAMES.iter().map(|a| coil_sensor_col(a)))
        .map(series)
        .collect();
    let mut table_dps = run.table_rate_dps.map(|_| Vec::with_capacity(n));
    // Per axis: true bias, true scale, noise, coil temperature; then chamber and case.
    let truth_len = if run.truth { n } else { 0 };
    let mut truth: Vec<Vec<f64>> = (0..14).map(|_| Vec::with_capacity(truth_len)).collect();

    for i in 0..n {
        let t_s = i as f64 / run.sample_rate_hz;
        let air_c = chamber.air_c(t_s);
        let omega_dps = run
            .table_rate_dps
            .map_or(0.0, |r| table::table_rate_dps(r, run.table_segment_s, t_s));
        for (k, ax) in axes.iter_mut().enumerate() {
            let (u, s) = (ax.unit, &ax.state);
            let bias_dph = u.bias0_dph
                + earth_dph
                + u.thermal_bias_dph(s.coil_c, s.coil_rate_c_per_s(u), s.stress_c)
                + u.gradient_and_saturation_bias_dph(s, air_c);
            let bias_dps = bias_dph / 3600.0;
            let scale = u.scale_of_state(s);
            let input_dps = if k == cfg.table_axis { omega_dps } else { 0.0 };
            let signal_dps = bias_dps + scale * input_dps;
            let out_dps = ax
                .quant
                .output_dps(signal_dps + ax.noise.next_dph() / 3600.0, dt_s);
            gyro[k].values.push(out_dps);
            let reading =
                s.sensor_c + u.sensor_offset_c + u.sensor_noise_c * ax.sensor_noise.normal();
            temp[k + 1]
                .values
                .push(quantize(reading, u.sensor_resolution_c));
            if run.truth {
                truth[4 * k].push(bias_dps);
                truth[4 * k + 1].push(scale);
                truth[4 * k + 2].push(out_dps - signal_dps);
                truth[4 * k + 3].push(s.coil_c);
            }
        }
        let case_c = axes[0].state.case_c;
        let reading = case_sensor_c + cs.offset_c + cs.noise_c * case_noise.normal();
        temp[0].values.push(quantize(reading, cs.resolution_c));
        if run.truth {
            truth[12].push(air_c);
            truth[13].push(case_c);
        }
        time_s.push(t_s);
        if let Some(tab) = &mut table_dps {
            tab.push(omega_dps);
        }
        for j in 0..substeps {
            let tj = t_s + j as f64 * h_s;
            let air = chamber.air_c(tj);
            // The case sensor lags the case's value at the start of the step, as the coil
            // sensors do inside ThermalStep.
            case_sensor_c += (axes[0].state.case_c - case_sensor_c) * case_alpha;
            for ax in &mut axes {
                ax.step.advance(&mut ax.state, air);
            }
            chamber.advance(setpoint.at(tj), h_s);
        }
    }
    let mut extra = Vec::new();
    if run.truth {
        let mut names = Vec::new();
        for a in AXIS_NAMES {
            for base in [TRUE_BIAS_COL, TRUE_SCALE_COL, NOISE_COL, COIL_TEMP_COL] {
                names.push(truth_col(base, a));
            }
        }
        names.push(CHAMBER_TEMP_COL.to_owned());
        names.push(CASE_TEMP_COL.to_owned());
        extra = names
            .into_iter()
            .zip(truth)
            .map(|(name, v)| ExtraColumn {
                name,
                values: v.iter().map(|x| format!("{x}")).collect(),
            })
            .collect();
    }
    Ok(ImuLog {
        time_s,
        gyro,
        temp,
        table: table_dps.map(|values| NamedSeries {
            name: DEFAULT_TABLE_COL.to_owned(),
            values,
        }),
        table_axis: run
            .table_rate_dps
            .map(|_| gyro_col(AXIS_NAMES[cfg.table_axis])),
        extra,
    })
}

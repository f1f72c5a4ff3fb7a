//! Settings of `gyrotherm plan`: the flight envelope (when no flight log gives it) and the
//! chamber's limits, and the fixed rules of the proposed profile (see [`crate::plan`]).

use crate::setting_rule::{check, check_opt, Rule, SettingError};

/// The chamber's default coldest set point, °C (the usual qualification chamber's range,
/// −55…+85 °C, the MIL-STD-810 extremes an airborne unit is tested to).
pub const CHAMBER_MIN_C: f64 = -55.0;
/// The chamber's default hottest set point, °C.
pub const CHAMBER_MAX_C: f64 = 85.0;
/// The chamber's default fastest ramp, °C/min (a common climatic chamber; thermal-shock
/// chambers are faster).
pub const CHAMBER_MAX_RATE_C_PER_MIN: f64 = 10.0;

/// Rate levels of the proposed ramps: `R·k/RATE_LEVELS`, k = 1..=RATE_LEVELS, R the largest
/// flight rate. With the coverage grid's 12 rate cells over −R…+R (cells R/6 wide), levels
/// R/3 apart leave at most one cell between two levels (or a level and the soaks' 0), so no
/// rate in between is further than the edge of the covered region.
pub(crate) const RATE_LEVELS: usize = 3;
/// Margin added to the flight's temperature extremes, °C: one narrowest coverage cell
/// ([`super::coverage::MIN_TEMP_CELL_C`]) beyond each, so the extremes lie inside a cell.
pub(crate) const TEMP_MARGIN_C: f64 = super::coverage::MIN_TEMP_CELL_C;
/// Factor on the flight's largest rate: the gyro's temperature follows a chamber ramp with a
/// lag, so its rate stays a little under the set point's (airborne: 9.2 °C/min on the sensor
/// for a 9.5 °C/min ramp, 3 % under); 10 % more reaches the flight's rate.
pub(crate) const RATE_MARGIN: f64 = 1.1;
/// Soak at each extreme, s: three times the sum of the case and coil lags of the simulated
/// unit (180 s + 300 s, `sim::FogUnit::default`), so the gyro is at rest again before the
/// next ramp and every ramp starts the same way. The slower stress lag (2500 s) is left to
/// the long soaks of the shock test the plan adds to, as are the temperatures in between.
pub(crate) const SOAK_S: f64 = 1440.0;
/// Long soaks per slowest identified lag: the first soak at each extreme lasts this many times
/// the slowest thermal lag the training logs' fit identified (at least [`SOAK_S`]), so that the
/// lag's state settles and can be told apart from the faster ones. 1.8 makes a lag at the lag
/// search's default bound (12,000 s) a 6 h soak, the length chosen on the design family and
/// confirmed on the confirmation family (the unit worst case 5.25× → 3.24× the noise floor;
/// docs/experiments/imu-soak.md).
pub(crate) const LONG_SOAK_PER_LAG: f64 = 1.8;
/// Room temperature the profile starts and ends at, °C.
pub(crate) const ROOM_C: f64 = 22.0;
/// Held-out steps a coverage cell needs ([`super::coverage::MIN_CELL_STEPS`]): each
/// temperature cell of a ramp gets at least this many seconds at 1 Hz, by repeating it.
pub(crate) const MIN_CELL_S: f64 = super::coverage::MIN_CELL_STEPS as f64;

pub use crate::setting_rule::{ABSOLUTE_ZERO_C, MAX_ENVELOPE_C};

/// The settings of one plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// Envelope's coldest temperature, °C (None: from the flight log).
    pub temp_min_c: Option<f64>,
    /// Envelope's hottest temperature, °C (None: from the flight log).
    pub temp_max_c: Option<f64>,
    /// Envelope's largest |dT|, °C/min (None: from the flight log).
    pub max_rate_c_per_min: Option<f64>,
    /// Chamber's coldest set point, °C.
    pub chamber_min_c: f64,
    /// Chamber's hottest set point, °C.
    pub chamber_max_c: f64,
    /// Chamber's fastest ramp, °C/min.
    pub chamber_max_rate_c_per_min: f64,
    /// The slowest thermal lag identified in the training logs so far, s
    /// ([`crate::plan::CoverageSummary::slowest_lag_s`]); None: none identified, and every
    /// soak lasts the fixed soak.
    pub slowest_lag_s: Option<f64>,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            temp_min_c: None,
            temp_max_c: None,
            max_rate_c_per_min: None,
            chamber_min_c: CHAMBER_MIN_C,
            chamber_max_c: CHAMBER_MAX_C,
            chamber_max_rate_c_per_min: CHAMBER_MAX_RATE_C_PER_MIN,
            slowest_lag_s: None,
        }
    }
}

impl PlanSettings {
    /// Check the settings: finite temperatures, positive rates, each minimum below its
    /// maximum; the chamber's set points and ramp within what `simulate --profile-file`
    /// accepts (`crate::sim::profile::TARGET_RANGE_C`, `crate::sim::profile::MAX_RAMP_C_PER_MIN`), since
    /// the plan is written as such a profile; the envelope's temperatures physical (above
    /// absolute zero, below [`MAX_ENVELOPE_C`]).
    pub fn validate(&self) -> Result<(), SettingError> {
        check_opt("temp_min_c", self.temp_min_c, Rule::FlightTemperature)?;
        check_opt("temp_max_c", self.temp_max_c, Rule::FlightTemperature)?;
        check_opt(
            "max_rate_c_per_min",
            self.max_rate_c_per_min,
            Rule::PositiveRate,
        )?;
        check_opt("slowest_lag_s", self.slowest_lag_s, Rule::PositiveSeconds)?;
        check("chamber_min_c", self.chamber_min_c, Rule::Finite)?;
        check("chamber_max_c", self.chamber_max_c, Rule::Finite)?;
        check(
            "chamber_max_rate_c_per_min",
            self.chamber_max_rate_c_per_min,
            Rule::PositiveRate,
        )?;
        let (lo, hi) = crate::sim::profile::TARGET_RANGE_C;
        let out = |setting: &'static str, v: f64, why: String| SettingError::Conflict {
            setting,
            other: "the simulator's profile limits",
            why: format!("{} {why}", crate::csvlog::short_f64(v)),
        };
        if self.chamber_min_c < lo {
            return Err(out(
                "chamber_min_c",
                self.chamber_min_c,
                format!("°C is below the coldest set point a profile may have, {lo} °C"),
            ));
        }
        if self.chamber_max_c > hi {
            return Err(out(
                "chamber_max_c",
                self.chamber_max_c,
                format!("°C is above the hottest set point a profile may have, {hi} °C"),
            ));
        }
        let max_ramp = crate::sim::profile::MAX_RAMP_C_PER_MIN;
        if self.chamber_max_rate_c_per_min > max_ramp {
            return Err(out(
                "chamber_max_rate_c_per_min",
                self.chamber_max_rate_c_per_min,
                format!("°C/min is faster than a profile may ramp, {max_ramp} °C/min"),
            ));
        }
        if self.chamber_min_c >= self.chamber_max_c {
            return Err(SettingError::Conflict {
                setting: "chamber_min_c",
                other: "chamber_max_c",
                why: format!(
                    "{} °C is not below {} °C",
                    self.chamber_min_c, self.chamber_max_c
                ),
            });
        }
        if let (Some(a), Some(b)) = (self.temp_min_c, self.temp_max_c) {
            if a >= b {
                return Err(SettingError::Conflict {
                    setting: "temp_min_c",
                    other: "temp_max_c",
                    why: format!("{a} °C is not below {b} °C"),
                });
            }
        }
        Ok(())
    }
}

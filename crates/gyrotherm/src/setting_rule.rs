//! The rules a setting's value may break, and the error that names the setting
//! ([`SettingError`]): the bottom of the settings (kept below the log format, which checks column lists by them), imported by every settings file and by
//! the modules they configure. The bounds the rules state are defined here, where they are
//! checked, and re-exported where they are documented ([`crate::settings::fit`], [`crate::settings::plan`]).

use std::fmt;

/// Most training epochs one may ask for: a thousand times the published method's 1000
/// (Adam steps), far beyond any loss that still falls, while the loss history of that many
/// epochs stays a few megabytes.
pub const MAX_EPOCHS: usize = 1_000_000;

/// Most training windows per Adam step one may ask for: four times the largest batch of the
/// outside recipe (256), and at 64 hidden units a step's activations stay under a gigabyte.
pub const MAX_WINDOWS: usize = 1024;

/// Absolute zero, °C: no envelope temperature below it.
pub const ABSOLUTE_ZERO_C: f64 = -273.15;
/// Hottest envelope temperature accepted, °C: far above any flight (and any chamber's
/// `crate::sim::profile::TARGET_RANGE_C`); beyond it a value is a typo, not a flight.
pub const MAX_ENVELOPE_C: f64 = 1000.0;

/// The rule a value broke.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Rule {
    /// Finite and > 0, seconds.
    PositiveSeconds,
    /// Finite and ≥ 0, seconds.
    NonNegativeSeconds,
    /// An integer ≥ 1.
    AtLeastOne,
    /// A number of training epochs: an integer from 1 to [`MAX_EPOCHS`].
    Epochs,
    /// Training windows per Adam step: an integer from 1 to [`MAX_WINDOWS`].
    Windows,
    /// A scale factor: finite and > 0 (gyro output over table rate, about 1).
    PositiveScaleFactor,
    /// A power-law noise exponent α: an integer from -4 to 2.
    NoiseAlpha,
    /// A number at all.
    Number,
    /// Finite and > 0 (a rate, °C/min).
    PositiveRate,
    /// Finite (a temperature, °C).
    Finite,
    /// A list of column names (one, or several separated by commas).
    ColumnList,
    /// Hidden units of an LSTM: a size the flight compensator's network is built for
    /// ([`gyrotherm_core::compensator::HIDDEN_SIZES`]).
    HiddenUnits,
    /// A temperature a flight reaches, °C: from absolute zero to
    /// [`MAX_ENVELOPE_C`].
    FlightTemperature,
    /// An IMU instance the autopilot calibrates.
    ImuInstance,
    /// A 32-bit device id.
    DeviceId,
    /// A ROS topic name.
    RosTopic,
}

impl Rule {
    fn text(self) -> &'static str {
        match self {
            Rule::PositiveSeconds => "is not a positive number of seconds",
            Rule::NonNegativeSeconds => "is not zero or a positive number of seconds",
            Rule::AtLeastOne => "must be at least 1",
            // Stated here as text; a test holds it equal to MAX_EPOCHS.
            Rule::Epochs => "must be a whole number from 1 to 1000000",
            // Stated here as text; a test holds it equal to MAX_WINDOWS.
            Rule::Windows => "must be a whole number from 1 to 1024",
            Rule::PositiveScaleFactor => {
                "is not a scale factor: give a positive number (gyro output over table rate, \
                 about 1)"
            }
            Rule::NoiseAlpha => {
                "is not allowed: the noise exponent α is an integer from -4 to 2 (2 white PM, 1 \
                 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM, -3 and -4 for \
                 Hadamard only)"
            }
            Rule::Number => "is not a number",
            Rule::PositiveRate => "is not a positive rate (°C/min)",
            Rule::Finite => "is not a finite number",
            Rule::ColumnList => {
                "is not a list of column names: give one name, or distinct names separated by \
                 commas"
            }
            Rule::HiddenUnits => {
                "is not a number of hidden units the flight compensator runs: give 8 (as \
                 published), 16, 32 or 64"
            }
            Rule::FlightTemperature => {
                "°C is not a temperature a flight reaches: give -273.15 to 1000 °C"
            }
            Rule::ImuInstance => {
                "is not an IMU the autopilot calibrates: ArduPilot takes 0 to 2 (INS_TCAL1 to \
                 INS_TCAL3), PX4 0 to 3 (TC_G0 to TC_G3)"
            }
            Rule::DeviceId => {
                "is not a device id: give the gyro's 32-bit DEVICE_ID as PX4 reports it \
                 (decimal, or hexadecimal with 0x)"
            }
            Rule::RosTopic => {
                "is not a ROS topic name: a letter or `/` first, then letters, digits, `_` \
                 and `/` (such as /imu0)"
            }
        }
    }

    /// Whether `v` keeps this rule (for the numeric rules).
    pub fn holds(self, v: f64) -> bool {
        match self {
            Rule::PositiveSeconds | Rule::PositiveScaleFactor => v.is_finite() && v > 0.0,
            Rule::NonNegativeSeconds => v.is_finite() && v >= 0.0,
            Rule::AtLeastOne => v >= 1.0,
            Rule::Epochs => v.fract() == 0.0 && (1.0..=MAX_EPOCHS as f64).contains(&v),
            Rule::Windows => v.fract() == 0.0 && (1.0..=MAX_WINDOWS as f64).contains(&v),
            Rule::NoiseAlpha => v.fract() == 0.0 && (-4.0..=2.0).contains(&v),
            Rule::Number
            | Rule::ColumnList
            | Rule::ImuInstance
            | Rule::DeviceId
            | Rule::RosTopic => true,
            Rule::PositiveRate => v.is_finite() && v > 0.0,
            Rule::Finite => v.is_finite(),
            Rule::HiddenUnits => gyrotherm_core::compensator::HIDDEN_SIZES
                .iter()
                .any(|&h| v == h as f64),
            Rule::FlightTemperature => (ABSOLUTE_ZERO_C..=MAX_ENVELOPE_C).contains(&v),
        }
    }
}

/// A setting that cannot be used: which setting (its name as in the settings structs, the
/// Python keyword and, with `-` for `_`, the command-line flag), the value, and the rule.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SettingError {
    /// A name not in the setting's list.
    Unknown {
        setting: &'static str,
        value: String,
        expected: &'static [&'static str],
    },
    /// A value that breaks the setting's rule.
    Invalid {
        setting: &'static str,
        value: String,
        rule: Rule,
    },
    /// Two settings that cannot be given together.
    Conflict {
        setting: &'static str,
        other: &'static str,
        why: String,
    },
}

impl SettingError {
    pub(crate) fn unknown(
        setting: &'static str,
        value: &str,
        expected: &'static [&'static str],
    ) -> Self {
        SettingError::Unknown {
            setting,
            value: value.to_owned(),
            expected,
        }
    }

    /// The setting at fault.
    pub fn setting(&self) -> &'static str {
        match self {
            SettingError::Unknown { setting, .. }
            | SettingError::Invalid { setting, .. }
            | SettingError::Conflict { setting, .. } => setting,
        }
    }
}

/// `a`, `a or b`, `a, b or c`.
pub(crate) fn or_list(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => format!("`{one}`"),
        [init @ .., last] => format!(
            "{} or `{last}`",
            init.iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

impl fmt::Display for SettingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingError::Unknown {
                setting,
                value,
                expected,
            } => write!(
                f,
                "{setting}: unknown value {value:?}; use {}",
                or_list(expected)
            ),
            SettingError::Invalid {
                setting,
                value,
                rule,
            } if matches!(rule, Rule::AtLeastOne | Rule::Epochs | Rule::Windows) => {
                write!(f, "{setting} {}, not {value}", rule.text())
            }
            SettingError::Invalid {
                setting,
                value,
                rule,
            } => write!(f, "{setting} = {value} {}", rule.text()),
            SettingError::Conflict {
                setting,
                other,
                why,
            } => write!(f, "{setting} and {other} conflict: {why}"),
        }
    }
}

impl std::error::Error for SettingError {}

/// `v` if it keeps `rule`, else [`SettingError::Invalid`] naming `setting`.
pub fn check(setting: &'static str, v: f64, rule: Rule) -> Result<f64, SettingError> {
    if rule.holds(v) {
        Ok(v)
    } else {
        Err(SettingError::Invalid {
            setting,
            // 1e308, not 309 digits.
            value: crate::number_text::short_f64(v),
            rule,
        })
    }
}

/// [`check`] for an optional value (None passes).
pub(crate) fn check_opt(
    setting: &'static str,
    v: Option<f64>,
    rule: Rule,
) -> Result<Option<f64>, SettingError> {
    v.map(|x| check(setting, x, rule)).transpose()
}

/// Parse a number typed by a user and [`check`] it: the parser the command line and Python
/// share for every numeric setting.
pub fn parse_number(setting: &'static str, s: &str, rule: Rule) -> Result<f64, SettingError> {
    let v: f64 = s.trim().parse().map_err(|_| SettingError::Invalid {
        setting,
        value: format!("{s:?}"),
        rule: Rule::Number,
    })?;
    check(setting, v, rule).map_err(|_| SettingError::Invalid {
        setting,
        value: format!("{s:?}"),
        rule,
    })
}

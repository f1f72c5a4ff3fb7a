//! Writing a model as an autopilot's gyro temperature-calibration parameters
//! ([`crate::export::ardupilot`], [`crate::export::px4`]): which of the autopilot's IMUs the
//! parameters are for, which of its gyro axes a single-gyro model fills, and (PX4) the
//! device id the firmware matches them to.

use crate::setting_rule::{Rule, SettingError};

/// A gyro axis of the autopilot's IMU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GyroAxis {
    X,
    Y,
    Z,
}

/// The axes in order (the order of the autopilot's parameters).
pub const GYRO_AXES: [GyroAxis; 3] = [GyroAxis::X, GyroAxis::Y, GyroAxis::Z];
/// Names of [`GYRO_AXES`].
pub(crate) const GYRO_AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

impl GyroAxis {
    /// The name on the command line (`--axis`).
    pub fn as_str(self) -> &'static str {
        GYRO_AXIS_NAMES[self.index()]
    }

    /// 0 for X, 1 for Y, 2 for Z.
    pub fn index(self) -> usize {
        match self {
            GyroAxis::X => 0,
            GyroAxis::Y => 1,
            GyroAxis::Z => 2,
        }
    }
}

impl std::fmt::Display for GyroAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for GyroAxis {
    type Err = SettingError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        GYRO_AXES
            .into_iter()
            .find(|a| a.as_str() == s)
            .ok_or_else(|| SettingError::unknown("axis", s, &GYRO_AXIS_NAMES))
    }
}

/// Default IMU instance (the autopilot's first IMU: ArduPilot `INS_TCAL1_*`, PX4 `TC_G0_*`).
pub(crate) const DEFAULT_INSTANCE: u8 = 0;
/// Default axis a single-gyro model fills.
pub(crate) const DEFAULT_AXIS: GyroAxis = GyroAxis::X;
/// IMUs ArduPilot calibrates (`INS_TCAL1` to `INS_TCAL3`).
pub(crate) const ARDUPILOT_INSTANCES: u8 = 3;
/// Gyros PX4 calibrates (`TC_G0` to `TC_G3`, `GYRO_COUNT_MAX`).
pub(crate) const PX4_INSTANCES: u8 = 4;

/// What an autopilot export writes besides the polynomial.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AutopilotSettings {
    /// The autopilot's IMU, from 0: ArduPilot `INS_TCAL{instance + 1}`, PX4
    /// `TC_G{instance}`.
    pub instance: u8,
    /// The axis a single-gyro model's bias goes to; the other two get zero coefficients
    /// (left uncorrected). Ignored for an inertial-unit model, whose three axes are X, Y
    /// and Z in its column order.
    pub axis: GyroAxis,
    /// PX4 only: the gyro's device id (`TC_G{n}_ID`), which the firmware matches to the
    /// sensor; with no id the parameters correct nothing, so PX4 export needs it.
    pub device_id: Option<u32>,
}

impl Default for AutopilotSettings {
    fn default() -> Self {
        AutopilotSettings {
            instance: DEFAULT_INSTANCE,
            axis: DEFAULT_AXIS,
            device_id: None,
        }
    }
}

impl AutopilotSettings {
    /// Check the instance against the autopilot's count (`instances`, the target's).
    pub fn validate(&self, instances: u8) -> Result<(), SettingError> {
        if self.instance >= instances {
            return Err(SettingError::Invalid {
                setting: "instance",
                value: self.instance.to_string(),
                rule: Rule::ImuInstance,
            });
        }
        Ok(())
    }
}

/// Parse an IMU instance (`--instance`): a whole number from 0.
pub fn parse_instance(s: &str) -> Result<u8, SettingError> {
    s.trim().parse().map_err(|_| SettingError::Invalid {
        setting: "instance",
        value: format!("{s:?}"),
        rule: Rule::Number,
    })
}

/// Parse a PX4 device id (`--device-id`): decimal, or hexadecimal with `0x`.
pub fn parse_device_id(s: &str) -> Result<u32, SettingError> {
    let t = s.trim();
    let v = match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(hex) => u32::from_str_radix(hex, 16).ok(),
        None => t.parse::<u32>().ok(),
    };
    // PX4 stores the id in an INT32 parameter (the same 32 bits).
    v.ok_or_else(|| SettingError::Invalid {
        setting: "device_id",
        value: format!("{s:?}"),
        rule: Rule::DeviceId,
    })
}

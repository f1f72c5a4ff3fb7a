//! Errors the flight crate reports instead of panicking.

use core::fmt;

/// Which input channel was at fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Channel {
    /// Time stamp, s.
    Time,
    /// Gyro output, °/s.
    Gyro,
    /// Temperature, °C.
    Temperature,
    /// A derived model input (feature index), e.g. the LSTM's input vector.
    Feature(u8),
}

/// An input the core refused. The state of whatever refused it is left untouched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputError {
    /// NaN or ±infinity on the named channel.
    NonFinite(Channel),
    /// Time did not increase from the previous sample.
    TimeNotIncreasing,
    /// Time so far after the first sample that its step index would reach
    /// [`MAX_STEP_INDEX`](crate::features::MAX_STEP_INDEX) (steps could no longer be counted
    /// exactly).
    TimeOutOfRange,
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Channel::Time => f.write_str("time"),
            Channel::Gyro => f.write_str("gyro"),
            Channel::Temperature => f.write_str("temperature"),
            Channel::Feature(k) => write!(f, "feature {k}"),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::NonFinite(c) => write!(f, "non-finite {c} input"),
            InputError::TimeNotIncreasing => f.write_str("time did not increase"),
            InputError::TimeOutOfRange => {
                f.write_str("time too far after the first sample to count its step exactly")
            }
        }
    }
}

impl core::error::Error for InputError {}

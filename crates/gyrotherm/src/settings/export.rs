//! What `gyrotherm export --target` can write: the one list of export targets, each with its
//! name and one line of help. It sits with the settings, below both the export that writes a
//! target and the comparison that can show an autopilot target's polynomial as a column.

use crate::setting_rule::SettingError;

/// An export target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportTarget {
    /// The full model as C99 flight code.
    C,
    /// The full model as a Rust module for `gyrotherm-core`.
    Rust,
    /// ArduPilot's gyro temperature calibration, `INS_TCAL{n}_*` ([`crate::export::ardupilot`]).
    Ardupilot,
    /// PX4's gyro thermal compensation, `TC_G{n}_*` ([`crate::export::px4`]).
    Px4,
}

/// Every target, in the order `--help` lists them.
pub const EXPORT_TARGETS: [ExportTarget; 4] = [
    ExportTarget::C,
    ExportTarget::Rust,
    ExportTarget::Ardupilot,
    ExportTarget::Px4,
];

/// The names of [`EXPORT_TARGETS`], in its order (made from it, so the two cannot differ).
pub(crate) const EXPORT_TARGET_NAMES: [&str; EXPORT_TARGETS.len()] = {
    let mut names = [""; EXPORT_TARGETS.len()];
    let mut i = 0;
    while i < names.len() {
        names[i] = EXPORT_TARGETS[i].as_str();
        i += 1;
    }
    names
};

impl ExportTarget {
    /// The name on the command line (`--target`).
    pub const fn as_str(self) -> &'static str {
        match self {
            ExportTarget::C => "c",
            ExportTarget::Rust => "rust",
            ExportTarget::Ardupilot => "ardupilot",
            ExportTarget::Px4 => "px4",
        }
    }

    /// One line on what is written (the `--help` text of the value).
    pub fn help(self) -> &'static str {
        match self {
            ExportTarget::C => {
                "C99: gyrotherm_model.h and gyrotherm_model.c (no heap, no global mutable state)"
            }
            ExportTarget::Rust => {
                "Rust: gyrotherm_model.rs, the model as a `static` for gyrotherm-core"
            }
            ExportTarget::Ardupilot => {
                "ArduPilot parameters INS_TCALn_* (gyro_tcal.parm): a cubic in temperature \
                 fitted to the model's steady-state bias"
            }
            ExportTarget::Px4 => {
                "PX4 parameters TC_Gn_* for QGroundControl (gyro_tc.params): a cubic in \
                 temperature fitted to the model's steady-state bias"
            }
        }
    }

    /// Whether the target is an autopilot's parameter file (a polynomial fitted to the
    /// model's steady-state bias), not the full model as flight code.
    pub const fn is_autopilot(self) -> bool {
        matches!(self, ExportTarget::Ardupilot | ExportTarget::Px4)
    }

    /// The label of its comparison column (autopilot targets; `compare --methods`).
    pub const fn column_label(self) -> &'static str {
        match self {
            ExportTarget::Ardupilot => "ArduPilot cubic",
            ExportTarget::Px4 => "PX4 cubic",
            ExportTarget::C | ExportTarget::Rust => "flight code",
        }
    }
}

impl std::fmt::Display for ExportTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for ExportTarget {
    type Err = SettingError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        EXPORT_TARGETS
            .into_iter()
            .find(|t| t.as_str() == s)
            .ok_or_else(|| SettingError::unknown("target", s, &EXPORT_TARGET_NAMES))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back() {
        for t in EXPORT_TARGETS {
            assert_eq!(t.as_str().parse::<ExportTarget>().unwrap(), t);
            assert!(!t.help().is_empty());
        }
        assert!("arduplane".parse::<ExportTarget>().is_err());
    }
}

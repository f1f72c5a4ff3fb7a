//! What `gyrotherm export --target` can write: the one list of export targets, each with its
//! name and one line of help.

use super::Lang;
use crate::settings::SettingError;

/// An export target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportTarget {
    /// The full model as C99 flight code.
    C,
    /// The full model as a Rust module for `gyrotherm-core`.
    Rust,
    /// ArduPilot's gyro temperature calibration, `INS_TCAL{n}_*` ([`super::ardupilot`]).
    Ardupilot,
    /// PX4's gyro thermal compensation, `TC_G{n}_*` ([`super::px4`]).
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
pub const EXPORT_TARGET_NAMES: [&str; EXPORT_TARGETS.len()] = {
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
            ExportTarget::C => Lang::C.help(),
            ExportTarget::Rust => Lang::Rust.help(),
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

    /// The flight-code language, for the targets that write the full model.
    pub fn lang(self) -> Option<Lang> {
        match self {
            ExportTarget::C => Some(Lang::C),
            ExportTarget::Rust => Some(Lang::Rust),
            ExportTarget::Ardupilot | ExportTarget::Px4 => None,
        }
    }
}

impl From<Lang> for ExportTarget {
    fn from(l: Lang) -> Self {
        match l {
            Lang::C => ExportTarget::C,
            Lang::Rust => ExportTarget::Rust,
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
    fn names_are_the_list_and_parse_back() {
        let names: Vec<&str> = EXPORT_TARGETS.iter().map(|t| t.as_str()).collect();
        assert_eq!(names, EXPORT_TARGET_NAMES);
        for t in EXPORT_TARGETS {
            assert_eq!(t.as_str().parse::<ExportTarget>().unwrap(), t);
            assert!(!t.help().is_empty());
        }
        assert!("arduplane".parse::<ExportTarget>().is_err());
    }
}

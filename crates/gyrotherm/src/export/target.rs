//! The export targets (the list is [`crate::settings::export`]) and the flight-code language
//! each full-model target writes.

use super::Lang;
pub use crate::settings::export::{ExportTarget, EXPORT_TARGETS};

impl ExportTarget {
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

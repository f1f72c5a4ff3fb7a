//! Reading a log: [`ReadOptions`] (defined in `csvlog`, where the reader uses it) checked
//! here, and the lists of values its settings take.

use crate::csvlog::{GyroUnit, ReadOptions};
use crate::setting_rule::{check_opt, Rule, SettingError};

/// Names of the gyro units, default first.
pub const GYRO_UNIT_NAMES: [&str; 3] = ["dps", "dph", "rad/s"];

/// Names of the field separators, default first (`tab` is also accepted as a literal tab or
/// `\t`, `,` as `comma`, `;` as `semicolon`).
pub const DELIMITER_NAMES: [&str; 3] = [",", ";", "tab"];

impl GyroUnit {
    /// The name on the command line and in Python.
    pub fn as_str(&self) -> &'static str {
        match self {
            GyroUnit::Dps => "dps",
            GyroUnit::Dph => "dph",
            GyroUnit::RadPerS => "rad/s",
        }
    }
}

impl std::fmt::Display for GyroUnit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Parse a field separator: `,`, `;` or `tab` (see [`DELIMITER_NAMES`]).
pub fn parse_delimiter(s: &str) -> Result<u8, SettingError> {
    match s {
        "," | "comma" => Ok(b','),
        ";" | "semicolon" => Ok(b';'),
        "tab" | "\t" | "\\t" => Ok(b'\t'),
        _ => Err(SettingError::unknown("delimiter", s, &DELIMITER_NAMES)),
    }
}

/// The name of a field separator byte (the inverse of [`parse_delimiter`]).
pub fn delimiter_name(d: u8) -> &'static str {
    match d {
        b';' => ";",
        b'\t' => "tab",
        _ => ",",
    }
}

impl ReadOptions {
    /// Check every value; the error names the setting and the rule.
    pub fn validate(&self) -> Result<(), SettingError> {
        self.validate_columns()?;
        check_opt(
            "fill_gaps_max_s",
            self.fill_gaps_max_s,
            Rule::PositiveSeconds,
        )?;
        check_opt(
            "sample_period_s",
            self.sample_period_s,
            Rule::PositiveSeconds,
        )?;
        parse_delimiter(delimiter_name(self.delimiter))
            .ok()
            .filter(|d| *d == self.delimiter)
            .ok_or_else(|| {
                SettingError::unknown(
                    "delimiter",
                    &(self.delimiter as char).to_string(),
                    &DELIMITER_NAMES,
                )
            })?;
        Ok(())
    }
}

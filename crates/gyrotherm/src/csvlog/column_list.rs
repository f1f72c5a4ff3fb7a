//! Column lists: an inertial unit's log holds several gyros and temperature sensors, so
//! [`ReadOptions::gyro_col`] and [`ReadOptions::temp_col`] take one name or a comma-separated
//! list (`gyro_x_dps,gyro_y_dps,gyro_z_dps`). One name reads a single-axis log exactly as
//! before. The order of a list is the order of the model's axes and sensors, and of the
//! exported code's `gyro[]` and `temp[]`.
//!
//! A rate table turns one axis at a time, so a log has one table column (`--table-col`). The
//! axis it drives is the gyro whose output follows it (a slope between
//! [`TABLE_AXIS_SLOPE_RANGE`]), or the one named by `--table-axis GYRO_COL`
//! ([`parse_table_axis`]); give one table log per axis.

use super::{ReadOptions, DEFAULT_TABLE_COL, GYRO_COL, TEMP_COL, TIME_COL};
// Named at the crate root, not in `settings`, whose modules read `ReadOptions`: the log
// format takes the settings' error type only, not the modules that describe the options.
use crate::setting_rule::{Rule, SettingError};

/// Separator of the names in a column list.
pub(crate) const COLUMN_LIST_SEPARATOR: char = ',';

/// Slope of a gyro's output on the table rate that marks the axis the table turns: a scale
/// factor near 1 (He et al. 2024 eq. (1): Ĝ = B + K·G, K ≈ 1); the other axes read ≈ 0.
pub(crate) const TABLE_AXIS_SLOPE_RANGE: (f64, f64) = (0.5, 2.0);

/// Split a column list into its names: non-empty (spaces around a name are dropped) and
/// distinct; the error names `setting`.
pub(crate) fn split_columns(setting: &'static str, s: &str) -> Result<Vec<String>, SettingError> {
    let names: Vec<String> = s
        .split(COLUMN_LIST_SEPARATOR)
        .map(|n| n.trim().to_owned())
        .collect();
    let bad = || SettingError::Invalid {
        setting,
        value: format!("{s:?}"),
        rule: Rule::ColumnList,
    };
    if names.iter().any(String::is_empty) {
        return Err(bad());
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(bad());
        }
    }
    Ok(names)
}

/// Check `--table-axis`: one of the gyro columns.
pub(crate) fn parse_table_axis(s: &str, gyro_cols: &[String]) -> Result<usize, SettingError> {
    gyro_cols
        .iter()
        .position(|g| g == s.trim())
        .ok_or_else(|| SettingError::Conflict {
            setting: "table_axis",
            other: "gyro_col",
            why: format!(
                "{s:?} is not one of the gyro columns ({})",
                gyro_cols.join(", ")
            ),
        })
}

impl ReadOptions {
    /// The gyro columns, in order (one for a single-axis log).
    pub fn gyro_cols(&self) -> Result<Vec<String>, SettingError> {
        split_columns("gyro_col", &self.gyro_col)
    }

    /// The temperature columns, in order (one for a log with one sensor).
    pub fn temp_cols(&self) -> Result<Vec<String>, SettingError> {
        split_columns("temp_col", &self.temp_col)
    }

    /// Whether the options name more than one gyro or temperature column (an inertial unit's
    /// log, read with [`crate::csvlog::read_imu_log`]).
    pub(crate) fn is_multi_column(&self) -> bool {
        self.gyro_col.contains(COLUMN_LIST_SEPARATOR)
            || self.temp_col.contains(COLUMN_LIST_SEPARATOR)
    }

    /// The name a single-axis [`crate::csvlog::TestLog`] holds the file's column `name` under:
    /// the mapped time, gyro, temperature and table columns under the standard names (the
    /// gyro already in °/s), any other column under its own.
    pub fn log_column<'a>(&self, name: &'a str) -> &'a str {
        match name {
            n if n == self.gyro_col => GYRO_COL,
            n if n == self.temp_col => TEMP_COL,
            n if n == self.table_col => DEFAULT_TABLE_COL,
            n if n == self.time_col => TIME_COL,
            n => n,
        }
    }

    /// The file's name of a [`crate::csvlog::TestLog`] column (`log_column`'s inverse): what a
    /// result calls the column, so that it is the user's name, not the standard one.
    pub fn file_column<'a>(&'a self, log_column: &'a str) -> &'a str {
        match log_column {
            GYRO_COL => &self.gyro_col,
            TEMP_COL => &self.temp_col,
            DEFAULT_TABLE_COL => &self.table_col,
            TIME_COL => &self.time_col,
            n => n,
        }
    }

    /// Check the column lists (non-empty, distinct names; no name in both lists).
    pub(crate) fn validate_columns(&self) -> Result<(), SettingError> {
        let gyro = self.gyro_cols()?;
        let temp = self.temp_cols()?;
        if let Some(both) = gyro.iter().find(|g| temp.contains(g)) {
            return Err(SettingError::Conflict {
                setting: "gyro_col",
                other: "temp_col",
                why: format!("column {both:?} is named as a gyro and as a temperature"),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_name_is_a_list_of_one() {
        assert_eq!(split_columns("gyro_col", "gyro_dps").unwrap(), ["gyro_dps"]);
        assert!(!ReadOptions::default().is_multi_column());
    }

    #[test]
    fn lists_split_trim_and_refuse_empty_or_repeated_names() {
        assert_eq!(
            split_columns("temp_col", "temp_case_c, temp_x_c").unwrap(),
            ["temp_case_c", "temp_x_c"]
        );
        for bad in ["a,,b", "a,b,a", ",", ""] {
            let e = split_columns("temp_col", bad).unwrap_err();
            assert_eq!(e.setting(), "temp_col", "{bad:?}");
        }
        let o = ReadOptions {
            gyro_col: "a,b".into(),
            temp_col: "t,b".into(),
            ..ReadOptions::default()
        };
        assert!(o.is_multi_column());
        assert!(o.validate_columns().is_err());
    }

    #[test]
    fn a_column_keeps_the_files_name() {
        let o = ReadOptions {
            gyro_col: "w".into(),
            temp_col: "T".into(),
            ..ReadOptions::default()
        };
        assert_eq!(o.log_column("w"), "gyro_dps");
        assert_eq!(o.log_column("T"), "temp_c");
        assert_eq!(o.log_column("x_dph"), "x_dph");
        assert_eq!(o.file_column("gyro_dps"), "w");
        assert_eq!(o.file_column("temp_c"), "T");
        assert_eq!(o.file_column("table_dps"), "table_dps");
        assert_eq!(o.file_column("x_dph"), "x_dph");
    }

    #[test]
    fn table_axis_must_be_a_gyro_column() {
        let g = ["gx".to_owned(), "gy".to_owned()];
        assert_eq!(parse_table_axis("gy", &g).unwrap(), 1);
        let e = parse_table_axis("gz", &g).unwrap_err().to_string();
        assert!(
            e.contains("\"gz\" is not one of the gyro columns (gx, gy)"),
            "{e}"
        );
    }
}

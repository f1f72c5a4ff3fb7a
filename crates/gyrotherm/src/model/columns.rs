//! The log columns a model file was trained on: the names given and the reading options they
//! imply.

use serde::{Deserialize, Serialize};

use super::ModelFileError;
use crate::csvlog::ReadOptions;

/// The columns of the logs a model was trained on: the header names of time, gyro output,
/// temperature and rate table, and the unit of the gyro column (see [`ReadOptions`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnsDef {
    pub time_col: String,
    pub gyro_col: String,
    pub temp_col: String,
    pub table_col: String,
    /// `dps`, `dph` or `rad/s`.
    pub gyro_unit: String,
}

/// Which column options a user named (each one named overrides the model's
/// [`ColumnsDef`]; the others come from the model).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GivenColumns {
    pub time_col: bool,
    pub gyro_col: bool,
    pub temp_col: bool,
    pub table_col: bool,
    pub gyro_unit: bool,
}

impl ColumnsDef {
    /// The columns `opts` reads.
    pub fn of(opts: &ReadOptions) -> ColumnsDef {
        ColumnsDef {
            time_col: opts.time_col.clone(),
            gyro_col: opts.gyro_col.clone(),
            temp_col: opts.temp_col.clone(),
            table_col: opts.table_col.clone(),
            gyro_unit: opts.gyro_unit.as_str().to_owned(),
        }
    }

    /// `base` with these columns, except those `given` says the user named.
    pub fn read_options(
        &self,
        base: &ReadOptions,
        given: GivenColumns,
    ) -> Result<ReadOptions, ModelFileError> {
        let pick = |given: bool, flag: &String, mine: &String| {
            if given {
                flag.clone()
            } else {
                mine.clone()
            }
        };
        let gyro_unit = if given.gyro_unit {
            base.gyro_unit
        } else {
            self.gyro_unit
                .parse()
                .map_err(|e: String| ModelFileError::invalid("columns.gyro_unit", e))?
        };
        Ok(ReadOptions {
            time_col: pick(given.time_col, &base.time_col, &self.time_col),
            gyro_col: pick(given.gyro_col, &base.gyro_col, &self.gyro_col),
            temp_col: pick(given.temp_col, &base.temp_col, &self.temp_col),
            table_col: pick(given.table_col, &base.table_col, &self.table_col),
            gyro_unit,
            ..base.clone()
        })
    }

    /// Checked: one column each, names a log can hold, a known gyro unit.
    pub fn validate(&self) -> Result<(), ModelFileError> {
        let opts = self.read_options(&ReadOptions::default(), GivenColumns::default())?;
        if opts.is_multi_column() {
            return Err(ModelFileError::invalid(
                "columns",
                "a single-axis model reads one gyro and one temperature column".to_owned(),
            ));
        }
        opts.validate()
            .map_err(|e| ModelFileError::invalid("columns", e.to_string()))
    }
}

//! A log in memory, apart from any file format: what the readers of [`super`] (CSV, ULog,
//! DataFlash) give and the writers take.
//!
//! - [`ImuLog`]: the log of a unit of N gyro axes and M temperature sensors (a single gyro is
//!   a unit of one axis and one sensor), each column named; the table rate and the axis it
//!   turns; pass-through columns as text.
//! - [`TestLog`]: one axis of a log with one temperature, as a fit, the features and the
//!   figures read it ([`ImuLog::axis_data`], [`ImuLog::axis_log`]), and as a single gyro's log
//!   is read and written.
//!
//! Rates are in °/s and temperatures in °C here, whatever the file's units.

/// Standard column names.
pub const TIME_COL: &str = "time_s";
/// Gyro output, °/s.
pub const GYRO_COL: &str = "gyro_dps";
/// Temperature, °C.
pub const TEMP_COL: &str = "temp_c";
/// Rate-table input rate, °/s (optional).
pub const DEFAULT_TABLE_COL: &str = "table_dps";

/// Names of the simulator's truth columns (written with `simulate --truth`).
pub const TRUE_BIAS_COL: &str = "true_bias_dps";
/// True scale factor K (dimensionless, 1.0 nominal) in Ĝ = B + K·G.
pub const TRUE_SCALE_COL: &str = "true_scale";
/// Noise-only part of the gyro output, °/s.
pub const NOISE_COL: &str = "noise_dps";

/// One test log in memory. `gyro_dps` is always in °/s, whatever the file's unit.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TestLog {
    /// Time, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Gyro output, °/s.
    pub gyro_dps: Vec<f64>,
    /// Temperature, °C.
    pub temp_c: Vec<f64>,
    /// Rate-table input rate, °/s (None: static test).
    pub table_dps: Option<Vec<f64>>,
    /// Other columns, passed through to outputs unchanged (raw text of each field).
    pub extra: Vec<ExtraColumn>,
}

/// A pass-through column.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExtraColumn {
    pub name: String,
    pub values: Vec<String>,
}

impl TestLog {
    pub fn len(&self) -> usize {
        self.time_s.len()
    }
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }
    /// Median of the time steps, s (NaN for fewer than two samples).
    pub fn sample_period_s(&self) -> f64 {
        median_step_s(&self.time_s)
    }
    /// A pass-through column parsed as numbers (None if absent or not all numeric).
    pub fn extra_f64(&self, name: &str) -> Option<Vec<f64>> {
        let col = self.extra.iter().find(|c| c.name == name)?;
        col.values.iter().map(|v| v.trim().parse().ok()).collect()
    }
    /// True for a static test: no table column, or a table column that is zero throughout.
    pub fn is_static(&self) -> bool {
        self.table_dps
            .as_ref()
            .is_none_or(|t| t.iter().all(|v| *v == 0.0))
    }
    /// The numeric column `name` (a standard column or a numeric pass-through column). The
    /// gyro and temperature columns are moved out (left empty here) so a long log is held
    /// once; the others are copied.
    pub fn take_column(&mut self, name: &str) -> Result<Vec<f64>, ColumnError> {
        match name {
            GYRO_COL => Ok(std::mem::take(&mut self.gyro_dps)),
            TEMP_COL => Ok(std::mem::take(&mut self.temp_c)),
            TIME_COL => Ok(self.time_s.clone()),
            DEFAULT_TABLE_COL => self.table_dps.clone().ok_or(ColumnError::NoTable),
            name => self.extra_f64(name).ok_or_else(|| {
                if self.extra.iter().any(|c| c.name == name) {
                    ColumnError::NotNumeric {
                        name: name.to_owned(),
                    }
                } else {
                    ColumnError::Missing {
                        name: name.to_owned(),
                        available: self.column_names(),
                    }
                }
            }),
        }
    }
    /// Names of the columns held: the standard ones present, then the pass-through ones.
    pub(crate) fn column_names(&self) -> Vec<String> {
        [GYRO_COL, TEMP_COL]
            .into_iter()
            .chain(self.table_dps.as_ref().map(|_| DEFAULT_TABLE_COL))
            .chain(self.extra.iter().map(|c| c.name.as_str()))
            .map(str::to_owned)
            .collect()
    }
}

/// Median of the steps of `time_s`, s (NaN for fewer than two samples): the sample period
/// of a log, single gyro's or unit's.
pub(crate) fn median_step_s(time_s: &[f64]) -> f64 {
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return f64::NAN;
    }
    // The element a sort would put there, without the sort.
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Why [`TestLog::take_column`] has no numbers for a column.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ColumnError {
    /// `table_dps` asked for on a log without one.
    NoTable,
    /// No column of that name.
    Missing {
        name: String,
        available: Vec<String>,
    },
    /// The pass-through column holds a field that is not a number.
    NotNumeric { name: String },
}

impl std::fmt::Display for ColumnError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ColumnError::NoTable => write!(f, "no table_dps column in this log"),
            ColumnError::Missing { name, available } => {
                write!(f, "no column `{name}`; available: {}", available.join(", "))
            }
            ColumnError::NotNumeric { name } => write!(f, "column `{name}` is not all numeric"),
        }
    }
}

impl std::error::Error for ColumnError {}

/// A named column of numbers.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NamedSeries {
    pub name: String,
    pub values: Vec<f64>,
}

/// The names of a unit log's gyro columns and of its temperature columns, in column order.
pub(crate) type UnitColumns = (Vec<String>, Vec<String>);

/// An inertial unit's log in memory: gyro outputs in °/s, temperatures in °C, in the order of
/// the column lists.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ImuLog {
    /// Time, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Gyro outputs, °/s.
    pub gyro: Vec<NamedSeries>,
    /// Temperatures, °C (a sensor fault may leave NaN in a simulated log being written).
    pub temp: Vec<NamedSeries>,
    /// Table rate, °/s, and its column name (None: static run).
    pub table: Option<NamedSeries>,
    /// The gyro column the table turns (None: static run).
    pub table_axis: Option<String>,
    /// Other columns, passed through.
    pub extra: Vec<ExtraColumn>,
}

impl ImuLog {
    pub fn len(&self) -> usize {
        self.time_s.len()
    }
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// A single gyro's log as the unit of one axis, its columns moved, not copied: the gyro
    /// named `gyro`, the temperature `temp`, the table rate (when the log has one, zeros
    /// included) named `table` and turning that axis. [`ImuLog::axis_log`]`(0, 0)` gives the
    /// log back, and the unit's file is the single gyro's, byte for byte.
    pub fn of_axis(log: TestLog, gyro: &str, temp: &str, table: &str) -> ImuLog {
        let named = |name: &str, values| NamedSeries {
            name: name.to_owned(),
            values,
        };
        ImuLog {
            time_s: log.time_s,
            table_axis: log.table_dps.as_ref().map(|_| gyro.to_owned()),
            table: log.table_dps.map(|t| named(table, t)),
            gyro: vec![named(gyro, log.gyro_dps)],
            temp: vec![named(temp, log.temp_c)],
            extra: log.extra,
        }
    }

    /// The names of its gyro and its temperature columns, in column order.
    pub(crate) fn column_names(&self) -> UnitColumns {
        (
            self.gyro.iter().map(|s| s.name.clone()).collect(),
            self.temp.iter().map(|s| s.name.clone()).collect(),
        )
    }

    /// The gyro and temperature columns that every log of `logs` holds (None without logs),
    /// or the name of the first log whose columns differ from the first log's.
    pub(crate) fn shared_columns<'a>(
        logs: impl IntoIterator<Item = &'a (String, ImuLog)>,
    ) -> Result<Option<UnitColumns>, &'a str> {
        let mut columns = None;
        for (name, l) in logs {
            let c = l.column_names();
            match &columns {
                None => columns = Some(c),
                Some(first) if *first != c => return Err(name),
                Some(_) => {}
            }
        }
        Ok(columns)
    }

    /// Index of the gyro column the table turns.
    pub(crate) fn table_axis_index(&self) -> Option<usize> {
        let a = self.table_axis.as_deref()?;
        self.gyro.iter().position(|g| g.name == a)
    }

    /// One axis as a single-axis log without pass-through columns (what a fit reads): gyro
    /// `axis`, temperature `temp`, the table rate only when the table turns this axis.
    pub fn axis_data(&self, axis: usize, temp: usize) -> TestLog {
        TestLog {
            time_s: self.time_s.clone(),
            gyro_dps: self.gyro[axis].values.clone(),
            temp_c: self.temp[temp].values.clone(),
            table_dps: (self.table_axis_index() == Some(axis))
                .then(|| self.table.as_ref().map(|t| t.values.clone()))
                .flatten(),
            extra: Vec::new(),
        }
    }

    /// One axis as a single-axis log: gyro `axis` with temperature `temp`; the table rate only
    /// when the table turns this axis (for the others the run is static); the other gyro and
    /// temperature columns and the pass-through ones as pass-through text.
    pub fn axis_log(&self, axis: usize, temp: usize) -> TestLog {
        let text = |s: &NamedSeries| ExtraColumn {
            name: s.name.clone(),
            values: s.values.iter().map(|v| format!("{v}")).collect(),
        };
        let extra = self
            .gyro
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != axis)
            .map(|(_, s)| text(s))
            .chain(
                self.temp
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != temp)
                    .map(|(_, s)| text(s)),
            )
            .chain(self.extra.iter().cloned())
            .collect();
        TestLog {
            extra,
            ..self.axis_data(axis, temp)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(gyros: &[&str], temps: &[&str]) -> ImuLog {
        let series = |n: &&str| NamedSeries {
            name: (*n).to_owned(),
            values: vec![0.0],
        };
        ImuLog {
            time_s: vec![0.0],
            gyro: gyros.iter().map(series).collect(),
            temp: temps.iter().map(series).collect(),
            ..ImuLog::default()
        }
    }

    #[test]
    fn shared_columns_are_the_first_log_s_or_name_the_first_log_that_differs() {
        let a = ("a.csv".to_owned(), unit(&["gx", "gy"], &["t0", "t1"]));
        let b = ("b.csv".to_owned(), unit(&["gx", "gy"], &["t0", "t1"]));
        let c = ("c.csv".to_owned(), unit(&["gx", "gy"], &["t1", "t0"]));
        let none: [(String, ImuLog); 0] = [];
        assert_eq!(ImuLog::shared_columns(&none), Ok(None));
        let want = (
            vec!["gx".into(), "gy".into()],
            vec!["t0".into(), "t1".into()],
        );
        assert_eq!(ImuLog::shared_columns([&a, &b]), Ok(Some(want)));
        // The temperature order differs: another column layout.
        assert_eq!(ImuLog::shared_columns([&a, &b, &c]), Err("c.csv"));
    }
}

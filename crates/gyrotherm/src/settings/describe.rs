//! Every setting of every job, with its default and accepted values, as data: printed by the
//! hidden `gyrotherm settings --json`, exposed to Python as `gyrotherm.settings()`, and
//! compared with `--help` and Python's signatures by the parity test
//! (`crates/gyrotherm-py/tests/test_parity.py`).

use serde::Serialize;

use super::allan::{AllanSettings, KIND_NAMES, TAU_SET_NAMES};
use super::compensate::temp_sensor_defaults;
use super::evaluate::EvaluateSettings;
use super::fit::FitSettings;
use super::method::METHOD_NAMES;
use super::read::{delimiter_name, DELIMITER_NAMES, GYRO_UNIT_NAMES};
use crate::csvlog::{ReadOptions, LOG_FORMAT_NAMES};

/// One setting: its name (the Python keyword; the flag is `--` plus the name with `-` for
/// `_`, except `cross`, whose flag is `--no-cross`), its default as text (None: no default,
/// the setting is optional), and the accepted names (empty: any value of its type).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OptionSpec {
    pub name: &'static str,
    pub default: Option<String>,
    pub values: Vec<&'static str>,
    /// Whether the setting is a switch (a flag without a value on the command line).
    pub switch: bool,
    /// A deprecated spelling, hidden from `--help` (none at present).
    pub deprecated: bool,
    /// Whether a value outside `values` is accepted too (`taus`: a list of seconds;
    /// `delimiter`: other spellings of the same separators).
    pub open: bool,
}

fn opt(name: &'static str, default: Option<String>) -> OptionSpec {
    OptionSpec {
        name,
        default,
        values: Vec::new(),
        switch: false,
        deprecated: false,
        open: false,
    }
}

fn choice(name: &'static str, default: &str, values: &[&'static str]) -> OptionSpec {
    OptionSpec {
        values: values.to_vec(),
        ..opt(name, Some(default.to_owned()))
    }
}

fn switch(name: &'static str, default: bool) -> OptionSpec {
    OptionSpec {
        switch: true,
        ..opt(name, Some(default.to_string()))
    }
}

/// The settings of reading a log (every command that reads one).
pub fn log_options() -> Vec<OptionSpec> {
    let d = ReadOptions::default();
    vec![
        // Which listed gyro column a rate-table log drives (default: the one that follows
        // the table, `csvlog::column_list`); a column name, so no list of values.
        opt("table_axis", None),
        opt("time_col", Some(d.time_col)),
        opt("gyro_col", Some(d.gyro_col)),
        opt("temp_col", Some(d.temp_col)),
        opt("table_col", Some(d.table_col)),
        choice("gyro_unit", d.gyro_unit.as_str(), &GYRO_UNIT_NAMES),
        opt("fill_gaps_max_s", d.fill_gaps_max_s.map(|v| v.to_string())),
        opt("sample_period_s", d.sample_period_s.map(|v| v.to_string())),
        // Open: `comma`, `semicolon`, a literal tab and `\t` are accepted spellings too.
        OptionSpec {
            open: true,
            ..choice("delimiter", delimiter_name(d.delimiter), &DELIMITER_NAMES)
        },
        // No default: the file's extension picks the format.
        OptionSpec {
            values: LOG_FORMAT_NAMES.to_vec(),
            ..opt("format", None)
        },
        opt("instance", Some(d.instance.to_string())),
    ]
}

/// The settings of fitting (`train`; also `compare`, `report`, `demo`).
pub(crate) fn fit_options() -> Vec<OptionSpec> {
    let d = FitSettings::default();
    vec![
        choice("method", d.method.as_str(), &METHOD_NAMES),
        opt("epochs", d.epochs.map(|e| e.to_string())),
        opt("seed", Some(d.seed.to_string())),
        opt("hidden", d.hidden.map(|h| h.to_string())),
        opt("windows", d.windows.map(|w| w.to_string())),
        opt("bias_window_s", Some(d.bias_window_s.to_string())),
        opt("settle_s", Some(d.settle_s.to_string())),
        opt("poly_temp_degree", Some(d.poly_temp_degree.to_string())),
        opt("poly_rate_degree", Some(d.poly_rate_degree.to_string())),
        switch("cross", d.cross),
        switch("validate_on_runs", d.validate_on_runs),
    ]
}

/// The temperature-sensor limits (`train` stores them in the model; `compensate` uses them).
pub(crate) fn sensor_options() -> Vec<OptionSpec> {
    temp_sensor_defaults()
        .into_iter()
        .map(|(name, v)| opt(name, Some(v.to_string())))
        .collect()
}

/// The settings of `allan`.
pub(crate) fn allan_options() -> Vec<OptionSpec> {
    let d = AllanSettings::default();
    vec![
        opt("column", Some(d.column)),
        choice("kind", d.kind.name(), &KIND_NAMES),
        OptionSpec {
            open: true,
            ..choice("taus", &d.taus.to_string(), &TAU_SET_NAMES)
        },
        opt("alpha", d.alpha.map(|a| a.to_string())),
        opt("rostopic", Some(super::kalibr::DEFAULT_ROSTOPIC.to_owned())),
    ]
}

/// The settings of `evaluate`.
pub(crate) fn evaluate_options() -> Vec<OptionSpec> {
    let d = EvaluateSettings::default();
    vec![
        opt("column", Some(d.column)),
        opt("tau_s", d.tau_s.map(|v| v.to_string())),
        opt("settle_s", Some(d.settle_s.to_string())),
        opt("reference_scale", d.reference_scale.map(|v| v.to_string())),
    ]
}

/// The settings of `plan` (the flight log is a setting: the envelope comes from it).
pub(crate) fn plan_options() -> Vec<OptionSpec> {
    let d = super::plan::PlanSettings::default();
    let num = |v: Option<f64>| v.map(|v| v.to_string());
    vec![
        opt("flight", None),
        opt("temp_min_c", num(d.temp_min_c)),
        opt("temp_max_c", num(d.temp_max_c)),
        opt("max_rate_c_per_min", num(d.max_rate_c_per_min)),
        opt("chamber_min_c", num(Some(d.chamber_min_c))),
        opt("chamber_max_c", num(Some(d.chamber_max_c))),
        opt(
            "chamber_max_rate_c_per_min",
            num(Some(d.chamber_max_rate_c_per_min)),
        ),
    ]
}

/// Every job's settings: `train` (fit, sensor limits and log options), `compensate` (log
/// options; the sensor limits come from the model), `allan`, `evaluate` and `plan` (theirs and the
/// log options).
pub fn describe() -> Vec<(&'static str, Vec<OptionSpec>)> {
    let with_log = |mut v: Vec<OptionSpec>| {
        v.extend(log_options());
        v
    };
    vec![
        (
            "train",
            with_log([fit_options(), sensor_options()].concat()),
        ),
        ("compensate", log_options()),
        ("allan", with_log(allan_options())),
        ("evaluate", with_log(evaluate_options())),
        ("plan", with_log(plan_options())),
    ]
}

/// [`describe`] as JSON text: `{"train": [{"name", "default", "values", "switch",
/// "deprecated", "open"}, …], …}`.
pub fn describe_json() -> String {
    let map: serde_json::Map<String, serde_json::Value> = describe()
        .into_iter()
        .map(|(cmd, opts)| {
            (
                cmd.to_owned(),
                serde_json::to_value(opts).unwrap_or(serde_json::Value::Null),
            )
        })
        .collect();
    serde_json::to_string_pretty(&serde_json::Value::Object(map)).unwrap_or_default()
}

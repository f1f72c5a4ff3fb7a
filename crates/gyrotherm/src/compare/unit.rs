//! `compare` on an inertial unit, axis by axis: every method fitted and judged per axis, and
//! the table across axes that `report` and `compare` show.
//!
//! Each axis is judged as a single-axis log ([`axis_test_log`]): its gyro, the sensor its
//! model reads, the table rate only in the runs where the table turns this axis (in the
//! others the axis stands still, so they are static runs for it), and, in a simulated log,
//! the axis's truth columns under the single-axis names (`noise_dps_x` → `noise_dps`) so the
//! noise floor is the axis's own. The single-axis figures and comparison then apply as they
//! are, so a one-axis figure and its per-axis counterpart are the same number.
//!
//! With several temperature columns the comparison fits the unit as `train` with the same
//! lists and fit settings builds it (`fit_imu_with_events`): per axis the sensors
//! cross-validation keeps. Each axis's table then holds every one-sensor method fitted on
//! the sensor that axis's one-sensor choice picks (the sensor whose one-sensor fit has the
//! lowest cross-validated RMS, the unit fit's first sensor; so the one-sensor columns differ
//! only by method), and beside them the unit's own fit of the axis on all the sensors it
//! keeps (`UnitFitColumn`, named for what it holds and how many sensors it reads).

use serde::Serialize;

use crate::compare::{
    compare, performance, CompareConfig, CompareError, Comparison, ComparisonSummary,
    ComparisonTable, Performance, PerformanceError, TableFigure,
};
use crate::compensate::unit::compensate_imu;
use crate::csvlog::{ExtraColumn, ImuLog, TestLog};
use crate::fit::unit::{fit_imu_with_events, ImuEvents, UnitFitError};
use crate::fit::{NamedLog, Target};
use crate::model::unit::{ImuAxis, ImuError, ImuModel};
use crate::model::{ModelFile, TempSensorDef};
use crate::per_thread::on_threads;
use crate::string_table::Table;

/// Why a unit comparison could not be made (told as
/// [`UnitCompareError`](crate::spec::unit::UnitCompareError), variant for variant).
#[derive(Debug)]
pub(crate) enum UnitCompareError {
    /// The comparison of axis `gyro`.
    Compare { gyro: String, source: CompareError },
    /// The unit fit's figures of axis `gyro` on held-out log `log`.
    UnitFit {
        gyro: String,
        log: String,
        source: PerformanceError,
    },
    /// The unit model (compensating with it).
    Unit(ImuError),
    /// Fitting the unit model.
    Fit(UnitFitError),
    /// The logs or settings do not fit together (the message says what to do).
    Layout(String),
}

/// Axis `axis` of a unit log as a single-axis log for judging (see the module doc):
/// gyro `axis`, temperature `temp`, the table rate when the table turns this axis, and the
/// pass-through columns, the axis's truth columns renamed to the single-axis names.
pub fn axis_test_log(log: &ImuLog, axis: usize, temp: usize) -> TestLog {
    let mut out = log.axis_data(axis, temp);
    let suffix = crate::sim::imu::axis_of_gyro_col(&log.gyro[axis].name).map(|a| format!("_{a}"));
    out.extra = log
        .extra
        .iter()
        .map(|c| {
            let base = suffix
                .as_deref()
                .and_then(|s| c.name.strip_suffix(s))
                .filter(|b| !b.is_empty());
            match base {
                Some(b) => ExtraColumn {
                    name: b.to_owned(),
                    values: c.values.clone(),
                },
                None => c.clone(),
            }
        })
        .collect();
    out
}

/// The bias-stability τ of a unit comparison when none was asked for: the single-axis rule
/// ([`crate::compare::default_tau_s`]) on the first axis's view of the held-out logs (every
/// axis shares the time column). Returns τ and, when it is not 100 s, the sample period it
/// is a multiple of.
pub(crate) fn default_tau_s(test: &[(String, ImuLog)]) -> (f64, Option<f64>) {
    // The first axis's view is static unless the table turns that axis with a non-zero rate
    // (`ImuLog::axis_data`, `TestLog::is_static`); read here without copying the log.
    let first_axis_static = |l: &ImuLog| {
        l.table_axis_index() != Some(0)
            || l.table
                .as_ref()
                .is_none_or(|t| t.values.iter().all(|v| *v == 0.0))
    };
    crate::compare::tau_of_runs(
        test.iter()
            .filter(|(_, l)| !l.gyro.is_empty() && !l.temp.is_empty())
            .map(|(_, l)| (l.time_s.as_slice(), first_axis_static(l))),
    )
}

/// The unit's own fit of one axis in a comparison: the model `train` with the same lists
/// builds for it, on every sensor cross-validation keeps.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct UnitFitColumn {
    /// What the model holds and what it reads, e.g. `thermal-state LS (3 sensors: temp_x_c,
    /// temp_case_c, temp_y_c)`.
    pub label: String,
    /// The column's short name in the tables, e.g. `thermal LS, 3 sensors`.
    pub header: String,
    /// The method the unit was fitted with.
    pub method: &'static str,
    /// The temperature columns the axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// Its figures on each held-out log, in order.
    pub performance: Vec<Performance>,
    /// Its compensated rate, °/s, on each held-out log, in order (for a spec verdict and the
    /// report's σ figure; not in the JSON summary).
    #[serde(skip)]
    pub compensated_dps: Vec<Vec<f64>>,
    /// The axis's first-sensor model, which carries the axis's coverage map (its first
    /// sensor's cells, σ scaled to the several-sensor fit): what the report's coverage figures
    /// draw for this axis. Not in the JSON summary.
    #[serde(skip)]
    pub coverage_model: ModelFile,
}

impl UnitFitColumn {
    /// The column of `axis` (fitted with `method`) with its figures per held-out log.
    pub fn new(
        axis: &ImuAxis,
        performance: Vec<Performance>,
        compensated_dps: Vec<Vec<f64>>,
    ) -> Self {
        let n = axis.temps.len();
        let what = axis.model.label();
        let sensors = if n == 1 { "sensor" } else { "sensors" };
        let short = if what == "thermal-state LS" {
            "thermal LS"
        } else {
            what
        };
        UnitFitColumn {
            label: format!("{what} ({n} {sensors}: {})", axis.temps.join(", ")),
            header: format!("{short}, {n} {sensors}"),
            method: axis.model.method.as_str(),
            temps: axis.temps.clone(),
            performance,
            compensated_dps,
            coverage_model: axis.model.clone(),
        }
    }
}

/// One axis of a unit comparison: the single-axis logs it was judged on and the comparison.
#[derive(Debug, Clone)]
pub(crate) struct AxisComparison {
    /// The gyro column.
    pub gyro: String,
    /// The temperature column every one-sensor method of this axis reads.
    pub temp: String,
    /// The unit's own fit of this axis on all the sensors it keeps (with several
    /// temperature columns).
    pub unit_fit: Option<UnitFitColumn>,
    /// The training logs as this axis saw them (name, log).
    pub train: Vec<(String, TestLog)>,
    /// The held-out logs as this axis saw them, in order.
    pub test: Vec<(String, TestLog)>,
    pub comparison: Comparison,
}

impl AxisComparison {
    /// The training logs as named logs (what the single-axis report takes).
    pub(crate) fn train_named(&self) -> Vec<NamedLog<'_>> {
        self.train
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect()
    }

    /// The held-out logs as named logs.
    pub(crate) fn test_named(&self) -> Vec<NamedLog<'_>> {
        self.test
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect()
    }
    /// The axis's results table: the single-axis table, and the unit fit's column beside
    /// the one-sensor methods.
    pub fn table(&self, cfg: &CompareConfig) -> ComparisonTable {
        let mut t = self.comparison.table(cfg);
        if let Some(u) = &self.unit_fit {
            let floors: Vec<Option<f64>> =
                self.comparison.tests.iter().map(|r| r.floor_dph).collect();
            t.push_column(&u.header, &u.performance, &floors);
        }
        t
    }

    /// One line per fitted model, as the single-axis comparison prints them, then the unit
    /// fit's line.
    pub(crate) fn model_lines(&self) -> Vec<String> {
        let mut lines = self.comparison.model_lines();
        if let Some(u) = &self.unit_fit {
            lines.push(format!(
                "{:>16}: the unit's {} fit of this axis as train builds it: {}",
                u.header, u.method, u.label
            ));
        }
        lines
    }
}

/// A unit comparison: one comparison per axis, in gyro column order.
#[derive(Debug, Clone)]
pub(crate) struct ImuComparison {
    pub axes: Vec<AxisComparison>,
}

/// Progress of a unit comparison: axis index, then the comparison's own (column key,
/// target, epoch, loss).
pub(crate) type ImuCompareProgress<'a> =
    dyn Fn(usize, &'static str, Target, usize, f64) + Sync + 'a;

/// `compare` on unit logs: the sensor per axis from the unit fit with `cfg.fit` (skipped
/// with one temperature column; `events` tells its steps), then every column of `cfg`
/// fitted and judged per axis on that sensor, the axes on their own threads.
pub(crate) fn compare_imu(
    train: &[(String, ImuLog)],
    test: &[(String, ImuLog)],
    cfg: &CompareConfig,
    temp_sensor: &TempSensorDef,
    progress: &ImuCompareProgress,
    events: &ImuEvents,
) -> Result<ImuComparison, UnitCompareError> {
    if train.is_empty() {
        return Err(UnitCompareError::Layout("no training logs".into()));
    }
    let (gyro_cols, temp_cols) = ImuLog::shared_columns(train.iter().chain(test))
        .map_err(|n| {
            UnitCompareError::Layout(format!(
                "{n}: every log must be read with the same gyro and temperature columns"
            ))
        })?
        .unwrap_or_default();
    let unit = if temp_cols.len() == 1 {
        None
    } else {
        Some(
            fit_imu_with_events(train, &cfg.fit, temp_sensor, &|_, _, _, _, _| {}, events)
                .map_err(UnitCompareError::Fit)?,
        )
    };
    let sensors: Vec<usize> = unit
        .as_ref()
        .map_or_else(|| vec![0; gyro_cols.len()], ImuModel::sensor_index);
    // The unit's compensated output of every held-out log, all axes at once.
    let unit_out = unit
        .as_ref()
        .map(|m| {
            test.iter()
                .map(|(_, l)| compensate_imu(m, l))
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()
        .map_err(UnitCompareError::Unit)?;
    let axes: Vec<Result<AxisComparison, UnitCompareError>> = on_threads(gyro_cols.len(), |k| {
        let j = sensors[k];
        let per_axis = |logs: &[(String, ImuLog)]| -> Vec<(String, TestLog)> {
            logs.iter()
                .map(|(n, l)| (n.clone(), axis_test_log(l, k, j)))
                .collect()
        };
        let (train, test) = (per_axis(train), per_axis(test));
        let comparison = {
            let tr: Vec<NamedLog> = train
                .iter()
                .map(|(n, l)| NamedLog { name: n, log: l })
                .collect();
            let te: Vec<NamedLog> = test
                .iter()
                .map(|(n, l)| NamedLog { name: n, log: l })
                .collect();
            compare(&tr, &te, cfg, &|key, t, e, l| progress(k, key, t, e, l)).map_err(|source| {
                UnitCompareError::Compare {
                    gyro: gyro_cols[k].clone(),
                    source,
                }
            })?
        };
        let unit_fit = match (unit.as_ref(), unit_out.as_ref()) {
            (Some(m), Some(outs)) => {
                let perf = test
                    .iter()
                    .zip(outs)
                    .map(|((name, l), out)| {
                        performance(l, &out[k].gyro_comp_dps, cfg.tau_s, cfg.settle_s).map_err(
                            |source| UnitCompareError::UnitFit {
                                gyro: gyro_cols[k].clone(),
                                log: name.clone(),
                                source,
                            },
                        )
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let comp = outs.iter().map(|o| o[k].gyro_comp_dps.clone()).collect();
                Some(UnitFitColumn::new(&m.axes[k], perf, comp))
            }
            _ => None,
        };
        Ok(AxisComparison {
            gyro: gyro_cols[k].clone(),
            temp: temp_cols[j].clone(),
            unit_fit,
            train,
            test,
            comparison,
        })
    });
    Ok(ImuComparison {
        axes: axes.into_iter().collect::<Result<Vec<_>, _>>()?,
    })
}

/// The header of the unit fit's column in the table across axes.
pub(crate) const UNIT_FIT_HEADER: &str = "unit fit (axis's sensors)";

/// One axis in `gyrotherm compare --json` for a unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AxisSummary {
    pub gyro: String,
    /// The sensor the one-sensor methods read.
    pub temp: String,
    pub comparison: ComparisonSummary,
    /// The unit's own fit of the axis (several temperature columns): its label, sensors and
    /// figures per held-out log (in the order of `comparison.tests`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit_fit: Option<UnitFitColumn>,
}

/// A unit comparison as `gyrotherm compare --json` prints it: per axis the single-axis
/// summary, then the table across axes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct ImuComparisonSummary {
    pub axes: Vec<AxisSummary>,
    pub across_axes: AcrossAxes,
}

/// The table across axes as JSON: its headers and rows of formatted cells.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AcrossAxes {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl ImuComparison {
    /// `gyrotherm compare --json` of the unit (and Python's `compare`): the
    /// [`summary`](Self::summary), with `verdicts` (each axis's,
    /// [`judge_unit_comparison`](crate::spec::unit::judge_unit_comparison))
    /// when it was judged against a spec.
    pub(crate) fn summary_json<V: Serialize>(
        &self,
        cfg: &CompareConfig,
        verdicts: Option<&[V]>,
    ) -> Result<serde_json::Value, serde_json::Error> {
        let mut j = serde_json::to_value(self.summary(cfg))?;
        if let (Some(v), Some(o)) = (verdicts, j.as_object_mut()) {
            o.insert("verdicts".into(), serde_json::to_value(v)?);
        }
        Ok(j)
    }

    /// The JSON form.
    pub fn summary(&self, cfg: &CompareConfig) -> ImuComparisonSummary {
        let t = self.across_axes(cfg);
        ImuComparisonSummary {
            axes: self
                .axes
                .iter()
                .map(|a| AxisSummary {
                    gyro: a.gyro.clone(),
                    temp: a.temp.clone(),
                    comparison: a.comparison.summary(cfg),
                    unit_fit: a.unit_fit.clone(),
                })
                .collect(),
            across_axes: AcrossAxes {
                headers: t.headers,
                rows: t.rows,
            },
        }
    }

    /// The table across axes (axis × figure): per held-out log and figure (bias stability,
    /// × noise floor, scale-factor error, SF thermal error) one row per axis, with the raw
    /// output, each method (columns named by method, the same for every axis), the unit's own
    /// fit when there is one (`UNIT_FIT_HEADER`: each axis's row reads that axis's sensors)
    /// and the noise floor. The per-rate output ranges stay in the axes' own tables.
    pub fn across_axes(&self, cfg: &CompareConfig) -> Table {
        let mut headers = vec![
            "held-out log".to_owned(),
            "figure".to_owned(),
            "axis".to_owned(),
            "raw".to_owned(),
        ];
        let keys: Vec<&'static str> = cfg.candidates.iter().map(|c| c.key(&cfg.fit)).collect();
        headers.extend(keys.iter().map(|k| (*k).to_owned()));
        // The unit's own fit reads each axis's own sensors (the axes' tables name them).
        if self.axes.iter().any(|a| a.unit_fit.is_some()) {
            headers.push(UNIT_FIT_HEADER.to_owned());
        }
        headers.push("noise floor".to_owned());
        let tables: Vec<_> = self.axes.iter().map(|a| a.table(cfg)).collect();
        let mut rows = Vec::new();
        let n_tests = tables.iter().map(|t| t.blocks.len()).max().unwrap_or(0);
        for b in 0..n_tests {
            // A table run is static for the axes it does not turn, so the axes' blocks of
            // one log may hold different figures: every figure any axis has, in order.
            let mut figures = Vec::new();
            for t in &tables {
                for row in t.blocks.get(b).into_iter().flat_map(|blk| &blk.rows) {
                    let per_rate = matches!(row.figure, TableFigure::OutputAt { .. });
                    if !per_rate && !figures.contains(&row.figure) {
                        figures.push(row.figure);
                    }
                }
            }
            let log = tables
                .iter()
                .find_map(|t| t.blocks.get(b))
                .map_or(String::new(), |blk| blk.log.clone());
            let mut first_row = true;
            for figure in figures {
                let mut first_axis = true;
                for (a, t) in self.axes.iter().zip(&tables) {
                    let Some(r) = t
                        .blocks
                        .get(b)
                        .and_then(|blk| blk.rows.iter().find(|x| x.figure == figure))
                    else {
                        continue;
                    };
                    let mut cells = vec![
                        if first_row {
                            log.clone()
                        } else {
                            String::new()
                        },
                        if first_axis {
                            figure.label()
                        } else {
                            String::new()
                        },
                        a.gyro.clone(),
                    ];
                    first_row = false;
                    first_axis = false;
                    cells.extend(r.cells.iter().cloned());
                    cells.push(r.floor.clone().unwrap_or_default());
                    rows.push(cells);
                }
            }
        }
        Table { headers, rows }
    }
}

/// `t` as aligned text: the header, a rule, the rows (columns padded to their widest cell).
pub(crate) fn write_text_table(w: &mut dyn std::io::Write, t: &Table) -> std::io::Result<()> {
    let n = t
        .headers
        .len()
        .max(t.rows.iter().map(Vec::len).max().unwrap_or(0));
    let mut width = vec![0usize; n];
    for row in std::iter::once(&t.headers).chain(&t.rows) {
        for (i, c) in row.iter().enumerate() {
            width[i] = width[i].max(c.chars().count());
        }
    }
    let line = |w: &mut dyn std::io::Write, row: &[String]| -> std::io::Result<()> {
        let cells: Vec<String> = (0..n)
            .map(|i| {
                let c = row.get(i).map_or("", String::as_str);
                let pad = width[i].saturating_sub(c.chars().count());
                if i < 3 {
                    format!("{c}{}", " ".repeat(pad))
                } else {
                    format!("{}{c}", " ".repeat(pad))
                }
            })
            .collect();
        writeln!(w, "{}", cells.join("  ").trim_end())
    };
    line(w, &t.headers)?;
    writeln!(
        w,
        "{}",
        "-".repeat(width.iter().sum::<usize>() + 2 * n.saturating_sub(1))
    )?;
    for r in &t.rows {
        line(w, r)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csvlog::NamedSeries;

    fn series(name: &str, v: &[f64]) -> NamedSeries {
        NamedSeries {
            name: name.into(),
            values: v.to_vec(),
        }
    }

    /// The unit's τ rule reads each log as the single-gyro rule reads the first axis's view
    /// (`axis_test_log(l, 0, 0)`): a table turning another axis leaves that view static.
    #[test]
    fn unit_tau_is_the_single_rule_on_the_first_axis_view() {
        let log = |period: f64, table: Option<(&str, f64)>| {
            let time_s: Vec<f64> = (0..8).map(|k| k as f64 * period).collect();
            let n = time_s.len();
            ImuLog {
                time_s,
                gyro: vec![series("gx", &vec![0.0; n]), series("gy", &vec![0.0; n])],
                temp: vec![series("t", &vec![20.0; n])],
                table: table.map(|(_, rate)| series("table_dps", &vec![rate; n])),
                table_axis: table.map(|(a, _)| a.to_owned()),
                extra: Vec::new(),
            }
        };
        let cases = [
            // Static at 15 s, table on y at 1 s (static for x): τ from 15 s.
            vec![log(15.0, None), log(1.0, Some(("gy", 10.0)))],
            // Static at 1 s, table on x at 15 s: τ from 1 s.
            vec![log(1.0, None), log(15.0, Some(("gx", 10.0)))],
            // Only a table log on x at 7 s: it counts, no log being static.
            vec![log(7.0, Some(("gx", 10.0)))],
        ];
        let want = [(105.0, Some(15.0)), (100.0, None), (98.0, Some(7.0))];
        for (logs, want) in cases.into_iter().zip(want) {
            let named: Vec<(String, ImuLog)> =
                logs.into_iter().map(|l| ("l".to_owned(), l)).collect();
            let views: Vec<(String, TestLog)> = named
                .iter()
                .map(|(n, l)| (n.clone(), axis_test_log(l, 0, 0)))
                .collect();
            let single: Vec<NamedLog> = views
                .iter()
                .map(|(n, l)| NamedLog { name: n, log: l })
                .collect();
            assert_eq!(crate::compare::default_tau_s(&single), want);
            assert_eq!(default_tau_s(&named), want);
        }
    }

    fn text(name: &str, v: &[&str]) -> ExtraColumn {
        ExtraColumn {
            name: name.into(),
            values: v.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn an_axis_sees_its_own_truth_under_the_single_axis_names() {
        let log = ImuLog {
            time_s: vec![0.0, 1.0],
            gyro: vec![
                series("gyro_x_dps", &[1.0, 2.0]),
                series("gyro_y_dps", &[3.0, 4.0]),
            ],
            temp: vec![series("temp_case_c", &[20.0, 21.0])],
            table: Some(series("table_dps", &[0.0, 20.0])),
            table_axis: Some("gyro_y_dps".into()),
            extra: vec![
                text("noise_dps_x", &["0.1", "0.2"]),
                text("noise_dps_y", &["0.3", "0.4"]),
                text("chamber_temp_c", &["22", "23"]),
            ],
        };
        let y = axis_test_log(&log, 1, 0);
        assert_eq!(y.gyro_dps, [3.0, 4.0]);
        assert_eq!(y.extra_f64("noise_dps"), Some(vec![0.3, 0.4]));
        assert_eq!(y.extra_f64("noise_dps_x"), Some(vec![0.1, 0.2]));
        assert_eq!(y.extra_f64("chamber_temp_c"), Some(vec![22.0, 23.0]));
        assert_eq!(y.table_dps.as_deref(), Some(&[0.0, 20.0][..]));
        let x = axis_test_log(&log, 0, 0);
        assert_eq!(x.extra_f64("noise_dps"), Some(vec![0.1, 0.2]));
        // The table turns y: for x the run is static.
        assert!(x.table_dps.is_none());
        // Gyro names the simulator did not write get no renaming.
        let mut other = log.clone();
        other.gyro[1].name = "gy".into();
        other.table_axis = Some("gy".into());
        assert!(axis_test_log(&other, 1, 0).extra_f64("noise_dps").is_none());
    }

    #[test]
    fn the_table_across_axes_aligns_its_columns() {
        let t = Table {
            headers: vec![
                "held-out log".into(),
                "figure".into(),
                "axis".into(),
                "raw".into(),
            ],
            rows: vec![vec![
                "a.csv".into(),
                "bias".into(),
                "gx".into(),
                "0.5".into(),
            ]],
        };
        let mut out = Vec::new();
        write_text_table(&mut out, &t).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "held-out log  figure  axis  raw");
        assert_eq!(lines[1], "-".repeat(31));
        assert_eq!(lines[2], "a.csv         bias    gx    0.5");
    }
}

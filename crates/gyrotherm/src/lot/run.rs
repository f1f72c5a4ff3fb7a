//! A run: what the station recorded of one unit judged (its inputs, figures, verdicts and
//! axes), and the lot's view of the latest run of each unit.

use serde::Serialize;
use sha2::{Digest, Sha256};

use super::rfc3339_utc;
use crate::spec::unit::UnitVerdict;

/// One input file of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Input {
    /// Position among the run's held-out logs, from 0.
    pub position: u32,
    /// The path as given.
    pub path: String,
    /// SHA-256 of the file's bytes, hex.
    pub sha256: String,
    /// `static` or `rate_table`.
    pub kind: &'static str,
}

/// One measured figure of one held-out log of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureRow {
    /// The [`AxisRecord::axis`] it was measured on, for an inertial unit's run (None for a
    /// single-axis run, stored as axis 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<u32>,
    /// The [`Input::position`] of the log it was measured on.
    pub position: u32,
    /// The figure's key ([`spec::FIGURES`](crate::spec::FIGURES)).
    pub figure: String,
    pub value: f64,
    /// The spec's limits on it, if any.
    pub limit_min: Option<f64>,
    pub limit_max: Option<f64>,
    /// `Some(true)` pass, `Some(false)` fail, `None` not limited.
    pub pass: Option<bool>,
    /// Distance to the nearest limit (positive inside), when limited.
    pub margin: Option<f64>,
}

/// The verdict of a run: `pass`, `fail`, or `none` (judged without a spec).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RunVerdict {
    Pass,
    Fail,
    None,
}

impl RunVerdict {
    /// The word stored in the database.
    pub fn as_str(self) -> &'static str {
        match self {
            RunVerdict::Pass => "pass",
            RunVerdict::Fail => "fail",
            RunVerdict::None => "none",
        }
    }

    pub(super) fn parse(s: &str) -> Option<RunVerdict> {
        match s {
            "pass" => Some(RunVerdict::Pass),
            "fail" => Some(RunVerdict::Fail),
            "none" => Some(RunVerdict::None),
            _ => None,
        }
    }
}

/// One gyro axis of an inertial unit's run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisRecord {
    /// Its position among the unit's axes, from 0 (the model's gyro column order).
    pub axis: u32,
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns the axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// The axis's verdict: `pass` when each limited figure passes on every log that gives
    /// it, `none` when judged without a spec.
    pub verdict: RunVerdict,
}

/// One unit judged once: what a lot records.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Run {
    /// Its id in the store (0 before it is stored); ids grow in the order runs are added.
    pub id: i64,
    /// The unit's serial number.
    pub unit: String,
    /// When it was judged, ms since 1970-01-01 UTC.
    pub tested_at_unix_ms: i64,
    /// The gyrotherm version that judged it.
    pub gyrotherm_version: String,
    /// Which station judged it (host name unless given).
    pub station: String,
    pub model_path: String,
    /// SHA-256 of the model file's bytes.
    pub model_sha256: String,
    /// The model's own `content_sha256` (its content, however it is formatted).
    pub model_content_sha256: String,
    pub model_method: String,
    /// The spec sheet's name, SHA-256 and text, when judged against one.
    pub spec_name: Option<String>,
    pub spec_sha256: Option<String>,
    pub spec_toml: Option<String>,
    pub verdict: RunVerdict,
    /// True for the newest run of its unit (set when read back).
    pub latest: bool,
    pub inputs: Vec<Input>,
    /// An inertial unit's axes (empty for a single-axis run); the run's `verdict` is then the
    /// unit's: `pass` only when every axis passes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub axes: Vec<AxisRecord>,
    pub figures: Vec<FigureRow>,
}

impl Run {
    /// The figure's value on the log where it is worst: the smallest margin when limited,
    /// else the largest magnitude. None when no log of the run gives it.
    pub fn worst(&self, figure: &str) -> Option<&FigureRow> {
        self.figures
            .iter()
            .filter(|f| f.figure == figure)
            .min_by(|a, b| match (a.margin, b.margin) {
                (Some(x), Some(y)) => x.total_cmp(&y),
                _ => b.value.abs().total_cmp(&a.value.abs()),
            })
    }

    /// The test date as RFC 3339 UTC.
    pub fn tested_at(&self) -> String {
        rfc3339_utc(self.tested_at_unix_ms)
    }

    /// Whether this is an inertial unit's run (with axes).
    pub(crate) fn is_unit(&self) -> bool {
        !self.axes.is_empty()
    }

    /// The record of axis `axis` (None: a single-axis run, or no such axis).
    pub fn axis_of(&self, axis: Option<u32>) -> Option<&AxisRecord> {
        let k = axis?;
        self.axes.iter().find(|a| a.axis == k)
    }

    /// The gyro column of axis `axis` (None: a single-axis run, or no such axis).
    pub(crate) fn gyro_of(&self, axis: Option<u32>) -> Option<&str> {
        self.axis_of(axis).map(|a| a.gyro.as_str())
    }
}

/// The unit's verdict from its axes' verdicts: `none` when no axis was judged, else the rule
/// of [`UnitVerdict::from_axes`] (a unit passes only when every axis passes).
pub(crate) fn unit_verdict_of_axes(axes: &[AxisRecord]) -> RunVerdict {
    if axes.iter().all(|a| a.verdict == RunVerdict::None) {
        return RunVerdict::None;
    }
    let v = UnitVerdict::from_axes(
        "",
        "",
        "compensated",
        axes.iter()
            .map(|a| (a.gyro.as_str(), a.verdict != RunVerdict::Fail)),
    );
    RunVerdict::of(Some(v.pass))
}

/// Check a run read back against the rules of its axes and make its figures' axes what the
/// reader expects: a single-axis run has every figure on axis 0 (read back as None); a unit's
/// figures name one of its axes, and its verdict is its axes' ([`unit_verdict_of_axes`]).
pub(crate) fn check_axes(r: &mut Run) -> Result<(), String> {
    let id = r.id;
    if r.axes.is_empty() {
        for f in &mut r.figures {
            if f.axis.is_some_and(|a| a != 0) {
                return Err(format!(
                    "run {id}: figure {} on axis {:?} of a run without axes",
                    f.figure, f.axis
                ));
            }
            f.axis = None;
        }
        return Ok(());
    }
    for f in &r.figures {
        let k = f.axis.unwrap_or(0);
        if !r.axes.iter().any(|a| a.axis == k) {
            return Err(format!(
                "run {id}: figure {} on axis {k}, which the run does not have",
                f.figure
            ));
        }
    }
    let want = unit_verdict_of_axes(&r.axes);
    if r.verdict != want {
        return Err(format!(
            "run {id}: unit verdict {} but its axes give {}",
            r.verdict.as_str(),
            want.as_str()
        ));
    }
    Ok(())
}

/// Mark the newest run of each unit (highest id) as [`Run::latest`].
pub(crate) fn mark_latest(runs: &mut [Run]) {
    let mut newest: std::collections::HashMap<&str, i64> = Default::default();
    for r in runs.iter() {
        let e = newest.entry(r.unit.as_str()).or_insert(r.id);
        *e = (*e).max(r.id);
    }
    let newest: std::collections::HashMap<String, i64> = newest
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    for r in runs.iter_mut() {
        r.latest = newest.get(&r.unit) == Some(&r.id);
    }
}

/// A run with made-up figures, for benchmarks and tests of the stores and the report (no
/// log is read): unit `unit`, dated `tested_at_unix_ms`, a static and a rate-table input, and
/// the bias stability, ARW and thermal scale-factor error drawn from `seed` around typical
/// values, judged against `bias_stability_dph <= 0.02`, `arw_deg_rt_h <= 0.005` and
/// `sf_thermal_error_ppm <= 30`.
pub fn synthetic_run(unit: &str, seed: u64, tested_at_unix_ms: i64) -> Run {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let limits = [
        (0u32, "bias_stability_dph", 0.012, 0.005, 0.02),
        (0, "arw_deg_rt_h", 0.003, 0.001, 0.005),
        (1, "sf_thermal_error_ppm", 18.0, 8.0, 30.0),
    ];
    let mut figures = Vec::new();
    for (position, key, mean, sd, max) in limits {
        let value: f64 = (mean + sd * (rng.gen::<f64>() * 2.0 - 1.0) * 1.7).max(0.0);
        let limit = crate::spec::Limit {
            min: None,
            max: Some(max),
        };
        figures.push(FigureRow {
            axis: None,
            position,
            figure: key.to_string(),
            value,
            limit_min: None,
            limit_max: Some(max),
            pass: Some(limit.passes(value)),
            margin: Some(limit.margin(value)),
        });
    }
    figures.push(FigureRow {
        axis: None,
        position: 0,
        figure: "bias_dph".into(),
        value: rng.gen::<f64>() * 0.2 - 0.1,
        limit_min: None,
        limit_max: None,
        pass: None,
        margin: None,
    });
    // The order the stores read back: by log, then by figure key.
    figures.sort_by(|a, b| (a.position, &a.figure).cmp(&(b.position, &b.figure)));
    let pass = figures.iter().all(|f| f.pass != Some(false));
    let digest = |s: &str| format!("{:x}", Sha256::digest(s.as_bytes()));
    Run {
        id: 0,
        unit: unit.to_string(),
        tested_at_unix_ms,
        gyrotherm_version: env!("CARGO_PKG_VERSION").to_string(),
        station: "synthetic".into(),
        model_path: format!("{unit}/model.json"),
        model_sha256: digest(&format!("{unit}/model")),
        model_content_sha256: digest(&format!("{unit}/content")),
        model_method: "lstm".into(),
        spec_name: Some("synthetic".into()),
        spec_sha256: Some(digest("synthetic spec")),
        spec_toml: Some("[limits]\nbias_stability_dph = { max = 0.02 }\n".into()),
        verdict: if pass {
            RunVerdict::Pass
        } else {
            RunVerdict::Fail
        },
        latest: false,
        inputs: vec![
            Input {
                position: 0,
                path: format!("{unit}/static.csv"),
                sha256: digest(&format!("{unit}/static")),
                kind: "static",
            },
            Input {
                position: 1,
                path: format!("{unit}/table.csv"),
                sha256: digest(&format!("{unit}/table")),
                kind: "rate_table",
            },
        ],
        axes: Vec::new(),
        figures,
    }
}

/// This machine's host name (the default station name), or `unknown`.
pub fn default_station() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .ok()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok().filter(|s| !s.is_empty()))
        .unwrap_or_else(|| "unknown".into())
}

//! Judging a unit for the lot: its held-out logs compensated with its model, every figure
//! measured and judged against the spec sheet.

use std::path::Path;

use serde::Serialize;
use sha2::{Digest, Sha256};

use super::{now_unix_ms, AxisRecord, FigureRow, Input, LotError, Run, RunVerdict};
use crate::compensate::compensate_log;
use crate::csvlog::{ImuLog, LogSet, LogSetForm, TestLog};
use crate::fit::NamedLog;
use crate::metrics::EvaluationOptions;
use crate::model::unit::ImuModel;
use crate::model::ModelFile;
use crate::spec::unit::UnitVerdict;
use crate::spec::{self, MeasureOptions, Spec};
use crate::unit_model::Model;

/// What `judge_unit` needs besides the logs; for an inertial unit (several gyro axes,
/// `judge_imu_unit`) the same with its logs (`ImuUnitInputs`).
#[derive(Debug, Clone)]
pub struct UnitInputs<'a, L = (String, TestLog)> {
    pub unit: &'a str,
    pub station: &'a str,
    pub model_path: &'a Path,
    /// The held-out logs, already read, with the paths they were read from, as given (an
    /// inertial unit's read with the model's columns, [`ImuModel::read_options`]).
    pub tests: &'a [L],
    pub spec: Option<&'a Spec>,
    /// Bias-stability τ, s (None: `compare`'s default for these logs; for an inertial unit
    /// `crate::compare::unit::default_tau_s`).
    pub tau_s: Option<f64>,
    /// Settle time at each table segment start, s.
    pub settle_s: f64,
}

/// `name` if it can name a unit in a lot: not empty, no white space around it, no control
/// character. The stores check every run they record; the judging functions trim the name
/// first, so ` A1 ` and `A1` are one unit.
pub fn check_unit_name(name: &str) -> Result<&str, LotError> {
    let bad = |why| {
        Err(LotError::UnitName {
            name: name.to_owned(),
            why,
        })
    };
    if name.trim().is_empty() {
        bad("is empty")
    } else if name.chars().any(char::is_control) {
        bad("holds a control character")
    } else if name.trim() != name {
        bad("has white space before or after it")
    } else {
        Ok(name)
    }
}

/// SHA-256 of a file's bytes, hex.
pub(crate) fn file_sha256(path: &Path) -> Result<String, LotError> {
    let bytes = std::fs::read(path).map_err(|source| LotError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(format!("{:x}", Sha256::digest(&bytes)))
}

/// Judge one unit: compensate each held-out log with its model, measure every figure, judge
/// against the spec; the [`Run`] to record (dated now), and the spec's verdict when given.
pub(crate) fn judge_unit(u: &UnitInputs) -> Result<(Run, Option<spec::Verdict>), LotError> {
    check_unit_name(u.unit.trim())?;
    let (text, model_sha256) = u.model_text()?;
    let (model, _) = ModelFile::from_json_sealed(&text).map_err(|e| u.model_err(e.into()))?;
    let content = model.content_digest().map_err(|e| u.model_err(e.into()))?;
    let named: Vec<NamedLog> = u
        .tests
        .iter()
        .map(|(p, l)| NamedLog { name: p, log: l })
        .collect();
    let opts = u.measure_options(|| crate::compare::default_tau_s(&named).0);
    let mut inputs = Vec::new();
    let mut measured = Vec::new();
    for (i, (name, log)) in u.tests.iter().enumerate() {
        inputs.push(Input {
            position: i as u32,
            path: name.clone(),
            sha256: file_sha256(Path::new(name))?,
            kind: if log.is_static() {
                "static"
            } else {
                "rate_table"
            },
        });
        let comp = compensate_log(&model, log).map_err(|e| u.model_err(e.into()))?;
        let f =
            spec::measure(log, &comp.gyro_comp_dps, &opts).map_err(|source| LotError::Measure {
                log: name.clone(),
                source,
            })?;
        measured.push((name.clone(), f));
    }
    let verdict = match u.spec {
        Some(s) => Some(spec::judge(s, &measured).map_err(LotError::Spec)?),
        None => None,
    };
    let mut figures = Vec::new();
    for (i, (_, f)) in measured.iter().enumerate() {
        for (&key, &value) in f {
            figures.push(u.figure_row(None, i, key, value));
        }
    }
    let run = u.run(
        model_sha256,
        content,
        model.method.as_str().to_string(),
        RunVerdict::of(verdict.as_ref().map(|v| v.pass)),
        inputs,
        Vec::new(),
        figures,
    );
    Ok((run, verdict))
}

/// What [`judge_imu_unit`] needs besides the logs: an inertial unit's [`UnitInputs`].
pub(crate) type ImuUnitInputs<'a> = UnitInputs<'a, (String, ImuLog)>;

impl<L> UnitInputs<'_, L> {
    /// A model error in [`UnitInputs::model_path`].
    fn model_err(&self, source: Box<dyn std::error::Error + Send + Sync>) -> LotError {
        LotError::Model {
            path: self.model_path.to_path_buf(),
            source,
        }
    }

    /// The model file's text and the SHA-256 of its bytes.
    fn model_text(&self) -> Result<(String, String), LotError> {
        let text = crate::input_file::read_capped_to_string(
            self.model_path,
            crate::input_file::InputKind::Model,
        )
        .map_err(|source| LotError::Read {
            path: self.model_path.to_path_buf(),
            source,
        })?;
        let sha = format!("{:x}", Sha256::digest(text.as_bytes()));
        Ok((text, sha))
    }

    /// How each figure is measured: τ (`tau_s` when given, else the default for the logs)
    /// and the settle time.
    fn measure_options(&self, default_tau_s: impl FnOnce() -> f64) -> MeasureOptions {
        MeasureOptions {
            evaluation: EvaluationOptions {
                tau_s: self.tau_s.unwrap_or_else(default_tau_s),
                settle_s: self.settle_s,
                reference_scale: None,
            },
            noise_terms: true,
        }
    }

    /// A figure's row, with the spec's limit for it and its verdict when a spec is given.
    fn figure_row(&self, axis: Option<u32>, position: usize, key: &str, value: f64) -> FigureRow {
        let limit = self.spec.and_then(|s| s.limit(key));
        FigureRow {
            axis,
            position: position as u32,
            figure: key.to_string(),
            value,
            limit_min: limit.and_then(|l| l.min),
            limit_max: limit.and_then(|l| l.max),
            pass: limit.map(|l| l.passes(value)),
            margin: limit.map(|l| l.margin(value)),
        }
    }

    /// The [`Run`] of this unit, dated now, with what the judging found.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        model_sha256: String,
        model_content_sha256: String,
        model_method: String,
        verdict: RunVerdict,
        inputs: Vec<Input>,
        axes: Vec<AxisRecord>,
        figures: Vec<FigureRow>,
    ) -> Run {
        Run {
            id: 0,
            unit: self.unit.trim().to_string(),
            tested_at_unix_ms: now_unix_ms(),
            gyrotherm_version: env!("CARGO_PKG_VERSION").to_string(),
            station: self.station.to_string(),
            model_path: self.model_path.display().to_string(),
            model_sha256,
            model_content_sha256,
            model_method,
            spec_name: self.spec.map(|s| s.name.clone()),
            spec_sha256: self.spec.map(|s| s.sha256.clone()),
            spec_toml: self.spec.map(|s| s.text.clone()),
            verdict,
            latest: false,
            inputs,
            axes,
            figures,
        }
    }
}

impl RunVerdict {
    /// Pass or fail as judged, none without a spec.
    pub(super) fn of(pass: Option<bool>) -> RunVerdict {
        match pass {
            Some(true) => RunVerdict::Pass,
            Some(false) => RunVerdict::Fail,
            None => RunVerdict::None,
        }
    }
}

/// The verdict of an inertial unit's run: each axis's (in the model's order, with its gyro
/// column) and the unit's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImuRunVerdict {
    pub axes: Vec<(String, spec::Verdict)>,
    pub unit: UnitVerdict,
}

/// Judge an inertial unit: compensate each held-out log with the unit's model, measure every
/// figure of each axis (`crate::spec::unit::measure_unit`, as `evaluate --model` measures
/// it), judge each axis and the unit against the spec
/// (`crate::spec::unit::judge_unit_figures`); the [`Run`] to record (dated now, a row per
/// axis in [`Run::axes`], each figure with its axis) and the verdicts when a spec is given.
pub(crate) fn judge_imu_unit(u: &ImuUnitInputs) -> Result<(Run, Option<ImuRunVerdict>), LotError> {
    check_unit_name(u.unit.trim())?;
    let (text, model_sha256) = u.model_text()?;
    let model = ImuModel::from_json(&text).map_err(|e| u.model_err(e.into()))?;
    let content = model.content_digest().map_err(|e| u.model_err(e.into()))?;
    let opts = u.measure_options(|| crate::compare::unit::default_tau_s(u.tests).0);
    let mut inputs = Vec::with_capacity(u.tests.len());
    for (i, (path, log)) in u.tests.iter().enumerate() {
        inputs.push(Input {
            position: i as u32,
            path: path.clone(),
            sha256: file_sha256(Path::new(path))?,
            kind: if log.table.is_none() {
                "static"
            } else {
                "rate_table"
            },
        });
    }
    let measured =
        crate::spec::unit::measure_unit(&model, u.tests, &opts).map_err(LotError::Unit)?;
    let verdict = match u.spec {
        Some(s) => {
            let (axes, unit) =
                crate::spec::unit::judge_unit_figures(s, &measured).map_err(LotError::Unit)?;
            Some(ImuRunVerdict {
                axes: measured.iter().map(|a| a.gyro.clone()).zip(axes).collect(),
                unit,
            })
        }
        None => None,
    };
    let mut figures = Vec::new();
    let mut axes = Vec::with_capacity(measured.len());
    for (k, a) in measured.iter().enumerate() {
        for (i, (_, f)) in a.measured.iter().enumerate() {
            for (&key, &value) in f {
                figures.push(u.figure_row(Some(k as u32), i, key, value));
            }
        }
        axes.push(AxisRecord {
            axis: k as u32,
            gyro: a.gyro.clone(),
            temps: a.temps.clone(),
            verdict: RunVerdict::of(verdict.as_ref().map(|v| v.axes[k].1.pass)),
        });
    }
    let mut methods: Vec<&str> = Vec::new();
    for a in &model.axes {
        let m = a.model.method.as_str();
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    let run = u.run(
        model_sha256,
        content,
        methods.join(","),
        RunVerdict::of(verdict.as_ref().map(|v| v.unit.pass)),
        inputs,
        axes,
        figures,
    );
    Ok((run, verdict))
}

/// The verdict of a run judged through [`judge_model`], in the shape its model gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelRunVerdict {
    /// A single-gyro model's one verdict.
    Axis(spec::Verdict),
    /// An inertial unit's verdicts, per axis and the unit's.
    Unit(ImuRunVerdict),
}

impl ModelRunVerdict {
    /// The verdicts to print, each under its heading when the run has axes of its own
    /// (`axis K (GYRO) against the spec:`), then the unit's line when it has one.
    pub fn parts(&self) -> (Vec<(Option<String>, &spec::Verdict)>, Option<String>) {
        match self {
            ModelRunVerdict::Axis(v) => (vec![(None, v)], None),
            ModelRunVerdict::Unit(v) => (
                v.axes
                    .iter()
                    .enumerate()
                    .map(|(k, (gyro, axis))| {
                        (
                            Some(format!("axis {} ({gyro}) against the spec:", k + 1)),
                            axis,
                        )
                    })
                    .collect(),
                Some(v.unit.line(v.axes.len())),
            ),
        }
    }
}

/// Judge one unit with its model of either form (`judge_unit` for a single-gyro model,
/// `judge_imu_unit` for an inertial unit's) on its held-out logs (read in the model's form,
/// [`Model::read_logs`]); `u` says the rest (its `tests` are not read).
pub fn judge_model(
    model: &Model,
    u: &UnitInputs<'_, ()>,
    logs: &LogSet,
) -> Result<(Run, Option<ModelRunVerdict>), LotError> {
    fn with<'a, L>(u: &UnitInputs<'a, ()>, tests: &'a [L]) -> UnitInputs<'a, L> {
        UnitInputs {
            unit: u.unit,
            station: u.station,
            model_path: u.model_path,
            tests,
            spec: u.spec,
            tau_s: u.tau_s,
            settle_s: u.settle_s,
        }
    }
    match (model.is_unit(), logs.form()) {
        (true, LogSetForm::Unit(tests)) => {
            let (run, v) = judge_imu_unit(&with(u, tests))?;
            Ok((run, v.map(ModelRunVerdict::Unit)))
        }
        (false, LogSetForm::Single(tests)) => {
            let (run, v) = judge_unit(&with(u, tests))?;
            Ok((run, v.map(ModelRunVerdict::Axis)))
        }
        (unit, _) => Err(LotError::Model {
            path: u.model_path.to_path_buf(),
            source: if unit {
                "an inertial unit's model judges a unit's logs, read with its columns".into()
            } else {
                "a single-axis model; --gyro-col/--temp-col lists need an inertial unit's \
                 model (`gyrotherm train` with the same lists), whose columns lot add then reads"
                    .into()
            },
        }),
    }
}
